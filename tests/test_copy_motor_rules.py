"""A task callable commands a batched copy's motors (gym/views.py) with the rules of a Simulation's
(sim/motion.py WheelMotor.set_velocity): a negative velocity in position control is ignored with
Webots' error line, a speed above maxVelocity (inf too) is clamped, NaN and bools are refused; the
same commands give the same poses, bit for bit."""

from __future__ import annotations

import math

import pytest

from sensorium.gym.views import CopySim
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import default_world_path, load_world


def test_a_copys_motors_follow_the_simulations_velocity_rules(capsys):
    world = load_world(default_world_path())
    sims = [Simulation(world), CopySim(BatchedSimulation(world, 2), 1)]
    for s in sims:
        left, right = s.robot("scout").motor("left wheel motor"), s.robot("scout").motor("right wheel motor")
        left.set_position(3.0)
        right.set_position(3.0)
        left.set_velocity(4.0)
        right.set_velocity(math.inf)                          # clamped to maxVelocity
        assert right.velocity == right.max_velocity
        capsys.readouterr()
        left.set_velocity(-2.0)                               # in position control: ignored, with Webots' line
        assert left.velocity == 4.0
        err = capsys.readouterr().err
        assert err == ("Error: setVelocity() called with negative 'velocity' argument in position control mode "
                       "(3): motor 'left wheel motor' keeps 4.\n")
        for bad in (math.nan, True):
            with pytest.raises(ValueError, match=r"^motor 'left wheel motor': velocity must be a number"):
                left.set_velocity(bad)
        s.run(20)
    single, copy = (s.robot("scout").pose for s in sims)
    assert single.translation.tobytes() == copy.translation.tobytes()
    assert single.rotation.tobytes() == copy.rotation.tobytes()
