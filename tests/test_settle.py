"""Wheeled robots settle on the ground at load, as Webots' physics drops them (sim/ground.py
``settle_world``): a robot whose drive gives ``wheel_bottom`` is lowered (or raised) so its lowest
wheel's bottom touches the ground under its origin -- a floor plane, a box top, a terrain -- its
x, y and rotation kept; over nothing, or without ``wheel_bottom``, it keeps its height bit for bit.
Closed forms, the load note, a cliff sensor reading the floor, the .wbt import's wheel bottom, and
the batched simulation's poses bit for bit."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world, parse_world
from sensorium.server.world.poses import pose_from_model

R = 0.03                 # wheel radius; wheel_bottom -R: the axle through the robot's origin
DRIVE = {"wheel_radius": R, "axle_length": 0.1, "wheel_bottom": -R}
FLOOR = {"name": "floor", "geometry": {"type": "plane"}}


def _robot(name: str = "r", at=(0.3, -0.2, 0.075), yaw: float = 0.7, drive: dict | None = None, **extra) -> dict:
    return {"name": name, "pose": {"translation": list(at), "rotation": [0, 0, 1, yaw]},
            "differential_drive": DRIVE if drive is None else drive, **extra}


def _loaded(solids: list[dict], robots: list[dict], source: str = "<memory>"):
    return parse_world({"solids": solids, "robots": robots}, source=source)


def _sim(solids: list[dict], robots: list[dict]) -> Simulation:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")        # (a robot over no ground in a terrain world is said: not tested here)
        return Simulation(_loaded(solids, robots), precision="exact")


def _t(sim: Simulation, name: str = "r") -> np.ndarray:
    return sim.robot(name).pose.translation


def _grid(tz: float = 0.0) -> dict:
    """A terrain rising 0.25 m per metre along +x: heights 0.25·x at its points, x, y in [0, 2]."""
    heights = [0.25 * i * 0.5 for j in range(5) for i in range(5)]
    return {"name": "hill", "pose": {"translation": [0.0, 0.0, tz]},
            "geometry": {"type": "elevation_grid", "height": heights, "x_dimension": 5, "x_spacing": 0.5,
                         "y_dimension": 5, "y_spacing": 0.5}}


def _box(name: str, centre, size) -> dict:
    return {"name": name, "pose": {"translation": list(centre)}, "geometry": {"type": "box", "size": list(size)}}


# ---------------------------------------------------------------------- closed forms

@pytest.mark.parametrize("h", [0.075, 0.0301, 5.0])
def test_a_two_wheel_robot_above_a_plane_drops_until_its_wheels_touch_it(h: float) -> None:
    sim = _sim([FLOOR], [_robot(at=(0.3, -0.2, h))])
    t = _t(sim)
    assert t[2] == 0.0 - (-R)                       # its wheel bottom (origin − R) on the plane at 0, exactly
    assert (t[0], t[1]) == (0.3, -0.2)              # x, y kept
    yaw = math.atan2(sim.robot("r").pose.rotation[1, 0], sim.robot("r").pose.rotation[0, 0])
    assert yaw == pytest.approx(0.7, abs=1e-15)
    sim.step()                                      # and it stays there
    assert _t(sim)[2] == 0.0 + R


def test_a_raised_plane_and_a_robot_below_it_half_sunk() -> None:
    plane = {**FLOOR, "pose": {"translation": [0.0, 0.0, 0.2]}}
    assert _t(_sim([plane], [_robot(at=(0.0, 0.0, 0.9))]))[2] == 0.2 - (-R)
    # half sunk: the axle 1.5 cm above the floor (the wheel's lower half in it) -> raised
    assert _t(_sim([plane], [_robot(at=(0.0, 0.0, 0.2 + R / 2))]))[2] == 0.2 - (-R)


def test_over_a_box_floor_its_top_is_the_ground_and_not_the_plane_below() -> None:
    deck = _box("deck", (0.0, 0.0, 0.1), (1.0, 1.0, 0.2))       # top at 0.1 + 0.1
    top = 0.1 + 0.1
    assert _t(_sim([FLOOR, deck], [_robot(at=(0.3, -0.2, 0.6))]))[2] == top - (-R)
    # sunk 2 cm into the deck, its axle still above the top: raised onto it, not dropped to the plane
    assert _t(_sim([FLOOR, deck], [_robot(at=(0.3, -0.2, top + 0.01))]))[2] == top - (-R)
    # beside the deck: the plane
    assert _t(_sim([FLOOR, deck], [_robot(at=(0.8, 0.0, 0.6))]))[2] == 0.0 + R


def test_a_box_top_above_its_axle_and_origin_is_no_ground_for_it() -> None:
    """A table top 0.5 m up over a robot on the floor: the robot was put under the table, not into
    it, so it settles on the floor (its axle below the table top, the box is not its ground)."""
    table = _box("table", (0.0, 0.0, 0.5), (1.0, 1.0, 0.04))
    assert _t(_sim([FLOOR, table], [_robot(at=(0.3, -0.2, 0.1))]))[2] == 0.0 + R


def test_a_driveless_robots_floor_is_ground_and_a_driven_robots_body_is_not() -> None:
    """Webots' create.wbt keeps its floor Plane in a robot (its ground supervisor): a robot without a
    drive is ground as it loads; another driven robot's body under it is not."""
    keeper = {"name": "ground", "pose": {"translation": [0.0, 0.0, 0.05]},
              "shapes": [{"geometry": {"type": "plane"}}]}
    assert _t(_sim([], [keeper, _robot(at=(0.3, -0.2, 0.2))]))[2] == 0.05 - (-R)
    other = _robot("other", at=(0.3, -0.2, 0.0), body={"geometry": {"type": "box", "size": [0.2, 0.2, 0.1]}})
    assert _t(_sim([FLOOR], [other, _robot(at=(0.3, -0.2, 0.4))]))[2] == 0.0 + R


