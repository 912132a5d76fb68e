"""A car's free wheels (no motor: the front ones of a propulsion car, the rear ones of a traction
car) roll with the car: each one's encoder reads its world-file angle plus its contact point's
travel along its rolling direction over its radius (the front wheels along their own steering), in
the single simulation and the batched one alike. Closed-form checks: straight at v for t turns a
wheel by v t / r, a steady turn each wheel by its own arc over its radius."""

from __future__ import annotations

import math

import pytest

from sensorium.client.webots.vehicle.driver import ackermann_angles
from sensorium.server.sim import states
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, parse_world

L, TF, TR, RF, RR = 2.0, 1.4, 1.5, 0.3, 0.35      # wheelbase, tracks, wheel radii (m)
STEP = 16


def world(kind: str = "propulsion", start: float = 0.7, **extra) -> dict:
    free = ("front", RF) if kind == "propulsion" else ("rear", RR)
    sensors = [{"device": "PositionSensor", "name": f"right_{free[0]}_sensor", "free_wheel": f"right_{free[0]}",
                "position": start},
               {"device": "PositionSensor", "name": f"left_{free[0]}_sensor", "free_wheel": f"left_{free[0]}",
                "free_wheel_sign": -1}]
    return {"world_info": {"basic_time_step": STEP, "contact": False},
            "robots": [{"name": "car", "pose": {"translation": [0, 0, 0.3]},
                        "body": {"geometry": {"type": "cylinder", "radius": 0.5, "height": 0.4}},
                        "ackermann_drive": {"wheelbase": L, "track_front": TF, "track_rear": TR,
                                            "front_wheel_radius": RF, "rear_wheel_radius": RR, "type": kind,
                                            "max_wheel_speed": 1000.0},
                        "devices": sensors, **extra}]}


def drive(sim: Simulation, kind: str, delta: float, omega: float) -> None:
    r = sim.robot("car")
    right, left = ackermann_angles(delta, L, TF)
    r.motor("right_steer").set_position(right)
    r.motor("left_steer").set_position(left)
    sim.run(10)                                   # the wheels held at 0: the car stands while it steers
    axle = "rear" if kind == "propulsion" else "front"
    for side in ("right", "left"):
        m = r.motor(f"{side}_{axle}_wheel")
        m.set_position(math.inf)
        m.set_velocity(omega)


def encoders(sim: Simulation, axle: str) -> tuple[float, float]:
    r = sim.robot("car")
    return r.device(f"right_{axle}_sensor").value, r.device(f"left_{axle}_sensor").value


@pytest.mark.parametrize("kind, axle, radius", [("propulsion", "front", RF), ("traction", "rear", RR)])
def test_straight_at_v_for_t_turns_a_free_wheel_by_v_t_over_r(kind: str, axle: str, radius: float) -> None:
    sim = Simulation(parse_world(world(kind)))
    for side in ("right", "left"):
        sim.robot("car").device(f"{side}_{axle}_sensor").enable(STEP)
    sim.run(1)
    assert encoders(sim, axle) == (0.7, 0.0)       # the world file's angles before the car moves
    drive(sim, kind, 0.0, 10.0)
    n = 250
    sim.run(n)
    driven_radius = RR if kind == "propulsion" else RF
    v, t = driven_radius * 10.0, n * STEP / 1000.0
    assert sim.robot("car").pose.translation[0] == pytest.approx(v * t, rel=1e-12)
    right, left = encoders(sim, axle)
    assert right == pytest.approx(0.7 + v * t / radius, rel=1e-12)
    assert left == pytest.approx(-v * t / radius, rel=1e-12)   # its axis is the car's right (free_wheel_sign -1)


@pytest.mark.parametrize("kind", ["propulsion", "traction"])
@pytest.mark.parametrize("delta", [0.3, -0.2])
def test_a_steady_turn_turns_each_free_wheel_by_its_own_arc(kind: str, delta: float) -> None:
    sim = Simulation(parse_world(world(kind, start=0.0)))
    axle = "front" if kind == "propulsion" else "rear"
    for side in ("right", "left"):
        sim.robot("car").device(f"{side}_{axle}_sensor").enable(STEP)
    drive(sim, kind, delta, 8.0)
    sim.run(1)
    start = sim.robot("car").pose.translation.copy()
    before = encoders(sim, axle)
    n = 300
    sim.run(n)
    # the rear axle's centre on its circle of radius R = L / tan δ about the centre (0, -R) of the
    # car's frame when it started; its turn φ from the chord it moved
    R = L / math.tan(delta)
    chord = math.hypot(*(sim.robot("car").pose.translation[:2] - start[:2]))
    phi = 2.0 * math.asin(chord / (2.0 * abs(R)))
    # each wheel's distance from the turn centre (right is -y, the centre at -R on the y axis)
    if kind == "propulsion":
        arms = (math.hypot(L, R - TF / 2), math.hypot(L, R + TF / 2))
        radius = RF
    else:
        arms = (abs(R - TR / 2), abs(R + TR / 2))
        radius = RR
    right, left = encoders(sim, axle)
    assert right - before[0] == pytest.approx(arms[0] * phi / radius, rel=1e-9)
    assert -(left - before[1]) == pytest.approx(arms[1] * phi / radius, rel=1e-9)
    # a turn to the right: the left (outer) wheel rolls further
    assert (abs(left - before[1]) > right - before[0]) == (delta > 0)


