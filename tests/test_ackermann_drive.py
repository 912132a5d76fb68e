"""Car-like robots (kinematic Ackermann steering): the front wheels' angles for a steering angle, the
bicycle model's circle about the turn centre on the rear axle's line, straight driving, the motors'
limits, contact at a wall, the world file's checks and the batched simulation's copies.
Closed-form checks."""

from __future__ import annotations

import math

import pytest

from sensorium.client.webots.vehicle.driver import ackermann_angles
from sensorium.schemas import world as wm
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, parse_world

L, TF, TR, RF, RR = 2.0, 1.4, 1.5, 0.3, 0.35      # wheelbase, tracks, wheel radii (m)


def car(name: str = "car", x: float = 0.0, y: float = 0.0, yaw: float = 0.0, **drive) -> dict:
    return {"name": name, "pose": {"translation": [x, y, 0.3], "rotation": [0, 0, 1, yaw]},
            "body": {"geometry": {"type": "cylinder", "radius": 0.5, "height": 0.4}},
            "ackermann_drive": {"wheelbase": L, "track_front": TF, "track_rear": TR, "front_wheel_radius": RF,
                                "rear_wheel_radius": RR, "max_wheel_speed": 1000.0, **drive}}


def sim_of(*robots: dict, solids=(), step: int = 16, contact: bool = False) -> Simulation:
    return Simulation(parse_world({"world_info": {"basic_time_step": step, "contact": contact},
                                   "solids": list(solids), "robots": list(robots)}))


def steer(sim: Simulation, delta: float, name: str = "car", settle: int = 10) -> tuple[float, float]:
    """Turn the front wheels to Webots' Driver angles for ``delta`` with the car standing (wheels
    held by position control at 0), and check it stood."""
    r = sim.robot(name)
    right, left = ackermann_angles(delta, L, TF)
    r.motor("right_steer").set_position(right)
    r.motor("left_steer").set_position(left)
    before = r.pose.translation.copy()
    sim.run(settle)
    assert (r.pose.translation == before).all()
    assert r.motor("right_steer").position == right and r.motor("left_steer").position == left
    return right, left


def roll(sim: Simulation, speeds: dict[str, float], name: str = "car") -> None:
    for motor, omega in speeds.items():
        m = sim.robot(name).motor(motor)
        m.set_position(math.inf)
        m.set_velocity(omega)


def pose2d(sim: Simulation, name: str = "car") -> tuple[float, float, float]:
    p = sim.robot(name).pose
    return float(p.translation[0]), float(p.translation[1]), math.atan2(p.rotation[1, 0], p.rotation[0, 0])


@pytest.mark.parametrize("delta", [0.05, 0.3, -0.45])
def test_front_wheel_angles_meet_on_the_rear_axle_line(delta: float) -> None:
    right, left = ackermann_angles(delta, L, TF)
    radius = L / math.tan(delta)                 # the turn centre at (0, -radius), positive delta: to the right
    assert math.tan(right) == pytest.approx(L / (radius - TF / 2), rel=1e-12)    # right wheel at (L, -TF/2)
    assert math.tan(left) == pytest.approx(L / (radius + TF / 2), rel=1e-12)
    assert abs(right if delta > 0 else left) > abs(delta) > abs(left if delta > 0 else right)   # inner wheel steers more
    assert ackermann_angles(0.0, L, TF) == (0.0, 0.0)


@pytest.mark.parametrize("delta", [0.3, -0.2])
def test_constant_steering_and_speed_drive_the_closed_form_circle(delta: float) -> None:
    sim = sim_of(car(x=1.0, y=-2.0, yaw=0.4))
    steer(sim, delta)
    omega = 20.0                                    # rad/s on both rear wheels: the rear axle's centre at RR*omega
    roll(sim, {"right_rear_wheel": omega, "left_rear_wheel": omega})
    n = 1000
    sim.run(n)
    v, radius, t = RR * omega, L / math.tan(delta), n * 0.016
    phi = v * t / radius                            # turned clockwise for delta > 0
    cx, cy = 1.0 + radius * math.sin(0.4), -2.0 - radius * math.cos(0.4)      # the centre, right of the car
    x, y, yaw = pose2d(sim)
    ex, ey = cx - radius * math.sin(0.4 - phi), cy + radius * math.cos(0.4 - phi)
    assert (x, y) == pytest.approx((ex, ey), abs=1e-9)
    assert math.remainder(yaw - (0.4 - phi), 2 * math.pi) == pytest.approx(0.0, abs=1e-9)
    assert math.hypot(x - cx, y - cy) == pytest.approx(abs(radius), abs=1e-9)