def test_over_a_terrain_it_settles_on_the_triangle_under_its_origin() -> None:
    # at the grid point x = 1.0 (i = 2): height 0.25·1.0 exactly (0.25 * 2 * 0.5), plus the grid's height
    sim = _sim([_grid(0.1)], [_robot(at=(1.0, 0.5, 2.0), yaw=0.0)])
    assert _t(sim)[2] == (0.1 + 0.25 * 2 * 0.5) - (-R)
    r = sim.robot("r").pose.rotation                  # riding it: the slope's pitch, as before
    assert math.atan2(-r[2, 0], r[0, 0]) == pytest.approx(-math.atan(0.25), abs=1e-12)
    d = sim.robot("r").drive
    for m in (*d.lefts, *d.rights):
        m.set_position(math.inf)
        m.set_velocity(2.0)
    sim.run(10)                                         # drives up keeping its wheels on the ground
    x = _t(sim)[0]
    assert _t(sim)[2] == pytest.approx(0.1 + 0.25 * x + R, abs=1e-12)


def test_over_nothing_without_wheel_bottom_or_not_upright_it_keeps_its_pose() -> None:
    deck = _box("deck", (5.0, 5.0, 0.1), (1.0, 1.0, 0.2))     # nowhere under it
    w = _loaded([deck], [_robot(at=(0.3, -0.2, 0.075))])
    sim = Simulation(w)
    assert w.world.robots[0].pose.translation == (0.3, -0.2, 0.075)
    assert _t(sim)[2] == 0.075
    assert not [n for n in w.warnings if "settled" in n]
    plain = {k: v for k, v in DRIVE.items() if k != "wheel_bottom"}      # a YAML drive without it
    assert _t(_sim([FLOOR], [_robot(drive=plain)]))[2] == 0.075
    tilted = _robot()
    tilted["pose"]["rotation"] = [1, 0, 0, 0.3]                          # rolled 0.3 rad: not settled
    assert _t(_sim([FLOOR], [tilted]))[2] == 0.075
    tilted["pose"]["rotation"] = [1, 0, 0, 2e-3]                         # 2 mrad: past the tolerance
    assert _t(_sim([FLOOR], [tilted]))[2] == 0.075
    tilted["pose"]["rotation"] = [1, 0, 0, 5e-4]     # a tilt physics left in a saved world: settled
    assert _t(_sim([FLOOR], [tilted]))[2] == R
    still = {"name": "arm", "pose": {"translation": [0.0, 0.0, 0.4]}}     # no drive: never moved
    assert _sim([FLOOR], [still]).scene.robot_poses[0].translation[2] == 0.4


def test_a_robot_touching_the_floor_changes_nothing_bit_for_bit() -> None:
    """Wheels already on the floor (and within 1 µm of it): the pose is the world file's, its bits."""
    for z in (R, R + 1e-7, R - 1e-7):
        w = _loaded([FLOOR], [_robot(at=(0.3, -0.2, z))])
        sim = Simulation(w)
        assert _t(sim)[2] == z
        assert sim.world.robots[0] is w.world.robots[0]


