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


# -- between readings: a box robot (0.4 x 0.2 m) with plates 0.02 m deep whose front face is 0.22 m
# ahead of its centre, each plate its own bumper's, 0.03 m from a wall's face; at 10 rad/s its
# wheels (radius 0.1) move it 0.016 m per 16 ms step, so driven ahead it touches the wall at the end
# of step 2 (clipped at 0.03 m) and, backed off from step 3, is 0.002 m behind its start after step 4.
PLATES = ("fast", "slow", "off", "kept", "late")


def plates_world() -> wm.World:
    plate = {"pose": {"translation": [0.21, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.02, 0.2, 0.1]}}
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 16},
        "solids": [{"name": "wall", "pose": {"translation": [0.35, 0.0, 0.1]},
                    "geometry": {"type": "box", "size": [0.2, 2.0, 0.2]}}],
        "robots": [{"name": "r", "pose": {"translation": [0.0, 0.0, 0.1]},
                    "body": {"geometry": {"type": "box", "size": [0.4, 0.2, 0.2]}},
                    "shapes": [{**plate, "of_device": n} for n in PLATES],
                    "devices": [{"device": "TouchSensor", "name": n} for n in PLATES],
                    "differential_drive": {"wheel_radius": 0.1, "axle_length": 0.3, "max_wheel_speed": 1000}}]})


class Both:
    """One Simulation per copy and a BatchedSimulation of as many copies, driven alike; each reading
    of every copy compared bit for bit with its Simulation's."""

    def __init__(self, copies: int):
        from sensorium.server.sim.batched import BatchedSimulation
        self.sims = [Simulation(plates_world()) for _ in range(copies)]
        self.bs = BatchedSimulation(plates_world(), copies)
        self.slot = self.bs.slot("r")

    def enable(self, name: str, period: int, copies=None) -> None:
        for c in range(len(self.sims)) if copies is None else copies:
            self.sims[c].device(f"r/{name}").enable(period)
        self.bs.enable(self.bs.device("r", name), period, copies=copies)

    def drive(self, w: float, copies=None) -> None:
        idx = range(len(self.sims)) if copies is None else copies
        for c in idx:
            drive(self.sims[c], w)
        self.bs.set_wheels(self.slot, [w] * len(idx), [w] * len(idx), copies=None if copies is None else list(idx))

    def step(self) -> None:
        self.bs.step()
        for s in self.sims:
            s.step()

    def value(self, name: str) -> list[float]:
        """Every copy's reading (the Simulations'), after checking the batched one has its bits."""
        got = self.bs.value(self.bs.device("r", name))
        want = np.array([s.device(f"r/{name}").value for s in self.sims], dtype=np.float64)
        assert got.tobytes() == want.tobytes(), (name, got, want)
        return want.tolist()


