"""On a slope the wheels' speed is along the ground (motion.PlanarState.over_ground, ground.slope_scales):
the horizontal displacement per step is the wheels' distance times the cosine of the slope along the
heading, and the heading (about the world's up) turns at the turn rate about the ground's normal times
(1 + k²)/√(1 + gx² + gy²). The ramp of tests/test_ground_ramp.py (angle A, low edge flush with the floor
at x = 1); wheels of radius 0.05 m at 4 rad/s: 0.2 m/s along the ground."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.server.raycast import packets
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.motion import arc_step
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world
from tests._slopes import STEP, copies_at_headings, ramp_world, step_copies_as_singles
from tests.test_ground_ramp import HALF, A, _drive, _ramp_z, _robot

N = 100                                  # 1.6 s at 0.2 m/s: 0.32 m along the ramp


def _single(robots: list[dict], ramp: bool = True) -> Simulation:
    return Simulation(parse_world(ramp_world(robots, ramp)), precision="exact")


def test_driving_straight_up_a_ramp_covers_r_w_t_along_it_and_its_cosine_across() -> None:
    sim = _single([_robot("r", (1.2, 0.0, _ramp_z(1.2) + HALF))])
    start = sim.robot("r").pose.translation.copy()
    _drive(sim, "r", 4.0)
    for _ in range(N):
        sim.step()
    end = sim.robot("r").pose.translation
    along = 0.05 * 4.0 * N * STEP / 1000.0                                     # r·ω·t = 0.32 m
    dx, dz = end[0] - start[0], end[2] - start[2]
    assert dx == pytest.approx(along * math.cos(A), abs=1e-9)
    assert math.hypot(dx, dz) == pytest.approx(along, abs=1e-9)
    assert dz == pytest.approx(along * math.sin(A), abs=1e-9) and end[1] == 0.0
    # the Supervisor's getVelocity: 0.2 m/s along the ramp
    assert np.array(sim.robot("r").drive.velocity()[:3]) == pytest.approx([0.2 * math.cos(A), 0.0, 0.2 * math.sin(A)],
                                                                           abs=1e-12)


def test_turning_in_place_on_the_ramp_the_heading_turns_faster_seen_from_above() -> None:
    """Heading up the ramp (k = tan A), wheels at -4 and 4 rad/s turn it at 1.6 rad/s about the ramp's
    normal: its yaw about the world's up turns by 1.6·dt·(1 + tan² A)/√(1 + tan² A) = 1.6·dt / cos A in
    the first step; on the floor by 1.6·dt."""
    for on_ramp in (True, False):
        at = (1.2, 0.0, _ramp_z(1.2) + HALF) if on_ramp else (0.0, 0.0, HALF)
        sim = _single([_robot("r", at)])
        left, right = sim.robot("r").motors.values()
        for m, w in ((left, -4.0), (right, 4.0)):
            m.set_position(math.inf)
            m.set_velocity(w)
        sim.step()
        turn = 0.05 * 8.0 / 0.25 * STEP / 1000.0
        assert sim.robot("r").drive.yaw == pytest.approx(turn / math.cos(A) if on_ramp else turn, abs=1e-12)


def test_on_the_floor_a_world_with_a_ramp_drives_as_one_without() -> None:
    """A robot driving curves on the floor beside the ramp: bit for bit the robot of a world without a
    ramp (no ground), and each step the exact arc of its wheels (motion.arc_step)."""
    robots = [_robot("r", (0.0, -1.5, HALF), 0.3)]
    sims = [_single(robots, ramp) for ramp in (True, False)]
    for s in sims:
        left, right = s.robot("r").motors.values()
        for m, w in ((left, 3.0), (right, 4.5)):
            m.set_position(math.inf)
            m.set_velocity(w)
    v, w = 0.05 * 7.5 / 2.0, 0.05 * 1.5 / 0.25
    x, y, yaw = 0.0, -1.5, 0.3
    for _ in range(60):
        for s in sims:
            s.step()
        x, y, yaw = arc_step(x, y, yaw, v, w, STEP / 1000.0)
        a, b = (s.robot("r").pose for s in sims)
        assert a.translation.tobytes() == b.translation.tobytes() and a.rotation.tobytes() == b.rotation.tobytes()
        assert a.translation[:2].tolist() == [x, y]


@pytest.mark.parametrize("c_drive", [True, False])
def test_batched_copies_on_the_ramp_are_the_single_simulation_bit_for_bit(c_drive: bool) -> None:
    """Copies placed on the ramp at three headings, driving curves up and across it: every copy's pose
    is a Simulation's, bit for bit, through the C drive pass and the numpy one."""
    if c_drive and packets.library() is None:
        pytest.skip(f"no packets helper: {packets.status()}")
    at = [1.6, 0.0, _ramp_z(1.6) + HALF]
    bs, slot, sims = copies_at_headings(lambda yaw: _robot("r", tuple(at), yaw), at, [0.0, 0.8, -2.0])
    if not c_drive:
        bs._drive_step = None
    for c, s in enumerate(sims):
        assert s.robot("r").pose.rotation.tobytes() == bs.rot[c, slot].tobytes()
    bs.set_wheels(slot, np.array([3.0, 5.0, 4.0]), np.array([4.0, 4.0, 2.0]))
    for c, s in enumerate(sims):
        left, right = s.robot("r").motors.values()
        for m, w in ((left, [3.0, 5.0, 4.0][c]), (right, [4.0, 4.0, 2.0][c])):
            m.set_position(math.inf)
            m.set_velocity(w)
    assert step_copies_as_singles(bs, slot, sims, 80) > 100


