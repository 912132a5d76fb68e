"""Transport on loopback: lockstep step round trips (1 and 8 controllers) against a raw pyzmq
REQ/REP ping-pong floor measured in the same run, world steps/s vs controllers, and point-cloud
topic throughput against a raw PUB/SUB floor. Server, floors and controllers are separate
processes (``python -m sensorium.benchmarks.transport ROLE …``)."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

from .common import Config, Plot, Section, Series, Table, Target, fmt_growth, fmt_time, growth, median, pct

ENV = {**os.environ, "PYTHONUNBUFFERED": "1"}


# ============================================================================ subprocess roles
def _role_rep_echo(endpoint: str) -> None:
    """Raw pyzmq REP: echo every message (the floor of any request/reply round trip)."""
    import zmq

    ctx = zmq.Context()
    s = ctx.socket(zmq.REP)
    port = s.bind_to_random_port(endpoint)
    print(f"ready {endpoint}:{port}", flush=True)
    poller = zmq.Poller()
    poller.register(s, zmq.POLLIN)
    while True:
        if not poller.poll(10_000):
            break                                    # idle for 10 s: the parent is gone
        msg = s.recv()
        if msg == b"quit":
            s.send(b"bye")
            break
        s.send(msg)
    s.close(0)
    ctx.term()


def _role_router_echo(endpoint: str) -> None:
    """A minimal Python msgpack server on a ROUTER: answer every request with a step-like ok reply.
    With the client library on the other end, it is the floor of a Python request/reply round trip."""
    import msgpack
    import zmq

    ctx = zmq.Context()
    s = ctx.socket(zmq.ROUTER)
    port = s.bind_to_random_port(endpoint)
    print(f"ready {endpoint}:{port}", flush=True)
    poller = zmq.Poller()
    poller.register(s, zmq.POLLIN)
    while poller.poll(10_000):
        frames = s.recv_multipart()
        req = msgpack.unpackb(frames[-1], raw=False)
        if req.get("service") == "quit":
            break
        body = msgpack.packb({"id": req["id"], "ok": True, "result": {"status": 0, "time_ms": 0, "values": {}}},
                             use_bin_type=True)
        s.send_multipart(frames[:-1] + [body])
    s.close(0)
    ctx.term()


def _chunks(call, close) -> None:
    """Serve timing requests from stdin: 'run K' → K timed calls, printed as a JSON list of
    seconds; anything else → ``close()`` and stop. (Lets the parent interleave several clients.)"""
    for _ in range(200):
        call()
    print("ready", flush=True)
    for line in sys.stdin:
        parts = line.split()
        if not parts or parts[0] != "run":
            break
        out = np.empty(int(parts[1]))
        for i in range(len(out)):
            t0 = time.perf_counter()
            call()
            out[i] = time.perf_counter() - t0
        print(json.dumps(out.tolist()), flush=True)
    close()


def _role_conn_client(endpoint: str) -> None:
    """The client library's Connection calling a step-like service."""
    from sensorium.client.connection import Connection

    conn = Connection(endpoint, timeout=30)
    args = {"duration": 8}

    def close():
        conn.send("quit", {})
        conn.close()

    _chunks(lambda: conn.call("/c0/robot/step", args), close)


def _role_dealer_client(endpoint: str) -> None:
    """A bare DEALER: pack, send, blocking recv, unpack."""
    import msgpack
    import zmq

    ctx = zmq.Context()
    s = ctx.socket(zmq.DEALER)
    s.connect(endpoint)
    body = msgpack.packb({"id": 7, "service": "/c0/robot/step", "args": {"duration": 8}}, use_bin_type=True)

    def call():
        s.send(body)
        msgpack.unpackb(s.recv(), raw=False)

    def close():
        s.send(msgpack.packb({"id": 0, "service": "quit", "args": {}}))
        s.close(0)
        ctx.term()

    _chunks(call, close)


