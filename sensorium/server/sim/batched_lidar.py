"""Rotating lidars in the batched simulation: every copy's head turns with that copy's clock and
sweeps its sector each basic step, bit for bit the range images the single simulation's Lidar
(sim/sensors.py, on devices/lidar.py's ``rotating_sweep``) makes.

What the single device does, per copy:

* while enabled (any positive sampling period: the head turns every basic step whatever the
  period) the head moves by ``-2π·f·dt`` and the step samples the columns ``rotating_sweep`` gives
  for the head angle before it -- the same call here, made once per distinct head angle and kept
  with the sector's beams (copies reset or enabled at different times sit at different angles;
  every episode's heads pass the same angles again);
* the head angle is the copy's own: 0 in a freshly built (reset) copy, held while disabled, and
  continued from there when enabled again; columns not swept yet keep their last value (zeros
  after a reset);
* a sector's beams are the device's beams of those columns (layer-major, columns in sweep order),
  turned into the copy's world by the single ``_rotate``'s products and sums, from the stacked
  ``Pose.compose`` the fixed lidars use (a lidar riding a joint: its copy's local pose from
  batched_joints.py, the head turning within it as in the single device); they go out as runs from one origin per copy, traced as
  coherent packets as the single device's one-origin cast is. Runs must have one length per cast,
  and a sector has one of two lengths (the sweep per step need not be a whole number of columns),
  so each length is a cast of its own (as range finders are: batched_depth.py);
* the ranges: ``lidar.ranges_from_hits`` of the sector, elementwise the same values for all copies
  at once without noise; with noise each copy's sector draws from its own stream, one standard
  normal per valid value in the sector's order.

No point cloud is kept (the batched simulation serves observations: range images).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from sensorium.server.devices import lidar as lmath
from sensorium.server.raycast import packets
from sensorium.server.raycast.engine import RayHits, RayKind
from sensorium.server.sim.sensors import Lidar
from sensorium.server.world.arrays import unique_ints

__all__ = ["RotatingLidars"]

# sectors kept per lidar (keyed by head angle: every episode's heads pass the same angles again),
# up to this many beams in all (~24 MB of beam columns); cleared when full
_SECTOR_BEAMS_KEPT = 1 << 20


class RotatingLidars:
    """The rotating lidars of a :class:`.batched.BatchedSimulation` (``lidars``: all its lidar
    templates, indexed by lidar column): every copy's head angle, each step's sectors and images."""

    def __init__(self, sim: Any, lidars: list[Lidar]):
        self.sim = sim
        self.lidars = lidars
        self.columns = [k for k, lid in enumerate(lidars) if lid.rotating]
        self.mask = np.array([lid.rotating for lid in lidars], dtype=bool)   # per lidar column
        self.head = np.zeros((sim.copies, len(lidars)))   # per copy and lidar column: the head angle (rad)
        self._sweeps: dict[int, dict[float, _Sector]] = {k: {} for k in self.columns}   # per lidar, by head angle
        self._kept_beams = dict.fromkeys(self.columns, 0)   # per lidar: the beams of its kept sectors
        self._beam_rows: dict[tuple[int, int], tuple] = {}   # per (lidar, sector length): beam buffers

    def reset(self, idx: np.ndarray) -> None:
        """A freshly built device: the head at angle 0 (the images are the simulation's, zeroed)."""
        self.head[idx] = 0.0

    def _sweep(self, col: int, head: float, dt_ms: int) -> _Sector:
        """The sector lidar ``col`` sweeps from this head angle (its columns and the angle after
        depend on nothing else: the lidar's frequency and the basic step are constants here)."""
        kept = self._sweeps[col]
        got = kept.get(head)
        if got is None:
            lid = self.lidars[col]
            sweep = lmath.rotating_sweep(lid.params, head, lid.frequency, dt_ms)
            got = _Sector(lid, sweep, self.sim._lidar_skip(col))   # (the fixed lidars' own-body test, decided once)
            beams = lid.config.number_of_layers * max(1, len(sweep.columns))
            if self._kept_beams[col] + beams > _SECTOR_BEAMS_KEPT:
                kept.clear()
                self._kept_beams[col] = 0
            kept[head] = got
            self._kept_beams[col] += beams
        return got

    # -- planning: each step's sectors
    def plan(self, live: np.ndarray, dt_ms: int) -> tuple[dict, list]:
        """(state, no joined requests): the sectors of every live copy's enabled rotating lidars,
        grouped by sector length; the heads turned. :meth:`finish` casts each group."""
        sim = self.sim
        state: dict = {"items": []}
        period = sim.period["Lidar"]
        for col in self.columns:
            on = (period[live, col] > 0).nonzero()[0]
            if not len(on):
                continue
            c = live[on]
            heads, where = np.unique(self.head[c, col], return_inverse=True)
            sectors = [self._sweep(col, h, dt_ms) for h in heads.tolist()]
            self.head[c, col] = np.array([s.sweep.head_angle_after for s in sectors])[where]
            sizes = np.array([len(s.sweep.columns) for s in sectors], dtype=np.int64)
            for n in unique_ints(sizes).tolist():
                if n == 0:      # a head that does not turn (frequency 0) samples nothing
                    continue
                pick = (sizes[where] == n).nonzero()[0]
                pick = pick[np.argsort(where[pick], kind="stable")]    # the copies of one head angle together
                state["items"].append(self._rays(col, c[pick], where[pick], sectors, n))
        return state, []

    def _rays(self, col: int, c: np.ndarray, group: np.ndarray, sectors: list[_Sector], n: int) -> tuple:
        """(lidar, copies, (copies, n) their sectors' columns, request): the sector beams of lidar
        ``col`` in copies ``c`` (``group``: each one's sector in ``sectors``, copies of one sector
        consecutive), copy after copy, each copy's in the single device's order (layer-major)."""
        from sensorium.server.sim.batched import _lidar_beams, _Rays  # (batched.py imports this module)

        sim = self.sim
        lid = self.lidars[col]
        L = lid.config.number_of_layers
        k = L * n                               # the rays of one copy's sector
        m = len(c)
        slot = lid.robot_index
        rr = sim.rot[c, slot]
        rider = ("Lidar", col)
        if rider in sim.joints.riders:   # on a joint: each copy's local pose (batched_joints.py), the head
            rot = np.matmul(rr, sim.joints.local_rot[rider][c])             # turning within it as in Simulation
            org = np.matmul(rr, sim.joints.local_pos[rider][c][:, :, None])[:, :, 0] + sim.pos[c, slot]
        else:
            rot = np.matmul(rr, lid.local_pose.rotation)                    # Pose.compose, stacked
            org = np.matmul(rr, lid.local_pose.translation[None, :, None])[:, :, 0] + sim.pos[c, slot]
        O, D, D32 = self._buffers(col, n, m * k)
        cuts = [0, *(np.flatnonzero(group[1:] != group[:-1]) + 1).tolist(), m]
        for a, b in zip(cuts[:-1], cuts[1:]):   # the copies of one sector: sensors._rotate's sums, in one pass
            cols = sectors[int(group[a])].local
            rows = slice(a * k, b * k)
            if packets.lidar_beams(rot[a:b], org[a:b], cols, (O[rows], D[rows], D32[rows])) is None:
                O[rows], D[rows], D32[rows] = _lidar_beams(rot[a:b], org[a:b], cols)
        swept = np.stack([sectors[int(g)].sweep.columns for g in group.tolist()])
        t_far = lid._t_far
        if isinstance(t_far, np.ndarray):          # per layer (a planar head's depth): each beam's own
            t_far = np.concatenate([sectors[int(g)].t_far for g in group.tolist()])
        mount: np.ndarray | int
        if lid._own_body is not None:   # its robot's body (or link) met apart, in the body frame (finish)
            mount = sim.slot_of_body(lid._own_body[1])
        elif all(isinstance(sectors[int(g)].skip, int) for g in group.tolist()) and \
                len({sectors[int(g)].skip for g in group.tolist()}) == 1:
            mount = sectors[int(group[0])].skip   # type: ignore[assignment]
        else:
            mount = np.concatenate([np.broadcast_to(sectors[int(g)].skip, (k,)) for g in group.tolist()])
        return (col, c, swept, _Rays(O, D, lid.params.near, t_far, RayKind.VISUAL, np.repeat(c, k), -1, mount,
                                     distance_only=True, d32=D32, coherent=True, origin_rows=org, run=k))

    def _buffers(self, col: int, n: int, rows: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Origins, directions and float32 directions for ``rows`` beams of lidar ``col``'s sectors of
        ``n`` columns this step (each step's rays are cast and finished within the step: written over
        the last step's, without a fresh allocation's page faults)."""
        got = self._beam_rows.get((col, n))
        if got is None or len(got[0]) < rows:
            got = self._beam_rows[(col, n)] = (np.empty((rows, 3)), np.empty((rows, 3)),
                                               np.empty((rows, 3), dtype=np.float32))
        return got[0][:rows], got[1][:rows], got[2][:rows]

    # -- finishing: the sectors' ranges into every copy's image
    def finish(self, state: dict, hits: list[RayHits]) -> None:
        """Cast each group's beams and write their ranges (``hits``: none, see :meth:`plan`)."""
        from sensorium.server.sim.batched import _Stream  # (batched.py imports this module)

        sim = self.sim
        for col, c, swept, r in state["items"]:
            h = sim.rays.cast(r.origins, r.directions, r.t_near, r.t_far, r.kind, r.copy, sim.rot, sim.pos, r.exclude,
                              r.mount, False, True, r.d32, True, origin_rows=r.origin_rows, run=r.run)
            lid = self.lidars[col]
            L = lid.config.number_of_layers
            m, n = swept.shape
            dist = h.distance.reshape(m, L, n)
            if lid._own_body is not None:
                dist = np.minimum(dist, np.moveaxis(lid._own_distances()[:, swept], 1, 0))
            img = sim.range_images[col]
            # (a rotating lidar's values read only the directions' shape: its planar factor is
            # cos e_i in every column, its cylindrical one 1)
            if lid.params.noise > 0:     # each copy's sector draws from its own stream, in the sector's order
                nc = sim._noise_col[("Lidar", col)]
                shape = np.broadcast_to(lid._all_dirs[:, :1, :], (L, n, 3))
                for k, cc in enumerate(c.tolist()):
                    img[cc][:, swept[k]] = lmath.ranges_from_hits(lid.params, dist[k], shape,
                                                                  _Stream(sim.noise, cc, nc))  # type: ignore[arg-type]
                ranges = None
            elif lid.params.planar:   # elementwise: every copy's sector in one call, as (layers, copies · n)
                flat = np.moveaxis(dist, 1, 0).reshape(L, m * n)
                shape = np.broadcast_to(lid._all_dirs[:, :1, :], (L, m * n, 3))
                ranges = np.moveaxis(lmath.ranges_from_hits(lid.params, flat, shape, None).reshape(L, m, n), 1, 0)
            else:                     # elementwise, no factor: the sectors as they are
                flat = dist.reshape(m * L, n)
                ranges = lmath.ranges_from_hits(lid.params, flat, np.broadcast_to(lid._all_dirs[:1, :1, :], (m * L, n, 3)),
                                                None).reshape(m, L, n)
            if ranges is not None:
                img[c[:, None, None], np.arange(L)[None, :, None], swept[:, None, :]] = ranges
            sim.last["Lidar"][c, col] = sim.time_ms[c]
            sim.counters["measurements"] += m


class _Sector:
    """What a lidar's sweep from one head angle needs, made once per head angle: the sweep, the
    sector's beams in the lidar frame as three columns (L·n, layer-major), their far limits (a
    planar head's, per beam) and mount slots (one value when every beam's is the same)."""

    __slots__ = ("sweep", "local", "t_far", "skip")

    def __init__(self, lid: Lidar, sweep: lmath.RotatingSweep, skip: np.ndarray):
        L, W = lid.config.number_of_layers, lid.config.horizontal_resolution
        cols = sweep.columns
        self.sweep = sweep
        self.local = tuple(np.ascontiguousarray(x.reshape(L, W)[:, cols]).reshape(-1) for x in lid._dir_columns)
        self.t_far = (np.ascontiguousarray(lid._t_far[:, cols]).reshape(-1) if isinstance(lid._t_far, np.ndarray)
                      else None)
        mine = skip.reshape(L, W)[:, cols].reshape(-1)
        self.skip: np.ndarray | int = int(mine[0]) if len(mine) and (mine == mine[0]).all() else mine
