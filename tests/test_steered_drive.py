"""Steered-wheel robots (``steered_drive``): four wheels at the corners of a 0.4 x 0.3 box, each on a
steering hinge moved as any joint is, strafe, turn in place and drive as closed form says; the fit
of a two-wheel arrangement is the differential drive's twist; bad declarations are one line; the
batched simulation drives them bit for bit as the single one (free wheels too). Our own worlds."""

from __future__ import annotations

import math

import pytest
from _packets import use_packets

from sensorium.schemas import world as wm
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.motion import DifferentialDrive, SteeredDrive
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.geometry import Pose
from sensorium.server.world.loader import WorldError, parse_world

R = 0.05                               # wheel radius
CX, CY = 0.2, 0.15                     # the corners of the 0.4 x 0.3 box
CORNERS = {"fl": (CX, CY), "fr": (CX, -CY), "rl": (-CX, CY), "rr": (-CX, -CY)}
DT = 0.016


def swerve(**drive) -> dict:
    return {"name": "sw", "pose": {"translation": [0.0, 0.0, 0.1]},
            "body": {"geometry": {"type": "box", "size": [0.4, 0.3, 0.1]}},
            "steered_drive": {"max_wheel_speed": 20.0, "wheels": [
                {"motor": f"{k} wheel", "steer": f"{k} steer", "position": list(p), "radius": R}
                for k, p in CORNERS.items()], **drive},
            "devices": [{"device": "RotationalMotor", "name": f"{k} steer", "axis": [0.0, 0.0, 1.0],
                         "anchor": [p[0], p[1], 0.0], "max_velocity": 100.0} for k, p in CORNERS.items()]
            + [{"device": "PositionSensor", "name": "fl steer sensor", "motor": "fl steer"}]}


def sim_of(robot: dict) -> Simulation:
    return Simulation(parse_world({"world_info": {"basic_time_step": 16, "contact": False}, "robots": [robot]}))


def steer(sim: Simulation, angles: dict[str, float], steps: int = 60) -> None:
    for k, a in angles.items():
        sim.robot("sw").motor(f"{k} steer").set_position(a)
    sim.run(steps)
    for k, a in angles.items():
        assert sim.robot("sw").motor(f"{k} steer").position == a


def roll(sim: Simulation, speeds: dict[str, float]) -> None:
    for k, omega in speeds.items():
        m = sim.robot("sw").motor(f"{k} wheel")
        m.set_position(math.inf)
        m.set_velocity(omega)


def pose2d(sim: Simulation) -> tuple[float, float, float]:
    p = sim.robot("sw").pose
    return float(p.translation[0]), float(p.translation[1]), math.atan2(p.rotation[1, 0], p.rotation[0, 0])


def test_steering_does_not_move_the_body_and_straight_wheels_drive_forward() -> None:
    sim = sim_of(swerve())
    steer(sim, dict.fromkeys(CORNERS, 0.7))
    assert pose2d(sim) == (0.0, 0.0, 0.0)              # the wheels did not roll
    steer(sim, dict.fromkeys(CORNERS, 0.0))
    roll(sim, dict.fromkeys(CORNERS, 4.0))
    sim.run(100)                                        # 1.6 s at r·ω = 0.2 m/s
    assert pose2d(sim) == pytest.approx((R * 4.0 * 1.6, 0.0, 0.0), abs=1e-12)


@pytest.mark.parametrize("omega", [4.0, -2.5])
def test_all_steered_to_a_quarter_turn_moves_sideways_at_r_omega(omega: float) -> None:
    sim = sim_of(swerve())
    steer(sim, dict.fromkeys(CORNERS, math.pi / 2))
    roll(sim, dict.fromkeys(CORNERS, omega))
    sim.run(100)
    assert pose2d(sim) == pytest.approx((0.0, R * omega * 1.6, 0.0), abs=1e-12)
    assert sim.robot("sw").drive.velocity()[:3] == pytest.approx([0.0, R * omega, 0.0], abs=1e-12)


