"""The Connector and the Brake (Webots' nodes) in the simulation, closed form: two robots' connectors
facing each other read presence 1 on the near side of each of Webots' boundaries (origins within
``distance_tolerance``, x axes opposed within ``axis_tolerance``, z axes within ``rotation_tolerance``
of an allowed docking rotation) and 0 just past it; face types and models; -1 for a passive one and
before the first value; the sampling period's timing; the lock state (lock, unlock, auto_lock, a
reset); the Brake's description; the world-file checks and the .wbt import."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.daemon.services import Core
from sensorium.server.devices import connector as cmath
from sensorium.server.sim.connector import ConnectorWarning
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.geometry import Pose
from sensorium.server.world.loader import check_world, load_world

STEP = 16
ARM = 0.1        # robot a's connector sits 0.1 m ahead of its origin, facing +x


def world(d: float = 0.005, yaw: float = math.pi, roll: float = 0.0, a: dict | None = None, b: dict | None = None,
          b_robot: dict | None = None) -> wm.World:
    """Robot a's connector at (0.1, 0, 0), its x axis +x; robot b's connector at its own origin,
    ``d`` further along x, turned by ``yaw`` about z (π: facing a) and then by ``roll`` about its own
    x axis. For yaw = π the rotation Rz(π)·Rx(roll) is a half turn about (0, sin(roll/2), cos(roll/2)):
    b's x axis is exactly -x and its z axis (0, sin roll, cos roll), at ``roll`` from a's."""
    if roll:
        assert yaw == math.pi
        rotation = [0.0, math.sin(roll / 2.0), math.cos(roll / 2.0), math.pi]
    else:
        rotation = [0.0, 0.0, 1.0, yaw]
    return wm.World.model_validate({
        "world_info": {"basic_time_step": STEP},
        "robots": [
            {"name": "a", "devices": [{"device": "Connector", "name": "dock", "pose": {"translation": [ARM, 0, 0]},
                                       **(a or {})}]},
            {"name": "b", "pose": {"translation": [ARM + d, 0.0, 0.0]},
             "devices": [{"device": "Connector", "name": "dock", "pose": {"rotation": rotation}, **(b or {})}],
             **(b_robot or {})}]})


def presence(w: wm.World, who: str = "a/dock") -> int:
    sim = Simulation(w)
    dev = sim.device(who)
    dev.enable(STEP)
    sim.step()
    return dev.value


@pytest.mark.parametrize(("d", "expected"), [(0.0, 1), (0.0099, 1), (0.0101, 0), (-0.0099, 1), (0.05, 0)])
def test_presence_within_the_distance_tolerance(d: float, expected: int) -> None:
    # Webots' default tolerance 0.01 m between the origins (b's connector behind a's: d < 0, still near)
    assert presence(world(d)) == expected
    assert presence(world(d), "b/dock") == expected


@pytest.mark.parametrize(("tolerance", "expected"), [(0.0301, 1), (0.0299, 0)])
def test_each_connector_judges_with_its_own_distance_tolerance(tolerance: float, expected: int) -> None:
    w = world(0.03, a={"distance_tolerance": tolerance})
    assert presence(w, "a/dock") == expected
    assert presence(w, "b/dock") == 0                 # b keeps Webots' 0.01


@pytest.mark.parametrize(("off", "expected"), [(0.19, 1), (-0.19, 1), (0.21, 0), (-0.21, 0)])
def test_presence_needs_the_x_axes_opposed_within_the_axis_tolerance(off: float, expected: int) -> None:
    # b turned by pi - off about z: the x axes at pi - |off| (> pi - 0.2 needed), the z axes parallel
    assert presence(world(0.0, yaw=math.pi - off)) == expected


def test_facing_the_same_way_is_no_presence() -> None:
    assert presence(world(0.0, yaw=0.0)) == 0


@pytest.mark.parametrize(("roll", "expected"), [
    (0.19, 1), (0.21, 0),                                         # about 0
    (math.pi / 2 - 0.19, 1), (math.pi / 2 + 0.19, 1),             # about a quarter turn (4 rotations)
    (math.pi / 2 - 0.21, 0), (math.pi / 2 + 0.21, 0),
    (math.pi - 0.19, 1), (math.pi - 0.21, 0)])                    # about the half turn
def test_presence_needs_the_z_axes_at_an_allowed_docking_rotation(roll: float, expected: int) -> None:
    assert presence(world(0.0, roll=roll)) == expected


@pytest.mark.parametrize(("rotations", "roll", "expected"), [
    (2, math.pi / 2, 0), (2, math.pi - 0.1, 1), (1, math.pi - 0.1, 0), (1, 0.1, 1), (0, math.pi / 2 + 0.3, 1),
    (3, 2 * math.pi / 3 + 0.1, 1), (3, math.pi / 2, 0)])
def test_the_number_of_rotations_sets_the_docking_angles(rotations: int, roll: float, expected: int) -> None:
    w = world(0.0, roll=roll, a={"number_of_rotations": rotations})
    assert presence(w, "a/dock") == expected


@pytest.mark.parametrize(("ta", "tb", "pa", "pb"), [
    ("symmetric", "symmetric", 1, 1), ("active", "passive", 1, -1), ("passive", "active", -1, 1),
    ("active", "active", 0, 0), ("symmetric", "active", 0, 0), ("symmetric", "passive", 0, -1),
    ("passive", "passive", -1, -1)])
def test_face_types_dock_symmetric_with_symmetric_and_active_with_passive(ta: str, tb: str, pa: int, pb: int) -> None:
    # a passive connector reads -1 whatever is in front of it (Webots: "not applicable")
    w = world(0.0, a={"type": ta}, b={"type": tb})
    assert (presence(w, "a/dock"), presence(w, "b/dock")) == (pa, pb)


def test_models_must_be_equal() -> None:
    assert presence(world(0.0, a={"model": "MX-1"}, b={"model": "MX-1"})) == 1
    assert presence(world(0.0, a={"model": "MX-1"}, b={"model": "MX-2"})) == 0


def test_a_lone_connector_reads_no_presence() -> None:
    w = wm.World.model_validate({"world_info": {"basic_time_step": STEP},
                                 "robots": [{"name": "a", "devices": [{"device": "Connector", "name": "dock"}]}]})
    assert presence(w) == 0


def test_minus_one_before_the_first_value_then_the_value_at_each_period() -> None:
    sim = Simulation(world(0.0))
    dock = sim.device("a/dock")
    assert dock.value == -1 and dock.step_reading() == {"value": -1}
    sim.step()
    assert dock.value == -1 and dock.measured_at_ms == -1          # not enabled: never measured
    dock.enable(48)                                                 # at 16 ms: values at 64, 112, ...
    sim.step()
    sim.step()
    assert dock.value == -1
    sim.step()
    assert (sim.time_ms, dock.value, dock.measured_at_ms) == (64, 1, 64)
    b = sim.robots["b"]
    sim.place_robot(b, Pose(b.pose.rotation, b.pose.translation + [0.5, 0.0, 0.0]))      # away, at 64 ms
    sim.step()
    sim.step()
    assert (sim.time_ms, dock.value) == (96, 1)                     # the last value kept between periods
    sim.step()
    assert (sim.time_ms, dock.value, dock.measured_at_ms) == (112, 0, 112)


def test_lock_unlock_and_is_locked() -> None:
    sim = Simulation(world(0.5, b={"type": "symmetric", "is_locked": True}))
    a, b = sim.device("a/dock"), sim.device("b/dock")
    assert (a.is_locked, b.is_locked) == (False, True)
    with warnings.catch_warnings():
        warnings.simplefilter("error")                    # no peer present: nothing to join, no warning
        assert a.lock() is True and a.is_locked
        assert b.unlock() is False and not b.is_locked
    sim.reset()                                           # the world file's lock states again
    assert (a.is_locked, b.is_locked) == (False, True)


def test_a_passive_connector_cannot_lock() -> None:
    sim = Simulation(world(0.0, b={"type": "passive"}))
    b = sim.device("b/dock")
    assert b.lock() is False and not b.is_locked
    with pytest.raises(ValueError, match="passive connector cannot be locked"):
        world(0.0, b={"type": "passive", "is_locked": True})


def test_locking_with_a_peer_present_joins_nothing_and_says_so_once() -> None:
    sim = Simulation(world(0.0))
    a = sim.device("a/dock")
    with pytest.warns(ConnectorWarning, match="nothing is joined"):
        a.lock()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        a.unlock()
        a.lock()                                          # once per connector
    assert a.is_locked


def test_auto_lock_attaches_only_a_locked_connector_and_keeps_its_lock_state() -> None:
    # Webots: auto-locking needs isLocked already true (wb_connector_lock called before); meeting a peer
    # does not change the lock state, it makes the link, which needs physics: the one warning here
    sim = Simulation(world(0.5, a={"auto_lock": True}))
    a = sim.device("a/dock")
    b_robot = sim.robots["b"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sim.step()
        sim.place_robot(b_robot, Pose(b_robot.pose.rotation, np.array([ARM, 0.0, 0.0])))
        sim.step()                                        # a peer present, a unlocked: nothing happens
    assert not a.is_locked
    sim.place_robot(b_robot, Pose(b_robot.pose.rotation, np.array([ARM + 0.5, 0.0, 0.0])))
    a.lock()
    sim.step()
    sim.place_robot(b_robot, Pose(b_robot.pose.rotation, np.array([ARM, 0.0, 0.0])))
    with pytest.warns(ConnectorWarning, match="nothing is joined"):
        sim.step()
    assert a.is_locked


def test_the_pure_rule_by_hand() -> None:
    x, mx = np.array([1.0, 0.0, 0.0]), np.array([-1.0, 0.0, 0.0])
    assert cmath.unit_angle(x, mx) == math.pi and cmath.unit_angle(x, x) == 0.0
    assert cmath.axes_opposed(x, mx, 0.0) is False                  # strictly above pi - 0: never
    assert cmath.near_enough(np.zeros(3), np.array([0.01, 0.0, 0.0]), 0.01)      # <=, as Webots
    z = np.array([0.0, 0.0, 1.0])
    assert cmath.rotation_aligned(z, z, 4, 0.0) is False            # strictly within the tolerance
    assert cmath.compatible("active", "", "passive", "") and not cmath.compatible("passive", "", "passive", "")


def test_the_attach_descriptions() -> None:
    core = Core(Simulation(world(0.0, a={"type": "active", "auto_lock": True}, b={"type": "passive"})))
    devs = {d["name"]: d for d in core._describe_robot("a")}
    d = devs["dock"]
    assert d["type"] == "Connector" and d["simulated"] is True and d["connector_type"] == "active"
    assert (d["is_locked"], d["auto_lock"], d["distance_tolerance"], d["number_of_rotations"]) == (False, True, 0.01, 4)


BRAKES = {"world_info": {"basic_time_step": STEP}, "robots": [{"name": "arm", "devices": [
    {"device": "RotationalMotor", "name": "shoulder"},
    {"device": "PositionSensor", "name": "shoulder sensor", "motor": "shoulder"},
    {"device": "Brake", "name": "shoulder brake", "motor": "shoulder", "position_sensor": "shoulder sensor"},
    {"device": "LinearMotor", "name": "slide"},
    {"device": "Brake", "name": "slide brake", "motor": "slide", "joint_type": "linear"},
    {"device": "Brake", "name": "loose brake"}]}]}


def test_a_brake_describes_its_joint() -> None:
    core = Core(Simulation(wm.World.model_validate(BRAKES)))
    devs = {d["name"]: d for d in core._describe_robot("arm")}
    assert {k: devs["shoulder brake"][k] for k in ("type", "joint_type", "motor", "position_sensor", "simulated")} == \
        {"type": "Brake", "joint_type": 0, "motor": "shoulder", "position_sensor": "shoulder sensor", "simulated": True}
    assert (devs["slide brake"]["joint_type"], devs["slide brake"]["motor"]) == (1, "slide")
    assert (devs["loose brake"]["motor"], devs["loose brake"]["position_sensor"]) == (None, None)


def test_a_brake_names_devices_of_its_robot_and_its_motor_s_joint_type() -> None:
    bad = {**BRAKES, "robots": [{"name": "arm", "devices": [
        *BRAKES["robots"][0]["devices"],
        {"device": "Brake", "name": "b1", "motor": "elbow"},
        {"device": "Brake", "name": "b2", "position_sensor": "shoulder"},
        {"device": "Brake", "name": "b3", "motor": "slide"}]}]}
    problems = {p.path: p.message for p in check_world(wm.World.model_validate(bad), Path.cwd())}
    assert "'elbow' is not a motor of this robot" in problems["robots[0].devices[6].motor"]
    assert "'shoulder' is not a PositionSensor" in problems["robots[0].devices[7].position_sensor"]
    assert "its motor 'slide' is linear" in problems["robots[0].devices[8].joint_type"]


WBT = """#VRML_SIM R2023b utf8
WorldInfo { basicTimeStep 16 }
Robot {
  name "a"
  children [
    Connector { translation 0.1 0 0 name "dock" type "active" model "M" distanceTolerance -1 axisTolerance 4
                numberOfRotations 2 isLocked TRUE autoLock TRUE }
    HingeJoint {
      device [ RotationalMotor { name "m" } PositionSensor { name "ps" } Brake { name "br" } ]
    }
    SliderJoint { device [ Brake { name "slider brake" } ] }
  ]
  controller "<extern>"
}
"""


def test_a_wbt_connector_and_brake_load_simulated_with_webots_resets(tmp_path: Path) -> None:
    path = tmp_path / "dock.wbt"
    path.write_text(WBT)
    loaded = load_world(path)
    said = list(loaded.warnings)
    assert not [s for s in said if "not simulated" in s or "no value" in s], said
    assert any("distanceTolerance: -1 is negative; using 0" in s for s in said), said
    assert any("axisTolerance: 4 is outside [0, pi]" in s for s in said), said
    devs = {d.name: d for d in loaded.world.robots[0].devices}
    dock = devs["dock"]
    assert isinstance(dock, wm.Connector)
    assert (dock.type, dock.model, dock.distance_tolerance, dock.axis_tolerance, dock.number_of_rotations,
            dock.is_locked, dock.auto_lock) == ("active", "M", 0.0, math.pi, 2, True, True)
    br, sb = devs["br"], devs["slider brake"]
    assert isinstance(br, wm.Brake) and (br.joint_type, br.motor, br.position_sensor) == ("rotational", "m", "ps")
    assert isinstance(sb, wm.Brake) and (sb.joint_type, sb.motor, sb.position_sensor) == ("linear", None, None)


def crate_world(eye: dict | None = None) -> wm.World:
    """Robot a's active connector at (0.1, 0, 0) facing +x; a crate at (1, 0, 0) whose child (at -0.4
    in its frame) carries a passive connector 0.5 m further back, turned to face -x: at (0.1, 0, 0)."""
    return wm.World.model_validate({
        "world_info": {"basic_time_step": STEP},
        "robots": [{"name": "a", "devices": [{"device": "Connector", "name": "dock", "type": "active",
                                              "pose": {"translation": [ARM, 0, 0]}}]}],
        "solids": [{"name": "crate", "pose": {"translation": [1.0, 0.0, 0.0]}, "children": [
            {"name": "handle", "pose": {"translation": [-0.4, 0.0, 0.0]}, "connectors": [
                {"device": "Connector", "name": "eye", "type": "passive",
                 "pose": {"translation": [-0.5, 0.0, 0.0], "rotation": [0, 0, 1, math.pi]}, **(eye or {})}]}]}]})


def test_a_robot_connector_sees_a_connector_on_a_solid_as_the_solid_moves_and_goes() -> None:
    sim = Simulation(crate_world())
    dock = sim.device("a/dock")
    dock.enable(STEP)
    sim.step()
    assert dock.value == 1
    sim.set_solid_pose("crate", [1.0, 0.02, 0.0])          # 2 cm aside: beyond the 1 cm tolerance
    sim.step()
    assert dock.value == 0
    sim.set_solid_pose("crate", [1.0, 0.009, 0.0])
    sim.step()
    assert dock.value == 1
    sim.remove_solid("crate")
    sim.step()
    assert dock.value == 0
    assert presence(crate_world({"type": "active"})) == 0                  # active-active: incompatible


def test_a_wbt_connector_outside_a_robot_is_a_solid_s_connector(tmp_path: Path) -> None:
    path = tmp_path / "crate.wbt"
    path.write_text(WBT.replace('distanceTolerance -1 axisTolerance 4\n                numberOfRotations 2 ', "")
                    + 'Solid { translation 1 0 0 name "crate" children [\n'
                      '  Connector { translation -0.9 0 0 rotation 0 0 1 3.141592653589793 name "eye" type "passive"'
                      ' model "M" } ] }\n')
    loaded = load_world(path)
    assert not [w for w in loaded.warnings if "Connector" in w], loaded.warnings
    [eye] = loaded.world.solids[0].children[0].connectors
    assert (eye.name, eye.type, eye.model) == ("eye", "passive", "M")
    sim = Simulation(loaded)
    dock = sim.device("a/dock")
    dock.enable(STEP)
    with pytest.warns(ConnectorWarning, match="'a/dock': locked with a peer present"):   # locked, auto-lock
        sim.step()
    assert dock.value == 1


def test_the_batched_simulation_refuses_a_connector_in_one_line() -> None:
    from sensorium.server.sim.batched import BatchedError, BatchedSimulation

    sim = BatchedSimulation(crate_world(), copies=2)
    with pytest.raises(BatchedError, match="'dock' is a Connector; the batched simulation measures"):
        sim.device("a", "dock")


HOP = """#VRML_SIM R2023b utf8
WorldInfo { basicTimeStep 16 }
""" + "".join(f"""Robot {{
  name "{name}" translation {x} 0 0 rotation 0 0 1 {turn}
  children [
    HingeJoint {{
      jointParameters HingeJointParameters {{ axis 0 -1 0 anchor 0 0 0.06 }}
      device [ RotationalMotor {{ name "upper motor" maxVelocity 1 minPosition -1.57 maxPosition 1.57 }}
               PositionSensor {{ name "upper sensor" }} ]
      endPoint Solid {{ translation 0 0 0.06 children [
        Connector {{ translation 0 0 0.055 rotation 0 -1 0 1.5707963267948966 model "magnetic" autoLock TRUE
                    axisTolerance 3.14 rotationTolerance 3.14 }} ] }}
    }}
  ]
  controller "<extern>"
}}
""" for name, x, turn in (("MyBot 1", 0.0, 0.0), ("MyBot 2", 0.11, math.pi)))


def test_connectors_on_arms_dock_when_the_arms_turn_them_face_to_face(tmp_path: Path) -> None:
    """Webots' connector sample's robots (our own world): each connector sits on a hinge about -y
    through (0, 0, 0.06), 0.055 m above it, its x axis (docking axis) up. Joints at 0: both point up,
    0.11 m apart: no peer. Both arms turned by -1.57 rad: each connector is 0.055 m in front of its
    robot at 0.06 m height (sin 1.57 ≈ 1), the two 0.11 m apart robots facing each other: the
    connectors meet (within 0.01 m) with opposed x axes, and each robot's presence is 1."""
    path = tmp_path / "hop.wbt"
    path.write_text(HOP)
    sim = Simulation(load_world(path))
    docks = [sim.device(f"MyBot {i}/connector") for i in (1, 2)]
    for d in docks:
        d.enable(STEP)
    sim.step()
    assert [d.value for d in docks] == [0, 0]
    for i in (1, 2):
        sim.robot(f"MyBot {i}").motor("upper motor").set_position(-1.57)
    for _ in range(200):                         # 1.57 rad at 1 rad/s: 1.6 s and the ramp (16 ms steps)
        sim.step()
    assert [sim.robot(f"MyBot {i}").motor("upper motor").position for i in (1, 2)] == [-1.57, -1.57]
    a, b = (d.placed() for d in docks)
    assert a[1] == pytest.approx([0.055 * math.sin(1.57), 0.0, 0.06 + 0.055 * math.cos(1.57)], abs=1e-12)
    assert float(np.dot(a[0][:, 0], b[0][:, 0])) == pytest.approx(math.cos(2 * 1.57), abs=1e-12)   # nearly opposed
    assert [d.value for d in docks] == [1, 1]


def test_probe_reads_connectors_and_brakes(tmp_path) -> None:
    """``sensorium probe --enable all:P`` on a world with connectors and a brake (Webots' connector.wbt
    and brake.wbt samples): it ended in a traceback (AttributeError: 'Connector' object has no attribute
    'readings'). Each now says what it reads: a connector its presence (the two face to face: 1) and
    lock state, a brake its joint's type (whole numbers and flags as they are, not array summaries)."""
    import json
    import subprocess
    import sys

    w = world(0.0)
    data = w.model_dump(mode="json", exclude_defaults=True)
    data["robots"][0]["devices"].append({"device": "Brake", "name": "brake", "joint_type": "linear"})
    (tmp_path / "w.json").write_text(json.dumps(data))
    res = subprocess.run([sys.executable, "-m", "sensorium", "probe", str(tmp_path / "w.json"), "--steps", "2",
                          "--json", "--enable", "all:32"], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    rows = {(r["robot"], r["device"]): r for r in map(json.loads, res.stdout.splitlines()) if r["step"] == 2}
    assert rows[("a", "dock")]["presence"] == 1 and rows[("a", "dock")]["is_locked"] is False
    assert rows[("b", "dock")]["presence"] == 1
    assert rows[("a", "brake")]["type"] == 1
