"""Real processes: a ``sensorium serve`` subprocess and several controller processes.

* three controllers (different robots, different step durations) in lockstep see values that are
  bit-identical to an in-process ``Simulation`` of the same world, seed, enables and steps;
* a controller SIGKILLed mid-run does not block the others, and a new process can take its robot;
* Webots-style controllers (the examples) run through ``sensorium controller``, and ``sensorium
  topics`` / ``echo`` work against the live server;
* a controller driving the e-puck's wheel motors ends at exactly the pose (and passes exactly the
  poses, on the ``/epuck/pose`` topic) of the in-process simulation; the examples really drive.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
import time
from pathlib import Path

import pytest
from _serve import Proc, Served, sensorium, serve

from sensorium.client.connection import Connection

REPO = Path(__file__).resolve().parents[1]
TRIO = REPO / "tests" / "worlds" / "trio.yaml"
ARENA = REPO / "sensorium" / "worlds" / "arena.yaml"
CONTROLLERS = REPO / "tests" / "controllers"
EXAMPLES = REPO / "sensorium" / "client" / "examples"

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints and signals")


def start_server(world: Path, tmp: Path, *extra: str) -> Served:
    """``sensorium serve WORLD`` on ipc endpoints in ``tmp``, ready."""
    rpc, pub = f"ipc://{tmp}/rpc", f"ipc://{tmp}/pub"
    server = serve(world, *extra, rpc=rpc, pub=pub)
    assert server.rpc == rpc and server.pub == pub, server.ready_line
    return server


def run_paused(world: Path, tmp: Path, script: str, robot: str, env: dict[str, str] | None = None) -> Proc:
    """Serve ``world`` paused, run the controller ``script`` (in ``tests/controllers/``, or a path:
    a compiled one) on ``robot`` once it is attached (the world then runs fast), and return its
    finished process (exit status 0 checked; its stdout in ``.out``)."""
    server = start_server(world, tmp, "--mode", "pause")
    try:
        ctl = Proc(sensorium("controller", str(CONTROLLERS / script), "--url", server.url(robot)), env=env)
        try:
            server.wait_attached({robot})
            server.conn.call("set_mode", {"mode": "fast"})
            assert ctl.wait(120) == 0, ctl.stderr()
        finally:
            ctl.kill()
    finally:
        server.stop()
    return ctl


@pytest.fixture
def servers():
    started: list[Served] = []
    procs: list[Proc] = []
    yield started, procs
    for p in procs:
        p.kill()
    for s in started:
        s.stop()


# ====================================================================== bit identity

# robot -> (step duration ms, steps, device specs NAME:PERIOD[:pc]); 12*16 = 6*32 = 4*48 = 192 ms
PLANS = {
    "ant": (16, 12, ["ir:16", "eye:32"]),
    "bee": (32, 6, ["lidar:32:pc", "sonar:48"]),
    "cat": (48, 4, ["eye:16", "front:64"]),
}


def reference_run() -> dict[str, list[dict]]:
    """What each controller must see, from the in-process simulation of the same world."""
    from sensorium.server.sim.simulation import Simulation

    sim = Simulation.from_file(TRIO)
    for robot, (_, _, specs) in PLANS.items():
        for spec in specs:
            name, period, *flags = spec.split(":")
            dev = sim.device(f"{robot}/{name}")
            dev.enable(int(period))
            if "pc" in flags:
                dev.enable_point_cloud()
    expected: dict[str, list[dict]] = {robot: [] for robot in PLANS}
    end = max(d * n for d, n, _ in PLANS.values())
    while sim.time_ms < end:
        sim.step()
        for robot, (duration, steps, specs) in PLANS.items():
            if sim.time_ms % duration or len(expected[robot]) >= steps:
                continue
            values = {}
            for spec in specs:
                name, _, *flags = spec.split(":")
                dev = sim.device(f"{robot}/{name}")
                if dev.kind == "Lidar":
                    values[name] = {"range": dev.range_image.astype("<f4").tobytes().hex()}
                    if "pc" in flags:
                        values[name]["cloud"] = dev.point_cloud.tobytes().hex()
                else:
                    values[name] = {"value": float(dev.value).hex()}
            expected[robot].append({"t": sim.time_ms, "status": 0, "values": values})
    return expected


def test_three_controllers_in_lockstep_match_the_in_process_simulation(servers, tmp_path):
    started, procs = servers
    server = start_server(TRIO, tmp_path, "--mode", "pause", "--heartbeat-ms", "500")
    started.append(server)
    for robot, (duration, steps, specs) in PLANS.items():
        procs.append(Proc(sensorium("controller", str(CONTROLLERS / "record.py"), "--url", server.url(robot),
                                    str(duration), str(steps), *specs)))
    server.wait_attached(set(PLANS))
    assert server.conn.call("set_mode", {"mode": "fast"})["mode"] == "fast"
    for p in procs:
        assert p.wait(60) == 0, p.stderr()
    seen = {robot: [json.loads(line) for line in p.out] for robot, p in zip(PLANS, procs)}
    expected = reference_run()
    for robot in PLANS:
        assert [s["t"] for s in seen[robot]] == [e["t"] for e in expected[robot]]
        for got, want in zip(seen[robot], expected[robot]):
            assert got == want, f"{robot} at t={want['t']} ms differs"
    # the devices really produced different values over time (the comparison is not vacuous)
    assert len({s["values"]["ir"]["value"] for s in seen["ant"]}) > 6
    assert len({s["values"]["lidar"]["range"] for s in seen["bee"]}) == 6
    assert math.isnan(float.fromhex(seen["cat"][0]["values"]["front"]["value"]))   # first value due at 64 ms
    assert server.stop() == 0


# ====================================================================== crash and re-attach

def _stepper(server: Served, robot: str, duration: int, steps: int, device: str) -> Proc:
    return Proc([sys.executable, str(CONTROLLERS / "stepper.py"), str(duration), str(steps), device],
                env={"SENSORIUM_CONTROLLER_URL": server.url(robot)})


def _times_until(proc: Proc, predicate, timeout: float = 60.0) -> list[tuple[int, int, float]]:
    rows = []
    deadline = time.monotonic() + timeout
    while True:
        t, status, value = proc.line(max(0.1, deadline - time.monotonic())).split()
        rows.append((int(t), int(status), float(value)))
        if predicate(rows[-1]):
            return rows
        assert time.monotonic() < deadline, rows[-3:]


def test_killed_controller_blocks_nobody_and_its_robot_can_be_attached_again(servers, tmp_path):
    started, procs = servers
    server = start_server(TRIO, tmp_path, "--mode", "pause", "--heartbeat-ms", "200")
    started.append(server)
    ant = _stepper(server, "ant", 16, 0, "ir")
    bee = _stepper(server, "bee", 32, 0, "sonar")
    cat = _stepper(server, "cat", 48, 0, "front")
    procs += [ant, bee, cat]
    for p in (ant, bee, cat):
        assert p.line() == "attached"
    server.conn.call("set_mode", {"mode": "fast"})
    _times_until(bee, lambda row: row[0] >= 320)
    ant.kill()
    killed_at = server.conn.call("get_info")["time_ms"]
    # the others keep stepping once the server has dropped the dead session (3 x 200 ms)
    rows = _times_until(bee, lambda row: row[0] >= killed_at + 50 * 32, timeout=60)
    assert all(status == 0 for _, status, _ in rows)
    _times_until(cat, lambda row: row[0] >= killed_at + 20 * 48, timeout=60)
    # a new process takes the robot (refused with ROBOT_TAKEN until the old session expired)
    deadline = time.monotonic() + 60
    while True:
        again = _stepper(server, "ant", 16, 5, "ir")
        procs.append(again)
        code = again.wait(60)
        if code == 0:
            break
        assert "ROBOT_TAKEN" in again.stderr(), again.stderr()
        assert time.monotonic() < deadline, "the dead controller's robot was never released"
        time.sleep(0.1)
    rows = [line.split() for line in again.out[1:]]
    assert len(rows) == 5 and all(int(t) > killed_at and s == "0" for t, s, _ in rows)
    assert [int(t) for t, _, _ in rows] == sorted(int(t) for t, _, _ in rows)
    assert not any(v == "nan" for _, _, v in rows[1:])
    # quitting the server ends the remaining controllers' loops with -1
    assert server.stop() == 0
    for p in (bee, cat):
        assert p.wait(60) == 0, p.stderr()
        assert p.out[-1].split()[1] == "-1"


def test_heartbeat_keeps_a_slow_controller_attached(servers, tmp_path):
    """Computing for many heartbeat periods between steps does not lose the robot (pings come
    from the client's background thread), while a peer that stops pinging is dropped."""
    from sensorium.client.wb import RobotClient

    started, _ = servers
    server = start_server(TRIO, tmp_path, "--heartbeat-ms", "100")
    started.append(server)
    with RobotClient(server.url("ant")) as ant:
        ant.enable(ant.by_name["ir"], 16, "test")
        assert ant.step() == 0
        time.sleep(1.0)                                   # 10 heartbeats, 3 would drop a silent peer
        assert {r["name"]: r["attached"] for r in server.conn.call("get_info")["robots"]}["ant"]
        assert ant.step(32) == 0 and ant.time_ms == 48
        silent = Connection(server.rpc, timeout=5.0)      # attaches, then never pings
        silent.call("attach", {"robot": "bee"})
        time.sleep(0.6)
        assert ant.step() == 0                            # not blocked by the silent peer...
        assert not {r["name"]: r["attached"] for r in server.conn.call("get_info")["robots"]}["bee"]   # ...it was dropped
        silent.close()


# ====================================================================== Webots-style examples, CLI

def test_examples_through_the_launcher_with_topics_and_echo(servers, tmp_path):
    started, procs = servers
    server = start_server(ARENA, tmp_path, "--mode", "pause", "--heartbeat-ms", "200")
    started.append(server)
    topics = subprocess.run(sensorium("topics", "--url", server.rpc), capture_output=True, text=True,
                            timeout=30, cwd=str(REPO))
    assert topics.returncode == 0, topics.stderr
    listed = dict(line.split() for line in topics.stdout.splitlines())
    assert listed["/scout/lidar/laser_scan"] == "sensor_msgs/msg/LaserScan"
    assert listed["/epuck/ps0/value"] == "sensor_msgs/msg/Range"
    echo = Proc(sensorium("echo", "/epuck/ls0/value", "--url", server.pub, "--count", "2", "--timeout", "30"))
    procs.append(echo)
    deadline = time.monotonic() + 20
    while not any(p.startswith(b"/epuck/ls0/value") for p in server.conn.call("get_counters")["subscriptions"]):
        assert time.monotonic() < deadline, "echo never subscribed"
        time.sleep(0.05)
    braitenberg = Proc(sensorium("controller", str(EXAMPLES / "braitenberg.py"), "--robot", "epuck",
                                 "--url", server.rpc, "5"))
    wanderer = Proc(sensorium("controller", str(EXAMPLES / "wanderer.py"), "--url", server.url("scout"), "3", "-v"))
    procs += [braitenberg, wanderer]
    server.wait_attached({"epuck", "scout"})
    server.conn.call("set_mode", {"mode": "fast"})
    assert braitenberg.wait(60) == 0, braitenberg.stderr()
    assert wanderer.wait(60) == 0, wanderer.stderr()
    assert len(braitenberg.out) == 5 and "ls0=" in braitenberg.out[0] and "wheels" in braitenberg.out[-1]
    assert "nan" not in braitenberg.out[0]
    decisions = [line for line in wanderer.out if "ahead=" in line]
    assert len(decisions) == 3 and "-> forward" in decisions[0]
    assert echo.wait(30) == 0, echo.stderr()
    heads = [line for line in echo.out if line.startswith("# /epuck/ls0/value [sensor_msgs/msg/Illuminance]")]
    assert len(heads) == 2 and echo.out.count("---") == 2 and any(line.startswith("illuminance: ") for line in echo.out)
    assert server.stop() == 0


# ====================================================================== wheel motors, poses

def _pose_values(pose) -> list[float]:
    from sensorium.server.daemon.topics import pose_quaternion

    return [float(v) for v in pose.translation] + pose_quaternion(pose)


def _message_pose(body: dict) -> list[float]:
    p, q = body["pose"]["position"], body["pose"]["orientation"]
    return [p["x"], p["y"], p["z"], q["x"], q["y"], q["z"], q["w"]]


def test_driven_epuck_matches_the_in_process_simulation(servers, tmp_path):
    from sensorium.client.topics import Subscriber
    from sensorium.server.sim.simulation import Simulation

    steps, switch_at, speeds, later = 60, 40, (5.0, 5.0), (2.0, 6.0)     # straight, then a left arc
    started, procs = servers
    server = start_server(ARENA, tmp_path, "--mode", "pause", "--heartbeat-ms", "500")
    started.append(server)
    start_pose = server.conn.call("/epuck/robot/get_pose")
    with Subscriber(server.pub, "/epuck/pose") as sub:
        deadline = time.monotonic() + 20
        while b"/epuck/pose\0" not in server.conn.call("get_counters")["subscriptions"]:
            assert time.monotonic() < deadline, "the subscription never arrived"
            time.sleep(0.02)
        drive = Proc(sensorium("controller", str(CONTROLLERS / "drive.py"), "--url", server.url("epuck"), str(steps),
                               *map(str, speeds), str(switch_at), *map(str, later)))
        procs.append(drive)
        server.wait_attached({"epuck"})
        server.conn.call("set_mode", {"mode": "fast"})
        assert drive.wait(60) == 0, drive.stderr()
        assert drive.out == [str(32 * steps)]
        got = server.conn.call("/epuck/robot/get_pose")
        messages = []
        while len(messages) < steps and (msg := sub.recv(timeout=10)) is not None:
            messages.append(msg)
    # the same commands in process: applied before the first step, the turn before step 41
    sim = Simulation.from_file(ARENA)
    epuck = sim.robot("epuck")
    expected = []
    for n in range(steps):
        for motor, speed in zip(("left wheel motor", "right wheel motor"), later if n == switch_at else speeds):
            if n in (0, switch_at):
                epuck.motor(motor).set_position(math.inf)
                epuck.motor(motor).set_velocity(speed)
        sim.step()
        expected.append((sim.time_ms, _pose_values(epuck.pose)))
    assert got["translation"] + got["quaternion"] == expected[-1][1]            # bit-identical floats
    assert [(m.stamp_ns // 1_000_000, m.seq, _message_pose(m.body)) for m in messages] == [
        (t, i, pose) for i, (t, pose) in enumerate(expected)]
    assert all(m.body["header"]["frame_id"] == "world" and m.type == "geometry_msgs/msg/PoseStamped" for m in messages)
    # it really drove: 40 steps straight at 5 rad/s x 0.0205 m, then turned left
    travelled = math.dist(start_pose["translation"][:2], got["translation"][:2])
    assert 0.13 < travelled < 0.2
    assert got["quaternion"] != start_pose["quaternion"]
    assert server.stop() == 0


def test_examples_drive_their_robots(servers, tmp_path):
    started, procs = servers
    server = start_server(ARENA, tmp_path, "--mode", "pause", "--heartbeat-ms", "500")
    started.append(server)
    before = {r: server.conn.call(f"/{r}/robot/get_pose") for r in ("epuck", "scout")}
    braitenberg = Proc(sensorium("controller", str(EXAMPLES / "braitenberg.py"), "--url", server.url("epuck"), "300"))
    wanderer = Proc(sensorium("controller", str(EXAMPLES / "wanderer.py"), "--url", server.url("scout"), "100", "-v"))
    procs += [braitenberg, wanderer]
    server.wait_attached({"epuck", "scout"})
    server.conn.call("set_mode", {"mode": "fast"})
    assert braitenberg.wait(120) == 0, braitenberg.stderr()
    assert wanderer.wait(120) == 0, wanderer.stderr()
    assert len(braitenberg.out) == 300
    assert len([line for line in wanderer.out if "ahead=" in line]) == 100
    after = {r: server.conn.call(f"/{r}/robot/get_pose") for r in ("epuck", "scout")}
    moved = {r: math.dist(before[r]["translation"][:2], after[r]["translation"][:2]) for r in before}
    assert moved["epuck"] > 0.1, moved          # ~9.6 s at about half the e-puck's top speed
    assert moved["scout"] > 0.05 or after["scout"]["quaternion"] != before["scout"]["quaternion"], moved
    assert server.stop() == 0
