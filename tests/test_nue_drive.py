"""A robot built y-up in a NUE .wbt world (Webots before R2022a: x north, y up, z east; the robot's
own y up) drives as Webots drives it: the import finds its drive in the plane normal to its y
(forward = the wheels' axis × its up, a 3-D ``forward``), and the kinematic drive rolls it in the
world's ground plane, turning about the world's up. Closed forms (a straight run of v·t along its
forward, a spin of 2rω/L·t about y in place), its ENU twin (the same robot built z-up in an ENU
world, every axis permuted) step by step with its encoders and GPS, and the batched simulation bit
for bit."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world
from tests.test_batched_kinematic import native  # noqa: F401  (the fixture: C helper and math paths)

R = 0.025                # wheel radius
L = 0.1                  # between the wheels
DT = 0.016               # basicTimeStep 16
START = (0.2, 0.0, -0.4)     # NUE (north, up, east); its wheels' bottom on y = 0
YAW = 0.6                # about the world's up


def _nue_to_enu(v) -> list[float]:
    """A vector's coordinates, NUE (x north, y up, z east) -> ENU (x east, y north, z up); the same
    permutation takes the y-up robot's own frame to its z-up twin's."""
    return [v[2], v[0], v[1]]


NUE_TO_ENU = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
"""The NUE -> ENU permutation as a matrix (:func:`_nue_to_enu`)."""


def _world(tmp_path: Path, system: str, axle_ahead: float = 0.0) -> Path:
    """One two-wheel robot with encoders and a GPS off its origin: in a NUE world built y-up (its
    wheels turning about its x, axles R above its origin along its y), or in an ENU world its twin
    built z-up (every vector of the robot and its pose permuted). ``axle_ahead``: the wheels' centre
    that far along the robot's forward from its origin."""
    turn = (lambda v: list(v)) if system == "NUE" else _nue_to_enu

    def vec(v) -> str:
        return " ".join(repr(float(x)) for x in turn(v))

    # the wheel's cylinder (along its own y) laid along the hinge axis: the robot's x (NUE), its y (ENU)
    wheel_turn = "rotation 0 0 1 1.5707963267948966" if system == "NUE" else ""

    def wheel(side: str, x: float) -> str:
        at = vec((x, R, axle_ahead))
        return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis {vec((1, 0, 0))} anchor {at} }}\n'
                f'  device [ RotationalMotor {{ name "{side} wheel motor" maxVelocity 10 }}\n'
                f'           PositionSensor {{ name "{side} wheel sensor" }} ]\n'
                f'  endPoint Solid {{ translation {at} {wheel_turn} name "{side} wheel"\n'
                f'    children [ Shape {{ geometry Cylinder {{ radius {R} height 0.01 }} }} ]\n'
                f'    boundingObject Cylinder {{ radius {R} height 0.01 }} physics Physics {{ }} }} }}\n')

    text = (f'#VRML_SIM R2023b utf8\nWorldInfo {{ coordinateSystem "{system}" basicTimeStep 16 }}\n'
            f'Robot {{ translation {vec(START)} rotation {vec((0, 1, 0))} {YAW} name "bot" controller "<extern>"\n'
            f'  children [\n{wheel("left", L / 2)}{wheel("right", -L / 2)}'
            f'    GPS {{ name "gps" translation {vec((0.01, 0.04, 0.03))} }} ]\n'
            '  boundingObject Pose { translation ' + vec((0, 0.05, 0)) + ' children [ Box { size '
            + " ".join(repr(abs(x)) for x in turn((0.08, 0.04, 0.06))) + ' } ] }\n'
            '  physics Physics { } }\n')
    path = tmp_path / f"{system}.wbt"
    path.write_text(text)
    return path


def _sim(path: Path) -> Simulation:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return Simulation(load_world(path), precision="exact")


def _batched(path: Path, copies: int) -> BatchedSimulation:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return BatchedSimulation(load_world(path), copies=copies, precision="exact")


def _spin(sim: Simulation, robot: str, motors, speeds) -> None:
    """Each of ``motors`` in velocity control at its speed."""
    for name, u in zip(motors, speeds):
        m = sim.robot(robot).motor(name)
        m.set_position(math.inf)
        m.set_velocity(u)


