"""The Pen (Webots' WbPen): ink laid where the pen points, each basic step, for infra-red sensors.

What Webots does (``WbPen.cpp``, ``WbNodeUtilities::findIntersectingShape``,
``WbPaintTexture.cpp``, ``WbSimulationWorld::step``), and so what this does:

* at the start of every basic step (``prePhysicsStep``: before the robots move, so at the pose
  the previous step ended with) each pen whose ``write`` is on casts one ray from its origin along
  its −z axis and takes the nearest visual shape it meets — any shape: the world's, other robots',
  its own robot's — strictly nearer than ``max_distance`` (≤ 0: no limit);
* that shape's paint texture takes a disc of ink at the hit's texture-set-1 coordinates
  (:class:`sensorium.server.world.textures.InkLayer`: density blending, lead size in texels);
* then the world's ``ink_evaporation`` fades every wet texel, and the step goes on (motion, then
  the sensors, which read the ink at their end-of-step pose).

A controller's ``write``/``set_ink_color`` (services of the daemon) change the pen's state at
once; the next basic step paints with it — the step Webots applies them to, since libController
sends them with the next step request. ``set_ink_color`` keeps Webots' precision: each channel
``byte / 255`` in float32, the density clamped to [0, 1].

Each stroke that inked at least one texel is a new "measurement" of the pen: its topics publish
where it was laid (``stroke``, world coordinates) and with which ink (``ink``).
"""

from __future__ import annotations

import math
from collections import Counter
from typing import Any

import numpy as np

from sensorium.server.raycast.engine import RayKind
from sensorium.server.sim.batches import world_frames
from sensorium.server.sim.sensors import Device


def ink_channel(byte: int) -> float:
    """Webots' ``byte / 255.0f``: the channel as the float32 Webots stores, widened to a double."""
    return float(np.float32(byte) / np.float32(255.0))


class Pen(Device):
    """One pen: ``write``, the ink (``ink_color`` RGB in [0, 1], ``ink_density``), its latest
    stroke (``stroke``: the world point it inked, NaN before the first; ``ink``: (r, g, b,
    density) it used) and how many strokes it laid (``measurements``)."""

    topic_frames = {"stroke": "world"}     # the stroke is a world point (daemon/topics.py header)

    def __post_init__(self) -> None:
        super().__post_init__()
        c = self.config
        self.write = bool(c.write)
        self.ink_color: tuple[float, float, float] = tuple(float(v) for v in c.ink_color)  # type: ignore[assignment]
        self.ink_density = float(c.ink_density)
        self.stroke = np.full(3, math.nan)
        self.ink = (math.nan, math.nan, math.nan, math.nan)

    # -- controller API
    def set_write(self, write: bool) -> None:
        """``wb_pen_write``: from the next basic step the pen writes (True) or not."""
        self.write = bool(write)

    def set_ink_color(self, color: int, density: float) -> None:
        """``wb_pen_set_ink_color``: 0xRRGGBB (bits above 24 ignored, as libController's masks do)
        and a density clamped to [0, 1] (WbPen: WbFieldChecker)."""
        if isinstance(color, bool) or not isinstance(color, (int, np.integer)):
            raise ValueError(f"ink colour must be an integer 0xRRGGBB, got {color!r}")
        density = float(density)
        if not math.isfinite(density):
            raise ValueError(f"ink density must be finite, got {density!r}")
        c = int(color)
        self.ink_color = (ink_channel((c >> 16) & 0xFF), ink_channel((c >> 8) & 0xFF), ink_channel(c & 0xFF))
        self.ink_density = min(max(density, 0.0), 1.0)

    def describe(self) -> dict:
        c = self.config
        return {"write": self.write, "ink_color": [float(v) for v in self.ink_color],
                "ink_density": float(self.ink_density), "lead_size": float(c.lead_size),
                "max_distance": float(c.max_distance)}

    def readings(self) -> dict:
        return {"stroke": self.stroke, "ink": self.ink}

    def step_reading(self) -> dict:
        return {}


def lay_ink(pens: list[Pen], scene: Any, robot_poses: list, now_ms: int, counters: Counter[str]) -> int:
    """One basic step of every writing pen (see the module docstring): one batched visual cast from
    the pens' poses now (the start of the step), then a stroke on each shape hit nearer than its
    pen's ``max_distance``. Returns the strokes that inked something."""
    writing = [p for p in pens if p.write]
    if not writing:
        return 0
    rot, origins = world_frames(writing, robot_poses)
    directions = -rot[:, :, 2]
    limit = np.array([p.config.max_distance if p.config.max_distance > 0.0 else math.inf for p in writing])
    counters["rays_pen"] += len(writing)
    counters["cast_calls"] += 1
    hits = scene.engine.cast(origins, directions, 0.0, limit, kind=RayKind.VISUAL, exclude_owner=-1)
    laid = 0
    for k, pen in enumerate(writing):
        shape, t = int(hits.shape[k]), float(hits.distance[k])
        if shape < 0 or not t < limit[k]:          # nothing, or not strictly nearer than maxDistance
            continue
        if scene.paint(shape, origins[k], directions[k], t, pen.config.lead_size, pen.ink_color, pen.ink_density):
            pen.stroke = origins[k] + t * directions[k]
            pen.ink = (*pen.ink_color, pen.ink_density)
            pen._mark(now_ms)
            laid += 1
    counters["ink_strokes"] += laid
    return laid