# ---------------------------------------------------------------------- the load note

def test_the_load_note_says_which_robot_from_what_height_to_what() -> None:
    robots = [_robot("high", at=(0.0, 0.0, 0.075)), _robot("close", at=(1.0, 0.0, R + 0.0005)),
              _robot("sunk", at=(2.0, 0.0, 0.01))]
    w = _loaded([FLOOR], robots, source="w.yaml")
    sim = Simulation(w)
    assert _t(sim, "close")[2] == R                     # settled, but by 0.5 mm: no note
    said = [n for n in w.warnings if "settled" in n]
    assert said == [
        "w.yaml: robot 'high' settled on the ground at load, as Webots' physics drops it: its origin's z from "
        "0.0750 to 0.0300 m (its lowest wheel now touches the ground under it)",
        "w.yaml: robot 'sunk' settled on the ground at load, as Webots' physics drops it: its origin's z from "
        "0.0100 to 0.0300 m (its lowest wheel now touches the ground under it)"]
    assert "warning: w.yaml: robot 'high' settled" in "\n".join(w.report.lines())
    Simulation(w)                                       # a second simulation of it: said once
    assert len([n for n in w.warnings if "settled" in n]) == 2


def test_the_notes_are_capped() -> None:
    w = _loaded([FLOOR], [_robot(f"r{i}", at=(float(i), 0.0, 0.5)) for i in range(11)], source="w.yaml")
    Simulation(w)
    said = [n for n in w.warnings if "settled" in n]
    assert len(said) == 9 and said[-1] == "w.yaml: 3 more robots settled on the ground at load"
    assert "'r7'" in said[7]


# ---------------------------------------------------------------------- sensors see from the settled height

CLIFF = {"device": "DistanceSensor", "name": "cliff", "type": "infra-red", "number_of_rays": 1,
         "pose": {"translation": [0.1, 0.0, -0.02], "rotation": [0, 1, 0, math.pi / 2]},     # looking down
         "lookup_table": [[0.0, 0.0, 0.0], [0.1, 1000.0, 0.0]]}


def test_a_cliff_sensor_reads_the_floor_after_settling() -> None:
    """Placed 4.5 cm high, as Webots' create.wbt places the Create, its cliff sensor 2 cm below the
    axle would read 0.065 m of air (650); settled, the white floor 1 cm below it: 100."""
    def cliff(drive: dict) -> float:
        sim = _sim([FLOOR], [_robot(at=(0.3, -0.2, R + 0.045), devices=[CLIFF], drive=drive)])
        sim.robot("r").device("cliff").enable(16)
        sim.step()
        return float(sim.robot("r").device("cliff").value)

    assert cliff(DRIVE) == pytest.approx((R - 0.02) / 0.1 * 1000.0, abs=1e-9)
    hovering = {k: v for k, v in DRIVE.items() if k != "wheel_bottom"}      # not settled: as before
    assert cliff(hovering) == pytest.approx((R + 0.045 - 0.02) / 0.1 * 1000.0, abs=1e-9)


# ---------------------------------------------------------------------- the batched simulation

@pytest.mark.parametrize("solids", [[FLOOR], [FLOOR, _box("deck", (0.0, 0.0, 0.1), (1.0, 1.0, 0.2))], [_grid(0.1)]])
def test_the_batched_copies_settle_as_the_simulation_does(solids: list[dict]) -> None:
    robots = [_robot("a", at=(1.0, 0.5, 0.6), yaw=0.0), _robot("b", at=(0.2, 0.3, 0.011))]
    sim = _sim(solids, robots)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        bs = BatchedSimulation(_loaded(solids, robots), copies=2, precision="exact")
    for slot, name in enumerate(("a", "b")):
        assert sim.robot(name).pose.translation[2] != robots[slot]["pose"]["translation"][2]
        for c in range(2):
            p = bs.pose(c, slot)
            assert np.array_equal(p.translation, sim.robot(name).pose.translation)
            assert np.array_equal(p.rotation, sim.robot(name).pose.rotation)


# ---------------------------------------------------------------------- the .wbt import

