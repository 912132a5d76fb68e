"""Webots' vehicle library (``from vehicle import Driver, Car``) on a car-like robot: a controller
written in Webots' style runs unchanged against ``sensorium serve`` and the car follows the
closed-form circle of its steering angle and cruising speed; the Car read-outs; the engine-model
functions say once that they are not simulated; a robot that is not a car ends the controller with
one line. Slow: a server and controllers as processes."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from tests._serve import Proc, sensorium, serve

L, T, R = 2.6, 1.5, 0.35
WORLD = f"""
world_info: {{basic_time_step: 16}}
robots:
  - name: car
    body: {{geometry: {{type: box, size: [4.2, 1.8, 1.2]}}}}
    ackermann_drive: {{wheelbase: {L}, track_front: {T}, track_rear: {T}, front_wheel_radius: 0.3,
                      rear_wheel_radius: {R}, type: propulsion, max_steering_angle: 0.6, max_steering_speed: 100}}
    devices:
      - {{device: PositionSensor, name: right_steer_sensor, motor: right_steer}}
      - {{device: PositionSensor, name: left_steer_sensor, motor: left_steer}}
      - {{device: PositionSensor, name: right_rear_sensor, motor: right_rear_wheel}}
      - {{device: PositionSensor, name: left_rear_sensor, motor: left_rear_wheel}}
  - name: bot
    synchronization: false
    pose: {{translation: [0, 30, 0]}}
    differential_drive: {{}}
"""

# a controller as a Webots user writes one (only the stop after 400 steps and the prints are the test's)
DRIVER = """\
from vehicle import Driver

driver = Driver()
driver.setSteeringAngle(0.2)
driver.setCruisingSpeed(20)
driver.setThrottle(0.5)
driver.setThrottle(0.7)
steps = 0
while driver.step() != -1:
    steps += 1
    if steps == 400:
        break
print(driver.getCurrentSpeed(), driver.getTargetCruisingSpeed(), driver.getSteeringAngle(), driver.getTime(),
      driver.getControlMode() == Driver.SPEED, driver.getGear(), flush=True)
"""

CAR = """\
from vehicle import Car

car = Car()
car.step()
print(car.getType() == Car.PROPULSION, car.getWheelbase(), car.getTrackFront(), car.getFrontWheelRadius(),
      car.getRearWheelRadius(), flush=True)
car.setCruisingSpeed(-9)
car.setSteeringAngle(-0.3)
for _ in range(3):
    car.step()
print(car.getRightSteeringAngle(), car.getLeftSteeringAngle(), car.getWheelSpeed(Car.WHEEL_REAR_LEFT),
      car.getWheelSpeed(Car.WHEEL_FRONT_LEFT), car.getWheelEncoder(Car.WHEEL_REAR_RIGHT), flush=True)