def _drive(sim: Simulation, left: float, right: float) -> None:
    d = sim.robot("bot").drive
    for motors, speed in ((d.lefts, left), (d.rights, right)):
        for m in motors:
            m.set_position(math.inf)
            m.set_velocity(speed)


def _ry(a: float) -> np.ndarray:
    """A turn by ``a`` about NUE's up (y)."""
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def test_the_import_finds_a_y_up_robots_drive_in_the_plane_normal_to_its_y(tmp_path: Path) -> None:
    """Wheels about the robot's +x, its up its y: forward x × y = its +z, the left wheel at +x; the
    ENU twin's is the drive it always had (forward its x, left its +y)."""
    (robot,) = load_world(_world(tmp_path, "NUE")).world.robots
    d = robot.differential_drive
    assert d is not None and tuple(d.forward) == (0.0, 0.0, 1.0)
    assert (d.left_motor, d.right_motor, d.axle_length, d.wheel_radius) == ("left wheel motor", "right wheel motor", L, R)
    assert d.axle_center == (0.0, 0.0) and d.wheel_bottom == pytest.approx(0.0, abs=1e-15)
    (twin,) = load_world(_world(tmp_path, "ENU")).world.robots
    t = twin.differential_drive
    assert t is not None and tuple(t.forward) == (1.0, 0.0) and t.axle_center == (0.0, 0.0)
    # the wheels' centre 2 cm ahead along its forward (its z), not its up: the drive's axle_center
    (ahead,) = load_world(_world(tmp_path, "NUE", axle_ahead=0.02)).world.robots
    assert ahead.differential_drive is not None
    assert ahead.differential_drive.axle_center == pytest.approx((0.02, 0.0), abs=1e-15)


def test_equal_wheel_speeds_drive_a_y_up_robot_straight_along_its_forward_by_v_t(tmp_path: Path) -> None:
    """Both wheels at 4 rad/s for 50 steps: v = 4R, along its forward (its z turned by the yaw about
    y: (sin, 0, cos)) by exactly v·t, its height and rotation kept; its encoders read 4·t."""
    sim = _sim(_world(tmp_path, "NUE"))
    _drive(sim, 4.0, 4.0)
    sim.robot("bot").device("left wheel sensor").enable(16)
    sim.run(50)
    t = 50 * DT
    pose = sim.robot("bot").pose
    want = np.array(START) + 4.0 * R * t * np.array([math.sin(YAW), 0.0, math.cos(YAW)])
    assert np.abs(pose.translation - want).max() <= 1e-9
    assert pose.translation[1] == START[1]
    assert np.abs(pose.rotation - _ry(YAW)).max() <= 1e-12
    assert sim.robot("bot").device("left wheel sensor").value == pytest.approx(4.0 * t, abs=1e-12)


def test_opposite_wheel_speeds_spin_a_y_up_robot_in_place_about_the_worlds_up(tmp_path: Path) -> None:
    """Left at -4, right at +4 rad/s: it turns left (counter-clockwise seen from above, about +y) at
    2·4R/L, in place: after 0.8 s its rotation is Ry(yaw + 1.6) and its origin has not moved."""
    sim = _sim(_world(tmp_path, "NUE"))
    _drive(sim, -4.0, 4.0)
    sim.run(50)
    pose = sim.robot("bot").pose
    assert np.abs(pose.rotation - _ry(YAW + 2.0 * 4.0 * R / L * 50 * DT)).max() <= 1e-9
    assert np.abs(pose.translation - np.array(START)).max() <= 1e-12


def test_a_y_up_robot_in_a_nue_world_drives_as_its_enu_twin(tmp_path: Path) -> None:
    """The same commands (straight, arcs both ways, a spin, backwards) on the y-up robot in the NUE
    world and its z-up twin in the ENU world: after every step their poses agree with every axis
    permuted to 1e-12, their encoders read the same and their GPSs the same position permuted."""
    nue, enu = _sim(_world(tmp_path, "NUE")), _sim(_world(tmp_path, "ENU"))
    for sim in (nue, enu):
        for name in ("left wheel sensor", "right wheel sensor", "gps"):
            sim.robot("bot").device(name).enable(16)
    moved = 0.0
    for left, right in ((5.0, 5.0), (2.0, 6.0), (7.0, -1.0), (-3.0, 3.0), (-4.0, -6.0)):
        for sim in (nue, enu):
            _drive(sim, left, right)
        for _ in range(40):
            _step_twins(nue, enu, "bot", 1)
            for name in ("left wheel sensor", "right wheel sensor"):
                assert nue.robot("bot").device(name).value == enu.robot("bot").device(name).value
            ga, gb = nue.robot("bot").device("gps").values, enu.robot("bot").device("gps").values
            assert np.abs(NUE_TO_ENU @ ga - gb).max() <= 1e-12
            a = nue.robot("bot").pose
            moved = max(moved, float(np.hypot(a.translation[0] - START[0], a.translation[2] - START[2])))
    assert moved > 0.1 and nue.robot("bot").pose.translation[1] == START[1]


