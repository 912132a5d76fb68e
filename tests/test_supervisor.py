"""Supervisor services, robot extras, encoders and LEDs through the sans-IO core on a real
simulation (tests/worlds/webots_api.yaml), plus the in-process pose setters."""

from __future__ import annotations

import itertools
import math

import msgpack
import numpy as np
import pytest
from test_webots_api import WORLD

from sensorium.schemas.wire import ErrorCode
from sensorium.server.daemon.services import Core
from sensorium.server.daemon.supervisor import matrix_axis_angle
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world, parse_world
from sensorium.server.world.poses import axis_angle_matrix

A, B = b"A", b"B"


class Live:
    def __init__(self, sim=None):
        self.sim = sim or Simulation(load_world(WORLD))
        n = itertools.count()
        self.core = Core(self.sim, new_token=lambda: f"s{next(n)}", log=lambda line: None)
        self.ids = itertools.count(1)
        self.pending: dict[int, dict] = {}

    def send(self, peer, service, args=None):
        rid = next(self.ids)
        body = msgpack.packb({"id": rid, "service": service, "args": args or {}})
        for frames in self.core.handle([peer, body], 0.0):
            r = msgpack.unpackb(frames[-1])
            self.pending[r["id"]] = r
        return rid

    def call(self, peer, service, args=None):
        return self.pending.pop(self.send(peer, service, args))

    def ok(self, peer, service, args=None):
        r = self.call(peer, service, args)
        assert r["ok"] is True, r
        return r["result"]

    def err(self, peer, service, args, code):
        r = self.call(peer, service, args)
        assert r["ok"] is False and r["error"]["code"] == code, r
        return r["error"]["message"]

    def step(self, peer, robot, args=None):
        rid = self.send(peer, f"/{robot}/robot/step", args)
        while rid not in self.pending:
            replies, _ = self.core.step_once(0.0)
            for frames in replies:
                r = msgpack.unpackb(frames[-1])
                self.pending[r["id"]] = r
        r = self.pending.pop(rid)
        assert r["ok"] is True, r
        return r["result"]


@pytest.fixture
def live():
    lv = Live()
    lv.ok(A, "attach", {"robot": "pioneer"})
    lv.ok(B, "attach", {"robot": "rover"})
    return lv


def test_supervisor_services_need_a_supervisor_robot_and_its_controller(live):
    msg = live.err(B, "/rover/robot/get_self", {}, ErrorCode.NOT_SUPERVISOR)
    assert "supervisor: true" in msg
    live.err(B, "/pioneer/robot/get_self", {}, ErrorCode.NOT_ATTACHED)      # not pioneer's controller
    live.err(B, "/rover/robot/simulation_reset", {}, ErrorCode.NOT_SUPERVISOR)
    assert live.ok(A, "/pioneer/robot/get_self") == {"node": 1, "type": "Robot", "name": "pioneer", "def_name": "",
                                                     "parent": 0, "proto": ""}
    assert live.ok(A, "/pioneer/robot/get_from_def", {"name": "wall"}) == {"node": 4, "type": "Solid", "name": "wall",
                                                                           "def_name": "", "parent": 0, "proto": ""}
    assert live.ok(A, "/pioneer/robot/get_from_def", {"name": "rover"})["node"] == 2
    assert live.ok(A, "/pioneer/robot/get_from_def", {"name": "nothing"}) == {
        "node": 0, "type": "", "name": "", "def_name": "", "parent": -1, "proto": ""}
    live.err(A, "/pioneer/robot/get_field", {"node": 99, "field": "translation"}, ErrorCode.INVALID_ARGUMENT)
    # a robot written without nested nodes (a YAML world) holds one node per device, in device order, then
    # its shapes that visual rays see (Shape nodes)
    kids = live.ok(A, "/pioneer/robot/get_field", {"node": 1, "field": "children"})
    devices = live.ok(A, "/pioneer/robot/get_device_list")["list"]
    assert kids["type"] == "MFNode" and len(kids["value"]) > len(devices)
    named = [live.ok(A, "/pioneer/robot/get_from_id", {"id": k}) for k in kids["value"]]
    assert [n["name"] for n in named[:len(devices)]] == devices
    assert {n["type"] for n in named[len(devices):]} == {"Shape"}
    assert live.ok(A, "/pioneer/robot/get_field", {"node": 1, "field": "parent"}) == {"type": "", "value": []}
    live.err(A, "/pioneer/robot/set_field", {"node": 1, "field": "rotation", "value": [0, 0, 1]},
             ErrorCode.INVALID_ARGUMENT)
    live.err(A, "/pioneer/robot/set_field", {"node": 1, "field": "rotation", "value": [0, 0, 0, 1]},
             ErrorCode.INVALID_ARGUMENT)


