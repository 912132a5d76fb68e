"""Mecanum and omni-wheel robots on a slope: their body twist (vx, vy, ωz) is in the ground's plane
(ground.slope_twist, PlanarState.twist_over_ground), so the wheels' distance is along the ground. On
the ramp of tests/test_ground_ramp.py (angle A, rising along +x): heading up it a forward drive covers
r·ω·t·cos A horizontally, sideways up it a strafe covers r·ω·t·cos A, across it a strafe r·ω·t; at any
heading a strafe's displacement is r·ω·t long, in the ramp's plane, square to the robot's forward axis
there. Batched copies agree with the single simulation bit for bit; on the floor nothing changes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world
from tests._slopes import STEP, copies_at_headings, ramp_world, step_copies_as_singles
from tests.test_ground_ramp import BODY, HALF, A, _ramp_z

N = 60                                   # 0.96 s
R, LX, LY = 0.05, 0.1, 0.12
MECANUM = {"wheel_radius": R, "lx": LX, "ly": LY, "max_wheel_speed": 12.0}
ORDER = ("wheel2", "wheel1", "wheel4", "wheel3")          # front left, front right, rear left, rear right
OMNI_R, OMNI_L = 0.03, 0.1
OMNI_ANGLES = (0.0, 2.0943951023931953, 4.1887902047863905)
OMNI = {"max_wheel_speed": 20.0,
        "wheels": [{"motor": f"w{i}", "position": [OMNI_L * math.cos(a), OMNI_L * math.sin(a)],
                    "axis": [math.cos(a), math.sin(a)], "radius": OMNI_R} for i, a in enumerate(OMNI_ANGLES)]}


def _robot(at: tuple[float, float, float], yaw: float, omni: bool = False) -> dict:
    drive = {"omni_drive": OMNI} if omni else {"mecanum_drive": MECANUM}
    return {"name": "r", "pose": {"translation": list(at), "rotation": [0, 0, 1, yaw]}, "body": BODY, **drive}


def _mecanum_speeds(vx: float, vy: float, w: float = 0.0) -> list[float]:
    """The youBot rollers' wheel speeds (front left, front right, rear left, rear right) for a twist."""
    c = LX + LY
    return [(vx - vy - c * w) / R, (vx + vy + c * w) / R, (vx + vy - c * w) / R, (vx - vy + c * w) / R]


def _omni_speeds(vx: float, vy: float) -> list[float]:
    """Each omni wheel's speed for a translation: its rim rolls along d = axis × up."""
    return [(math.sin(a) * vx - math.cos(a) * vy) / OMNI_R for a in OMNI_ANGLES]


def _command(sim: Simulation, names, speeds) -> None:
    for name, u in zip(names, speeds):
        m = sim.robot("r").motors[name]
        m.set_position(math.inf)
        m.set_velocity(u)


def _run(at, yaw: float, speeds, omni: bool = False, ramp: bool = True) -> tuple[np.ndarray, np.ndarray, Simulation]:
    sim = Simulation(parse_world(ramp_world([_robot(at, yaw, omni)], ramp)), precision="exact")
    start = sim.robot("r").pose.translation.copy()
    _command(sim, [w["motor"] for w in OMNI["wheels"]] if omni else ORDER, speeds)
    for _ in range(N):
        sim.step()
    return start, sim.robot("r").pose.translation.copy(), sim


@pytest.mark.parametrize("omni", [False, True])
def test_closed_forms_up_sideways_and_across_the_ramp(omni: bool) -> None:
    v = 0.2                                                        # m/s along the ground
    dist = v * N * STEP / 1000.0
    speeds = _omni_speeds if omni else _mecanum_speeds
    at = (1.3, 0.0, _ramp_z(1.3) + HALF)
    # heading up the ramp, driving forward: r·ω·t·cos A along x
    start, end, _ = _run(at, 0.0, speeds(v, 0.0), omni)
    assert end[0] - start[0] == pytest.approx(dist * math.cos(A), abs=1e-9)
    assert end[2] - start[2] == pytest.approx(dist * math.sin(A), abs=1e-9)
    assert end[1] == pytest.approx(0.0, abs=1e-9)
    # heading -y (its left up the ramp), strafing left: sideways up it, r·ω·t·cos A along x
    start, end, _ = _run(at, -math.pi / 2, speeds(0.0, v), omni)
    assert end[0] - start[0] == pytest.approx(dist * math.cos(A), abs=1e-9)
    assert end[2] - start[2] == pytest.approx(dist * math.sin(A), abs=1e-9)
    assert end[1] == pytest.approx(0.0, abs=1e-9)
    # heading up the ramp, strafing left: across it, level, r·ω·t along y
    start, end, _ = _run(at, 0.0, speeds(0.0, v), omni)
    assert end[1] - start[1] == pytest.approx(dist, abs=1e-9)
    assert end[0] - start[0] == pytest.approx(0.0, abs=1e-9) and end[2] - start[2] == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("yaw", [0.5, 2.2, -0.9])
