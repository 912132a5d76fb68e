"""Recording a real server: ``serve --record`` (lossless, from the step loop), ``record --connect``
(a subscriber that counts what it lost), kill -9 of a recording server, and determinism: two real
runs with the same world, seed and controller commands record identical message bytes."""

from __future__ import annotations

import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import msgpack
import pytest
import zmq
from _serve import child_env, serve

from sensorium.server.recording.live import LiveRecorder
from sensorium.server.recording.reader import Recording
from sensorium.server.world.loader import default_world_path

PY = sys.executable


class Server:
    def __init__(self, tmp: Path, *extra: str, name: str = "s"):
        self.rpc_url = f"ipc://{tmp}/{name}-rpc"
        self.pub_url = f"ipc://{tmp}/{name}-pub"
        self.proc = serve(None, *extra, rpc=self.rpc_url, pub=self.pub_url, wait=False, stop_signal=signal.SIGTERM)
        self.dealer = None

    def ready(self) -> Server:
        if self.dealer is not None:
            return self
        self.proc.wait_ready()
        self.ctx = zmq.Context()
        self.dealer = self.ctx.socket(zmq.DEALER)
        self.dealer.setsockopt(zmq.LINGER, 0)
        self.dealer.connect(self.rpc_url)
        self._id = 0
        return self

    def call(self, service: str, **args):
        self._id += 1
        self.dealer.send(msgpack.packb({"id": self._id, "service": service, "args": args}))
        assert self.dealer.poll(20000), f"no reply to {service}"
        reply = msgpack.unpackb(self.dealer.recv())
        assert reply["ok"], reply
        return reply["result"]

    def wait_subscribed(self, timeout: float = 30.0) -> None:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                if self.call("get_counters")["subscriptions"]:
                    return
            except AssertionError:  # no such service: give the subscription time to arrive
                time.sleep(0.3)
                return
            time.sleep(0.01)
        raise AssertionError("the subscription never reached the server")

    def stop(self, sig=signal.SIGTERM) -> str:
        if self.dealer is not None:
            self.dealer.close()
            self.ctx.term()
        code = self.proc.stop(sig)
        err = self.proc.stderr()
        assert code == 0, err
        return err

    def kill(self) -> None:
        self.proc.kill()


@pytest.fixture
def server_factory(tmp_path):
    started: list[Server] = []

    def make(*extra: str, name: str = "s", wait: bool = True) -> Server:
        s = Server(tmp_path, *extra, name=name)
        started.append(s)
        return s.ready() if wait else s

    yield make
    for s in started:
        s.kill()


def drive(server: Server, steps: int, move_at: int | None = None) -> None:
    """The controller: attach to the e-puck and step; optionally move the scout (a supervisor command)."""
    server.call("attach", robot="epuck")
    for k in range(steps):
        if move_at is not None and k == move_at:
            server.call("/scout/robot/set_pose", translation=[0.3, -0.2, 0.0], rotation=[0.0, 0.0, 1.0, 0.7])
        server.call("/epuck/robot/step", duration=32)


def messages(path) -> list[tuple]:
    with Recording(path) as rec:
        assert not rec.truncated
        return [(m.topic, m.ros_type, m.seq, m.stamp_ns, m.data) for m in rec.messages()]