def test_fields_are_independent_and_poses_match(live):
    rover = 2
    live.ok(A, "/pioneer/robot/set_field", {"node": rover, "field": "rotation", "value": [0, 0, 1, 0.5]})
    assert live.ok(A, "/pioneer/robot/get_field", {"node": rover, "field": "translation"})["value"] == [0.0, 1.0, 0.1]
    live.ok(A, "/pioneer/robot/set_field", {"node": rover, "field": "translation", "value": [0.5, 1.5, 0.1]})
    rot = live.ok(A, "/pioneer/robot/get_field", {"node": rover, "field": "rotation"})["value"]
    assert rot == pytest.approx([0, 0, 1, 0.5], abs=1e-12)
    pose = live.ok(A, "/pioneer/robot/get_node_pose", {"node": rover})
    assert pose["position"] == [0.5, 1.5, 0.1]
    assert np.array(pose["orientation"]).reshape(3, 3) == pytest.approx(axis_angle_matrix((0, 0, 1), 0.5), abs=1e-15)
    # the robot's own set_pose service: a translation alone keeps the rotation too
    live.ok(B, "/rover/robot/set_pose", {"translation": [0.0, 2.0, 0.1]})
    got = live.ok(B, "/rover/robot/get_pose")
    assert got["translation"] == [0.0, 2.0, 0.1]
    assert got["quaternion"] == pytest.approx([0, 0, math.sin(0.25), math.cos(0.25)], abs=1e-15)
    live.ok(B, "/rover/robot/set_pose", {"rotation": [0, 0, 1, 0.0]})          # rotation alone keeps the translation
    assert live.ok(B, "/rover/robot/get_pose")["translation"] == [0.0, 2.0, 0.1]


def test_reset_and_mode(live):
    live.ok(A, "/pioneer/robot/set_field", {"node": 4, "field": "translation", "value": [9.0, 0.0, 0.25]})
    live.ok(A, "/pioneer/left wheel motor/set_position", {"value": math.inf})
    live.ok(A, "/pioneer/left wheel motor/set_velocity", {"value": 5.0})
    live.ok(A, "/pioneer/led0/set", {"value": 2})
    live.step(A, "/pioneer".strip("/"))
    assert live.sim.robot("pioneer").pose.translation[0] != 0.0
    live.ok(A, "/pioneer/robot/simulation_reset")
    assert live.sim.robot("pioneer").pose.translation.tolist() == [0.0, 0.0, 0.1]
    assert live.sim.scene.solid_poses["wall"].translation.tolist() == [2.0, 0.0, 0.25]
    assert live.ok(B, "/pioneer/led0/get") == {"value": 0}
    assert live.sim.robot("pioneer").motors["left wheel motor"].target_position == 0.0
    assert live.sim.time_ms == 32                                   # the clock keeps running
    live.ok(A, "/pioneer/robot/simulation_set_mode", {"mode": 0})
    assert live.ok(B, "get_info")["mode"] == "pause"
    assert live.ok(A, "/pioneer/robot/simulation_get_mode") == {"value": 0}
    live.ok(A, "/pioneer/robot/simulation_set_mode", {"mode": 2})
    assert live.ok(B, "get_info")["mode"] == "fast"
    live.err(A, "/pioneer/robot/simulation_set_mode", {"mode": 3}, ErrorCode.INVALID_ARGUMENT)


def test_attach_robot_extras_and_custom_data(live):
    live.ok(A, "detach", {"session": "s0"})
    res = live.ok(A, "attach", {"robot": "pioneer"})
    assert (res["supervisor"], res["model"], res["custom_data"]) == (True, "Pioneer 3-DX (kinematic)", "gain=2")
    kinds = {d["name"]: d for d in res["devices"]}
    assert [d["index"] for d in res["devices"]] == list(range(len(res["devices"])))
    assert {k: v for k, v in kinds["left wheel sensor"].items() if k != "index"} == {
        "name": "left wheel sensor", "type": "PositionSensor", "sampling_period": 0, "motor": "left wheel motor",
        "noise": 0.0, "resolution": -1.0, "model": "", "simulated": True}
    assert {k: v for k, v in kinds["led0"].items() if k != "index"} == {
        "name": "led0", "type": "LED", "value": 0, "color": [1.0, 0, 0, 0, 1.0, 0], "gradual": False,
        "model": "", "simulated": True}
    live.err(B, "/pioneer/robot/set_custom_data", {"value": "x"}, ErrorCode.NOT_ATTACHED)
    live.ok(A, "/pioneer/robot/set_custom_data", {"value": "x"})
    assert live.ok(B, "/pioneer/robot/get_custom_data") == {"value": "x"}
    assert live.ok(B, "/pioneer/robot/get_model") == {"value": "Pioneer 3-DX (kinematic)"}
    assert live.ok(B, "/rover/robot/get_model") == {"value": ""}