def _wheel(side: str, y: float) -> str:
    return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 {y} 0.03 }}\n'
            f'  device [ RotationalMotor {{ name "{side} wheel motor" maxVelocity 10 }} ]\n'
            f'  endPoint Solid {{ translation 0 {y} 0.03 rotation 1 0 0 1.5707963267948966 name "{side} wheel"\n'
            '    children [ Shape { geometry Cylinder { radius 0.025 height 0.01 } } ]\n'
            '    boundingObject Cylinder { radius 0.025 height 0.01 } physics Physics { } } }\n')


def test_a_wbt_robot_takes_its_wheel_bottom_from_its_wheels_and_settles(tmp_path: Path) -> None:
    """A Robot with physics, axles 3 cm above its origin, wheels of radius 2.5 cm: wheel_bottom
    0.005; placed 4.5 cm above a floor at 0, its origin settles at -0.005 (wheel bottoms on the
    floor)."""
    text = ("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n"
            'Solid { name "floor" children [ Shape { geometry Plane { size 4 4 } } ] boundingObject Plane { size 4 4 } }\n'
            'Robot { translation 0.1 0.2 0.045 name "bot" controller "<extern>" children [\n'
            + _wheel("left", 0.05) + _wheel("right", -0.05) + "] physics Physics { } }\n")
    path = tmp_path / "w.wbt"
    path.write_text(text)
    w = load_world(path)
    assert w.world.robots[0].differential_drive.wheel_bottom == pytest.approx(0.005, abs=1e-12)
    sim = Simulation(w)
    assert _t(sim, "bot")[2] == 0.0 - w.world.robots[0].differential_drive.wheel_bottom
    assert [n for n in w.warnings if "settled" in n] == [
        f"{w.source}: robot 'bot' settled on the ground at load, as Webots' physics drops it: its origin's z from "
        "0.0450 to -0.0050 m (its lowest wheel now touches the ground under it)"]
    # without physics Webots' gravity does not move the robot: no wheel_bottom, it stays where it is put
    path.write_text(text.replace(" physics Physics { } }\n", " }\n"))
    w = load_world(path)
    assert w.world.robots[0].differential_drive.wheel_bottom is None
    assert _t(Simulation(w), "bot")[2] == 0.045 and not [n for n in w.warnings if "settled" in n]


def test_a_nue_world_settles_along_its_y() -> None:
    from tests.test_batched_nue import _to_nue

    plane = {**FLOOR, "pose": {"translation": [0.0, 0.0, 0.2]}}
    enu = _loaded([plane], [_robot(at=(0.3, -0.2, 0.9))]).world
    w = parse_world(_to_nue(enu), source="w.yaml")
    sim = Simulation(w, precision="exact")
    t = _t(sim)
    assert t[1] == 0.2 - (-R) and (t[0], t[2]) == (-0.2, 0.3)     # NUE: (north, up, east) = (y, z, x)
    assert [n for n in w.warnings if "settled" in n] == [
        "w.yaml: robot 'r' settled on the ground at load, as Webots' physics drops it: its origin's y from "
        "0.9000 to 0.2300 m (its lowest wheel now touches the ground under it)"]
    bs = BatchedSimulation(w, copies=1, precision="exact")
    assert np.array_equal(bs.pose(0, 0).translation, t)


# ---------------------------------------------------------------------- a car's free wheels

CAR_L, CAR_T, AXLE_Z = 2.6, 1.5, 0.35         # wheelbase, track, both axles' height above the car's origin


def _car_wheel(x: float, y: float, radius: float) -> str:
    return (f'Solid {{ translation {x} {y} {AXLE_Z} rotation 1 0 0 1.5707963267948966 children [ DEF W Shape {{ '
            f'geometry Cylinder {{ radius {radius} height 0.2 }} }} ] boundingObject USE W }}')


def _car_front(side: str, y: float, radius: float, driven: bool) -> str:
    spin = f'device2 [ RotationalMotor {{ name "{side}_front_wheel" maxVelocity 80 }} ] ' if driven else ""
    return (f'Hinge2Joint {{ jointParameters HingeJointParameters {{ axis 0 0 1 anchor {CAR_L} {y} {AXLE_Z} }} '
            f'jointParameters2 JointParameters {{ axis 0 1 0 }} '
            f'device [ RotationalMotor {{ name "{side}_steer" minPosition -0.6 maxPosition 0.6 maxVelocity 5 }} ] '
            f'{spin}endPoint {_car_wheel(CAR_L, y, radius)} }}\n')