def test_serve_record_and_determinism(server_factory, tmp_path):
    """Two real runs, same world/seed/commands ⇒ identical recorded message bytes."""
    servers = [server_factory("--record", str(tmp_path / f"run{k}.mcap"), name=f"run{k}", wait=False)
               for k in range(2)]  # two independent processes, run side by side

    def run(k: int) -> None:
        server = servers[k].ready()
        drive(server, 25, move_at=10)
        assert "recorded 500 messages" in server.stop(signal.SIGTERM if k == 0 else signal.SIGINT)

    threads = [threading.Thread(target=run, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(60)
    a, b = (messages(tmp_path / f"run{k}.mcap") for k in range(2))
    assert a == b
    topics = {m[0] for m in a}  # no subscriber at all: the recorder's demand computed every topic
    assert len(topics) == 20 and "/scout/lidar/point_cloud" in topics and "/epuck/ps0/value" in topics and "/clock" in topics
    assert "/epuck/pose" in topics and "/scout/pose" in topics
    for topic in topics:  # every topic, every step, seq from 0 without a hole
        seqs = [m[2] for m in a if m[0] == topic]
        assert seqs == list(range(25)), topic
    with Recording(tmp_path / "run0.mcap") as rec:
        meta = rec.metadata()["sensorium"]
        assert meta["seed"] == "42" and meta["basic_time_step_ms"] == "32" and meta["world"] == "arena"
        assert rec.world() == ("arena.yaml", default_world_path().read_bytes())
        assert rec.summary()["duration_s"] == pytest.approx(24 * 0.032)
    # the moved scout changed what the lidar saw: the recording reflects the command
    scans = [m[4] for m in a if m[0] == "/scout/lidar/laser_scan"]
    assert scans[9] != scans[11]


def test_serve_record_refuses_topics_that_match_nothing(tmp_path):
    """serve --record --topics with a typo recorded 0 messages without a word."""
    out = tmp_path / "typo.mcap"
    proc = subprocess.run([PY, "-m", "sensorium", "serve", "--rpc", f"ipc://{tmp_path}/r", "--pub", f"ipc://{tmp_path}/p",
                           "--record", str(out), "--topics", "/epuck", "/scout/sonar"],
                          capture_output=True, text=True, timeout=120, env=child_env())
    assert proc.returncode == 1 and proc.stdout == ""
    assert proc.stderr.startswith("sensorium serve: --topics /scout/sonar: no topic of world 'arena' matches it "
                                  "(closest: "), proc.stderr
    assert "/scout/sonar_left/value" in proc.stderr and not out.exists()


def test_record_connect_keeps_up_then_kill_9(server_factory, tmp_path):
    """A subscriber that keeps up reports 0 gaps; the server, recording at the same time, is then
    killed with SIGKILL: its file is truncated but readable, and ``sensorium info`` says so."""
    path = tmp_path / "killed.mcap"
    server = server_factory("--record", str(path), "--topics", "/epuck", name="conn")
    out = tmp_path / "sub.mcap"
    live = LiveRecorder(out, connect=server.rpc_url, topics=["/epuck"], log=lambda s: None)
    live.open()
    th = threading.Thread(target=live.run, kwargs={"duration": 30}, daemon=True)
    th.start()
    server.wait_subscribed()
    drive(server, 30)  # 8 distance + 2 light sensors + the pose: 330 messages
    deadline = time.monotonic() + 60
    while live.gaps.total_received < 330 and time.monotonic() < deadline:
        time.sleep(0.02)
    live.stop()
    th.join(5)
    summary = live.close()
    assert summary["received"] == 330 and summary["gaps"] == 0 and summary["lost"] == 0
    with Recording(out) as rec:
        assert rec.metadata()["sensorium"]["basic_time_step_ms"] == "32"
        subscribed = [(m.topic, m.seq, m.data) for m in rec.messages()]
    # the server's own recorder writes its chunk at least once a second, even while idle
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        try:
            with Recording(path) as rec:
                if sum(1 for _ in rec.messages()) == 330:
                    break
        except Exception:
            pass
        time.sleep(0.1)
    server.proc.kill()
    with Recording(path) as rec:
        assert rec.truncated
        recorded = [(m.topic, m.seq, m.data) for m in rec.messages()]
    assert recorded == subscribed  # nothing lost on either side: the exact published bytes
    info = subprocess.run([PY, "-m", "sensorium", "info", str(path)], capture_output=True, text=True, timeout=120)
    assert "Truncated:         YES" in info.stdout and "Messages:          330" in info.stdout


def test_record_connect_reports_exact_loss(server_factory, tmp_path):
    """A slow subscriber with a tiny queue loses messages; it says exactly how many, checked against
    the lossless recording the server made at the same time."""
    full = tmp_path / "full.mcap"
    server = server_factory("--record", str(full), "--topics", "/scout/lidar", name="loss")
    out = tmp_path / "lossy.mcap"
    release = threading.Event()
    live = LiveRecorder(out, connect=server.rpc_url, topics=["/scout/lidar/point_cloud"], rcvhwm=1,
                        on_message=lambda topic, seq: release.wait(30),  # asleep until released
                        log=lambda s: None)
    live.open()
    th = threading.Thread(target=live.run, kwargs={"duration": 60}, daemon=True)
    th.start()
    server.wait_subscribed()
    drive(server, 200)  # far more than the queues between server and reader hold
    release.set()
    last = -1
    while True:  # let the reader drain what it still has
        time.sleep(0.3)
        if live.gaps.total_received == last:
            break
        last = live.gaps.total_received
    server.call("/epuck/robot/step", duration=32)  # one more, read by a reader that keeps up
    deadline = time.monotonic() + 60
    while live.gaps.last.get("/scout/lidar/point_cloud") != 200 and time.monotonic() < deadline:
        time.sleep(0.02)
    live.stop()
    th.join(5)
    summary = live.close()
    server.stop()
    sent = [m for m in messages(full) if m[0] == "/scout/lidar/point_cloud"]
    assert [m[2] for m in sent] == list(range(201))
    with Recording(out) as rec:
        got = [(m.seq, m.data) for m in rec.messages()]
    assert got[0][0] == 0 and got[-1][0] == 200
    assert summary["lost"] == 201 - len(got) > 0
    assert summary["lost_by_topic"] == {"/scout/lidar/point_cloud": 201 - len(got)}
    assert summary["gaps"] == sum(1 for (a, _), (b, _) in zip(got, got[1:]) if b > a + 1)
    by_seq = {m[2]: m[4] for m in sent}
    assert all(by_seq[s] == d for s, d in got)  # what it did get is byte-identical
