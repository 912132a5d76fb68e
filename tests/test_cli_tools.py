"""The ROS-2-like command-line tools against real servers: echo (YAML, --full, --json, unknown topics,
no server), hz, topics --json, services, call; and a world of "<none>" robots that runs by itself."""

from __future__ import annotations

import json
import math
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml
from _serve import serve

FREE_WORLD = """\
world_info: {name: free, basic_time_step: 32}
solids:
  - {name: wall, pose: {translation: [1.0, 0.0, 0.1]}, geometry: {type: box, size: [0.1, 2.0, 0.2]}}
lights:
  - {type: PointLight, name: lamp, location: [0.0, 0.0, 1.0], intensity: 1.0}
robots:
  - name: bot
    controller: "<none>"
    pose: {translation: [0.0, 0.0, 0.1]}
    devices:
      - {device: LightSensor, name: ls, pose: {rotation: [0, 1, 0, -1.5708]}}
      - {device: Lidar, name: lidar, horizontal_resolution: 12, field_of_view: 1.0, number_of_layers: 1, max_range: 5.0}
"""


def cli(*args: str, timeout: float = 60) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "sensorium", *args], capture_output=True, text=True, timeout=timeout)


@pytest.fixture(scope="module")
def arena():
    with serve(None, "--mode", "pause", stop_signal=signal.SIGTERM) as s:
        yield s


@pytest.fixture(scope="module")
def free(tmp_path_factory):
    world = tmp_path_factory.mktemp("free") / "free.yaml"
    world.write_text(FREE_WORLD)
    with serve(world, "--mode", "realtime", stop_signal=signal.SIGTERM) as s:
        yield s


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


# ---------------------------------------------------------------------- echo

def test_echo_unknown_topic_fails_at_once_with_the_closest_names(arena):
    res = cli("echo", "/epuck/ls9/value", "--url", arena.rpc)
    assert res.returncode == 1
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "no topic '/epuck/ls9/value'" in lines[0]
    assert "/epuck/ls0/value" in lines[0] and "/epuck/ls1/value" in lines[0]
    prefix = cli("echo", "/epux/", "--url", arena.rpc)
    assert prefix.returncode == 1 and "no topic '/epux/'" in prefix.stderr


def test_echo_without_a_server_times_out_with_a_message():
    rpc, pub = f"tcp://127.0.0.1:{_free_port()}", f"tcp://127.0.0.1:{_free_port()}"
    t0 = time.monotonic()
    res = cli("echo", "/clock", "--url", rpc, "--pub", pub, "--timeout", "1")
    assert res.returncode == 1 and time.monotonic() - t0 < 30
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "no server answers" in lines[0] and rpc in lines[0]
    only_pub = cli("echo", "/clock", "--pub", pub, "--timeout", "1")        # no --url: nobody asked
    assert only_pub.returncode == 1 and "--url" in only_pub.stderr and len(only_pub.stderr.strip().splitlines()) == 1
    # the default wait when no server answers is the 5 s of every client command (was 10 s)
    default = cli("echo", "/clock", "--url", rpc, "--pub", pub)
    assert default.returncode == 1 and "for 5 s" in default.stderr, default.stderr


def test_endpoints_zeromq_refuses_are_one_line():
    """echo/hz --pub bogus://x (or tcp://HOST without a port), and --url bogus://x (taken for a topic
    endpoint), ended in a ZMQError traceback."""
    for cmd, extra in (("echo", ["--timeout", "1"]), ("hz", ["--duration", "1"])):
        for pub in ("bogus://x", "tcp://127.0.0.1"):
            res = cli(cmd, "/clock", "--pub", pub, *extra)
            lines = res.stderr.strip().splitlines()
            assert res.returncode == 1 and len(lines) == 1, res.stderr
            assert lines[0].startswith(f"sensorium {cmd}: cannot subscribe to {pub}: "), lines
        res = cli(cmd, "/clock", "--url", "bogus://x", *extra)
        assert res.returncode == 2 and res.stderr.strip().splitlines() == [
            f"sensorium {cmd}: BAD_URL: controller URL 'bogus://x': unsupported scheme 'bogus' (use tcp://, ipc:// "
            "or a robot name)"]