def _car_rear(side: str, y: float, radius: float, driven: bool, sensor: bool = True) -> str:
    devices = ([f'RotationalMotor {{ name "{side}_rear_wheel" maxVelocity 80 }}'] if driven else []) + (
        [f'PositionSensor {{ name "{side}_rear_sensor" }}'] if sensor else [])
    return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 {y} {AXLE_Z} }} '
            f'device [ {" ".join(devices)} ] endPoint {_car_wheel(0.0, y, radius)} }}\n')


def _car_world(tmp_path: Path, front_radius: float, rear_radius: float, traction: bool, sensor: bool = True) -> Path:
    wheels = (_car_front("right", -CAR_T / 2, front_radius, traction) + _car_front("left", CAR_T / 2, front_radius, traction)
              + _car_rear("right", -CAR_T / 2, rear_radius, not traction, sensor)
              + _car_rear("left", CAR_T / 2, rear_radius, not traction, sensor))
    path = tmp_path / "car.wbt"
    path.write_text("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n"
                    'Solid { translation 0 0 0.1 name "floor" children [ Shape { geometry Plane { size 40 40 } } ] '
                    "boundingObject Plane { size 40 40 } }\n"
                    'Robot { translation 0 0 1.5 name "car" controller "<extern>" children [\n' + wheels
                    + "] physics Physics { } }\n")
    return path


@pytest.mark.parametrize("traction, sensor", [(True, True), (True, False), (False, True)])
def test_a_cars_free_wheels_hold_it_up_as_its_driven_ones_do(tmp_path: Path, traction: bool, sensor: bool) -> None:
    """A front-wheel-drive car whose free rear wheels are larger (0.45 against 0.3: their bottoms 15 cm
    below the front ones'), with or without encoders, and a rear-wheel-drive car whose free front
    wheels are: the free wheels' bottoms count as the driven ones' (``wheel_bottom`` the lowest, both
    axles' in ``axle_bottoms``), so it lands on both axles as Webots' physics lays it, leaning by θ about
    its y with L sin θ = r_rear − r_front, its rear wheels touching the floor: origin = floor − (axle
    height · cos θ − the rear radius)."""
    small, large = 0.3, 0.45
    front, rear = (small, large) if traction else (large, small)
    w = load_world(_car_world(tmp_path, front, rear, traction, sensor))
    car = w.world.robots[0].ackermann_drive
    assert car is not None and car.type == ("traction" if traction else "propulsion")
    assert car.wheel_bottom == AXLE_Z - large
    assert car.axle_bottoms == pytest.approx((AXLE_Z - rear, AXLE_Z - front), abs=1e-12)
    assert not [n for n in w.warnings if "PositionSensor" in n]
    theta = math.asin((rear - front) / CAR_L)
    pose = Simulation(w).robot("car").pose
    assert pose.translation[2] == pytest.approx(0.1 - (AXLE_Z * math.cos(theta) - rear), abs=1e-12)
    assert pose.rotation[2, 0] == pytest.approx(-math.sin(theta), abs=1e-12)      # nose down when the rear is larger
    # equal wheels: the driven ones' bottom, as before
    w = load_world(_car_world(tmp_path, small, small, traction, sensor))
    assert w.world.robots[0].ackermann_drive.wheel_bottom == AXLE_Z - small


def test_a_nue_robot_built_y_up_settles_along_its_own_y() -> None:
    """A NUE world (x north, y up, z east) whose robot is built y up, as Webots' robots were before
    R2022a (identity rotation, or turned about the world's y): its wheel_bottom is along its own y,
    and it settles with y = floor + R; its x, z and rotation kept. The floor Plane is turned so its
    normal (local z) is the world's y."""
    floor = {"name": "floor", "pose": {"translation": [0.0, 0.2, 0.0], "rotation": [1, 0, 0, -math.pi / 2]},
             "geometry": {"type": "plane"}}
    robots = [{"name": "r", "pose": {"translation": [0.3, 0.9, -0.2]}, "differential_drive": DRIVE},
              {"name": "s", "pose": {"translation": [-1.0, 0.05, 0.5], "rotation": [0, 1, 0, 0.7]},
               "differential_drive": DRIVE}]
    w = parse_world({"world_info": {"coordinate_system": "NUE"}, "solids": [floor], "robots": robots},
                    source="w.yaml")
    sim = Simulation(w, precision="exact")
    for name, (x, z) in (("r", (0.3, -0.2)), ("s", (-1.0, 0.5))):
        t = _t(sim, name)
        assert (t[0], t[1], t[2]) == (x, 0.2 - (-R), z)
    assert np.array_equal(sim.robot("s").pose.rotation, pose_from_model(w.world.robots[1].pose).rotation)
    assert [n for n in w.warnings if "settled" in n] == [
        "w.yaml: robot 'r' settled on the ground at load, as Webots' physics drops it: its origin's y from "
        "0.9000 to 0.2300 m (its lowest wheel now touches the ground under it)",
        "w.yaml: robot 's' settled on the ground at load, as Webots' physics drops it: its origin's y from "
        "0.0500 to 0.2300 m (its lowest wheel now touches the ground under it)"]
    bs = BatchedSimulation(w, copies=2, precision="exact")
    for slot, name in enumerate(("r", "s")):
        for c in range(2):
            assert np.array_equal(bs.pose(c, slot).translation, _t(sim, name))