def _role_req(endpoint: str) -> None:
    """Raw pyzmq REQ ping-pong of a step request's size."""
    import zmq

    ctx = zmq.Context()
    s = ctx.socket(zmq.REQ)
    s.connect(endpoint)
    msg = b"\x83\xa2id\x01\xa7service\xaa/c0/robot/step\xa4args\x81\xa8duration\x08"

    def call():
        s.send(msg)
        s.recv()

    def close():
        s.send(b"quit")
        s.recv()
        s.close(0)
        ctx.term()

    _chunks(call, close)


def _role_stepper(rpc: str, robot: str, duration: str) -> None:
    """A Sensorium controller (client library ``Connection``) stepping its robot in lockstep."""
    from sensorium.client.connection import Connection

    conn = Connection(rpc, timeout=30)
    session = conn.call("attach", {"robot": robot})["session"]
    service, args = f"/{robot}/robot/step", {"duration": int(duration)}

    def close():
        conn.call("detach", {"session": session})
        conn.close()

    _chunks(lambda: conn.call(service, args), close)


def _role_pub(endpoint: str, size: str, count: str) -> None:
    """Raw pyzmq PUB: wait for a subscriber, then publish ``count`` messages of ``size`` bytes."""
    import zmq

    ctx = zmq.Context()
    s = ctx.socket(zmq.XPUB)
    s.setsockopt(zmq.SNDHWM, 100)
    port = s.bind_to_random_port(endpoint)
    print(f"ready {endpoint}:{port}", flush=True)
    if not s.poll(20_000):
        return
    s.recv()                                         # the subscription
    body = os.urandom(int(size))
    for i in range(int(count)):
        s.send_multipart([b"/pc\0", i.to_bytes(8, "little"), body])
    s.send_multipart([b"/pc\0", b"end", b""])
    time.sleep(1.0)
    s.close(0)
    ctx.term()


def _role_controller(rpc: str, robot: str, steps: str, duration: str) -> None:
    """A controller: attach, say 'ready', wait for 'go' on stdin, step ``steps`` times as fast as
    the lockstep allows, print the send/reply times (time.monotonic, comparable across processes)."""
    from sensorium.client.connection import Connection

    conn = Connection(rpc, timeout=60)
    conn.call("attach", {"robot": robot})
    print("ready", flush=True)
    sys.stdin.readline()
    n, d = int(steps), int(duration)
    t0 = np.empty(n)
    t1 = np.empty(n)
    service = f"/{robot}/robot/step"
    args = {"duration": d}
    for i in range(n):
        t0[i] = time.monotonic()
        conn.call(service, args)
        t1[i] = time.monotonic()
    print(json.dumps({"t0": t0.tolist(), "t1": t1.tolist()}), flush=True)
    conn.close()


def main(argv: list[str]) -> None:
    roles = {"rep-echo": _role_rep_echo, "req": _role_req, "router-echo": _role_router_echo,
             "conn-client": _role_conn_client, "dealer-client": _role_dealer_client, "stepper": _role_stepper, "pub": _role_pub, "controller": _role_controller}
    roles[argv[0]](*argv[1:])


# ============================================================================ process helpers
class Proc:
    def __init__(self, args: list[str], stdin: bool = False):
        self.p = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=ENV,
                                  stdin=subprocess.PIPE if stdin else subprocess.DEVNULL)
        self.err: list[str] = []
        threading.Thread(target=self._drain_err, daemon=True).start()

    def _drain_err(self) -> None:
        for line in self.p.stderr:
            self.err.append(line.rstrip())

    def line(self, timeout: float = 30.0) -> str:
        out: list[str] = []
        t = threading.Thread(target=lambda: out.append(self.p.stdout.readline()), daemon=True)
        t.start()
        t.join(timeout)
        if not out or not out[0]:
            raise RuntimeError(f"no output from {self.p.args[-4:]} (stderr: {' | '.join(self.err[-5:])})")
        return out[0].strip()

    def send(self, text: str) -> None:
        self.p.stdin.write(text + "\n")
        self.p.stdin.flush()

    def stop(self) -> None:
        if self.p.poll() is None:
            self.p.terminate()
            try:
                self.p.wait(5)
            except subprocess.TimeoutExpired:
                self.p.kill()
                self.p.wait(5)