def test_one_flag_one_meaning_and_the_old_spellings_still_work(free, tmp_path):
    """--url is the RPC endpoint for every client command, --pub a topic endpoint; echo/hz's --rpc,
    echo/hz's --url given a topic endpoint, and record's --connect keep working with one line."""
    old_rpc = cli("echo", "/clock", "--rpc", free.rpc, "--count", "1")
    assert old_rpc.returncode == 0, old_rpc.stderr
    assert old_rpc.stderr.strip().splitlines()[0] == ("sensorium echo: --rpc is deprecated: use --url (the server's "
                                                      "RPC endpoint, as for topics, services and call)")
    old_url = cli("hz", "/clock", "--url", free.pub, "--duration", "2", "--json")
    assert old_url.returncode == 0, old_url.stderr
    assert f"deprecated: use --pub {free.pub}" in old_url.stderr and old_url.stdout.strip()
    new = cli("echo", "/clock", "--url", free.rpc, "--pub", free.pub, "--count", "1")
    assert new.returncode == 0 and "deprecated" not in new.stderr, new.stderr
    rec = cli("record", str(tmp_path / "r.mcap"), "--connect", free.rpc, "--max-messages", "3")
    assert rec.returncode == 0, rec.stderr
    assert rec.stderr.startswith("sensorium record: --connect is deprecated: use --url")
    rec2 = cli("record", str(tmp_path / "r2.mcap"), "--url", free.rpc, "--max-messages", "3")
    assert rec2.returncode == 0 and "deprecated" not in rec2.stderr, rec2.stderr


def test_echo_says_why_a_waiting_world_is_silent(arena):
    res = cli("echo", "/clock", "--url", arena.rpc, "--timeout", "4")
    assert res.returncode == 1
    assert "paused" in res.stderr                        # the arena server runs in pause mode


def test_a_world_of_uncontrolled_robots_steps_by_itself_and_echo_prints_yaml(free):
    res = cli("echo", "/clock", "--url", free.rpc, "--count", "3")
    assert res.returncode == 0, res.stderr
    docs = [d for d in yaml.safe_load_all(res.stdout) if d is not None]
    assert len(docs) == 3
    stamps = [d["clock"]["sec"] * 10**9 + d["clock"]["nanosec"] for d in docs]
    assert all(b - a == 32_000_000 for a, b in zip(stamps, stamps[1:]))        # consecutive basic steps
    assert res.stdout.startswith("# /clock [rosgraph_msgs/msg/Clock] seq=")


def test_echo_summarises_arrays_unless_full_and_json_is_complete(free):
    short = cli("echo", "/bot/lidar/laser_scan", "--url", free.rpc, "--count", "1")
    assert short.returncode == 0, short.stderr
    assert "ranges: <float32[12]" in short.stdout
    full = cli("echo", "/bot/lidar/laser_scan", "--url", free.rpc, "--count", "1", "--full")
    doc = yaml.safe_load(full.stdout.split("\n---")[0])
    # Webots order: column 0 on the left, so the increment is negative (PROTOCOL.md, README ROS section)
    assert len(doc["ranges"]) == 12 and doc["angle_increment"] == pytest.approx(-1 / 12)
    assert doc["angle_min"] == pytest.approx(0.5 - 1 / 24)
    # the wall at x = 0.95 (its near face): every ray hits it at 0.95 / cos(angle)
    for i, r in enumerate(doc["ranges"]):
        angle = doc["angle_min"] + i * doc["angle_increment"]
        assert r == pytest.approx(0.95 / math.cos(angle), abs=1e-4)
    js = cli("echo", "/bot/lidar/laser_scan", "--url", free.rpc, "--count", "1", "--json")
    msg = json.loads(js.stdout)
    assert msg["topic"] == "/bot/lidar/laser_scan" and msg["type"] == "sensor_msgs/msg/LaserScan"
    assert len(msg["body"]["ranges"]) == 12 and msg["stamp_ns"] % 32_000_000 == 0


# ---------------------------------------------------------------------- hz, topics

def test_hz_measures_the_simulated_rate_exactly(free):
    res = cli("hz", "/clock", "/bot/ls/value", "--url", free.rpc, "--duration", "3", "--json")
    assert res.returncode == 0, res.stderr
    last = {}
    for line in res.stdout.splitlines():
        row = json.loads(line)
        last[row["topic"]] = row
    assert set(last) == {"/clock", "/bot/ls/value"}
    for row in last.values():
        assert row["sim_rate_hz"] == pytest.approx(1000 / 32)         # one message per 32 ms basic step
        assert row["rate_hz"] > 0 and row["min_s"] <= row["max_s"] and row["window"] >= 2
    text = cli("hz", "/clock", "--url", free.rpc, "--duration", "2")
    assert "/clock: average rate" in text.stdout and "std dev" in text.stdout


def test_hz_says_why_nothing_came_within_its_duration(arena):
    """hz --duration 1 against a paused world exited 1 without a word."""
    res = cli("hz", "/clock", "--url", arena.rpc, "--duration", "1")
    assert res.returncode == 1 and res.stdout == ""
    assert res.stderr.strip().splitlines() == [f"sensorium hz: nothing on '/clock' from {arena.pub} for 1 s: the server "
                                               "is paused (sensorium call set_mode '{mode: fast}')"]


