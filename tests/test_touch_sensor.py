"""TouchSensor: a bumper from the kinematic contact; force types read Webots' "no value"."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import messages as msgs
from sensorium.schemas import world as wm
from sensorium.server.daemon.services import Core
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world, sanitize


def make(kind="bumper"):
    data = {"world_info": {"basic_time_step": 16},
            "solids": [{"name": "wall", "pose": {"translation": [0.3, 0, 0.05]},
                        "geometry": {"type": "box", "size": [0.02, 1.0, 0.1]}}],
            "robots": [{"name": "r", "shapes": [{"pose": {"translation": [0, 0, 0.03]},
                                                  "geometry": {"type": "cylinder", "radius": 0.05, "height": 0.05}}],
                        "differential_drive": {"wheel_radius": 0.02, "axle_length": 0.08, "max_wheel_speed": 100},
                        "devices": [{"device": "TouchSensor", "name": "bumper", "type": kind}]}]}
    sim = Simulation(wm.World.model_validate(data))
    sim.device("r/bumper").enable(16)
    return sim


def drive(sim, w):
    for m in sim.robot("r").motors.values():
        m.set_position(math.inf)
        m.set_velocity(w)


def test_bumper_reads_one_while_pushing_a_wall():
    sim = make()
    b = sim.device("r/bumper")
    assert math.isnan(b.value)
    sim.step()
    assert b.value == 0.0                                  # at rest, nothing touched
    drive(sim, 10.0)                                       # 0.2 m/s towards the wall 0.24 m ahead
    values = []
    for _ in range(100):
        sim.step()
        values.append(b.value)
    first = values.index(1.0)
    # the body (radius 0.05) reaches the wall face (x = 0.29) at x = 0.24: 1.2 s = 75 steps of 16 ms
    assert 73 <= first <= 76 and all(v == 0.0 for v in values[:first]) and all(v == 1.0 for v in values[first:])
    assert sim.robot("r").pose.translation[0] < 0.24 + 1e-9
    drive(sim, -10.0)                                      # backing away: no longer pressing
    sim.step()
    assert b.value == 0.0


def test_force_types_read_no_value_and_are_announced():
    for kind in ("force", "force-3d"):
        sim = make(kind)
        sim.run(2)
        dev = sim.device("r/bumper")
        assert math.isnan(dev.value) and np.isnan(dev.values).all() and dev.measurements == 2
    world = wm.World.model_validate({"robots": [{"name": "r", "devices": [
        {"device": "TouchSensor", "name": "t", "type": "force"}]}]})
    _, warnings = sanitize(world)
    assert any("needs physics" in w and "robots[0].devices[0].type" in w for w in warnings)


def test_services_and_topics():
    core = Core(make())
    assert {"/r/bumper/get_value", "/r/bumper/get_type", "/r/bumper/get_lookup_table"} <= set(core.routes)
    types = {t.name: t.type for t in core.topics.topics}
    assert types["/r/bumper/value"] == msgs.FLOAT64 and "/r/bumper/values" not in types
    core3 = Core(make("force-3d"))
    assert {t.name: t.type for t in core3.topics.topics}["/r/bumper/values"] == msgs.VECTOR3_STAMPED


# -- bumpers with bounding shapes of their own: a Create-like round robot (body radius 0.15) with a left
# and a right bumper (boxes 0.02 deep and 0.12 wide whose centres are 0.16 m out at ±40°) and a rear
# one (180°). Along a direction at angle a, the box at angle b reaches 0.17 cos(a - b) + 0.06 |sin(a - b)|
# from the robot's centre; the body's circumscribed 16-gon at most 0.15 / cos(π/16) = 0.1529.
BUMPERS = {"left": math.radians(40.0), "right": math.radians(-40.0), "rear": math.pi}


def reach(a: float, b: float) -> float:
    return 0.17 * math.cos(a - b) + 0.06 * abs(math.sin(a - b))


def create_like(wall_angle: float, face: float = 0.5, bumper_shapes: bool = True, others=()) -> Simulation:
    """The robot at the origin heading +x, a wall whose face, normal to the direction ``wall_angle``
    (to the left of ahead when positive), is ``face`` m from the robot's centre."""
    u = (math.cos(wall_angle), math.sin(wall_angle))
    shapes = [{"name": "body", "pose": {"translation": [0, 0, 0.06]},
               "geometry": {"type": "cylinder", "radius": 0.15, "height": 0.1}}]
    devices = []
    for name, b in BUMPERS.items():
        if bumper_shapes:
            shapes.append({"name": name, "of_device": name,
                           "pose": {"translation": [0.16 * math.cos(b), 0.16 * math.sin(b), 0.06],
                                    "rotation": [0, 0, 1, b]},
                           "geometry": {"type": "box", "size": [0.02, 0.12, 0.06]}})
        devices.append({"device": "TouchSensor", "name": name,
                        "pose": {"translation": [0.16 * math.cos(b), 0.16 * math.sin(b), 0.06]}})
    data = {"world_info": {"basic_time_step": 16},
            "solids": [{"name": "wall", "pose": {"translation": [(face + 0.05) * u[0], (face + 0.05) * u[1], 0.1],
                                                  "rotation": [0, 0, 1, wall_angle]},
                        "geometry": {"type": "box", "size": [0.1, 3.0, 0.2]}}],
            "robots": [{"name": "r", "shapes": shapes, "devices": devices,
                        "differential_drive": {"wheel_radius": 0.02, "axle_length": 0.3, "max_wheel_speed": 100}},
                       *others]}
    sim = Simulation(wm.World.model_validate(data))
    for name in BUMPERS:
        sim.device(f"r/{name}").enable(16)
    return sim