def test_encoders_leds_and_step_zero(live):
    enc = "/pioneer/left wheel sensor/"
    live.ok(A, enc + "enable", {"value": 64})
    assert math.isnan(live.ok(B, enc + "get_value")["value"])                 # NaN before the first sample
    motors = {"left wheel motor": {"position": math.inf, "velocity": 2.0},
              "right wheel motor": {"position": math.inf, "velocity": 2.0}}
    r = live.step(A, "pioneer", {"duration": 0, "motors": motors})           # step(0): no time passes
    assert r == {"status": 0, "time_ms": 0, "values": {}}
    assert live.sim.robot("pioneer").motors["left wheel motor"].velocity == 2.0
    r = live.step(A, "pioneer", {"duration": 32})
    assert r["values"] == {}                                                 # 64 ms period: nothing yet
    r = live.step(A, "pioneer", {"duration": 33})                            # rounded up to 64
    assert r["time_ms"] == 96 and r["values"]["left wheel sensor"]["value"] == pytest.approx(2.0 * 0.064)
    r = live.step(A, "pioneer", {"duration": 0})                             # values already delivered
    assert r == {"status": 0, "time_ms": 96, "values": {}}
    # LEDs: index range, gradual colours
    live.err(A, "/pioneer/led0/set", {"value": 3}, ErrorCode.INVALID_ARGUMENT)
    live.err(B, "/pioneer/led0/set", {"value": 1}, ErrorCode.NOT_ATTACHED)
    live.ok(A, "/pioneer/rgb/set", {"value": 0xFF8000})
    assert live.ok(B, "/pioneer/rgb/get") == {"value": 0xFF8000}
    assert live.sim.robot("pioneer").devices["rgb"].rgb() == (1.0, 128 / 255, 0.0)
    live.err(A, "/pioneer/rgb/set", {"value": 0x1000000}, ErrorCode.INVALID_ARGUMENT)


def test_position_sensor_noise_and_resolution():
    def run(seed):
        data = load_world(WORLD).world.model_dump()
        data["world_info"]["random_seed"] = seed
        dev = data["robots"][0]["devices"]
        dev[0].update(noise=0.01, resolution=0.05)
        sim = Simulation(parse_world(data))
        r = sim.robot("pioneer")
        for m in r.motors.values():
            m.set_position(math.inf)
            m.set_velocity(3.0)
        r.devices["left wheel sensor"].enable(32)
        r.devices["right wheel sensor"].enable(32)
        out = []
        for _ in range(20):
            sim.step()
            out.append((r.devices["left wheel sensor"].value, r.devices["right wheel sensor"].value))
        return out
    a, b, c = run(1), run(1), run(2)
    assert a == b and a != c
    for k, (left, right) in enumerate(a, start=1):
        assert right == pytest.approx(3.0 * 0.032 * k, abs=1e-12)            # no noise on the right one
        assert left / 0.05 == pytest.approx(round(left / 0.05), abs=1e-9)    # quantised
        assert abs(left - 3.0 * 0.032 * k) < 0.025 + 5 * 0.01                # within resolution + 5 sigma