@pytest.mark.parametrize("omega", [3.0, -5.0])
def test_wheels_tangent_to_a_circle_about_the_centre_turn_in_place_at_r_omega_over_radius(omega: float) -> None:
    sim = sim_of(swerve())
    # a wheel at (x, y) rolls along (-y, x) for a turn to the left
    steer(sim, {k: math.atan2(x, -y) for k, (x, y) in CORNERS.items()})
    roll(sim, dict.fromkeys(CORNERS, omega))
    sim.run(50)                                         # 0.8 s
    rate = R * omega / math.hypot(CX, CY)
    x, y, yaw = pose2d(sim)
    assert (x, y) == pytest.approx((0.0, 0.0), abs=1e-12)
    assert yaw == pytest.approx(math.remainder(rate * 0.8, math.tau), abs=1e-12)


def test_wheels_that_disagree_move_the_robot_by_their_least_squares_twist() -> None:
    """Front wheels straight, rear ones at a quarter turn, all at ω: the fit of the four wheels'
    velocities (normal equations: vx = Σux/4, vy = Σuy/4, ωz = Σ(x·uy − y·ux)/Σ(x² + y²))."""
    sim = sim_of(swerve())
    steer(sim, {"fl": 0.0, "fr": 0.0, "rl": math.pi / 2, "rr": math.pi / 2})
    roll(sim, dict.fromkeys(CORNERS, 2.0))
    u = R * 2.0
    vel = {"fl": (u, 0.0), "fr": (u, 0.0), "rl": (0.0, u), "rr": (0.0, u)}
    vx = sum(v[0] for v in vel.values()) / 4
    vy = sum(v[1] for v in vel.values()) / 4
    w = sum(x * vel[k][1] - y * vel[k][0] for k, (x, y) in CORNERS.items()) / (4 * (CX * CX + CY * CY))
    sim.run(1)
    assert sim.robot("sw").drive.velocity()[5] == pytest.approx(w, abs=1e-12)
    half = math.sin(0.5 * w * DT)                       # one step of the exact twist move from the origin
    a, b = math.sin(w * DT) / w, 2.0 * half * half / w
    assert pose2d(sim) == pytest.approx((a * vx - b * vy, b * vx + a * vy, w * DT), abs=1e-12)


def test_two_wheels_at_plus_minus_y_steered_straight_are_the_differential_drive() -> None:
    config = wm.SteeredDrive.model_validate({"wheels": [
        {"motor": "left", "position": [0.0, 0.026], "radius": 0.0205},
        {"motor": "right", "position": [0.0, -0.026], "radius": 0.0205}]})
    diff = wm.DifferentialDrive.model_validate({"wheel_radius": 0.0205, "axle_length": 0.052,
                                                "left_motor": "left", "right_motor": "right"})
    steered = SteeredDrive(config, Pose.identity())
    steered.bind({})
    two = DifferentialDrive(diff, Pose.identity())
    for wl, wr in ((3.0, 3.0), (2.0, -1.5), (-4.0, 6.25), (0.0, 5.0)):
        vx, vy, w = steered.twist([wl, wr])
        assert vx == pytest.approx(two.wheel_radius * (wl + wr) / 2.0, abs=1e-12)
        assert vy == pytest.approx(0.0, abs=1e-12)
        assert w == pytest.approx(two.wheel_radius * (wr - wl) / two.axle_length, abs=1e-12)


def test_a_steering_hinge_about_down_turns_the_wheel_the_other_way() -> None:
    robot = swerve()
    for wheel in robot["steered_drive"]["wheels"]:
        wheel["steer_sign"] = -1
    sim = sim_of(robot)
    steer(sim, dict.fromkeys(CORNERS, math.pi / 2))
    roll(sim, dict.fromkeys(CORNERS, 4.0))
    sim.run(100)
    assert pose2d(sim) == pytest.approx((0.0, -R * 4.0 * 1.6, 0.0), abs=1e-12)