def readings(sim) -> dict[str, float]:
    return {name: sim.device(f"r/{name}").value for name in BUMPERS}


def test_a_bumper_with_its_own_shapes_reads_where_the_robot_was_hit():
    """Driven at 0.2 m/s into a wall at 30° to the left, the left bumper (which reaches 0.1778 m
    that way, farther than the body and the right bumper's 0.1145) touches it and reads 1, the right
    and the rear ones 0, while the robot slides along the wall; stopped there, the left one still
    touches (1); backed away, none does."""
    a = math.radians(30.0)
    sim = create_like(a)
    drive(sim, 10.0)
    first = None
    for k in range(200):
        sim.step()
        if first is None and readings(sim)["left"] == 1.0:
            first = k
            break
    assert first is not None
    # the left bumper reaches the face (0.5 from the centre along u) after 0.5 - reach(a, 40°) m along u,
    # i.e. (0.5 - 0.17784) / cos 30° = 0.3720 m along x: 1.86 s = 116.3 steps of 16 ms
    assert 115 <= first <= 117
    for _ in range(20):                                     # sliding along the wall, pressed on it
        sim.step()
        pose = sim.robot("r").pose.translation
        along = pose[0] * math.cos(a) + pose[1] * math.sin(a)
        assert abs(along - (0.5 - reach(a, BUMPERS["left"]))) < 1e-9
        assert readings(sim) == {"left": 1.0, "right": 0.0, "rear": 0.0}
    drive(sim, 0.0)                                         # standing still against the wall: still touching
    for _ in range(5):
        sim.step()
        assert readings(sim) == {"left": 1.0, "right": 0.0, "rear": 0.0}
    drive(sim, -10.0)
    sim.step()
    assert readings(sim) == {"left": 0.0, "right": 0.0, "rear": 0.0}


def test_head_on_both_front_bumpers_read_one_and_the_rear_one_zero():
    """Head-on into a wall 0.5 m ahead: the robot stops where both front bumpers' inner front corners
    (0.17 cos 40° + 0.06 sin 40° = 0.16880 m ahead) touch it; both read 1, the rear one 0."""
    sim = create_like(0.0)
    drive(sim, 10.0)
    for _ in range(150):
        sim.step()
    x = sim.robot("r").pose.translation[0]
    assert abs(x - (0.5 - reach(0.0, BUMPERS["left"]))) < 1e-9
    assert readings(sim) == {"left": 1.0, "right": 1.0, "rear": 0.0}


def test_a_bumper_reads_another_robot_that_touches_it_and_not_one_it_misses():
    """A standing robot (a post of radius 0.05, 0.12 m right of the path) is hit by the right bumper:
    it reads 1, the left one 0; that robot's own shapeless bumper keeps the body's rule (it was not
    driven, so never clipped: 0)."""
    sim = create_like(0.0, face=3.0, others=[{
        "name": "post", "pose": {"translation": [0.6, -0.12, 0.0]},
        "shapes": [{"pose": {"translation": [0, 0, 0.06]}, "geometry": {"type": "cylinder", "radius": 0.05, "height": 0.1}}],
        "devices": [{"device": "TouchSensor", "name": "bump"}]}])
    sim.device("post/bump").enable(16)
    drive(sim, 10.0)
    for _ in range(140):                                    # it reaches the post after about 129 steps
        sim.step()
    assert 0.4 < sim.robot("r").pose.translation[0] < 0.6 and sim.robot("r").pose.translation[1] > 0.0
    assert readings(sim) == {"left": 0.0, "right": 1.0, "rear": 0.0}
    assert sim.device("post/bump").value == 0.0


def test_a_bumper_without_shapes_of_its_own_keeps_the_body_rule():
    """The same robot whose bumpers have no shapes: all three read 1 while the body is stopped by
    the wall at 30° (its move clipped), and 0 once it stands still there."""
    sim = create_like(math.radians(30.0), bumper_shapes=False)
    drive(sim, 10.0)
    for _ in range(150):
        sim.step()
    assert readings(sim) == {"left": 1.0, "right": 1.0, "rear": 1.0}
    drive(sim, 0.0)
    sim.step()
    assert readings(sim) == {"left": 0.0, "right": 0.0, "rear": 0.0}