def test_a_strafe_at_any_heading_is_r_w_t_long_in_the_ramps_plane_square_to_forward(yaw: float) -> None:
    v = 0.15
    dist = v * N * STEP / 1000.0
    at = (1.5, 0.1, _ramp_z(1.5) + HALF)
    start, end, sim = _run(at, yaw, _mecanum_speeds(0.0, v))
    d = end - start
    assert d[2] == pytest.approx(d[0] * math.tan(A), abs=1e-12)                  # in the ramp's plane
    assert float(np.linalg.norm(d)) == pytest.approx(dist, abs=1e-9)             # r·ω·t along the ground
    forward = sim.robot("r").pose.rotation[:, 0]                                  # the robot's x, on the ramp
    assert float(forward @ d) == pytest.approx(0.0, abs=1e-9)                    # square to it
    left = sim.robot("r").pose.rotation[:, 1]
    assert float(left @ d) == pytest.approx(dist, abs=1e-9)


def test_turning_in_place_on_the_ramp_turns_faster_seen_from_above() -> None:
    """Heading up the ramp (k = tan A), a turn at ω about the normal turns the yaw at ω / cos A (the
    two-wheel robots' rule, ground.slope_scales): the first step's yaw."""
    w = 1.5
    for on_ramp in (True, False):
        at = (1.3, 0.0, _ramp_z(1.3) + HALF) if on_ramp else (0.0, 0.0, HALF)
        sim = Simulation(parse_world(ramp_world([_robot(at, 0.0)])), precision="exact")
        _command(sim, ORDER, _mecanum_speeds(0.0, 0.0, w))
        sim.step()
        rot = sim.robot("r").pose.rotation
        yaw = math.atan2(rot[1, 0], rot[0, 0])
        assert yaw == pytest.approx(w * STEP / 1000.0 / (math.cos(A) if on_ramp else 1.0), abs=1e-12)


@pytest.mark.parametrize("omni", [False, True])
def test_on_the_floor_a_world_with_a_ramp_drives_as_one_without(omni: bool) -> None:
    speeds = _omni_speeds(0.1, -0.05) if omni else _mecanum_speeds(0.1, -0.05, 0.7)
    at = (-0.5, 0.2, HALF)
    a, b = (_run(at, 0.4, speeds, omni, ramp)[2].robot("r").pose for ramp in (True, False))
    assert a.translation.tobytes() == b.translation.tobytes() and a.rotation.tobytes() == b.rotation.tobytes()


@pytest.mark.parametrize("omni", [False, True])
def test_batched_copies_on_the_ramp_are_the_single_simulation_bit_for_bit(omni: bool) -> None:
    at = [1.6, 0.0, _ramp_z(1.6) + HALF]
    bs, slot, sims = copies_at_headings(lambda yaw: _robot(tuple(at), yaw, omni), at, [0.0, 0.8, -2.0, 2.9])
    names = [w["motor"] for w in OMNI["wheels"]] if omni else list(ORDER)
    twists = [(0.15, 0.05, 0.3), (-0.05, 0.2, -0.6), (0.1, -0.1, 1.1), (0.0, 0.18, 0.0)]
    if omni:
        speeds = np.array([_omni_speeds(vx, vy) for vx, vy, _ in twists])
        speeds[:, 0] += 2.0                                       # and a turn
    else:
        speeds = np.array([_mecanum_speeds(*t) for t in twists])
    (bs.omni if omni else bs.mecanum).command(slot, speeds)
    for c, s in enumerate(sims):
        _command(s, names, speeds[c])
    assert step_copies_as_singles(bs, slot, sims, 80) > 150