def _role_args(*args: str) -> list[str]:
    return [sys.executable, "-m", "sensorium.benchmarks.transport", *args]


class Server:
    """``sensorium serve`` on ephemeral loopback ports."""

    def __init__(self, world: dict, tmp: Path, precision: str = "exact"):
        path = tmp / "world.json"
        path.write_text(json.dumps(world))
        self.proc = Proc([sys.executable, "-m", "sensorium", "serve", str(path), "--rpc", "tcp://127.0.0.1:0",
                          "--pub", "tcp://127.0.0.1:0", "--precision", precision])
        line = self.proc.line(60)
        fields = dict(part.split("=", 1) for part in line.split() if "=" in part)
        self.rpc, self.pub = fields["rpc"], fields["pub"]

    def stop(self) -> None:
        self.proc.p.send_signal(2)
        try:
            self.proc.p.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.stop()


def _robots_world(n: int, devices: list[dict] | None = None, step: int = 8) -> dict:
    return {"world_info": {"name": "bench-transport", "basic_time_step": step},
            "solids": [{"name": "floor", "geometry": {"type": "plane", "size": None}}],
            "robots": [{"name": f"c{i}", "pose": {"translation": [float(i), 0.0, 0.05]},
                        "devices": devices if (devices and i == 0) else []} for i in range(n)]}


