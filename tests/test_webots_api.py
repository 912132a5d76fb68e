"""Done-when test of issue 11 (the controller API part): a Webots-style controller that reads wheel
encoders, toggles LEDs, reads the keyboard and uses ``Supervisor`` to move things and reset its
robot runs unchanged through ``sensorium controller`` against a live ``sensorium serve``; every
number is compared with its closed form (tests/worlds/webots_api.yaml explains them)."""

from __future__ import annotations

import json
import math
import sys
import time

import pytest
from _serve import Proc, sensorium
from test_multiprocess import CONTROLLERS, REPO, start_server

from sensorium.client.topics import Subscriber

WORLD = REPO / "tests" / "worlds" / "webots_api.yaml"
STEP = 0.016            # m per basic step at 5 rad/s, wheel radius 0.1, 32 ms
TURN = 0.16             # rad per basic step

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")


@pytest.fixture
def server(tmp_path):
    s = start_server(WORLD, tmp_path, "--mode", "pause")
    yield s
    s.stop()


def _lines(proc: Proc) -> dict[str, dict]:
    return {d["tag"]: d for d in (json.loads(line) for line in proc.out)}


def test_webots_controller_with_encoders_leds_keyboard_and_supervisor(server):
    with Subscriber(server.pub, "/pioneer/led0/value", "/pioneer/left wheel sensor/value") as sub:
        deadline = time.monotonic() + 30
        while len(server.conn.call("get_counters")["subscriptions"]) < 2:
            assert time.monotonic() < deadline, "subscriber never subscribed"
            time.sleep(0.05)
        ctl = Proc(sensorium("controller", str(CONTROLLERS / "webots_api.py"), "--url", server.url("pioneer")))
        try:
            server.wait_attached({"pioneer"})
            server.conn.call("set_mode", {"mode": "fast"})
            assert ctl.wait(120) == 0, ctl.stderr()
        finally:
            ctl.kill()
        got = []
        while len(got) < 6:
            m = sub.recv(timeout=10.0)
            assert m is not None, f"only {len(got)} topic messages"
            got.append(m)
    out = _lines(ctl)
    info, drive, turned, reset, after = (out[k] for k in ("info", "drive", "turned", "reset", "after"))

    # Robot extras and the PositionSensor before its first sample
    assert info["model"] == "Pioneer 3-DX (kinematic)" and info["data"] == "gain=2"
    assert info["supervisor"] is True and info["mode"] == 0 and info["motor"] == "left wheel motor"
    assert info["before"] is None or math.isnan(info["before"])     # json: NaN
    assert drive["data"] == "gain=3"

    # keyboard: present, never a key; LEDs: what was set
    assert drive["keys"] == [-1]
    assert drive["leds"] == [1, 2, 1, 2] and drive["rgb"] == 0x336699

    # encoders: 0.16 rad per step from the first step on, also while the wall blocks the robot
    enc = drive["encoders"]
    assert len(enc) == 150
    for k, (left, right) in enumerate(enc, start=1):
        assert left == pytest.approx(TURN * k, abs=1e-9) and right == pytest.approx(TURN * k, abs=1e-9)

    # contact: stopped where the 0.2 m body touches the wall face at x = 1.9
    assert drive["translation"][0] == pytest.approx(1.7, abs=1e-9)
    assert drive["position"] == drive["translation"]
    assert abs(drive["translation"][1]) < 1e-12 and drive["translation"][2] == 0.1

    # Supervisor: a rotation alone keeps the translation; orientation is the rotation matrix
    assert turned["translation"] == drive["translation"]
    assert turned["rotation"] == pytest.approx([0.0, 0.0, 1.0, math.pi / 2], abs=1e-12)
    assert turned["orientation"] == pytest.approx([0, -1, 0, 1, 0, 0, 0, 0, 1], abs=1e-12)

    # simulationReset: robot, wall and wheels back to the start; motors back to their initial commands
    assert reset["translation"] == [0.0, 0.0, 0.1] and reset["rotation"] == [0.0, 0.0, 1.0, 0.0]
    assert reset["wall"] == [2.0, 0.0, 0.25]
    assert reset["encoders"] == [0.0, 0.0] and reset["velocity"] == 10.0 and reset["missing"] is True
    assert reset["data"] == "gain=2" == server.conn.call("/pioneer/robot/get_custom_data")["value"]

    # step(10 * basic) then step(basic + 1) rounded up to 2 basic steps: 12 steps of 0.016 m
    assert after["translation"][0] == pytest.approx(12 * STEP, abs=1e-9)
    assert after["time_ms"] == 150 * 32 + 32 + 320 + 64
    assert "not a multiple of the basic time step" in ctl.stderr()

    # topics: the LED's colour and the encoder's JointState
    led = [m for m in got if m.topic == "/pioneer/led0/value"]
    enc_msgs = [m for m in got if m.topic.startswith("/pioneer/left wheel sensor")]
    assert led and led[0].type == "std_msgs/msg/ColorRGBA"
    assert (led[0].body["r"], led[0].body["g"], led[0].body["b"], led[0].body["a"]) == (1.0, 0.0, 0.0, 1.0)
    assert enc_msgs and enc_msgs[0].type == "sensor_msgs/msg/JointState"
    assert enc_msgs[0].body["name"] == ["left wheel sensor"]