@pytest.mark.parametrize("change, message", [
    (lambda r: r["steered_drive"]["wheels"][0].update(steer="nowhere"),
     r"steered_drive\.wheels\[0\]\.steer: 'nowhere' is not one of the robot's RotationalMotor devices"),
    (lambda r: r["steered_drive"]["wheels"][1].update(steer="fl wheel"), "motor 'fl wheel' both rolls and steers"),
    (lambda r: [w.update(position=[0.1, 0.0]) for w in r["steered_drive"]["wheels"]],
     "the wheels all stand at one place"),
    (lambda r: r.update(differential_drive={}), "a robot has one drive at most"),
])
def test_bad_declarations_are_one_line(change, message: str) -> None:
    robot = swerve()
    change(robot)
    with pytest.raises(WorldError, match=message):
        sim_of(robot)


@pytest.mark.parametrize("precision", ["exact", "fast"])
def test_the_batched_simulation_drives_it_as_the_single_one_bit_for_bit(precision: str) -> None:
    """Three copies of the swerve robot in a 1.2 m square with a block (contact on), each against its own
    Simulation: every 30 steps new random steering targets (the corners near one heading, or turning
    in velocity control) and wheel speeds per copy, 300 steps; the pose, the steering encoder and every wheel's
    angle the same bits every step, the robot pressed against something in some steps."""
    import numpy as np

    walls = [{"name": n, "pose": {"translation": [x, y, 0.25]}, "geometry": {"type": "box", "size": [sx, sy, 0.5]}}
             for n, x, y, sx, sy in (("north", 0, 0.7, 1.6, 0.2), ("south", 0, -0.7, 1.6, 0.2),
                                     ("east", 0.7, 0, 0.2, 1.2), ("west", -0.7, 0, 0.2, 1.2),
                                     ("block", 0.4, 0.4, 0.15, 0.15))]
    loaded = parse_world({"world_info": {"basic_time_step": 16, "contact": True}, "solids": walls,
                          "robots": [swerve()]})
    n = 3
    batched = BatchedSimulation(loaded, n, precision=precision)
    singles = [Simulation(loaded, precision=precision) for _ in range(n)]
    enc = batched.device("sw", "fl steer sensor")
    batched.enable(enc, 16)
    for s in singles:
        s.device("sw/fl steer sensor").enable(16)
    rng = np.random.default_rng(7)
    pressed = 0
    for t in range(300):
        if t % 30 == 0:     # mostly agreeing wheels (a drive), each a little off (a fit), now and then spinning
            speeds = rng.uniform(-15.0, 15.0, size=(n, 1)) + rng.uniform(-2.0, 2.0, size=(n, 4))
            batched.steered.command(0, speeds)
            for c, s in enumerate(singles):
                heading, spin = float(rng.uniform(-2.0, 2.0)), rng.random() < 0.2
                for k, name in enumerate(CORNERS):
                    target = math.inf if spin else heading + float(rng.uniform(-0.2, 0.2))
                    velocity = float(rng.uniform(0.5, 4.0))
                    s.robot("sw").motor(f"{name} steer").command(target, velocity, None, None)
                    batched.joints.command(0, f"{name} steer", position=target, velocity=velocity, copies=[c])
                    roll(s, {name: float(speeds[c, k])})
        for s in singles:
            s.step()
        batched.step()
        for c, s in enumerate(singles):
            pose = s.robot("sw").pose
            got = batched.pose(c, 0)
            assert got.translation.tobytes() == pose.translation.tobytes(), (t, c)
            assert got.rotation.tobytes() == pose.rotation.tobytes(), (t, c)
            assert np.float64(batched.value(enc)[c]).tobytes() == np.float64(
                s.device("sw/fl steer sensor").value).tobytes(), (t, c)
            for name in CORNERS:
                col = batched.steered.column(0, f"{name} wheel")
                assert batched.steered.angle[c, col[0], col[1]] == s.robot("sw").motor(f"{name} wheel").position
            pressed += bool(s.robot("sw").pressing)
    assert pressed > 10


