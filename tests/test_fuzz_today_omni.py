"""Hypothesis fuzz of the batched omni-wheel robots (batched_omni.py, batched_holonomic.py): random
wheel layouts (3 to 16 wheels, any radii and places, nearly collinear ones whose pseudo-inverse is
ill-conditioned, axes nearly parallel), random commands (held positions, velocities up to far past
the maximum). A layout either loads or is refused with one problem per line naming the field; a
loaded one steps every copy as its own Simulation, bit for bit; rim speeds of one twist give that
twist back (closed form, within the layout's condition number); NaN and infinite speeds are refused
in one line by the batched command, NaN by the single motor."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS

from sensorium.gym.views import CopySim
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, parse_world

STEP = 16
FEW = settings(SETTINGS, max_examples=40)

coord = st.floats(-2.0, 2.0, allow_nan=False)
angle = st.floats(-math.pi, math.pi)


@st.composite
def layouts(draw) -> list[dict]:
    """3-16 wheels: anywhere with any axis, or on a line (positions nearly collinear, axes nearly
    parallel: the rows' third singular value tiny), or 120° apart as a Robotino."""
    n = draw(st.integers(3, 16))
    kind = draw(st.sampled_from(["free", "line", "ring"]))
    eps = draw(st.sampled_from([0.0, 1e-12, 1e-9, 1e-6, 1e-3]))
    wheels = []
    for i in range(n):
        if kind == "free":
            pos, th = [draw(coord), draw(coord)], draw(angle)
        elif kind == "line":           # along x, a hair off the line, axes a hair off x
            pos, th = [0.1 * i, eps * i * i], eps * (i % 3)
        else:
            t = 2.0 * math.pi * i / n
            pos, th = [0.2 * math.cos(t), 0.2 * math.sin(t)], t + eps
        wheels.append({"motor": f"w{i}", "position": pos, "axis": [math.cos(th), math.sin(th)],
                       "radius": draw(st.floats(0.005, 0.5))})
    return wheels


def world_of(wheels: list[dict], vmax: float):
    return parse_world({"world_info": {"basic_time_step": STEP, "random_seed": 3},
                        "robots": [{"name": "r", "pose": {"translation": [0.0, 0.0, 0.05]},
                                    "body": {"geometry": {"type": "cylinder", "radius": 0.1, "height": 0.05}},
                                    "omni_drive": {"max_wheel_speed": vmax, "wheels": wheels}}]})


def load(wheels: list[dict], vmax: float = 12.0):
    try:
        return world_of(wheels, vmax)
    except WorldError as e:
        for line in str(e).splitlines():          # one problem a line, naming the drive's field
            assert line.startswith("<memory>: robots[0] (r).omni_drive"), line
        assert "Traceback" not in str(e)
        return None


speeds = st.floats(-1e6, 1e6, allow_nan=False) | st.sampled_from([0.0, -0.0, 12.0, -12.0, 1e-300, 5e-324])


@FEW
@given(layouts(), st.lists(st.lists(speeds, min_size=16, max_size=16), min_size=2, max_size=2),
       st.integers(0, 3))
def test_any_layout_loads_or_is_refused_and_copies_step_as_simulation_bit_for_bit(wheels, cmds, held):
    w = load(wheels)
    if w is None:
        return
    n = len(wheels)
    batched = BatchedSimulation(w, 2)
    u = np.array([c[:n] for c in cmds])
    batched.omni.command(0, u)
    view = CopySim(batched, 0)
    for j in range(held):          # the first `held` wheels of copy 0 hold a position
        view.robot("r").motor(f"w{j}").set_position(float(j + 1))
        view.robot("r").motor(f"w{j}").set_velocity(12.0)
    singles = []
    for c in range(2):
        s = Simulation(w)
        for j in range(n):
            m = s.robot("r").motor(f"w{j}")
            if c == 0 and j < held:
                m.set_position(float(j + 1))
                m.set_velocity(12.0)
            else:
                m.set_position(math.inf)
                m.set_velocity(float(u[c, j]))
        singles.append(s)
    for t in range(12):
        batched.step()
        for c, s in enumerate(singles):
            s.step()
            pose = s.robot("r").pose
            assert np.isfinite(pose.translation).all() and np.isfinite(pose.rotation).all()
            assert pose.translation.tobytes() == batched.pos[c, 0].tobytes(), (t, c)
            assert pose.rotation.tobytes() == batched.rot[c, 0].tobytes(), (t, c)


@FEW
@given(layouts(), st.floats(-0.5, 0.5), st.floats(-0.5, 0.5), st.floats(-2.0, 2.0))
def test_rim_speeds_of_one_twist_give_that_twist_back(wheels, vx, vy, wz):
    w = load(wheels)
    if w is None:
        return
    drive = Simulation(w).robot("r").drive
    rows = []
    for wh in wheels:
        dx, dy = wh["axis"][1], -wh["axis"][0]
        rows.append((dx, dy, dx * -wh["position"][1] + dy * wh["position"][0]))
    cond = np.linalg.cond(np.array(rows))
    rims = [(r[0] * vx + r[1] * vy + r[2] * wz) / wh["radius"] for r, wh in zip(rows, wheels)]
    got = drive.twist(rims)
    assert got == pytest.approx((vx, vy, wz), abs=1e-13 * cond * (1 + abs(vx) + abs(vy) + abs(wz)) + 1e-12)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_nan_and_infinite_batched_speeds_are_refused_in_one_line(bad):
    wheels = [{"motor": f"w{i}", "position": [0.1 * math.cos(2.1 * i), 0.1 * math.sin(2.1 * i)],
               "axis": [math.cos(2.1 * i), math.sin(2.1 * i)], "radius": 0.05} for i in range(5)]
    w = world_of(wheels, 12.0)
    batched = BatchedSimulation(w, 2)
    before = batched.omni.velocity.copy(), batched.omni.target.copy()
    with pytest.raises(ValueError, match=r"^omni wheel speeds must be finite$"):
        batched.omni.command(0, [[1.0, 2.0, bad, 0.0, 0.0], [0.0] * 5])
    assert batched.omni.velocity.tobytes() == before[0].tobytes() and batched.omni.target.tobytes() == before[1].tobytes()
    if math.isnan(bad):
        with pytest.raises(ValueError, match=r"^motor 'w2': velocity must be a number"):
            Simulation(w).robot("r").motor("w2").set_velocity(bad)