def test_the_batched_simulation_drives_a_y_up_robot_as_the_single_one(tmp_path: Path, native) -> None:  # noqa: F811
    """Three copies, each its own wheel speeds (copy 0's first ones equal: straight along its forward by
    v·t), against a Simulation per copy: every pose bit for bit after every step (the C drive pass and
    its numpy fallback)."""
    path = _world(tmp_path, "NUE")
    bs = _batched(path, 3)
    sims = [_sim(path) for _ in range(3)]
    rng = np.random.default_rng(7)
    slot = bs.slot("bot")
    for k in range(4):
        lr = rng.uniform(-8.0, 8.0, size=(3, 2))
        if k == 0:
            lr[0] = 5.0
        bs.set_wheels(slot, lr[:, 0], lr[:, 1])
        for c, sim in enumerate(sims):
            _drive(sim, float(lr[c, 0]), float(lr[c, 1]))
        for _ in range(25):
            bs.step()
            for c, sim in enumerate(sims):
                sim.run(1)
                got, want = bs.pose(c, slot), sim.robot("bot").pose
                assert np.array_equal(got.translation, want.translation)
                assert np.array_equal(got.rotation, want.rotation)
        if k == 0:
            want = np.array(START) + 5.0 * R * 25 * DT * np.array([math.sin(YAW), 0.0, math.cos(YAW)])
            assert np.abs(bs.pose(0, slot).translation - want).max() <= 1e-9


def _twin_vec(system: str):
    """Coordinates given in the ENU twin's robot frame as a .wbt vector of ``system``'s world: permuted
    (ENU -> NUE) for the y-up robot, as they are for its z-up twin."""
    back = (lambda v: [v[1], v[2], v[0]]) if system == "NUE" else (lambda v: list(v))

    def vec(v) -> str:
        return " ".join(repr(float(x)) for x in back(v))
    return vec


def _twin_world(tmp_path: Path, system: str, stem: str, robot: str, at, children: str, info: str = "") -> Path:
    """A world of one robot ``robot`` with physics at ``at`` (ENU twin's coordinates), turned by YAW about
    its up, with ``children``; ``info``: more WorldInfo fields."""
    vec = _twin_vec(system)
    path = tmp_path / f"{stem}-{system}.wbt"
    path.write_text(f'#VRML_SIM R2023b utf8\nWorldInfo {{ coordinateSystem "{system}" basicTimeStep 16{info} }}\n'
                    f'Robot {{ translation {vec(at)} rotation {vec((0, 0, 1))} {YAW} name "{robot}" '
                    f'controller "<extern>"\n  children [\n{children}]\n  physics Physics {{ }} }}\n')
    return path


def _step_twins(nue: Simulation, enu: Simulation, robot: str, steps: int, bs: BatchedSimulation | None = None) -> None:
    """``steps`` basic steps of the NUE world, its ENU twin (and the NUE world's batched copy 0, given
    ``bs``): the twin's pose is the NUE one with every axis permuted, to 1e-12; the copy's the NUE one
    bit for bit."""
    p = NUE_TO_ENU
    for _ in range(steps):
        nue.run(1)
        enu.run(1)
        a, b = nue.robot(robot).pose, enu.robot(robot).pose
        if bs is not None:
            bs.step()
            assert np.array_equal(bs.pose(0, 0).translation, a.translation)
            assert np.array_equal(bs.pose(0, 0).rotation, a.rotation)
        assert np.abs(p @ a.translation - b.translation).max() <= 1e-12
        assert np.abs(p @ a.rotation @ p.T - b.rotation).max() <= 1e-12


