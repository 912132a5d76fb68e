"""The ray engine's public value types: ray kinds, precision modes, shape entries and hits."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum, IntEnum

import numpy as np

from sensorium.server.world.geometry import Pose, Primitive


class RayKind(IntEnum):
    BOUNDING = 0  # boundingObject rays: generic/sonar/laser distance sensors, light occlusion
    VISUAL = 1    # visual rays: infra-red distance sensors, lidar
    SHADOW = 2    # a camera's shadow rays: the visual shapes that cast shadows (Webots' Shape.castShadows)


class Precision(str, Enum):
    FAST = "fast"
    EXACT = "exact"


@dataclass(frozen=True, slots=True)
class ShapeEntry:
    primitive: Primitive
    local_pose: Pose          # shape pose in its body's frame
    bounding: bool            # seen by BOUNDING rays
    visual: bool              # seen by VISUAL rays
    transparent: bool = False  # invisible to VISUAL rays and to casts with skip_transparent
    casts_shadow: bool = True  # seen by SHADOW rays (when also visual and not transparent)


@dataclass(slots=True)
class RayHits:
    distance: np.ndarray  # (n,) float64, +inf where no hit
    normal: np.ndarray | None   # (n,3) float64 unit, dot(normal, dir) <= 0; zeros where no hit
    shape: np.ndarray | None    # (n,) int64 global shape index, -1 where no hit
    # (normal and shape are None when the cast was asked for distances only)