def test_the_gym_refuses_it_as_an_agent_in_one_line() -> None:
    gym = pytest.importorskip("sensorium.gym")
    loaded = parse_world({"world_info": {"basic_time_step": 16}, "robots": [swerve()]})
    with pytest.raises(ValueError, match="task robot 'sw' has a steered_drive, which the gym's actions"):
        gym.SensoriumEnv(loaded, gym.Task(robot="sw"))


def test_contact_stops_a_strafing_robot_at_a_wall() -> None:
    wall = {"name": "wall", "pose": {"translation": [0.0, 1.0, 0.25]}, "geometry": {"type": "box", "size": [4, 0.2, 0.5]}}
    sim = Simulation(parse_world({"world_info": {"basic_time_step": 16, "contact": True}, "solids": [wall],
                                  "robots": [swerve()]}))
    steer(sim, dict.fromkeys(CORNERS, math.pi / 2))
    roll(sim, dict.fromkeys(CORNERS, 10.0))
    sim.run(200)                                        # 3.2 s at 0.5 m/s: far past the wall unless stopped
    x, y, yaw = pose2d(sim)
    assert (x, yaw) == pytest.approx((0.0, 0.0), abs=1e-12)     # (cos(pi/2) is 6e-17, not 0)
    assert y == pytest.approx(0.9 - CY, abs=1e-9)       # its body's left side against the wall's face
    assert sim.robot("sw").pressing


def test_nue_world_strafes_to_the_robots_left_on_its_ground_plane() -> None:
    robot = swerve()
    robot["pose"] = {"translation": [0.0, 0.0, 0.0]}
    for d in robot["devices"]:                          # a robot built y-up: its steering hinges about its y
        if d["device"] == "RotationalMotor":
            d["axis"] = [0.0, 1.0, 0.0]
    sim = Simulation(parse_world({"world_info": {"basic_time_step": 16, "coordinate_system": "NUE", "contact": False},
                                  "robots": [robot]}))
    steer(sim, dict.fromkeys(CORNERS, math.pi / 2))
    roll(sim, dict.fromkeys(CORNERS, 4.0))
    sim.run(100)
    # x north (the robot's forward), y up, z east: its left is west, -z
    assert list(sim.robot("sw").pose.translation) == pytest.approx([0.0, 0.0, -R * 4.0 * 1.6], abs=1e-12)


def test_strafing_sideways_up_a_ramp_covers_r_omega_t_along_the_ground() -> None:
    """On tests/test_ground_ramp.py's ramp (angle A, rising along +x), heading -y with every wheel
    steered to its left (up the ramp): r·ω·t·cos A along x, r·ω·t·sin A up, as the holonomic drives."""
    from tests.test_ground_ramp import FLOOR, HALF, A, _ramp, _ramp_z

    robot = {**swerve(), "body": {"geometry": {"type": "cylinder", "radius": 0.1, "height": 2 * HALF}},
             "pose": {"translation": [1.3, 0.0, _ramp_z(1.3) + HALF], "rotation": [0, 0, 1, -math.pi / 2]}}
    sim = Simulation(parse_world({"world_info": {"basic_time_step": 16}, "solids": [FLOOR, _ramp()],
                                  "robots": [robot]}), precision="exact")
    steer(sim, dict.fromkeys(CORNERS, math.pi / 2))
    start = sim.robot("sw").pose.translation.copy()
    roll(sim, dict.fromkeys(CORNERS, 4.0))
    sim.run(60)
    d = sim.robot("sw").pose.translation - start
    dist = R * 4.0 * 0.96
    assert list(d) == pytest.approx([dist * math.cos(A), 0.0, dist * math.sin(A)], abs=1e-9)