def test_front_wheel_drive_at_the_drivers_differential_speeds() -> None:
    # traction: Webots' Driver gives each front wheel 2V times its share of the two turn radii L/sin(angle)
    sim = sim_of(car(type="traction"))
    delta = 0.25
    right, left = steer(sim, delta)
    rr_, rl_ = L / math.sin(right), L / math.sin(left)
    V = 5.0                                         # m/s, the front wheels' mean rolling speed
    roll(sim, {"right_front_wheel": 2 * V * rr_ / (rr_ + rl_) / RF, "left_front_wheel": 2 * V * rl_ / (rr_ + rl_) / RF})
    n = 400
    sim.run(n)
    radius = L / math.tan(delta)
    w = V / ((rr_ + rl_) / 2)                       # yaw rate: each front wheel rolls at w times its distance
    phi = w * n * 0.016
    x, y, yaw = pose2d(sim)
    assert (x, y) == pytest.approx((radius * math.sin(phi), -radius + radius * math.cos(phi)), abs=1e-9)
    assert math.remainder(yaw + phi, 2 * math.pi) == pytest.approx(0.0, abs=1e-9)


def test_straight_at_zero_steering_and_all_wheel_drive() -> None:
    sim = sim_of(car(type="4x4", yaw=math.pi / 3))
    roll(sim, {"right_front_wheel": 10.0, "left_front_wheel": 10.0, "right_rear_wheel": 10.0 * RF / RR,
               "left_rear_wheel": 10.0 * RF / RR})
    sim.run(250)
    x, y, yaw = pose2d(sim)
    d = RF * 10.0 * 4.0
    assert (x, y) == pytest.approx((d * math.cos(math.pi / 3), d * math.sin(math.pi / 3)), abs=1e-9)
    assert yaw == pytest.approx(math.pi / 3, abs=1e-12)


def test_steering_motor_limits_and_left_positive_steering() -> None:
    sim = sim_of(car(max_steering_angle=0.2, max_steering_speed=1.0, positive_steers="left"))
    r = sim.robot("car")
    r.motor("right_steer").set_position(0.5)        # clamped to maxPosition, as Webots
    r.motor("left_steer").set_position(0.5)
    sim.step()
    assert r.motor("right_steer").position == pytest.approx(0.016)     # at most max_steering_speed
    sim.run(20)
    assert r.motor("right_steer").position == 0.2
    roll(sim, {"right_rear_wheel": 10.0, "left_rear_wheel": 10.0})
    sim.run(50)
    x, y, yaw = pose2d(sim)
    assert y > 0 and yaw > 0                         # positive steers left here
    radius = L / math.tan(0.2)
    assert math.hypot(x, y - radius) == pytest.approx(radius, abs=1e-9)


def test_position_sensors_read_the_steering_and_wheels() -> None:
    c = car()
    c["devices"] = [{"device": "PositionSensor", "name": "right_steer_sensor", "motor": "right_steer"},
                    {"device": "PositionSensor", "name": "left_rear_sensor", "motor": "left_rear_wheel"}]
    sim = sim_of(c)
    for d in sim.robot("car").devices.values():
        d.enable(16)
    sim.robot("car").motor("right_steer").set_position(0.1)
    roll(sim, {"left_rear_wheel": 2.0})
    sim.run(10)
    dev = sim.robot("car").devices
    assert dev["right_steer_sensor"].value == pytest.approx(0.1)
    assert dev["left_rear_sensor"].value == pytest.approx(2.0 * 0.16)


def test_contact_stops_the_car_at_a_wall() -> None:
    wall = {"name": "wall", "pose": {"translation": [5.0, 0.0, 0.25]}, "geometry": {"type": "box", "size": [0.2, 8, 0.5]}}
    sim = sim_of(car(), solids=[wall], contact=True)
    roll(sim, {"right_rear_wheel": 20.0, "left_rear_wheel": 20.0})
    sim.run(200)
    x, y, _ = pose2d(sim)
    assert x == pytest.approx(4.9 - 0.5, abs=1e-9) and y == 0.0
    assert sim.counters["contacts"] > 0 and sim.robot("car").pressing