# ---------------------------------------------------------------------- a Supervisor's move

def _moves_world(coordinate_system: str = "ENU") -> dict:
    deck = _box("deck", (2.0, 0.0, 0.1), (1.0, 1.0, 0.2))                  # top at 0.2
    table = _box("table", (-2.0, 0.0, 0.5), (1.0, 1.0, 0.04))              # top at 0.52, far above any axle
    keeper = {"name": "keeper", "pose": {"translation": [0.0, 5.0, 0.0]},  # a driveless robot holding a floor box
              "shapes": [{"pose": {"translation": [0.0, 0.0, 0.35]}, "geometry": {"type": "box", "size": [1.0, 1.0, 0.1]}}]}
    plain = {k: v for k, v in DRIVE.items() if k != "wheel_bottom"}
    robots = [_robot(at=(0.3, -0.2, 0.2)), _robot("hover", at=(0.0, -3.0, 0.4), drive=plain),
              {"name": "arm", "pose": {"translation": [0.0, 3.0, 0.0]}}, keeper,
              {"name": "boss", "supervisor": True, "pose": {"translation": [9.0, 9.0, 0.0]}}]
    data = {"solids": [FLOOR, deck, table], "robots": robots}
    if coordinate_system == "NUE":
        from tests.test_batched_nue import _to_nue
        data = _to_nue(parse_world(data).world)
    return data


# where a Supervisor puts robot 'r' (ENU) -> where it settles: its wheels' bottom (origin - R) on the ground
MOVES = [((1.0, 1.0, 0.9), 0.0 + R),            # in the air over the floor: dropped onto it
         ((2.1, 0.2, 0.9), 0.2 + R),            # over the deck: onto its top
         ((2.1, 0.2, 0.2 + R / 2), 0.2 + R),    # half sunk into the deck, axle above its top: raised onto it
         ((-2.0, 0.0, 0.1), 0.0 + R),           # under the table: onto the floor below it
         ((0.0, 5.0, 0.9), 0.4 + R)]            # onto the driveless robot's box (top at 0.35 + 0.05)


@pytest.mark.parametrize("at, settled", MOVES)
def test_a_supervisor_move_of_a_wheeled_robot_settles_it_at_once(at, settled) -> None:
    """Webots' physics drops a robot a Supervisor puts in the air; here it settles at once, as at
    load: its height ground − wheel_bottom (closed form), x, y and rotation as given."""
    sim = _sim(*_split(_moves_world()))
    r = sim.robot("r")
    r.set_pose(list(at), rotation=[0, 0, 1, 0.4])
    t = _t(sim)
    assert (t[0], t[1]) == (at[0], at[1]) and t[2] == pytest.approx(settled, abs=1e-15)
    sim.step()
    assert np.array_equal(_t(sim), t)
    yaw = math.atan2(r.pose.rotation[1, 0], r.pose.rotation[0, 0])
    assert yaw == pytest.approx(0.4, abs=1e-15)


def _split(data: dict) -> tuple[list, list]:
    return data["solids"], data["robots"]


def test_a_supervisor_move_of_a_robot_that_does_not_settle_keeps_its_height() -> None:
    """A robot without a drive (an arm), one whose drive has no wheel_bottom, a tilted one: the
    height a Supervisor gives is kept, bit for bit, as at load."""
    sim = _sim(*_split(_moves_world()))
    sim.robot("arm").set_pose([0.5, 3.0, 0.77])
    sim.robot("hover").set_pose([0.5, -3.0, 0.66])
    sim.step()
    assert tuple(sim.robot("arm").pose.translation) == (0.5, 3.0, 0.77)
    assert tuple(_t(sim, "hover")) == (0.5, -3.0, 0.66)
    sim.robot("r").set_pose([1.0, 1.0, 0.9], rotation=[1, 0, 0, 0.3])
    assert tuple(_t(sim)) == (1.0, 1.0, 0.9)