"""


def _run(server, tmp_path: Path, name: str, source: str, robot: str = "car") -> Proc:
    script = tmp_path / f"{name}.py"
    script.write_text(source)
    proc = Proc(sensorium("controller", str(script), "--url", server.url(robot)))
    assert proc.wait(120) is not None
    return proc


def _ackermann(delta: float) -> tuple[float, float]:
    cot, half = 1 / math.tan(delta), T / (2 * L)
    return math.atan(1 / (cot - half)), math.atan(1 / (cot + half))


def test_a_webots_driver_controller_drives_the_closed_form_circle(tmp_path: Path) -> None:
    world = tmp_path / "car.yaml"
    world.write_text(WORLD)
    with serve(world, "--mode", "fast", "--heartbeat-ms", "500") as server:
        proc = _run(server, tmp_path, "driver", DRIVER)
        assert proc.returncode == 0, proc.stderr()
        speed, target, angle, t, mode, gear = proc.stdout().split()
        assert float(speed) == pytest.approx(20.0, abs=1e-9) and float(target) == 20.0
        right, left = _ackermann(0.2)
        assert float(angle) == pytest.approx((right + left) / 2, abs=1e-12)   # Webots: the encoders' mean
        assert mode == "True" and gear == "0"
        assert proc.stderr().count("wbu_driver_set_throttle(): not simulated") == 1
        pose = server.conn.call("/car/robot/get_pose")
        time_ms = server.conn.call("get_info")["time_ms"]
    assert float(t) * 1000 == pytest.approx(time_ms)
    # from its first step the car steers at Webots' angles (steering fast enough to settle in it) and its
    # rear axle's centre rolls at 20 km/h: a circle of radius L/tan(0.2) about (0, -radius), clockwise
    radius = L / math.tan(0.2)
    phi = 20 / 3.6 * time_ms / 1000 / radius
    x, y, _ = pose["translation"]
    assert (x, y) == pytest.approx((radius * math.sin(phi), -radius + radius * math.cos(phi)), abs=1e-9)
    qx, qy, qz, qw = pose["quaternion"]
    assert math.remainder(2 * math.atan2(qz, qw) + phi, 2 * math.pi) == pytest.approx(0.0, abs=1e-9)


def test_car_read_outs_and_a_robot_that_is_not_a_car(tmp_path: Path) -> None:
    world = tmp_path / "car.yaml"
    world.write_text(WORLD)
    with serve(world, "--mode", "fast", "--heartbeat-ms", "500") as server:
        proc = _run(server, tmp_path, "car", CAR)
        assert proc.returncode == 0, proc.stderr()
        first, second = proc.stdout().splitlines()
        assert first.split() == ["True", str(L), str(T), "0.3", str(R)]
        right, left = (float(v) for v in second.split()[:2])
        assert (right, left) == pytest.approx(_ackermann(-0.3), abs=1e-12)
        # reversing at 9 km/h while turning left: the rear left wheel is the inner one (Webots' rear differential)
        r = L / math.tan(-0.3)
        inner = 2 * -9 * (r + T / 2) / (2 * r) / 3.6 / R
        assert float(second.split()[2]) == pytest.approx(inner, rel=1e-12)
        assert second.split()[3] == "nan" and float(second.split()[4]) < 0      # no front motor; rolled backwards
        refused = _run(server, tmp_path, "bot", "from vehicle import Driver\nDriver()\nprint('constructed')\n",
                       robot="bot")
    assert refused.returncode == 1 and refused.stdout() == ""
    assert refused.stderr().strip().splitlines()[-1] == (
        "Error: Driver(): robot 'bot' has no ackermann_drive: Sensorium's vehicle library drives a car-like robot "
        "whose world entry has one (README \"World files\"; a .wbt car is mapped when its steering and wheel joints "
        "are a car's).")


LIGHTS_WORLD = Path(__file__).resolve().parent / "worlds" / "car_lights.yaml"
LIGHTS_PY = Path(__file__).resolve().parent / "controllers" / "car_lights.py"
BRAKE_LINE = "Warning: 'intensity' should be smaller or equal to 1, used 1 instead."   # Webots' line


def check_car_lights(lines: list[str]) -> None:
    """What tests/controllers/car_lights.py and tests/c/car_lights.c print on a fresh
    tests/worlds/car_lights.yaml: the world's engine type, the controller's commands kept and
    answered as Webots' library keeps them, the car's LEDs of Webots' names switched for them."""
    by = {line.split()[0]: line.split()[1:] for line in lines}
    assert by["start"] == ["1", "0.34000000000000002", "0", "0", "0", "0"]    # electric; Webots' default period
    # 50 steps straight at 36 km/h: the free front wheels (radius 0.3) roll 8 m; the left's axis is the car's right
    right, left, right_speed, left_speed = (float(v) for v in by["rolled"])
    assert right == pytest.approx(8 / 0.3, rel=1e-12) and left == pytest.approx(-8 / 0.3, rel=1e-12)
    # their speeds as Webots' driver works every wheel's out: the encoder's change over the last step, v / r
    assert right_speed == pytest.approx(10 / 0.3, rel=1e-9) and left_speed == pytest.approx(-10 / 0.3, rel=1e-9)
    assert by["brake"] == ["1", "1", "1"] and by["released"] == ["0", "0", "0"]       # intensity, lights, LED
    assert by["reverse"] == ["0"] and by["reversing"] == ["1", "1"] and by["stopped"] == ["0", "0"]
    assert by["blink"][0] == "0.064000000000000001"

    def lit(tokens: list[str], on_pattern: str) -> list[bool]:
        # Webots' driver: on while int(t / period) is even, t the time before the step
        ons = []
        for token in tokens:
            t, leds = token.split(":")
            on = int(round(float(t) * 1000) / 1000.0 / 0.064) % 2 == 0
            assert leds == (on_pattern if on else "00"), tokens
            ons.append(on)
        return ons
    blinks = lit(by["blink"][1:], "10")
    assert len(blinks) == 8 and any(blinks) and not all(blinks)
    assert by["auto"] == ["1", "0", "2"]      # right kept at 0.25, off at 0.19 (0.3 - 0.1); left kept without auto-off
    assert by["hazard"][0] == "1" and len(lit(by["hazard"][1:], "11")) == 4
    assert by["lights"] == ["1", "1", "1", "1", "1"]


def test_the_lights_indicators_brake_and_engine_as_webots_library_keeps_them(tmp_path: Path) -> None:
    with serve(LIGHTS_WORLD, "--mode", "fast", "--heartbeat-ms", "500") as server:
        proc = Proc(sensorium("controller", str(LIGHTS_PY), "--url", server.url("car")))
        assert proc.wait(120) is not None
    assert proc.returncode == 0, proc.stderr()
    check_car_lights(proc.stdout().splitlines())
    assert proc.stderr().strip().splitlines() == [BRAKE_LINE]     # nothing said to be unsimulated