def test_topics_json(arena):
    res = cli("topics", "--url", arena.rpc, "--json")
    data = json.loads(res.stdout)
    assert data["world"] == "arena" and data["pub_endpoint"] == arena.pub
    assert {"name": "/scout/lidar/laser_scan", "type": "sensor_msgs/msg/LaserScan"} in data["topics"]


# ---------------------------------------------------------------------- services, call

def test_services_lists_every_service_with_arguments(arena):
    res = cli("services", "--url", arena.rpc, "--json")
    assert res.returncode == 0, res.stderr
    by_name = {s["name"]: s for s in json.loads(res.stdout)["services"]}
    assert by_name["/epuck/ps0/enable"] == {"name": "/epuck/ps0/enable", "scope": "device", "robot": "epuck",
                                            "device": "ps0", "device_type": "DistanceSensor", "attached": True,
                                            "supervisor": False, "simulated": True, "args": {"value": "int"}}
    assert by_name["set_mode"]["args"] == {"mode": "fast|realtime|pause"}
    assert by_name["/scout/left wheel motor/set_velocity"]["device_type"] == "RotationalMotor"
    assert by_name["/epuck/robot/step"]["args"]["duration"] == "int?"
    text = cli("services", "--url", arena.rpc, "--robot", "scout")
    assert "scout/lidar (Lidar):" in text.stdout and "/epuck/" not in text.stdout
    assert "  /scout/lidar/enable  {value: int}  [attached controller only]" in text.stdout
    # a robot the world does not have: one line naming the robots (it printed nothing, exit 0)
    typo = cli("services", "--url", arena.rpc, "--robot", "epcuk")
    assert typo.returncode == 1 and typo.stdout == ""
    assert typo.stderr.strip().splitlines() == ["sensorium services: no robot 'epcuk' (robots: epuck, scout; "
                                                "'server' for the server's own services)"]


def test_call_from_the_shell(arena):
    pose = cli("call", "/epuck/robot/get_pose", "--url", arena.rpc)
    assert pose.returncode == 0, pose.stderr
    assert yaml.safe_load(pose.stdout)["translation"] == [-1.2, -0.3, 0.01]        # the arena world's start
    mode = cli("call", "set_mode", "{mode: realtime}", "--url", arena.rpc, "--json")
    assert json.loads(mode.stdout) == {"mode": "realtime"}
    assert json.loads(cli("call", "set_mode", '{"mode": "pause"}', "--url", arena.rpc, "--json").stdout) == {"mode": "pause"}
    bad = cli("call", "set_mode", "{mode: [", "--url", arena.rpc)
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1 and "ARGS" in bad.stderr
    wrong = cli("call", "set_mode", "{mode: warp}", "--url", arena.rpc)
    assert wrong.returncode == 1 and "INVALID_ARGUMENT" in wrong.stderr and len(wrong.stderr.strip().splitlines()) == 1
    attached = cli("call", "/epuck/robot/step", "--url", arena.rpc)
    assert attached.returncode == 1 and "NOT_ATTACHED" in attached.stderr
    unknown = cli("call", "/epuck/robot/fly", "--url", arena.rpc)
    assert unknown.returncode == 1 and "sensorium services" in unknown.stderr


def test_none_controller_robot_cannot_be_attached(free):
    res = cli("call", "attach", "{robot: bot}", "--url", free.rpc)
    assert res.returncode == 1 and "WRONG_STATE" in res.stderr and '"<none>"' in res.stderr


def test_server_says_once_that_it_waits(tmp_path: Path):
    s = serve(None, "--mode", "fast", stop_signal=signal.SIGTERM)
    try:
        deadline = time.monotonic() + 30
        info = None
        while time.monotonic() < deadline:
            res = cli("call", "get_info", "--url", s.rpc, "--json")
            if res.returncode == 0:
                info = json.loads(res.stdout)
                break
        assert info is not None and info["time_ms"] == 0               # nobody attached: no step
        time.sleep(0.5)
        assert json.loads(cli("call", "get_info", "--url", s.rpc, "--json").stdout)["time_ms"] == 0
    finally:
        s.stop()
        err = s.stderr()
    assert err.count("waiting for a controller to attach to robot 'epuck' or 'scout'") == 1


def test_the_controller_help_names_every_bundled_example():
    from sensorium.cli import build_parser
    from sensorium.cli.client import EXAMPLES_DIR

    parser = build_parser()
    sub = next(a for a in parser._subparsers._group_actions if a.choices).choices["controller"]   # noqa: SLF001
    text = " ".join(sub.format_help().split())
    names = sorted(p.stem for p in EXAMPLES_DIR.glob("[!_]*.py"))
    assert len(names) >= 6 and all(f"example:{n}" in text for n in names), (names, text)