def test_the_ground_a_supervisor_move_settles_on_is_the_world_as_it_is_now() -> None:
    """The deck moved away, the driveless robot's box moved under the robot, a solid removed: each
    move of the wheeled robot settles on the ground where it is then."""
    sim = _sim(*_split(_moves_world()))
    r = sim.robot("r")
    sim.set_solid_pose("deck", [2.0, 0.0, 0.3])                      # top at 0.4
    r.set_pose([2.1, 0.2, 0.9])
    assert _t(sim)[2] == 0.4 + R
    sim.robot("keeper").set_pose([4.0, 4.0, 0.1])                    # its box top at 0.1 + 0.35 + 0.05
    r.set_pose([4.0, 4.0, 0.9])
    assert _t(sim)[2] == pytest.approx((0.1 + 0.35 + 0.05) + R, abs=1e-15)
    sim.remove_solid("deck")
    r.set_pose([2.1, 0.2, 0.9])
    assert _t(sim)[2] == 0.0 + R


def test_a_supervisor_set_field_then_a_step_shows_the_settled_height() -> None:
    """Through the server's core: the supervisor sets the robot's translation 0.9 m up over the deck;
    after its next step the translation field and getPosition show it standing on the deck."""
    import itertools

    import msgpack

    from sensorium.server.daemon.services import Core

    sim = _sim(*_split(_moves_world()))
    n = itertools.count()
    core = Core(sim, new_token=lambda: f"s{next(n)}", log=lambda line: None)
    ids = itertools.count(1)

    def call(service: str, args: dict | None = None) -> dict:
        rid = next(ids)
        replies = list(core.handle([b"S", msgpack.packb({"id": rid, "service": service, "args": args or {}})], 0.0))
        while not replies:
            replies = core.step_once(0.0)[0]
        r = msgpack.unpackb(replies[-1][-1])
        assert r["id"] == rid and r["ok"] is True, r
        return r["result"]

    call("attach", {"robot": "boss"})
    node = call("/boss/robot/get_from_def", {"name": "r"})["node"]
    call("/boss/robot/set_field", {"node": node, "field": "translation", "value": [2.1, 0.2, 0.9]})
    call("/boss/robot/step")
    assert call("/boss/robot/get_field", {"node": node, "field": "translation"})["value"] == [2.1, 0.2, 0.2 + R]
    assert call("/boss/robot/get_node_pose", {"node": node})["position"] == [2.1, 0.2, 0.2 + R]


@pytest.mark.parametrize("coordinate_system", ["ENU", "NUE"])
def test_the_batched_copies_settle_a_move_as_the_simulation_does(coordinate_system: str) -> None:
    solids, robots = _split(_moves_world(coordinate_system))
    world = {"solids": solids, "robots": robots}
    if coordinate_system == "NUE":
        world["world_info"] = {"coordinate_system": "NUE"}
    sim = Simulation(parse_world(world), precision="exact")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        bs = BatchedSimulation(parse_world(world), copies=3, precision="exact")
    names = [r["name"] for r in robots]
    slot = names.index("r")
    turn = {"ENU": lambda v: list(v), "NUE": lambda v: [v[1], v[2], v[0]]}[coordinate_system]
    axis = turn((0.0, 0.0, 1.0))
    bs.set_pose(2, names.index("keeper"), turn((4.0, 4.0, 0.1)))       # copy 2's floor robot moved
    sim.robot("keeper").set_pose(turn((4.0, 4.0, 0.1)))
    for at, _ in [*MOVES, (((4.0, 4.0, 0.9)), None)]:
        sim.robot("r").set_pose(turn(at), rotation=[*axis, 0.4])
        bs.set_pose(2, slot, turn(at), rotation=[*axis, 0.4])
        p = bs.pose(2, slot)
        assert np.array_equal(p.translation, sim.robot("r").pose.translation)
        assert np.array_equal(p.rotation, sim.robot("r").pose.rotation)
    assert sim.robot("r").pose.translation[{"ENU": 2, "NUE": 1}[coordinate_system]] == pytest.approx(0.5 + R, abs=1e-15)
    bs.set_pose(0, slot, turn((4.0, 4.0, 0.9)), rotation=[*axis, 0.4])       # copy 0's keeper is elsewhere
    assert bs.pose(0, slot).translation[{"ENU": 2, "NUE": 1}[coordinate_system]] == 0.0 + R
    bs.step()
    sim.step()
    assert np.array_equal(bs.pose(2, slot).translation, sim.robot("r").pose.translation)