def test_a_slow_bumper_reads_a_touch_of_any_step_since_its_last_reading():
    """WbTouchSensor keeps each step's collision until the next reading clears it. Copy 0 touches
    the wall on step 2 only and backs off; copy 1 stands still; copy 2 moves one step (0.016 m, still
    0.014 m from the wall) and stops. The bumper read every step reads 0, 1, 0, 0 in copy 0; the one
    read every 64 ms reads 1 at step 4 there (the step-2 touch), 0 in the others, and 0 everywhere at
    step 8 (nothing touched since step 4); in both engines, bit for bit."""
    both = Both(3)
    both.enable("fast", 16)
    both.enable("slow", 64)
    both.drive(10.0, copies=[0, 2])
    fast, slow = [], []
    for k in range(1, 9):
        both.step()
        fast.append(both.value("fast"))
        slow.append(both.value("slow"))
        if k == 1:
            both.drive(0.0, copies=[2])
        if k == 2:
            assert both.sims[0].robot("r").pose.translation[0] == pytest.approx(0.03, abs=1e-9)
            both.drive(-10.0, copies=[0])
    assert [f[0] for f in fast] == [0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    assert all(f[1] == f[2] == 0.0 for f in fast)
    assert both.sims[0].robot("r").pose.translation[0] == pytest.approx(0.03 - 6 * 0.016, abs=1e-9)
    assert both.sims[2].robot("r").pose.translation[0] == pytest.approx(0.016, abs=1e-9)
    assert all(math.isnan(v) for v in slow[2]) and slow[3] == [1.0, 0.0, 0.0] and slow[7] == [0.0, 0.0, 0.0]
    assert both.sims[0].device("r/slow").measurements == 2


def test_a_touch_while_disabled_reads_at_the_first_reading_after_enable():
    """The same touch on step 2 in both engines. ``off`` (64 ms) is disabled after step 1, before
    the touch; ``kept`` (64 ms) after step 3, after the touch but before its reading; both are enabled
    again (64 ms) after step 4, so their first reading is at step 8, far from the wall: 1, as
    WbTouchSensor's flag, which only a reading clears, is set by a collision while disabled too; at
    step 12 they read 0. ``late`` is enabled for the first time after step 4: never enabled before,
    it was never asked and reads 0 at step 8 (Webots' reads 1: its flag is set from the start; see
    README "Bumpers")."""
    both = Both(2)
    both.enable("off", 64)
    both.enable("kept", 64)
    both.drive(10.0, copies=[0])
    got = {n: [] for n in ("off", "kept", "late")}
    for k in range(1, 13):
        both.step()
        for n in got:
            got[n].append(both.value(n))
        if k == 1:
            both.enable("off", 0)
        if k == 2:
            both.drive(-10.0, copies=[0])
        if k == 3:
            both.enable("kept", 0)
        if k == 4:
            for n in got:
                both.enable(n, 64)
    for n in ("off", "kept"):
        assert all(math.isnan(v) for row in got[n][:7] for v in row), n
        assert got[n][7] == [1.0, 0.0] and got[n][11] == [0.0, 0.0], n
    assert got["late"][7] == [0.0, 0.0] and got["late"][11] == [0.0, 0.0]


def test_a_simulation_reset_keeps_a_kept_touch_and_a_copy_s_reset_clears_it():
    """Touched on step 2, ``slow`` (64 ms) not yet read: a Simulation's reset (a Supervisor's
    simulationReset; WbTouchSensor never clears its flag but by a reading) after step 3 leaves it
    1 at step 4, the robot back at its start; a batched copy reset after step 3 is a freshly built
    world, its bumper enabled again at 64 ms reads 0 at its first reading (step 7)."""
    sim = Simulation(plates_world())
    sim.device("r/slow").enable(64)
    drive(sim, 10.0)
    for k in range(1, 5):
        sim.step()
        if k == 3:
            sim.reset()
    assert sim.robot("r").pose.translation[0] == 0.0 and sim.device("r/slow").value == 1.0
    both = Both(1)
    both.enable("slow", 64)
    both.drive(10.0)
    bs, ref = both.bs, both.bs.device("r", "slow")
    for k in range(1, 8):
        bs.step()
        if k == 3:
            bs.reset([0], [0])
            bs.enable(ref, 64)
    assert bs.time_ms[0] == 64 and bs.value(ref)[0] == 0.0


def test_a_bumper_due_every_step_is_never_asked_between_readings():
    """A bumper read every basic step is never sampled in between (its reading is the touch of its
    step, as before); a disabled bumper never enabled is never asked. The batched engine does not
    even look for bumpers between readings until one is enabled less often than every step (or
    disabled after an enable)."""
    both = Both(2)
    both.enable("fast", 16)
    both.drive(10.0)
    for _ in range(4):
        both.step()
        both.value("fast")
    assert not both.bs.kinematic.latching and both.value("fast") == [1.0, 1.0]
    both.enable("slow", 32, copies=[1])
    assert both.bs.kinematic.latching
    sim = Simulation(plates_world())
    sim.device("r/fast").enable(16)
    calls = {n: 0 for n in PLATES}
    for n in PLATES:
        dev = sim.device(f"r/{n}")
        dev.sample = (lambda n=n, f=dev.sample: (calls.__setitem__(n, calls[n] + 1), f())[1])
    drive(sim, 10.0)
    sim.run(6)
    assert calls == {n: 0 for n in PLATES} and sim.device("r/fast").value == 1.0