# A tricycle of ours: two driven rear wheels on one axle (the robot's origin at its centre), one free
# front wheel on a steering hinge L ahead (Webots' sick sample and forklifts are built this way).
L, B = 0.5, 0.2                        # wheelbase, half the rear track


def tricycle(sign: int = 1) -> dict:
    return {"name": "sw", "pose": {"translation": [0.0, 0.0, 0.1]},
            "body": {"geometry": {"type": "box", "size": [0.6, 0.4, 0.1]}},
            "steered_drive": {"max_wheel_speed": 20.0, "wheels": [
                {"motor": "rl wheel", "position": [0.0, B], "radius": R},
                {"motor": "rr wheel", "position": [0.0, -B], "radius": R},
                {"steer": "fr steer", "position": [L, 0.0], "radius": 0.03, "steer_sign": sign}]},
            "devices": [{"device": "RotationalMotor", "name": "fr steer", "axis": [0.0, 0.0, float(sign)],
                         "anchor": [L, 0.0, 0.0], "max_velocity": 100.0},
                        {"device": "PositionSensor", "name": "front encoder", "free_wheel": 2, "position": 0.5}]}


def test_a_tricycle_s_free_wheel_gives_the_bicycle_twist() -> None:
    """Rear wheels at one speed, the free front wheel at δ: v = r·ω and ωz = v·tan δ / L about the rear
    axle's centre (the drive's origin), no sideways slip, to 1e-12."""
    config = wm.SteeredDrive.model_validate(tricycle()["steered_drive"])

    class Hinge:
        position = 0.0

    drive = SteeredDrive(config, Pose.identity())
    hinge = Hinge()
    drive.bind({"fr steer": hinge})
    for delta, omega in ((0.0, 3.0), (0.3, 3.0), (-0.7, -2.0), (1.2, 5.5)):
        hinge.position = delta
        vx, vy, w = drive.twist([omega, omega, 0.0])
        assert (vx, vy, w) == pytest.approx((R * omega, 0.0, R * omega * math.tan(delta) / L), abs=1e-12)
    hinge.position = math.pi / 2                # the front wheel across: the rear wheels turn it about its axle
    assert drive.twist([-1.0, 1.0, 0.0]) == pytest.approx((0.0, 0.0, R * 2.0 / (2 * B)), abs=1e-12)


@pytest.mark.parametrize("sign", [1, -1])
def test_a_tricycle_drives_straight_then_on_the_bicycle_arc(sign: int) -> None:
    sim = sim_of(tricycle(sign))
    roll(sim, {"rl": 4.0, "rr": 4.0})
    sim.run(50)                                 # 0.8 s straight
    assert pose2d(sim) == pytest.approx((R * 4.0 * 0.8, 0.0, 0.0), abs=1e-12)
    sim.robot("sw").motor("fr steer").set_position(0.3)
    roll(sim, {"rl": 0.0, "rr": 0.0})
    sim.run(60)                                 # steering alone does not move it
    assert sim.robot("sw").motor("fr steer").position == 0.3
    assert pose2d(sim) == pytest.approx((R * 4.0 * 0.8, 0.0, 0.0), abs=1e-12)
    roll(sim, {"rl": 4.0, "rr": 4.0})
    sim.run(100)                                # 1.6 s on the circle of radius L / tan 0.3 about (x0, ±radius)
    v, delta = R * 4.0, 0.3 * sign
    w = v * math.tan(delta) / L
    x0, t = R * 4.0 * 0.8, 1.6
    expected = (x0 + v / w * math.sin(w * t), v / w * (1.0 - math.cos(w * t)), w * t)
    assert pose2d(sim) == pytest.approx(expected, abs=1e-9)
    assert sim.robot("sw").drive.velocity()[5] == pytest.approx(w, abs=1e-12)


def test_a_steered_drive_without_a_driven_wheel_is_one_line() -> None:
    robot = tricycle()
    for wheel in robot["steered_drive"]["wheels"]:
        wheel.pop("motor", None)
    with pytest.raises(WorldError, match="no wheel has a motor: a steered drive needs one driven wheel"):
        sim_of(robot)