def _omni_world(tmp_path: Path, system: str) -> Path:
    """Three omni wheels (spheres of radius R) 120° apart, 0.1 m from the centre, each turning about
    the line from the centre out through it (the omni_wheels how-to's layout): in the NUE world built
    y-up, in the ENU world its twin built z-up. Coordinates given in the twin's (ENU) robot frame."""
    vec = _twin_vec(system)

    wheels = ""
    for i in range(3):
        phi = 0.3 + i * 2.0 * math.pi / 3.0
        at = vec((0.1 * math.cos(phi), 0.1 * math.sin(phi), R))
        wheels += (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis {vec((math.cos(phi), math.sin(phi), 0))} '
                   f'anchor {at} }}\n  device [ RotationalMotor {{ name "w{i}" maxVelocity 20 }} ]\n'
                   f'  endPoint Solid {{ translation {at} name "wheel {i}" children [ Shape {{ geometry Sphere '
                   f'{{ radius {R} }} }} ] boundingObject Sphere {{ radius {R} }} physics Physics {{ }} }} }}\n')
    return _twin_world(tmp_path, system, "omni", "bot", (-0.4, 0.2, 0.0), wheels)


def test_a_y_up_omni_wheel_robot_in_a_nue_world_drives_as_its_enu_twin(tmp_path: Path) -> None:
    """Three omni wheels on the y-up robot: the import takes their places and axes in the plane normal
    to its y (its drive's forward its x); driven with the same wheel speeds as its z-up ENU twin, their
    poses agree with every axis permuted to 1e-12 after every step, and it has moved; a batched copy
    of the NUE world keeps the single simulation's poses bit for bit."""
    nue, enu = (_sim(_omni_world(tmp_path, s)) for s in ("NUE", "ENU"))
    bs = _batched(_omni_world(tmp_path, "NUE"), 1)
    d = nue.world.robots[0].omni_drive
    assert d is not None and tuple(d.forward) == (1.0, 0.0, 0.0)
    start = nue.robot("bot").pose.translation.copy()
    for speeds in ((4.0, -2.0, 1.0), (3.0, 3.0, 3.0), (-5.0, 2.0, 6.0)):
        for sim in (nue, enu):
            _spin(sim, "bot", ("w0", "w1", "w2"), speeds)
        bs.omni.command(0, np.array([speeds]))
        _step_twins(nue, enu, "bot", 30, bs)
    moved = nue.robot("bot").pose.translation - start
    assert math.hypot(moved[0], moved[2]) > 0.03 and moved[1] == 0.0


def _car_world(tmp_path: Path, system: str) -> Path:
    """A car: two steering hinges about its up 0.2 m ahead holding ball wheels, two driven rear wheels
    about its left under its origin (rear-wheel drive), ball wheels of radius R: built y-up in the NUE
    world, z-up in its ENU twin. Coordinates given in the twin's (ENU) robot frame."""
    vec = _twin_vec(system)

    def ball(name: str, at) -> str:
        return (f'Solid {{ translation {vec(at)} name "{name}" children [ Shape {{ geometry Sphere {{ radius {R} }} }} ] '
                f'boundingObject Sphere {{ radius {R} }} physics Physics {{ }} }}')

    joints = ""
    for side, y in (("right", -0.08), ("left", 0.08)):
        at = (0.2, y, R)
        joints += (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis {vec((0, 0, 1))} anchor {vec(at)} }}\n'
                   f'  device [ RotationalMotor {{ name "{side}_steer" maxVelocity 5 minPosition -0.6 maxPosition 0.6 }} ]\n'
                   f'  endPoint {ball(f"{side} front", at)} }}\n')
        at = (0.0, y, R)
        joints += (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis {vec((0, 1, 0))} anchor {vec(at)} }}\n'
                   f'  device [ RotationalMotor {{ name "{side}_rear_wheel" maxVelocity 30 }} ]\n'
                   f'  endPoint {ball(f"{side} rear", at)} }}\n')
    return _twin_world(tmp_path, system, "car", "car", (0.3, -0.1, 0.0), joints)