CAR = {"wheelbase": 0.3, "track_front": 0.2, "track_rear": 0.2, "front_wheel_radius": 0.05, "rear_wheel_radius": 0.05,
       "type": "propulsion", "max_wheel_speed": 30.0, "max_steering_angle": 0.5, "max_steering_speed": 4.0}


def _car(at: tuple[float, float, float], yaw: float = 0.0) -> dict:
    return {"name": "car", "pose": {"translation": list(at), "rotation": [0, 0, 1, yaw]},
            "body": {"geometry": {"type": "box", "size": [0.3, 0.15, 2 * HALF]}}, "ackermann_drive": CAR}


def _command(s, steer: float, wheel: float) -> None:
    for name, m in s.robot("car").motors.items():
        if "steer" in name:
            m.set_position(steer)
        else:
            m.set_position(math.inf)
            m.set_velocity(wheel)


def test_a_car_drives_up_the_ramp_at_its_wheels_speed_along_it_and_batched_copies_agree() -> None:
    """Straight up: r·ω·t along the ramp, its cosine along x (1e-9). Steering across it: a batched copy's
    poses are the Simulation's, bit for bit."""
    at = (1.3, 0.0, _ramp_z(1.3) + HALF)
    sim = _single([_car(at)])
    _command(sim, 0.0, 5.0)
    for _ in range(40):
        sim.step()
    end = sim.robot("car").pose.translation
    along = 0.05 * 5.0 * 40 * STEP / 1000.0
    assert end[0] - at[0] == pytest.approx(along * math.cos(A), abs=1e-9)
    assert math.hypot(end[0] - at[0], end[2] - at[2]) == pytest.approx(along, abs=1e-9)

    from sensorium.gym.views import CopySim
    world = parse_world(ramp_world([_car((1.6, -0.1, _ramp_z(1.6) + HALF), 0.4)]))
    single, batched = Simulation(world, precision="exact"), BatchedSimulation(world, 2)
    view = CopySim(batched, 1)
    tilted = 0
    for t in range(60):
        if t % 20 == 0:
            for s in (single, view):
                _command(s, [0.3, -0.4, 0.1][t // 20], [4.0, 6.0, -5.0][t // 20])
        single.step()
        view.step()
        a, b = single.robot("car").pose, view.robot("car").pose
        assert a.translation.tobytes() == b.translation.tobytes() and a.rotation.tobytes() == b.rotation.tobytes(), t
        tilted += single.robot("car").drive.slope is not None
    assert tilted > 40