def test_world_file_checks_name_the_field() -> None:
    with pytest.raises(WorldError, match=r"robots\[0\].*one drive at most"):
        parse_world({"robots": [{**car(), "differential_drive": {}}]})
    with pytest.raises(WorldError, match=r"robots\[0\] \(car\)\.ackermann_drive\.wheelbase"):
        parse_world({"robots": [car(wheelbase=0)]})
    with pytest.raises(WorldError, match=r"robots\[0\] \(car\)\.ackermann_drive.*own name"):
        parse_world({"robots": [car(left_steer="right_steer")]})
    with pytest.raises(WorldError, match=r"robots\[0\] \(car\)\.ackermann_drive\.type"):
        parse_world({"robots": [car(type="6x6")]})
    bad = car()
    bad["devices"] = [{"device": "PositionSensor", "name": "s", "motor": "right_front_wheel"}]
    with pytest.raises(WorldError, match=r"devices\[0\] \(s\)\.motor: 'right_front_wheel' is not a motor of this "
                                         r"robot \(motors: 'right_steer', 'left_steer', 'right_rear_wheel', "
                                         r"'left_rear_wheel'\)"):
        parse_world({"robots": [bad]})     # propulsion: the front wheels have no motors
    clash = car()
    clash["devices"] = [{"device": "LED", "name": "left_steer"}]
    with pytest.raises(WorldError, match="left_steer"):
        parse_world({"robots": [clash]})


def test_batched_simulation_circles_a_car_as_the_simulation() -> None:
    """The batched simulation drives cars (sensorium/server/sim/batched_car.py; tests/test_car_agent.py
    compares whole RL episodes): the closed-form circle's poses, bit for bit, in every copy."""
    w = parse_world({"world_info": {"basic_time_step": 16}, "robots": [car(type="4x4")]})
    sim, batched = Simulation(w), BatchedSimulation(w, copies=3)
    assert batched.cars is not None
    right, left = ackermann_angles(-0.3, L, TF)
    batched.cars.command(0, right, left, 12.0)
    sim.robot("car").motor("right_steer").set_position(right)
    sim.robot("car").motor("left_steer").set_position(left)
    for name in ("right_front_wheel", "left_front_wheel", "right_rear_wheel", "left_rear_wheel"):
        sim.robot("car").motor(name).set_position(math.inf)
        sim.robot("car").motor(name).set_velocity(12.0)
    for _ in range(200):
        sim.step()
        batched.step()
        for c in range(3):
            assert batched.pose(c, 0).translation.tobytes() == sim.robot("car").pose.translation.tobytes()
            assert batched.pose(c, 0).rotation.tobytes() == sim.robot("car").pose.rotation.tobytes()


def test_the_readme_car_is_a_valid_world_that_circles() -> None:
    import re
    from pathlib import Path

    import yaml

    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    (block,) = [b for b in re.findall(r"```yaml\n(.*?)```", readme, re.S)
                if b.startswith("robots:\n  - name: car") and "ackermann_drive" in b]   # (the Radar's car has none)
    sim = Simulation(parse_world(yaml.safe_load(block), source="README"))
    r = sim.robot("car")
    right, left = ackermann_angles(0.3, 2.6, 1.5)
    r.motor("right_steer").set_position(right)
    r.motor("left_steer").set_position(left)
    sim.run(10)
    for name in ("right_rear_wheel", "left_rear_wheel"):
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(10.0)
    sim.run(300)
    radius = 2.6 / math.tan(0.3)
    x, y, _ = pose2d(sim)
    assert math.hypot(x, y + radius) == pytest.approx(radius, abs=1e-9)


def test_attach_gives_a_clients_vehicle_library_the_car() -> None:
    import msgpack

    from sensorium.schemas import services as S
    from sensorium.server.daemon.services import Core

    core = Core(sim_of(car(max_steering_angle=0.5)), new_token=lambda: "s0", log=lambda *_: None)
    (frames,) = core.handle([b"A", msgpack.packb({"id": 1, "service": "attach", "args": {"robot": "car"}})], 0.0)
    reply = msgpack.unpackb(frames[-1])
    res = S.AttachResult.model_validate(reply["result"])
    # (the world entry's placement fields wheel_bottom and axle_bottoms are not the vehicle library's: not on the wire; nor
    # is motor_max_speeds: each motor's own maximum reaches the client as that motor's maxVelocity)
    assert res.ackermann_drive is not None and res.ackermann_drive.model_dump() == wm.AckermannDrive(
        wheelbase=L, track_front=TF, track_rear=TR, front_wheel_radius=RF, rear_wheel_radius=RR, max_wheel_speed=1000.0,
        max_steering_angle=0.5).model_dump(exclude={"wheel_bottom", "axle_bottoms", "motor_max_speeds"})
    motors = {d.name: (d.minPosition, d.maxPosition) for d in res.devices if d.type == "RotationalMotor"}
    assert motors == {"right_steer": (-0.5, 0.5), "left_steer": (-0.5, 0.5), "right_rear_wheel": (0.0, 0.0),
                      "left_rear_wheel": (0.0, 0.0)}       # Webots: 0 and 0 is no limit (a wheel)