def test_position_sensor_resolution_is_webots_discretize_also_backwards():
    """Webots rounds an encoder with WbMathsUtilities::discretize, ``(int)(v/res + 0.5)·res`` (C's
    cast truncates toward zero), as the light and distance sensors. Python's round() was used: a
    wheel turning backwards read one step more negative (-1.92 steps: -2 instead of Webots' -1). The
    batched simulation reads the same values."""
    from sensorium.schemas import world as wm
    from sensorium.server.sim.batched import BatchedSimulation

    res, w = 0.05, -3.0
    world = wm.World.model_validate({
        "world_info": {"basic_time_step": 16, "contact": False},
        "robots": [{"name": "bot", "differential_drive": {"wheel_radius": 0.02, "axle_length": 0.05,
                                                          "max_wheel_speed": 10.0},
                    "devices": [{"device": "PositionSensor", "name": "enc", "motor": "left wheel motor",
                                 "resolution": res}]}]})
    sim, bs = Simulation(world), BatchedSimulation(world, 1)
    sim.robot("bot").device("enc").enable(16)
    bs.enable(bs.device("bot", "enc"), 16)
    for m in sim.robot("bot").motors.values():
        m.set_position(math.inf)
    sim.robot("bot").drive.left.set_velocity(w)
    bs.set_wheels(0, np.array([w]), np.array([0.0]))
    for k in range(1, 40):
        sim.step()
        bs.step()
        angle = w * 0.016 * k
        want = int(angle / res + 0.5) * res + 0.0
        got = sim.robot("bot").device("enc").value
        assert got == pytest.approx(want, abs=1e-12), (k, angle, got, want)
        assert float(bs.value(bs.device("bot", "enc"))[0]) == got
    assert got == pytest.approx(-1.8, abs=1e-12)   # -1.872 rad = -37.44 steps: Webots' -36 (round() gave -37)


def test_in_process_pose_setters_keep_what_is_left_out():
    sim = Simulation(load_world(WORLD))
    rover = sim.robot("rover")
    rover.set_pose([0.0, 1.0, 0.1], rotation=[0, 0, 1, 1.0])
    rover.set_pose([2.0, 2.0, 0.1])
    assert rover.pose.rotation == pytest.approx(axis_angle_matrix((0, 0, 1), 1.0), abs=1e-15)
    rover.set_pose(rotation=[0, 0, 1, 0.0])
    assert rover.pose.translation.tolist() == [2.0, 2.0, 0.1]
    sim.set_solid_pose("wall", [2.0, 0.0, 0.25], rotation=[0, 0, 1, 0.3])
    sim.set_solid_pose("wall", [3.0, 0.0, 0.25])
    assert sim.scene.solid_poses["wall"].rotation == pytest.approx(axis_angle_matrix((0, 0, 1), 0.3), abs=1e-15)


@pytest.mark.parametrize("axis, angle", [((0, 0, 1), 0.0), ((0, 0, 1), 1.0), ((1, 2, 3), 2.5), ((1, -1, 0), math.pi),
                                         ((0.3, 0.1, -1), math.pi - 1e-7)])
def test_matrix_axis_angle_round_trip(axis, angle):
    aa = matrix_axis_angle(axis_angle_matrix(axis, angle))
    assert axis_angle_matrix(aa[:3], aa[3]) == pytest.approx(axis_angle_matrix(axis, angle), abs=1e-7)
    assert 0.0 <= aa[3] <= math.pi and math.hypot(*aa[:3]) == pytest.approx(1.0)


def test_info_summary_lists_encoders_leds_and_supervisor():
    from sensorium.server.sim.summary import world_summary

    s = world_summary(WORLD)
    pioneer = s["robots"][0]
    assert pioneer["supervisor"] is True and s["robots"][1]["supervisor"] is False
    lines = {d["name"]: d["summary"] for d in pioneer["devices"]}
    assert lines["left wheel sensor"] == "PositionSensor on 'left wheel motor' noise 0 resolution -1"
    assert lines["led0"] == "LED 2 colours" and lines["rgb"] == "LED gradual"


def test_info_summary_names_an_encoder_on_a_joint_nothing_turns():
    """A PositionSensor whose joint no drive turns (a gripper's arm) says so, not "on None"."""
    from sensorium.schemas import world as wm
    from sensorium.server.sim.summary import device_line

    assert device_line(wm.PositionSensor(device="PositionSensor", name="arm sensor")) == \
        "PositionSensor on a joint nothing turns here (present, reads its position, 0)"


def test_a_refused_set_field_value_is_one_short_line():
    # the value's union of types: one complaint naming the argument once (each member's mismatch echoed
    # the value, and the 512-character cut left only the first: "should be a valid boolean"), shortened
    live = Live()
    live.ok(A, "attach", {"robot": "pioneer"})
    for value, said in [("x" * 5000, "String should have at most 4096 characters"),
                        (float("nan"), "Input should be a finite number (got nan)")]:
        message = live.err(A, "/pioneer/robot/set_field", {"node": 1, "field": "translation", "value": value},
                           ErrorCode.INVALID_ARGUMENT)
        assert message.count("argument 'value'") == 1 and said in message and len(message) < 200, message