def test_a_tricycle_s_free_wheel_encoder_reads_what_it_rolled() -> None:
    """The free front wheel's PositionSensor (``free_wheel: 2``) reads its start position plus its
    ground point's travel along its heading over its radius: r·ω·t / 0.03 straight, then the bicycle's
    front wheel speed v / cos δ at δ = 0.3; back to its start on reset."""
    sim = sim_of(tricycle())
    enc = sim.robot("sw").devices["front encoder"]
    enc.enable(16)
    roll(sim, {"rl": 4.0, "rr": 4.0})
    sim.run(50)
    straight = R * 4.0 * 0.8 / 0.03
    assert enc.value == pytest.approx(0.5 + straight, abs=1e-12)
    roll(sim, {"rl": 0.0, "rr": 0.0})
    sim.robot("sw").motor("fr steer").set_position(0.3)
    sim.run(60)
    assert enc.value == pytest.approx(0.5 + straight, abs=1e-12)
    roll(sim, {"rl": 4.0, "rr": 4.0})
    sim.run(100)
    assert enc.value == pytest.approx(0.5 + straight + R * 4.0 / math.cos(0.3) * 1.6 / 0.03, abs=1e-9)
    sim.reset()
    sim.run(1)
    assert enc.value == 0.5


def test_a_free_wheel_encoder_on_a_driven_wheel_is_one_line() -> None:
    robot = tricycle()
    robot["devices"][1]["free_wheel"] = 0
    with pytest.raises(WorldError, match="PositionSensor 'front encoder': free_wheel 0 is no wheel without motor"):
        sim_of(robot)


def cart() -> dict:
    """Two driven rear wheels at (0, ±B) and two free front wheels at (L, ±B), each on its own steering
    hinge, with encoders on both free wheels; listed front left, rear left, front right, rear right (the
    motored wheels' speeds go to columns 1 and 3)."""
    fronts = {"fl": B, "fr": -B}
    return {"name": "cart", "pose": {"translation": [0.0, 0.0, 0.1]},
            "body": {"geometry": {"type": "box", "size": [0.6, 0.5, 0.1]}},
            "steered_drive": {"max_wheel_speed": 20.0, "wheels": [
                {"steer": "fl steer", "position": [L, B], "radius": 0.03},
                {"motor": "rl wheel", "position": [0.0, B], "radius": R},
                {"steer": "fr steer", "position": [L, -B], "radius": 0.03},
                {"motor": "rr wheel", "position": [0.0, -B], "radius": R}]},
            "devices": [{"device": "RotationalMotor", "name": f"{k} steer", "axis": [0.0, 0.0, 1.0],
                         "anchor": [L, y, 0.0], "max_velocity": 100.0} for k, y in fronts.items()]
            + [{"device": "PositionSensor", "name": f"{k} encoder", "free_wheel": i, "position": 0.25 + i}
               for i, k in ((0, "fl"), (2, "fr"))]}


@pytest.fixture(params=["helper", "math"])
def native(request, monkeypatch):
    """The batched simulation with the packets helper (libm's cos and sin in C) or without it
    (``SENSORIUM_PACKETS=0``)."""
    use_packets(request.param == "helper", monkeypatch)
    return request.param


