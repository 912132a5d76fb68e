"""Random motor commands for the step-by-step comparisons of cars and two-wheel robots, and the
comparison of a robot's every reading (tests/test_car_agent.py, tests/test_batched_nue.py)."""

from __future__ import annotations

import math

import numpy as np


def random_motor_commands(rng, world) -> dict:
    """Per robot motor: (a steering or held position, a velocity, whether a wheel holds a position)."""
    return {(r.name, m): (rng.uniform(-0.7, 0.7), rng.uniform(-40, 40), rng.random() < 0.3)
            for r in world.robots for _, m in r.drive_motors}


def command_motors(sim, cmds: dict) -> None:
    """``random_motor_commands``' commands on a Simulation or a batched copy's view: steering motors
    (and a two-wheel robot's "rs"/"ls") to their positions; a wheel to a held position at |velocity|,
    or in velocity control."""
    for (name, m), (pos, vel, hold) in cmds.items():
        motor = sim.robot(name).motors[m]
        if "steer" in m or m in ("rs", "ls"):
            motor.set_position(pos)
        elif hold:
            motor.set_position(pos * 10)
            motor.set_velocity(abs(vel))
        else:
            motor.set_position(math.inf)
            motor.set_velocity(vel)


def assert_same_readings(sim, view, name: str, tag) -> None:
    """Every device of robot ``name`` reads the same bits in ``sim`` and ``view`` (vector readings
    as ``values``, an InertialUnit's as ``roll_pitch_yaw``, the rest as ``value``)."""
    for d in sim.robot(name).model.devices:
        a, b = sim.robot(name).device(d.name), view.robot(name).device(d.name)
        what = "values" if hasattr(a, "values") and d.device != "PositionSensor" else "value"
        if d.device == "InertialUnit":
            what = "roll_pitch_yaw"
        assert np.asarray(getattr(a, what)).tobytes() == np.asarray(getattr(b, what)).tobytes(), (tag, d.name)
