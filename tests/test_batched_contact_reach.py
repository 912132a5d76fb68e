"""The batched engine's narrow phase leaves out, before Contact._clip_shaped, the moves of shaped
robots whose candidate solids are all certainly beyond the reach that method tests
(sensorium/server/sim/batched.py ``_out_of_reach``): the answers are those of calling it on every
near move, bit for bit, in the C drive pass and the numpy path."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.server.sim import contact as C
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.world.loader import parse_world


def _world():
    """Six 0.3 x 0.15 m box robots in a 4 m pen among boxes, cylinders, spheres and a slanted block."""
    rng = np.random.default_rng(5)
    solids = [{"name": "floor", "geometry": {"type": "plane", "size": None}}]
    for i, (x0, x1, y0, y1) in enumerate([(-2.1, 2.1, 2.0, 2.1), (-2.1, 2.1, -2.1, -2.0),
                                          (2.0, 2.1, -2.0, 2.0), (-2.1, -2.0, -2.0, 2.0)]):
        solids.append({"name": f"wall{i}", "pose": {"translation": [(x0 + x1) / 2, (y0 + y1) / 2, 0.25]},
                       "geometry": {"type": "box", "size": [x1 - x0, y1 - y0, 0.5]}})
    kinds = [{"type": "box", "size": [0.3, 0.2, 0.4]}, {"type": "cylinder", "radius": 0.12, "height": 0.4},
             {"type": "sphere", "radius": 0.15}]
    for i in range(12):
        x, y = rng.uniform(-1.7, 1.7, 2)
        solids.append({"name": f"s{i}", "geometry": kinds[i % 3],
                       "pose": {"translation": [float(x), float(y), 0.2 if i % 3 != 2 else 0.1],
                                "rotation": [0, 0, 1, float(rng.uniform(-3, 3))]}})
    robots = [{"name": f"r{i}", "pose": {"translation": [-1.5 + 0.6 * i, -1.8 + 0.07 * i, 0.05],
                                          "rotation": [0, 0, 1, 0.3 * i]},
               "body": {"geometry": {"type": "box", "size": [0.3, 0.15, 0.1]}},
               "differential_drive": {"wheel_radius": 0.05, "axle_length": 0.2, "max_wheel_speed": 40.0}}
              for i in range(6)]
    return parse_world({"world_info": {"basic_time_step": 32}, "solids": solids, "robots": robots})


def _run(native, leave_out, monkeypatch, counts):
    real = BatchedSimulation._out_of_reach

    def counted(self, copies, slots, starts, ends, yaw0, solid_hit, robot_hit, near):
        got = real(self, copies, slots, starts, ends, yaw0, solid_hit, robot_hit, near)
        # each move left out is one Contact._clip_shaped would end at once: nothing within its reaches
        for m in (near & ~got).nonzero()[0].tolist():
            r, c = int(slots[m]), int(copies[m])
            turn = math.remainder(float(self.yaw[c, r]) - float(yaw0[m]), math.tau)
            cands = [self.contact._in_band(self.contact._obs[j], -1.0, 1.0) for j in solid_hit[m].nonzero()[0].tolist()]
            foot = self.feet[r]
            assert C._in_reaches(cands, starts[m], foot.radius * (1.0 + min(abs(turn), 2.0)) if turn else None,
                                 ends[m] - starts[m], foot.radius, {}) == ([], [])
        counts[0] += int(near.sum())
        counts[1] += int((near & ~got).sum())
        return got if leave_out else near
    monkeypatch.setattr(BatchedSimulation, "_out_of_reach", counted)
    n = 3
    bs = BatchedSimulation(_world(), n)
    if not native:
        bs._drive_step = None
    bs.reset(np.arange(n), [1] * n)
    rng = np.random.default_rng(2)
    states = []
    for step in range(240):
        if step % 15 == 0:
            for r in range(6):
                left, right = rng.uniform(-40.0, 40.0, (2, n))
                bs.set_wheels(r, left, right)
        bs.step()
        states.append((bs.pos.tobytes(), bs.rot.tobytes(), bs.pressing.tobytes(), bs.centres.tobytes(),
                       bs.foot_yaw.tobytes()))
    return states, dict(bs.counters)


@pytest.mark.parametrize("native", [True, False])
def test_moves_left_out_of_the_narrow_phase_change_no_bit(native, monkeypatch):
    from sensorium.server.raycast import packets
    if native and packets.library() is None:
        pytest.skip(f"no packets helper: {packets.status()}")
    with_counts, without_counts = [0, 0], [0, 0]
    got = _run(native, True, monkeypatch, with_counts)
    want = _run(native, False, monkeypatch, without_counts)
    assert got[1] == want[1] and got[1]["contacts"] > 20
    for step, (a, b) in enumerate(zip(got[0], want[0])):
        assert a == b, step
    near, left_out = with_counts
    assert left_out > 50 and near - left_out > 50     # both kinds met, many times