def test_the_batched_simulation_drives_free_steered_wheels_as_the_single_one_bit_for_bit(native) -> None:
    """Three copies of a cart with two free steered front wheels (and a tricycle beside it) in a walled
    square, each against its own Simulation: every 40 steps per copy either both front wheels straight
    (its twist's one line, straight), at Ackermann angles (the bicycle's line), tangent to circles about
    the rear axle's centre with the rear wheels opposite (the driven wheels' a_i cancel) or at random
    angles apart (no one turn centre: the least-squares fallback), while the hinges move between them;
    random rear speeds per copy, 400 steps. Every step each robot's pose, each free wheel's encoder and
    rolled angle and each driven wheel's angle are the single simulation's bits."""
    import numpy as np

    walls = [{"name": n, "pose": {"translation": [x, y, 0.25]}, "geometry": {"type": "box", "size": [sx, sy, 0.5]}}
             for n, x, y, sx, sy in (("north", 0, 1.6, 3.6, 0.2), ("south", 0, -1.6, 3.6, 0.2),
                                     ("east", 1.7, 0, 0.2, 3.0), ("west", -1.7, 0, 0.2, 3.0))]
    trike = tricycle()
    trike["pose"]["translation"] = [-0.8, 0.8, 0.1]
    loaded = parse_world({"world_info": {"basic_time_step": 16, "contact": True}, "solids": walls,
                          "robots": [cart(), trike]})
    n = 3
    batched = BatchedSimulation(loaded, n)
    singles = [Simulation(loaded) for _ in range(n)]
    names = [("cart", "fl encoder"), ("cart", "fr encoder"), ("sw", "front encoder")]
    refs = [batched.device(robot, name) for robot, name in names]
    for ref in refs:
        batched.enable(ref, 16)
    for s in singles:
        for robot, name in names:
            s.device(f"{robot}/{name}").enable(16)
    rng = np.random.default_rng(11)
    tangent = (math.atan2(L, -B), math.atan2(L, B))
    pressed = 0
    for t in range(400):
        if t % 40 == 0:
            speeds = rng.uniform(-12.0, 12.0, size=(n, 2))
            for c, s in enumerate(singles):
                case = int(rng.integers(4))
                delta = float(rng.uniform(-0.6, 0.6))
                rear = speeds[c]
                if case == 0:
                    angles = (0.0, 0.0)
                elif case == 1:
                    cot = 1.0 / math.tan(delta)             # left-positive: the inner wheel steers more
                    angles = (math.atan(1.0 / (cot - B / L)), math.atan(1.0 / (cot + B / L)))
                elif case == 2:
                    angles, rear = tangent, np.array([-speeds[c, 0], speeds[c, 0]])
                else:
                    angles = tuple(float(a) for a in rng.uniform(-1.2, 1.2, size=2))
                batched.steered.command(0, rear[None, :], copies=[c])
                batched.steered.command(1, speeds[c][None, ::-1], copies=[c])
                for name, angle in zip(("fl", "fr"), angles):
                    s.robot("cart").motor(f"{name} steer").command(angle, 2.0, None, None)
                    batched.joints.command(0, f"{name} steer", position=angle, velocity=2.0, copies=[c])
                s.robot("sw").motor("fr steer").command(delta, 2.0, None, None)
                batched.joints.command(1, "fr steer", position=delta, velocity=2.0, copies=[c])
                for robot, wheels in (("cart", rear), ("sw", speeds[c][::-1])):
                    for name, omega in zip(("rl wheel", "rr wheel"), wheels):
                        m = s.robot(robot).motor(name)
                        m.set_position(math.inf)
                        m.set_velocity(float(omega))
        for s in singles:
            s.step()
        batched.step()
        for c, s in enumerate(singles):
            for slot, robot in enumerate(("cart", "sw")):
                pose, got = s.robot(robot).pose, batched.pose(c, slot)
                assert got.translation.tobytes() == pose.translation.tobytes(), (t, c, robot)
                assert got.rotation.tobytes() == pose.rotation.tobytes(), (t, c, robot)
                k = batched.steered.of[slot]
                drive = s.robot(robot).drive
                for i, turned in drive.free_turned.items():
                    assert batched.steered.free_turned[c, k, i] == turned, (t, c, robot, i)
                for name in ("rl wheel", "rr wheel"):
                    col = batched.steered.column(slot, name)
                    assert batched.steered.angle[c, col[0], col[1]] == s.robot(robot).motor(name).position
                pressed += bool(s.robot(robot).pressing)
            for ref, (robot, name) in zip(refs, names):
                assert np.float64(batched.value(ref)[c]).tobytes() == np.float64(
                    s.device(f"{robot}/{name}").value).tobytes(), (t, c, name)
    assert pressed > 10
    assert all(abs(float(batched.value(ref)[c])) > 1.0 for ref in refs for c in range(n))