HOSTILE_PY = Path(__file__).resolve().parent / "controllers" / "car_hostile.py"
HOSTILE_LINES = [                      # what a careless controller is told, in order (C prints the same)
    "Warning: wbu_driver_set_brake_intensity() called with an invalid 'intensity' argument (NaN): ignored.",
    "Warning: 'intensity' should be bigger or equal to 0, used 0 instead.",
    "Warning: 'intensity' should be smaller or equal to 1, used 1 instead.",
    *(f"Warning: wbu_car_set_indicator_period() called with an invalid 'period' argument ({p}): it must be a "
      "positive number of seconds; ignored." for p in ("0", "-1", "NaN", "inf", "-inf")),
    *(f"Warning: wbu_driver_set_steering_angle() called with an invalid 'steering_angle' argument ({a})"
      for a in ("NaN", "inf", "-inf")),
    *(f"Warning: wbu_driver_set_cruising_speed() called with an invalid 'speed' argument ({s}): ignored."
      for s in ("NaN", "-inf")),
    # a right angle's differential asks the rear wheels for more than their motors give: Webots' motor lines
    "WARNING: RotationalMotor \"right_rear_wheel\": The requested velocity -1.93011e+17 exceeds 'maxVelocity' = 100.",
    "WARNING: RotationalMotor \"left_rear_wheel\": The requested velocity 1.93011e+17 exceeds 'maxVelocity' = 100."]


def check_car_hostile(lines: list[str]) -> None:
    """What tests/controllers/car_hostile.py and tests/c/car_hostile.c print: a bad value changes nothing,
    an out-of-range brake is clamped as Webots clamps it, and the car keeps rolling straight and finite."""
    by = {line.split()[0]: line.split()[1:] for line in lines}
    assert by["brake_nan"] == ["0.25", "1"]
    assert by["brake_negative"] == ["0", "0", "0"] and by["brake_inf"] == ["1", "1", "1"]
    assert by["period"] == ["0.34000000000000002"]
    assert by["tiny"] == ["1e-300", "1", "0"]        # on: the quotient is past a double's integers
    # the bad commands changed nothing: 36 km/h at 0.2 rad, the rear wheels' differential speeds
    speed, steer, right, left = (float(v) for v in by["kept"])
    assert speed == 36.0 and steer != 0.0
    assert right < left and (right + left) / 2 * 0.35 == pytest.approx(10.0, rel=1e-12)
    # 5e-324 rad: front angles 0, the rear wheels both at 10 m/s / 0.35 m
    assert by["denormal"] == ["0", "0", format(10 / 0.35, ".17g"), format(10 / 0.35, ".17g")]
    # π/2: the front wheels at ±1.29 rad, their turn radii cancel; the rear shares stay finite, clamped by the motors
    assert by["right_angle"] == ["-1.2899586021736937", "1.2899586021736937", "-100", "100"]
    right_enc, left_enc, finite = by["rolled"]
    assert math.isfinite(float(right_enc)) and math.isfinite(float(left_enc)) and finite == "1"


def test_a_careless_driver_gets_one_line_per_bad_value_and_nothing_changes(tmp_path: Path) -> None:
    with serve(LIGHTS_WORLD, "--mode", "fast", "--heartbeat-ms", "500") as server:
        proc = Proc(sensorium("controller", str(HOSTILE_PY), "--url", server.url("car")))
        assert proc.wait(120) is not None
    assert proc.returncode == 0, proc.stderr()
    check_car_hostile(proc.stdout().splitlines())
    assert proc.stderr().strip().splitlines() == HOSTILE_LINES


def test_the_differentials_and_blinking_stay_finite_for_any_finite_command() -> None:
    """Hypothesis: for any finite steering angle (denormals, ±π/2, huge) the Ackermann angles and the
    three differentials' shares are finite numbers and the indicators' blinking is decided, for any
    positive period and any time of the simulation, without an exception."""
    from hypothesis import given, settings
    from hypothesis import strategies as st

    from sensorium.client.webots.vehicle.driver import Driver, ackermann_angles, blink_on

    geo = {"wheelbase": 2.6, "track_front": 1.5, "track_rear": 1.5, "front_wheel_radius": 0.3,
           "rear_wheel_radius": 0.35}
    angles = st.floats(allow_nan=False, allow_infinity=False) | st.sampled_from(
        [5e-324, -5e-324, 2.2250738585072014e-308, math.pi / 2, -math.pi / 2, math.pi, 1e300, 1e-160])

    @settings(max_examples=400, deadline=None, derandomize=True)
    @given(angles, st.floats(0.0, 1e12) | st.sampled_from([0.0, 0.016, 1e308]),
           st.floats(5e-324, 1e308) | st.sampled_from([5e-324, 1e-300, 0.34, 1e308]))
    def run(angle: float, t: float, period: float) -> None:
        car = object.__new__(Driver)              # its geometry and commands only, no server
        car._geo, car._angle = geo, angle
        car._angles = ackermann_angles(angle, geo["wheelbase"], geo["track_front"])
        assert all(math.isfinite(a) and abs(a) <= math.pi / 2 for a in car._angles), car._angles
        for share in (car._ratio_front(), car._ratio_rear(), car._ratio_central()):
            assert math.isfinite(share), (angle, share)
        assert blink_on(t, period) in (True, False)

    run()
