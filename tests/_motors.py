"""Random motor commands for the step-by-step comparisons of cars and two-wheel robots
(tests/test_car_agent.py, tests/test_batched_nue.py)."""

from __future__ import annotations

import math


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
