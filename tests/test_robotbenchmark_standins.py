"""The fourteenth sweep's stand-ins of Webots' robotbenchmark maze runner and wall following (our own
worlds and PROTOs under tests/worlds/robotbenchmark/, with Webots' poses, sizes and tables), driven in
process by the rules of Webots' sample controllers (`move_in_maze`, `wall_following`) written here: the
speeds, turns and slides are closed forms of the geometry (README, the fourteenth sweep)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.server.sim.simulation import Simulation

HERE = Path(__file__).parent / "worlds" / "robotbenchmark"
STEP = 0.016


def pose(sim, name):
    p = sim.robot(name).pose
    return p.translation, p.rotation


def test_the_naive_maze_runner_drives_turns_slides_and_catches_its_corner_in_a_joint():
    sim = Simulation.from_file(HERE / "maze_runner" / "worlds" / "maze_runner.wbt")
    bot = "Thymio II"
    motors = sim.robot(bot).motors
    prox = [sim.device(f"{bot}/prox.horizontal.{i}") for i in range(5)]
    for d in prox:
        d.enable(16)
    for m in motors.values():
        m.set_position(math.inf)
    v = 0.7 * 6                                          # move_in_maze: 70 % of 6 rad/s
    rotating = False
    log = []
    for _ in range(int(12.0 / STEP)):
        if not rotating and prox[2].value > 3500:
            rotating = True
        elif rotating and prox[0].value == 0:
            rotating = False
        motors["motor.left"].set_velocity(v)
        motors["motor.right"].set_velocity(-v if rotating else v)
        sim.step()
        t, r = pose(sim, bot)
        log.append((t[0], t[1], math.atan2(r[1, 0], r[0, 0]), rotating))
    x = np.array([e[0] for e in log])
    y = np.array([e[1] for e in log])
    yaw = np.array([e[2] for e in log])
    turning = np.array([e[3] for e in log])
    first = int(np.argmax(turning))
    # straight along +x at 4.2 x 0.021 m/s until the first wall, then in place at 2 x 0.0882 / 0.1 rad/s
    assert np.allclose(np.diff(x[:first]), 0.0882 * STEP, atol=1e-12) and np.ptp(y[:first]) < 1e-12
    last = first + int(np.argmin(turning[first:]))
    assert np.allclose(np.diff(yaw[first:last]), -2 * 0.0882 / 0.1 * STEP, atol=1e-12)
    assert np.ptp(x[first:last]) < 1e-12 and np.ptp(y[first:last]) < 1e-12
    heading = yaw[last]
    assert -math.pi / 2 < heading < -1.3                 # prox.horizontal.0 clears before a quarter turn
    # down the corridor 9 degrees into the right wall (block faces at x = 0.324 - 0.0075): it slides along
    # it, its front-left body corner (0.0555, 0.0575) on the face
    reach = 0.0555 * math.cos(heading) - 0.0575 * math.sin(heading)
    sliding = np.abs(x + reach - 0.3165) < 1e-9
    assert sliding.sum() > 100
    # the corner dips into the 5.6 mm joint between blocks (21) and (20) and meets block (20)'s end face
    # (y = -0.508605 + 0.1): no torque turns the robot off it here, where Webots' physics would
    # (its corner 0.0555 m ahead: the block's corner on the robot's front face)
    ahead = (0.3165 - x[-1]) * math.cos(heading) + (-0.508605 + 0.1 - y[-1]) * math.sin(heading)
    assert ahead == pytest.approx(0.0555, abs=1e-9)
    # ... its corner into the joint past the face by at most the gap times the tangent of its angle to it
    assert 0 < x[-1] + reach - 0.3165 < 0.0056 * math.tan(heading + math.pi / 2)
    assert (x[-1], y[-1]) == (x[-2], y[-2])


def test_linked_walls_stand_in_chains_its_walls_and_writes_the_referees_custom_data():
    sim = Simulation.from_file(HERE / "wall_following" / "worlds" / "wall_following.wbt")
    angles = [0, 0, -2, 0, 2, 0, -6, -2, -12, 12, 8, -6, 18, -6, -6, -6, -6, 12, 6, 2, -2, -2, -4,
              -4, 4, -4, 10, -6, 6, 14, -14, -2, -2, -2, -2, 2, -6, 2, 4, -8, 16, -8, -6, 2, 4]
    walls = sim.robot("linked walls")
    assert walls.model.custom_data == f"{len(angles)}," + "".join(f"{a}," for a in angles)
    # each wall's centre: the last one's plus half a length along each one's heading (turn x pi/24 about +y)
    x = z = o = 0.0
    turn = 0
    expected = []
    for a in angles:
        turn += a
        o1 = turn * math.pi / 24
        x += 0.5 * (math.sin(o) + math.sin(o1))
        z += 0.5 * (math.cos(o) + math.cos(o1))
        o = o1
        expected.append((x, z, o))
    parts = walls.bounding_parts()                      # in the robot's frame: the first wall, then the chain
    assert len(parts) == 1 + len(angles)
    for (_, p), (ex, ez, eo) in zip(parts[1:], expected):
        assert (p.translation[0], p.translation[2]) == pytest.approx((ex, ez), abs=1e-9)
        assert (p.rotation[0, 2], p.rotation[0, 0]) == pytest.approx((math.sin(eo), math.cos(eo)), abs=1e-9)
    # the Pioneer 3-DX stand-in (y-up in the NUE world) drives north at 5.24 x 0.0975 m/s
    bot = "Pioneer 3-DX"
    for m in sim.robot(bot).motors.values():
        m.set_position(math.inf)
        m.set_velocity(5.24)
    x0 = pose(sim, bot)[0].copy()
    for _ in range(64):
        sim.step()
    # (its forward -z turned by the world's 4.7123889 about +y: north, 8e-8 rad short of 3 pi / 2)
    run, turn = 64 * STEP * 5.24 * 0.0975, 4.7123889
    assert pose(sim, bot)[0] - x0 == pytest.approx([-run * math.sin(turn), 0, -run * math.cos(turn)], abs=1e-12)
