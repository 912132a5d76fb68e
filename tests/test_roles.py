"""Who may do what: world-wide controls need the supervisor role unless the server opens them,
and every pose a request sets is finite and within the world bounds (issue 16)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_supervisor import Live

from sensorium.schemas.wire import ErrorCode
from sensorium.server.daemon.roles import MAX_COORDINATE_M, is_local_endpoint, open_controls
from sensorium.server.daemon.serve import ServeOptions, build
from sensorium.server.daemon.services import Core

A, B, C = b"A", b"B", b"C"


def closed() -> Live:
    lv = Live()
    lv.core = Core(lv.sim, log=lambda line: None, open_controls=False)
    lv.ok(A, "attach", {"robot": "pioneer"})        # supervisor: true in the world
    lv.ok(B, "attach", {"robot": "rover"})          # a plain robot
    return lv


def test_set_mode_needs_the_supervisor_role_when_controls_are_closed():
    lv = closed()
    for peer in (B, C):                             # a plain robot's controller, an unattached caller
        msg = lv.err(peer, "set_mode", {"mode": "pause"}, ErrorCode.NOT_SUPERVISOR)
        assert "supervisor: true" in msg and "--controls open" in msg
    assert lv.ok(C, "get_info")["mode"] == "fast"   # nothing changed
    assert lv.ok(A, "set_mode", {"mode": "pause"}) == {"mode": "pause"}
    assert lv.ok(C, "get_info")["mode"] == "pause"
    lv.ok(A, "detach", {"session": lv.core.lockstep.session_for("pioneer").token})
    lv.err(A, "set_mode", {"mode": "fast"}, ErrorCode.NOT_SUPERVISOR)   # the role goes with the session


def test_set_pose_and_counters_need_the_supervisor_role_when_controls_are_closed():
    """issue 28: under --controls supervisor any client moved robots and read get_counters."""
    lv = closed()
    before = lv.ok(C, "/rover/robot/get_pose")
    for peer in (B, C):              # the rover's own controller, an unattached caller
        msg = lv.err(peer, "/rover/robot/set_pose", {"translation": [1.0, 2.0, 0.0]}, ErrorCode.NOT_SUPERVISOR)
        assert "supervisor: true" in msg
        msg = lv.err(peer, "get_counters", {}, ErrorCode.NOT_SUPERVISOR)
        assert "world-wide control" in msg and "changes the world" not in msg   # it only reads
    assert lv.ok(C, "/rover/robot/get_pose") == before             # nobody moved it
    assert lv.ok(A, "/rover/robot/set_pose", {"translation": [1.0, 2.0, 0.0]}) == {"success": True}
    assert lv.ok(C, "/rover/robot/get_pose")["translation"] == [1.0, 2.0, 0.0]
    assert "counters" in lv.ok(A, "get_counters")
    lv.ok(C, "get_info")                                           # reading the world stays open


@pytest.mark.parametrize("translation", [[1e300, 0.0, 0.0], [0.0, math.nan, 0.0], [0.0, 0.0, -2 * MAX_COORDINATE_M]])
def test_in_process_set_pose_rejects_absurd_poses(translation):
    lv = Live()
    robot = lv.sim.robots["rover"]
    before = robot.pose.translation.copy()
    with pytest.raises(ValueError, match="translation"):
        robot.set_pose(translation)
    assert (robot.pose.translation == before).all()
    with pytest.raises(ValueError, match="rotation"):
        robot.set_pose(None, rotation=[0.0, 0.0, 1.0, math.inf])


@pytest.mark.parametrize("translation", [[1e300, 0.0, 0.0], [0.0, math.inf, 0.0]])
def test_in_process_set_solid_pose_rejects_absurd_poses(translation):
    """issue 28, the rest of the in-process API: a solid's pose is checked like a robot's."""
    lv = Live()
    before = lv.sim.scene.solid_poses["wall"].translation.copy()
    with pytest.raises(ValueError, match="translation"):
        lv.sim.set_solid_pose("wall", translation)
    assert (lv.sim.scene.solid_poses["wall"].translation == before).all()


@pytest.mark.parametrize("scale", [1e300, 1e-300, 1.0])
def test_huge_or_tiny_quaternions_and_axes_give_the_rotation_they_denote(scale):
    """A quaternion (1e300, 0, 0, 1e300·0) is a half turn about x; its norm overflowed to inf and
    the robot ended up unrotated (an axis likewise). Values are scaled before normalising."""
    lv = Live()
    robot = lv.sim.robots["rover"]
    robot.set_pose(None, quaternion=[scale, 0.0, 0.0, 0.0])
    np.testing.assert_allclose(robot.pose.rotation, [[1, 0, 0], [0, -1, 0], [0, 0, -1]], atol=1e-12)
    robot.set_pose(None, rotation=[0.0, 0.0, scale, math.pi / 2])
    np.testing.assert_allclose(robot.pose.rotation, [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-12)


def test_open_controls_let_any_caller_set_the_mode():
    lv = Live()                                     # Core's default: open
    assert lv.ok(C, "set_mode", {"mode": "pause"}) == {"mode": "pause"}


@pytest.mark.parametrize("url,local", [
    ("tcp://127.0.0.1:5560", True), ("tcp://127.0.0.2:0", True), ("tcp://[::1]:5560", True),
    ("tcp://localhost:5560", True), ("ipc:///tmp/s.sock", True), ("inproc://x", True),
    ("tcp://0.0.0.0:5560", False), ("tcp://*:5560", False), ("tcp://192.168.1.5:5560", False),
    ("tcp://eth0:5560", False), ("tcp://[::]:5560", False),
])
def test_auto_controls_are_open_only_on_local_endpoints(url, local):
    assert is_local_endpoint(url) is local
    assert open_controls("auto", url) is local
    assert open_controls("open", url) is True
    assert open_controls("supervisor", url) is False


def test_serve_options_choose_the_controls():
    with pytest.raises(ValueError, match="--controls"):
        ServeOptions(controls="everyone").check()
    for controls, want in (("auto", True), ("supervisor", False), ("open", True)):
        core, transport = build(None, ServeOptions(rpc="tcp://127.0.0.1:0", pub="tcp://127.0.0.1:0", controls=controls))
        try:
            assert core.open_controls is want
        finally:
            transport.close()


@pytest.mark.parametrize("args", [
    {"translation": [1e300, 0.0, 0.0]},
    {"translation": [0.0, -(MAX_COORDINATE_M * 1.01), 0.0]},
    {"translation": [math.nan, 0.0, 0.0]},
    {"translation": [0.0, 0.0, math.inf]},
    {"rotation": [0.0, 0.0, 1.0, math.nan]},
    {"quaternion": [0.0, 0.0, math.inf, 1.0]},
])
def test_set_pose_rejects_non_finite_and_far_poses(args):
    lv = closed()
    before = lv.ok(B, "/rover/robot/get_pose")
    msg = lv.err(A, "/rover/robot/set_pose", args, ErrorCode.INVALID_ARGUMENT)   # the supervisor moves it
    assert "set_pose" in msg
    assert lv.ok(B, "/rover/robot/get_pose") == before


def test_set_pose_accepts_the_bounds():
    lv = closed()
    lv.ok(A, "/rover/robot/set_pose", {"translation": [MAX_COORDINATE_M, -MAX_COORDINATE_M, 0.1]})
    assert lv.ok(B, "/rover/robot/get_pose")["translation"] == [MAX_COORDINATE_M, -MAX_COORDINATE_M, 0.1]


@pytest.mark.parametrize("value", [[1e300, 0.0, 0.0], [0.0, 2e5, 0.0], [math.nan, 0.0, 0.0]])
def test_supervisor_set_field_rejects_far_or_non_finite_translations(value):
    lv = closed()
    before = lv.ok(A, "/pioneer/robot/get_field", {"node": 2, "field": "translation"})
    lv.err(A, "/pioneer/robot/set_field", {"node": 2, "field": "translation", "value": value},
           ErrorCode.INVALID_ARGUMENT)
    assert lv.ok(A, "/pioneer/robot/get_field", {"node": 2, "field": "translation"}) == before