@pytest.mark.parametrize("robot", ["cart", "tricycle"])
def test_the_copies_constrained_twists_are_the_single_drive_s_bits(robot: str, native) -> None:
    """batched_steered.constrained_twists (the C pass with the helper, numpy without) over 3000 copies of
    steering angles against SteeredDrive.constrained_twist copy by copy: random angles, the front wheels
    straight, at Ackermann angles, tangent about the rear axle's centre, across (π/2), with random and
    opposite rear speeds; every twist the same bits, every branch taken."""
    import numpy as np

    from sensorium.server.sim.batched_kinematic import libm_cos_sin
    from sensorium.server.sim.batched_steered import constrained_twists

    config = wm.SteeredDrive.model_validate((cart() if robot == "cart" else tricycle())["steered_drive"])
    drive = SteeredDrive(config, Pose.identity())

    class Hinge:
        position = 0.0

    hinges = [Hinge() for _ in drive.wheels]
    drive.steering = [h if steer is not None else None for h, (*_, steer) in zip(hinges, drive.wheels)]
    rng = np.random.default_rng(5)
    n, W = 3000, len(drive.wheels)
    steered = [i for i, (*_, steer) in enumerate(drive.wheels) if steer is not None]
    angles = np.zeros((n, W))
    case = rng.integers(5, size=n)
    for i in steered:
        angles[:, i] = np.select([case == 0, case == 1, case == 2, case == 3],
                                 [rng.uniform(-1.5, 1.5, n), 0.0, math.pi / 2,
                                  math.atan2(L, -drive.places[i][1])], rng.uniform(-0.6, 0.6, n))
    if robot == "cart":                   # case 4: Ackermann angles for one turn centre on the rear axle's line
        radius = L / np.tan(angles[case == 4, 0])
        angles[case == 4, 0] = np.arctan2(L, radius - B)
        angles[case == 4, 2] = np.arctan2(L, radius + B)
    rl, rr = [i for i, (m, *_) in enumerate(drive.wheels) if m is not None]     # the left and right rear wheels
    u = np.zeros((n, W))
    u[:, [rl, rr]] = rng.uniform(-10.0, 10.0, (n, 2))
    u[case == 3, rr] = -u[case == 3, rl]
    heading = np.array([h for _, _, h, _, _ in drive.wheels]) + angles
    cos, sin = libm_cos_sin(heading)
    places, driven = list(drive.places), [m is not None for m, *_ in drive.wheels]
    arrays = (np.array(places), np.array(driven, dtype=np.uint8))
    radius = np.array([r for _, r, *_ in drive.wheels])
    got = np.stack(constrained_twists(places, driven, radius, u, cos, sin, arrays), axis=1)
    lstsq = np.linalg.lstsq
    fits = []
    try:
        np.linalg.lstsq = lambda *a, **k: (fits.append(1), lstsq(*a, **k))[1]
        for c in range(n):
            for hinge, a in zip(hinges, angles[c]):
                hinge.position = float(a)
            fits.append(0)
            want = drive.constrained_twist(u[c].tolist())
            assert got[c].tobytes() == np.array(want).tobytes(), (c, case[c], got[c], want)
    finally:
        np.linalg.lstsq = lstsq
    assert sum(fits) > 50 if robot == "cart" else sum(fits) == 0      # (a tricycle's rows always meet in one line)
    turning = got[case == 3]                      # about the rear axle's centre at r·(ω_rr − ω_rl)/2B
    assert np.abs(turning[:, :2]).max() < 1e-12
    assert turning[:, 2] == pytest.approx(R * (u[case == 3, rr] - u[case == 3, rl]) / (2 * B), abs=1e-12)