def test_a_wbt_touch_sensor_bumper_reads_with_its_bounding_object(tmp_path: Path):
    """A .wbt robot whose TouchSensors have their own boundingObject (a Box, one inside a Pose): the
    converter keeps them as the robot's shapes of those devices, and driven into a wall at 30° to the
    left the left bumper reads 1, the right one 0; a TouchSensor without a boundingObject keeps the
    body's rule (1 while the move is clipped)."""
    a = math.radians(30.0)
    c, s = math.cos(a), math.sin(a)
    p = tmp_path / "w.wbt"
    p.write_text("#VRML_SIM R2023b utf8\n"
                 f'Solid {{ name "wall" translation {0.55 * c} {0.55 * s} 0.1 rotation 0 0 1 {a} '
                 "boundingObject Box { size 0.1 3 0.2 } }\n"
                 'Robot { name "r" boundingObject Pose { translation 0 0 0.06 children [ Cylinder { radius 0.15 height 0.1 } ] }\n'
                 " children [\n"
                 f'  TouchSensor {{ name "left" translation {0.16 * math.cos(0.7)} {0.16 * math.sin(0.7)} 0.06 '
                 "rotation 0 0 1 0.7 boundingObject Box { size 0.02 0.12 0.06 } }\n"
                 f'  TouchSensor {{ name "right" translation {0.15 * math.cos(-0.7)} {0.15 * math.sin(-0.7)} 0.06 '
                 "rotation 0 0 1 -0.7 boundingObject Pose { translation 0.01 0 0 children [ Box { size 0.02 0.12 0.06 } ] } }\n"
                 '  TouchSensor { name "plain" } ] }\n')
    lw = load_world(p)
    assert {(sh.of_device, sh.seen_by) for sh in lw.world.robots[0].shapes} == {(None, "bounding"), ("left", "bounding"),
                                                                               ("right", "bounding")}
    robot = lw.world.robots[0].model_copy(update={"differential_drive": wm.DifferentialDrive.model_validate(
        {"wheel_radius": 0.02, "axle_length": 0.3, "max_wheel_speed": 100})})
    sim = Simulation(lw.world.model_copy(update={"robots": [robot]}), base_dir=lw.base_dir)
    for n in ("left", "right", "plain"):
        sim.device(f"r/{n}").enable(16)
    drive(sim, 10.0)
    for _ in range(150):
        sim.step()
    assert [sim.device(f"r/{n}").value for n in ("left", "right", "plain")] == [1.0, 0.0, 1.0]


def test_a_slow_bumper_reads_the_touch_at_its_reading_s_step_only():
    """Pins the documented departure (README "Bumpers"): a reading is the touch at the end of the
    step it is due on. Two bumpers with identical plates (0.02 m deep, front face 0.22 m ahead of
    the centre) on a box robot 0.03 m from a wall, driven at 0.016 m per 16 ms step: the plates
    touch the wall at the end of step 2 (the move clipped there), the robot backs off on steps 3
    and 4. The bumper read every step reads 0, 1, 0, 0; the one read every 64 ms reads 0 at step 4
    -- Webots' would read 1 (WbTouchSensor keeps a collision of any step until the next reading)."""
    plate = {"pose": {"translation": [0.21, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.02, 0.2, 0.1]}}
    data = {"world_info": {"basic_time_step": 16},
            "solids": [{"name": "wall", "pose": {"translation": [0.35, 0.0, 0.1]},
                        "geometry": {"type": "box", "size": [0.2, 2.0, 0.2]}}],
            "robots": [{"name": "r", "pose": {"translation": [0.0, 0.0, 0.1]},
                        "body": {"geometry": {"type": "box", "size": [0.4, 0.2, 0.2]}},
                        "shapes": [{**plate, "of_device": "fast"}, {**plate, "of_device": "slow"}],
                        "devices": [{"device": "TouchSensor", "name": "fast"}, {"device": "TouchSensor", "name": "slow"}],
                        "differential_drive": {"wheel_radius": 0.1, "axle_length": 0.3, "max_wheel_speed": 1000}}]}
    sim = Simulation(wm.World.model_validate(data))
    fast, slow = sim.device("r/fast"), sim.device("r/slow")
    fast.enable(16)
    slow.enable(64)
    drive(sim, 10.0)                                       # 0.016 m per step: the wall's face 0.03 m ahead
    read = []
    for k in range(1, 5):
        sim.step()
        read.append(fast.value)
        if k == 2:
            assert sim.robot("r").pose.translation[0] == pytest.approx(0.03, abs=1e-9)
            drive(sim, -10.0)
    assert read == [0.0, 1.0, 0.0, 0.0]
    assert sim.robot("r").pose.translation[0] == pytest.approx(0.03 - 2 * 0.016, abs=1e-9)
    assert slow.measurements == 1 and slow.value == 0.0