def _y_up_wheel(side: str, x: float) -> str:
    """A wheel of a robot built y-up (its axle along its x, 3 cm above its origin along its y)."""
    return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 1 0 0 anchor {x} 0.03 0 }}\n'
            f'  device [ RotationalMotor {{ name "{side} wheel motor" maxVelocity 10 }} ]\n'
            f'  endPoint Solid {{ translation {x} 0.03 0 rotation 0 1 0 1.5707963267948966 name "{side} wheel"\n'
            '    children [ Shape { geometry Cylinder { radius 0.025 height 0.01 } } ]\n'
            '    boundingObject Cylinder { radius 0.025 height 0.01 } physics Physics { } } }\n')


def test_a_wbt_robot_built_y_up_in_a_nue_world_takes_its_wheel_bottom_along_its_y(tmp_path: Path) -> None:
    """A NUE .wbt whose Robot is built y-up (axles 3 cm above its origin along its y, wheels of radius
    2.5 cm): wheel_bottom 0.005 along its y; its floor (a Plane turned so its normal is the world's
    y) at y = 0.1: it settles at y = 0.1 − 0.005."""
    path = tmp_path / "w.wbt"
    path.write_text("#VRML_SIM R2023b utf8\nWorldInfo { coordinateSystem \"NUE\" basicTimeStep 16 }\n"
                    'Solid { translation 0 0.1 0 rotation 1 0 0 -1.5707963267948966 name "floor" '
                    "children [ Shape { geometry Plane { size 4 4 } } ] boundingObject Plane { size 4 4 } }\n"
                    'Robot { translation 0.2 0.3 -0.4 name "bot" controller "<extern>" children [\n'
                    + _y_up_wheel("left", 0.05) + _y_up_wheel("right", -0.05) + "] physics Physics { } }\n")
    w = load_world(path)
    (robot,) = w.world.robots
    drive = robot.differential_drive or robot.mecanum_drive or robot.omni_drive or robot.ackermann_drive
    assert drive is not None and drive.wheel_bottom == pytest.approx(0.005, abs=1e-12)
    t = _t(Simulation(w), "bot")
    assert (t[0], t[2]) == (0.2, -0.4) and t[1] == 0.1 - drive.wheel_bottom


def test_a_supervisor_move_over_a_terrain_settles_on_the_triangle_and_rides_from_there() -> None:
    """Put 2 m up over the terrain's grid point x = 1.5: it settles on it (0.1 + 0.25·1.5 + R), tilted
    by the slope, and drives on keeping its wheels on the ground; the batched copy the same bits."""
    robots = [_robot(at=(0.5, 0.5, 0.2), yaw=0.0)]
    sim = _sim([_grid(0.1)], robots)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        bs = BatchedSimulation(_loaded([_grid(0.1)], robots), copies=2, precision="exact")
    sim.robot("r").set_pose([1.5, 0.5, 2.0], rotation=[0, 0, 1, 0.0])
    bs.set_pose(1, 0, [1.5, 0.5, 2.0], rotation=[0, 0, 1, 0.0])
    assert _t(sim)[2] == pytest.approx(0.1 + 0.25 * 1.5 + R, abs=1e-15)
    r = sim.robot("r").pose.rotation
    assert math.atan2(-r[2, 0], r[0, 0]) == pytest.approx(-math.atan(0.25), abs=1e-12)
    assert np.array_equal(bs.pose(1, 0).translation, _t(sim))
    assert np.array_equal(bs.pose(1, 0).rotation, sim.robot("r").pose.rotation)
    d = sim.robot("r").drive
    for m in (*d.lefts, *d.rights):
        m.set_position(math.inf)
        m.set_velocity(-2.0)
    sim.run(10)                                         # drives down the slope, its wheels on the ground
    assert _t(sim)[2] == pytest.approx(0.1 + 0.25 * _t(sim)[0] + R, abs=1e-12)