def test_a_y_up_car_in_a_nue_world_steers_and_drives_as_its_enu_twin(tmp_path: Path) -> None:
    """A y-up car: the import finds its Ackermann drive with its y as up (steering about its y, its
    forward its z); steered both ways and driven both ways with its z-up ENU twin's commands, their
    poses agree with every axis permuted to 1e-12 after every step, and it has moved and turned; a
    batched copy of the NUE world keeps the single simulation's poses bit for bit."""
    nue, enu = (_sim(_car_world(tmp_path, s)) for s in ("NUE", "ENU"))
    bs = _batched(_car_world(tmp_path, "NUE"), 1)
    d = nue.world.robots[0].ackermann_drive
    assert d is not None and tuple(d.forward) == (0.0, 0.0, 1.0)
    assert (d.wheelbase, d.track_front, d.type) == (pytest.approx(0.2, abs=1e-15), pytest.approx(0.16, abs=1e-15),
                                                    "propulsion")
    start = nue.robot("car").pose.rotation.copy()
    for steer, speed in ((0.3, 10.0), (-0.4, 12.0), (0.2, -8.0)):
        for sim in (nue, enu):
            for name in ("right_steer", "left_steer"):
                sim.robot("car").motor(name).set_position(steer)
            _spin(sim, "car", ("right_rear_wheel", "left_rear_wheel"), (speed, speed))
        bs.cars.command(0, np.array([steer]), np.array([steer]), np.array([speed]))
        _step_twins(nue, enu, "car", 30, bs)
    assert np.abs(nue.robot("car").pose.rotation - start).max() > 0.05
    assert nue.robot("car").pose.translation[1] == 0.0      # (along up: its wheels stay on y = 0)


def _mecanum_world(tmp_path: Path, system: str) -> Path:
    """Four mecanum wheels (ball wheels of radius R whose friction a ContactProperties turns by ±45°,
    as a youBot's) at (±0.2, ±0.15) about its left axis: built y-up in the NUE world, z-up in its ENU
    twin. Coordinates given in the twin's (ENU) robot frame."""
    vec = _twin_vec(system)

    wheels = ""
    for name, x, y, material in (("fl", 0.2, 0.15, "A"), ("fr", 0.2, -0.15, "B"), ("rl", -0.2, 0.15, "B"),
                                 ("rr", -0.2, -0.15, "A")):
        at = vec((x, y, R))
        wheels += (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis {vec((0, 1, 0))} anchor {at} }}\n'
                   f'  device [ RotationalMotor {{ name "{name}" maxVelocity 20 }} ]\n'
                   f'  endPoint Solid {{ translation {at} name "{name} wheel" contactMaterial "{material}" children '
                   f'[ Shape {{ geometry Sphere {{ radius {R} }} }} ] boundingObject Sphere {{ radius {R} }} '
                   'physics Physics { } } }\n')
    info = (' contactProperties [\n'
            '  ContactProperties { material1 "A" coulombFriction [ 1.8 0 ] frictionRotation 0.785398 0 }\n'
            '  ContactProperties { material1 "B" coulombFriction [ 1.8 0 ] frictionRotation -0.785398 0 } ]')
    return _twin_world(tmp_path, system, "mecanum", "base", (0.1, 0.3, 0.0), wheels, info)


def test_a_y_up_mecanum_robot_in_a_nue_world_drives_as_its_enu_twin(tmp_path: Path) -> None:
    """A y-up mecanum base: the import finds its drive with its y as up (its forward its z); driven,
    strafed and turned with its z-up ENU twin's wheel speeds, their poses agree with every axis
    permuted to 1e-12 after every step; all wheels at +ω carry it along its forward by r·ω·t."""
    nue, enu = (_sim(_mecanum_world(tmp_path, s)) for s in ("NUE", "ENU"))
    d = nue.world.robots[0].mecanum_drive
    assert d is not None and tuple(d.forward) == (0.0, 0.0, 1.0)
    assert enu.world.robots[0].mecanum_drive is not None
    assert tuple(d.rollers) == tuple(enu.world.robots[0].mecanum_drive.rollers)
    start = nue.robot("base").pose.translation.copy()
    for k, speeds in enumerate(((6.0, 6.0, 6.0, 6.0), (-4.0, 4.0, 4.0, -4.0), (-3.0, 3.0, -3.0, 3.0))):
        for sim in (nue, enu):
            _spin(sim, "base", ("fl", "fr", "rl", "rr"), speeds)
        _step_twins(nue, enu, "base", 30)
        if k == 0:
            want = start + 6.0 * R * 30 * DT * np.array([math.sin(YAW), 0.0, math.cos(YAW)])
            assert np.abs(nue.robot("base").pose.translation - want).max() <= 1e-9