# ============================================================================ measurements
def round_trips(tmp: Path, n: int, rounds: int) -> dict[str, np.ndarray]:
    """Four request/reply clients, each its own process against its own server process, timed in
    alternating chunks (so load from other jobs hits all of them alike):
    raw REQ ↔ REP echo (the floor), bare DEALER ↔ minimal Python msgpack ROUTER, the client library's
    ``Connection`` ↔ that ROUTER, and a Sensorium controller ↔ ``sensorium serve`` (lockstep, 1 robot)."""
    servers: list = []
    clients: dict[str, Proc] = {}
    try:
        rep = Proc(_role_args("rep-echo", "tcp://127.0.0.1"))
        servers.append(rep)
        rep_ep = rep.line().split()[1]
        router = Proc(_role_args("router-echo", "tcp://127.0.0.1"))
        servers.append(router)
        router_ep = router.line().split()[1]
        sens = Server(_robots_world(1), tmp)
        servers.append(sens)
        clients = {
            "floor": Proc(_role_args("req", rep_ep), stdin=True),
            "bare": Proc(_role_args("dealer-client", router_ep), stdin=True),
            "conn": Proc(_role_args("conn-client", router_ep), stdin=True),
            "sensorium": Proc(_role_args("stepper", sens.rpc, "c0", "8"), stdin=True),
        }
        for c in clients.values():
            if c.line(60) != "ready":
                raise RuntimeError("client not ready")
        out: dict[str, list] = {k: [] for k in clients}
        chunk = max(1, n // rounds)
        for _ in range(rounds):
            for k, c in clients.items():
                c.send(f"run {chunk}")
                out[k] += json.loads(c.line(120))
        for c in clients.values():
            c.send("quit")
        return {k: np.asarray(v) for k, v in out.items()}
    finally:
        for c in clients.values():
            try:
                c.p.wait(5)
            except subprocess.TimeoutExpired:
                c.stop()
        for srv in servers:
            srv.stop()


def lockstep_multi(rpc: str, k: int, steps: int, step: int = 8) -> dict:
    """``k`` controller processes stepping in lockstep; round trips and world steps/s."""
    procs = [Proc(_role_args("controller", rpc, f"c{i}", str(steps), str(step)), stdin=True) for i in range(k)]
    try:
        for p in procs:
            if p.line(60) != "ready":
                raise RuntimeError("controller did not attach")
        for p in procs:
            p.send("go")
        res = [json.loads(p.line(300)) for p in procs]
    finally:
        for p in procs:
            p.stop()
    t0 = [np.asarray(r["t0"]) for r in res]
    t1 = [np.asarray(r["t1"]) for r in res]
    rtt = np.concatenate([b - a for a, b in zip(t0, t1)])
    # steady state: the window in which every controller was stepping; skip each one's first 10 %
    lo = max(a[len(a) // 10] for a in t0)
    hi = min(b[-1] for b in t1)
    counts = [np.sum((b >= lo) & (b <= hi)) for b in t1]
    steps_per_s = float(np.mean(counts)) / (hi - lo) if hi > lo else float("nan")
    return {"rtt": rtt, "steps_per_s": steps_per_s, "window_s": hi - lo}


def pubsub_floor(size: int, count: int) -> dict:
    import zmq

    pub = Proc(_role_args("pub", "tcp://127.0.0.1", str(size), str(count)))
    try:
        endpoint = pub.line().split()[1]
        ctx = zmq.Context()
        s = ctx.socket(zmq.SUB)
        s.setsockopt(zmq.RCVHWM, 1000)
        s.connect(endpoint)
        s.setsockopt(zmq.SUBSCRIBE, b"/pc\0")
        got, nbytes, t_first, t_last = 0, 0, None, None
        while s.poll(10_000):
            frames = s.recv_multipart()
            if frames[1] == b"end":
                break
            now = time.perf_counter()
            t_first = t_first or now
            t_last = now
            got += 1
            nbytes += sum(len(f) for f in frames)
        s.close(0)
        ctx.term()
    finally:
        pub.stop()
    dt = (t_last - t_first) if got > 1 else float("nan")
    return {"messages": got, "sent": count, "msgs_per_s": (got - 1) / dt, "mb_per_s": nbytes / dt / 1e6}


def point_cloud_topic(tmp: Path, W: int, L: int, steps: int, precision: str) -> dict:
    """Server with one lidar whose point cloud topic a SUB socket here demands; a controller
    process steps as fast as the lockstep allows; messages/s, MB/s and drops (seq gaps)."""
    import msgpack
    import zmq

    from sensorium.client.connection import Connection

    lidar = {"device": "Lidar", "name": "lidar", "horizontal_resolution": W, "number_of_layers": L,
             "field_of_view": 2 * math.pi, "vertical_field_of_view": 0.5, "max_range": 20.0, "type": "fixed"}
    world = _robots_world(1, [lidar], step=32)
    world["solids"] += [{"name": "wall", "pose": {"translation": [3.0, 0.0, 1.0]},
                         "geometry": {"type": "box", "size": [0.2, 8.0, 2.0]}}]
    server = Server(world, tmp, precision)
    try:
        ctx = zmq.Context()
        sub = ctx.socket(zmq.SUB)
        sub.setsockopt(zmq.RCVHWM, 1000)
        sub.connect(server.pub)
        topic = b"/c0/lidar/point_cloud\0"
        sub.setsockopt(zmq.SUBSCRIBE, topic)
        probe = Connection(server.rpc, timeout=10)
        deadline = time.monotonic() + 10
        while topic not in probe.call("get_counters").get("subscriptions", []):
            if time.monotonic() > deadline:
                raise RuntimeError("subscription never became active")
            time.sleep(0.02)
        probe.close()
        ctl = Proc(_role_args("controller", server.rpc, "c0", str(steps), "32"), stdin=True)
        try:
            ctl.line(60)
            ctl.send("go")
            got, nbytes, seqs, t_first, t_last = 0, 0, [], None, None
            while got < steps and sub.poll(15_000):
                frames = sub.recv_multipart()
                now = time.perf_counter()
                t_first = t_first or now
                t_last = now
                got += 1
                nbytes += sum(len(f) for f in frames)
                seqs.append(msgpack.unpackb(frames[1])["seq"])
            res = json.loads(ctl.line(120))
        finally:
            ctl.stop()
        sub.close(0)
        ctx.term()
    finally:
        server.stop()
    dt = (t_last - t_first) if got > 1 else float("nan")
    rtt = np.asarray(res["t1"]) - np.asarray(res["t0"])
    gaps = int(np.sum(np.diff(seqs) - 1)) if len(seqs) > 1 else 0
    return {"messages": got, "steps": steps, "msgs_per_s": (got - 1) / dt, "mb_per_s": nbytes / dt / 1e6,
            "bytes_per_msg": nbytes / max(got, 1), "points": W * L, "dropped": gaps + (steps - got),
            "step_rtt_median_s": float(np.median(rtt))}


def server_cpu_per_step(k: int, steps: int) -> dict:
    """The server's Python per world step without sockets: ``Core.handle`` of k step requests,
    ``step_once`` (simulation step + lockstep + replies), as the transport loop runs them."""
    from sensorium.schemas.wire import pack
    from sensorium.server.daemon.services import Core

    from .common import make_sim

    core = Core(make_sim(_robots_world(k)), log=lambda line: None)
    ids = [f"peer{i}".encode() for i in range(k)]
    for i, ident in enumerate(ids):
        core.handle([ident, pack({"id": 1, "service": "attach", "args": {"robot": f"c{i}"}})], time.monotonic())
    bodies = [pack({"id": 2, "service": f"/c{i}/robot/step", "args": {"duration": 8}}) for i in range(k)]
    t_handle = t_step = 0.0
    for _ in range(steps):
        now = time.monotonic()
        t0 = time.perf_counter()
        for ident, body in zip(ids, bodies):
            core.handle([ident, body], now)
        t1 = time.perf_counter()
        replies, _ = core.step_once(now)
        t2 = time.perf_counter()
        assert len(replies) == k
        t_handle += t1 - t0
        t_step += t2 - t1
    return {"handle_s": t_handle / steps, "step_once_s": t_step / steps, "total_s": (t_handle + t_step) / steps}


# ============================================================================ section
def run(cfg: Config) -> Section:
    sec = Section("transport", "Transport: lockstep and topics on loopback", intro=(
        "Everything over TCP on 127.0.0.1, each party its own process: `sensorium serve` (ROUTER + XPUB), "
        "controllers using the client library's `Connection` (DEALER), and raw pyzmq floors measured in "
        "the same run. The lockstep worlds have robots without devices, so a step costs the simulation "
        "almost nothing and the round trip is transport + request handling + lockstep bookkeeping. "
        "On 2 cores, 8 controller processes and the server share the CPU."))
    n = cfg.pick(3000, 300)
    t_all = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        rt = round_trips(Path(tmp), n, cfg.pick(10, 3))
    floor, bare, pyfloor, single = rt["floor"], rt["bare"], rt["conn"], rt["sensorium"]
    cfg.log(f"  transport: REQ/REP floor p50 {fmt_time(median(floor))}, Sensorium 1 controller {fmt_time(median(single))}")
    rows, data = [], {}
    data["reqrep_floor"] = {"p50_s": median(floor), "p99_s": pct(floor, 99)}
    data["python_floor_bare"] = {"p50_s": median(bare), "p99_s": pct(bare, 99)}
    data["python_floor"] = {"p50_s": median(pyfloor), "p99_s": pct(pyfloor, 99)}
    data["single"] = {"p50_s": median(single), "p99_s": pct(single, 99), "steps_per_s": 1.0 / float(np.mean(single))}
    for label, xs in (("raw pyzmq REQ/REP ping-pong (floor)", floor),
                      ("bare DEALER (msgpack, blocking recv) ↔ minimal Python msgpack ROUTER", bare),
                      ("client library `Connection` ↔ minimal Python msgpack ROUTER (no lockstep)", pyfloor),
                      ("Sensorium lockstep step, 1 controller (`Connection` ↔ `sensorium serve`)", single)):
        sps_col = f"{1.0 / float(np.mean(xs)):,.0f}" if xs is single else "–"
        rows.append([label, 1, fmt_time(median(xs)), fmt_time(pct(xs, 99)), sps_col, f"{median(xs) / median(floor):.2f}×"])
    steps_multi = cfg.pick(2000, 200)
    ks = cfg.pick([1, 2, 4, 8], [8])
    sps = {}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for k in ks:
            server = Server(_robots_world(k), tmp)
            try:
                m = lockstep_multi(server.rpc, k, steps_multi)
            finally:
                server.stop()
            sps[k] = m["steps_per_s"]
            data[f"multi_{k}"] = {"p50_s": median(m["rtt"]), "p99_s": pct(m["rtt"], 99), "steps_per_s": m["steps_per_s"]}
            rows.append([f"steps/s sweep: {k} controller process{'es' if k > 1 else ''} started together", k,
                         fmt_time(median(m["rtt"])), fmt_time(pct(m["rtt"], 99)), f"{m['steps_per_s']:,.0f}",
                         f"{median(m['rtt']) / median(floor):.2f}×"])
            cfg.log(f"  transport: {k} controllers {m['steps_per_s']:.0f} steps/s, p50 {fmt_time(median(m['rtt']))}")
        g = growth(list(sps), [1.0 / v for v in sps.values()])
        sec.tables.append(Table("lockstep", "Lockstep step round trip and world steps/s", [
            "what", "controllers", "round trip p50", "round trip p99", "world steps/s", "p50 ÷ REQ/REP floor"], rows, [
            f"Every client and server is its own process. The first four rows ({n:,} round trips each) were timed in "
            "alternating chunks, so their ratios share the same machine load; the controller-process rows "
            f"({steps_multi:,} steps per process) ran one after another, all controllers started together. World steps/s: steps every controller completed inside the window where all were stepping "
            "(each one's first 10 % skipped).",
            f"Time per world step vs controllers: {fmt_growth(g)}.",
        ]))
        cpu = {k: server_cpu_per_step(k, cfg.pick(3000, 500)) for k in (1, 8)}
        data["server_cpu"] = {str(k): v for k, v in cpu.items()}
        sec.tables.append(Table("server_cpu", "Server-side Python per world step (no sockets)", [
            "controllers", "handle step requests", "step_once (sim + lockstep + replies)", "total", "ceiling steps/s"], [
            [k, fmt_time(v["handle_s"]), fmt_time(v["step_once_s"]), fmt_time(v["total_s"]), f"{1 / v['total_s']:,.0f}"]
            for k, v in cpu.items()], [
            "`Core.handle` + `Core.step_once` called directly, as the transport loop calls them: what the server "
            "spends per world step before any socket work. 'ceiling' = 1 / total, the rate one core could sustain.",
        ]))
        sec.plots.append(Plot("lockstep", "World steps/s vs controllers in lockstep", "controllers", "world steps/s",
                              [Series("world steps/s", [float(k) for k in sps], list(sps.values()))], logy=False))
        data["steps_per_s"] = {str(k): v for k, v in sps.items()}
        data["controllers_growth"] = g

        # point-cloud topic throughput vs a raw PUB/SUB of the same size
        W, L = cfg.pick((1024, 16), (512, 16))
        pc_steps = cfg.pick(300, 40)
        pc = point_cloud_topic(tmp, W, L, pc_steps, "fast")
        floor_ps = pubsub_floor(int(pc["bytes_per_msg"]), cfg.pick(2000, 300))
        data["point_cloud_topic"] = pc
        data["pubsub_floor"] = floor_ps
        sec.tables.append(Table("topics", "Point-cloud topic throughput", [
            "what", "message size", "messages/s", "MB/s", "points/s", "dropped"], [
            ["raw pyzmq PUB → SUB, same message size (floor)", f"{pc['bytes_per_msg'] / 1e6:.2f} MB",
             f"{floor_ps['msgs_per_s']:,.0f}", f"{floor_ps['mb_per_s']:,.0f}", "–",
             f"{floor_ps['sent'] - floor_ps['messages']}"],
            [f"Sensorium /…/point_cloud, {W}×{L} lidar, lockstep as fast as possible", f"{pc['bytes_per_msg'] / 1e6:.2f} MB",
             f"{pc['msgs_per_s']:,.0f}", f"{pc['mb_per_s']:,.0f}", f"{pc['msgs_per_s'] * pc['points'] / 1e6:.1f} M",
             f"{pc['dropped']} of {pc['steps']}"],
        ], [
            "The Sensorium row is end to end: each message is a lidar scan computed (FAST precision), its point "
            "cloud built and packed, published on the XPUB and decoded by a SUB socket here; one controller "
            "process drives the lockstep. The subscriber alone demands the topic (the controller enables nothing). "
            f"Step round trip while publishing: {fmt_time(pc['step_rtt_median_s'])} (p50).",
        ]))

    # targets
    single = data["single"]
    ratio = single["p50_s"] / data["reqrep_floor"]["p50_s"]
    why = (f"p50 {fmt_time(single['p50_s'])} vs raw REQ/REP {fmt_time(data['reqrep_floor']['p50_s'])} "
           f"(p99 {fmt_time(single['p99_s'])} vs {fmt_time(data['reqrep_floor']['p99_s'])}).")
    if ratio > 1.5:
        c1 = data["server_cpu"]["1"]
        pf = data["python_floor"]["p50_s"]
        bf = data["python_floor_bare"]["p50_s"]
        why += (f" MISS by {ratio / 1.5:.2f}×: a bare DEALER against a do-nothing Python msgpack ROUTER takes "
                f"{fmt_time(bf)}; the client library's `Connection` instead of the bare DEALER adds {fmt_time(pf - bf)} "
                f"(its poller loop and non-blocking drain); Sensorium's server adds {fmt_time(single['p50_s'] - pf)} more, of which "
                f"{fmt_time(c1['total_s'])} is measured server Python without sockets ({fmt_time(c1['handle_s'])} request "
                f"parsing and argument validation, {fmt_time(c1['step_once_s'])} simulation step, lockstep and reply) and "
                f"{fmt_time(single['p50_s'] - pf - c1['total_s'])} its transport loop around that (polling three sockets, "
                "draining, sending) compared with the minimal server's.")
    sec.targets.append(Target("Lockstep step round trip vs raw pyzmq REQ/REP (1 controller, p50)", "≤ 1.5×",
                              f"{ratio:.2f}×", ratio <= 1.5, why))
    if 8 in sps:
        ok = sps[8] >= 2000
        why = f"{sps[8]:,.0f} world steps/s with 8 controller processes (p50 round trip {fmt_time(data['multi_8']['p50_s'])})."
        if not ok:
            c8 = data["server_cpu"]["8"]
            why += (f" MISS by {2000 / sps[8]:.1f}×: each world step needs 8 requests and 8 replies through one "
                    f"Python server loop — {fmt_time(c8['total_s'])} of server Python per world step before any socket "
                    f"work (ceiling {1 / c8['total_s']:,.0f} steps/s on one core) — and the 8 controller processes "
                    f"share the 2 cores with it (a client-library round trip costs {fmt_time(data['python_floor']['p50_s'])} "
                    "of Python and sockets even against a do-nothing server).")
        sec.targets.append(Target("World steps/s with 8 controllers", "≥ 2,000", f"{sps[8]:,.0f}", ok, why))
    sec.findings.append(
        f"Lockstep: 1 controller {fmt_time(single['p50_s'])} p50 per step ({ratio:.2f}× the raw REQ/REP floor); "
        + ", ".join(f"{k} controller{'s' if k > 1 else ''} {v:,.0f} steps/s" for k, v in sps.items()) + ".")
    sec.findings.append(
        f"Point clouds: {pc['msgs_per_s']:,.0f} messages/s of {pc['bytes_per_msg'] / 1e6:.2f} MB "
        f"({pc['mb_per_s']:,.0f} MB/s) end to end vs {floor_ps['msgs_per_s']:,.0f}/s ({floor_ps['mb_per_s']:,.0f} MB/s) for raw "
        "PUB/SUB of the same size: the scan itself, not the transport, bounds the rate.")
    sec.data = data
    sec.elapsed_s = time.perf_counter() - t_all
    return sec


if __name__ == "__main__":
    main(sys.argv[1:])