def test_the_batched_simulation_rolls_the_free_wheels_as_the_simulation() -> None:
    w = parse_world(world("propulsion"))
    sim, batched = Simulation(w), BatchedSimulation(w, copies=2)
    assert batched.cars is not None
    right, left = ackermann_angles(0.25, L, TF)
    batched.cars.command(0, right, left, 9.0)
    r = sim.robot("car")
    r.motor("right_steer").set_position(right)
    r.motor("left_steer").set_position(left)
    for name in ("right_rear_wheel", "left_rear_wheel"):
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(9.0)
    refs = [batched.device("car", f"{side}_front_sensor") for side in ("right", "left")]
    for ref in refs:
        batched.enable(ref, STEP)
    for side in ("right", "left"):
        r.device(f"{side}_front_sensor").enable(STEP)
    for _ in range(150):
        sim.step()
        batched.step()
        single = encoders(sim, "front")
        for ref, value in zip(refs, single):
            assert batched.value(ref).tolist() == [value, value]
    assert single[0] > 3.0          # they did roll


def test_a_reset_puts_the_free_wheels_back_at_their_world_file_angles() -> None:
    sim = Simulation(parse_world(world("propulsion")))
    for side in ("right", "left"):
        sim.robot("car").device(f"{side}_front_sensor").enable(STEP)
    drive(sim, "propulsion", 0.0, 10.0)
    sim.run(50)
    assert encoders(sim, "front")[0] > 1.0
    sim.reset()
    sim.run(1)
    assert encoders(sim, "front") == (0.7, 0.0)


@pytest.mark.parametrize("change, says", [
    ({"free_wheel": "right_rear"}, "PositionSensor 'right_front_sensor': free_wheel 'right_rear' has a motor in this "
                                   "propulsion car (name its motor instead)"),
    ({"motor": "right_steer"}, "PositionSensor 'right_front_sensor': give motor or free_wheel, not both"),
])
def test_a_free_wheel_that_is_none_is_said_in_one_line(change: dict, says: str) -> None:
    w = world("propulsion")
    w["robots"][0]["devices"][0].update(change)
    with pytest.raises(WorldError) as e:
        parse_world(w)
    assert says in str(e.value) and "\n" not in str(e.value).strip()


def test_a_free_wheel_needs_a_car() -> None:
    w = world("propulsion")
    del w["robots"][0]["ackermann_drive"]
    with pytest.raises(WorldError) as e:
        parse_world(w)
    assert "free_wheel 'right_front' needs the robot's ackermann_drive" in str(e.value)


def test_a_saved_state_keeps_the_free_wheels_angles_and_init_puts_them_back() -> None:
    sim = Simulation(parse_world(world("propulsion")))
    for side in ("right", "left"):
        sim.robot("car").device(f"{side}_front_sensor").enable(STEP)
    robot = sim.robot("car")
    scope = states.Scope("robot 'car'", robot="car", own_pose=True, motors=tuple(robot.motors))
    saved = states.States()
    drive(sim, "propulsion", 0.2, 10.0)
    sim.run(40)
    mid = encoders(sim, "front")
    saved.save(sim, 1, scope, "mid")
    sim.run(40)
    assert encoders(sim, "front") != mid
    saved.load(sim, 1, scope, "mid")
    sim.run(1)
    assert encoders(sim, "front") == mid             # the wheels hold: the car stands where it was saved
    saved.load(sim, 1, scope, states.INIT)
    sim.run(1)
    assert encoders(sim, "front") == (0.7, 0.0)


def test_a_long_drive_accumulates_no_drift_beyond_float64_summation() -> None:
    """250 000 steps (an hour at 16 ms) of a free wheel's roll at 100 km/h, straight and turning: each
    step adds one rounded increment, so the angle stays finite and within the naive summation's bound of
    the closed form n·(its increment) — half an ulp of the total per step, no drift beyond it; the batched
    engine's first 20 000 steps are the same sums, bit for bit."""
    import numpy as np

    sim = Simulation(parse_world(world("propulsion", start=0.0)))
    car = sim.robot("car").drive
    v, dt = 100 / 3.6, STEP / 1000.0
    n = 250_000
    for kl, delta in ((0.0, 0.0), (math.tan(0.2) / L, 0.2)):
        right, left = ackermann_angles(delta, L, TF)
        car.right_steer.position, car.left_steer.position = car.sign * right, car.sign * left
        car.free_turned = dict.fromkeys(car.free, 0.0)
        incs = {}
        for key, (x, y, r, steer) in car.free.items():     # one step's increment, as roll_free computes it
            d = car.steering()[steer] if steer >= 0 else 0.0
            incs[key] = v * dt * ((1.0 - kl * y) * math.cos(d) - kl * x * math.sin(d)) / r
        for _ in range(20_000):
            car.roll_free(v, kl, dt)
        early = dict(car.free_turned)
        for _ in range(n - 20_000):
            car.roll_free(v, kl, dt)
        for key, inc in incs.items():
            got, exact = car.free_turned[key], n * inc
            assert math.isfinite(got) and abs(got - exact) <= n * math.ulp(exact) / 2, (key, got, exact)
            assert abs(got - exact) / exact < 1e-10      # (about 0.6 µrad in 6e4 rad)

        batched = BatchedSimulation(parse_world(world("propulsion", start=0.0)), copies=3)
        cars = batched.cars
        assert cars is not None
        copies = np.arange(3)
        cars.angle[:, 0, 0], cars.angle[:, 0, 1] = car.sign * right, car.sign * left    # its steering motors
        for _ in range(20_000):
            cars._roll_free(copies, 0, np.full(3, v), np.full(3, kl), dt)
        for key, j in cars.free[0].items():
            assert cars.free_turned[:, 0, j].tolist() == [early[key]] * 3, key
