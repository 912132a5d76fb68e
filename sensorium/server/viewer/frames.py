"""Frame names and fixed transforms shared by the Foxglove scene and the ROS 2 export (no
foxglove-sdk needed): ``world``; ``<robot>`` placed by the robot's pose; ``<robot>/<device>`` fixed
on its robot by the device's ``pose``."""

from __future__ import annotations

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.world.poses import matrix_quaternion, pose_from_model

__all__ = ["WORLD_FRAME", "INFINITE_PLANE_SIZE", "Mount", "mounts", "quat_from_x"]

WORLD_FRAME = "world"
INFINITE_PLANE_SIZE = 50.0      # metres: an infinite plane is drawn as a square of this side

Mount = tuple[str, tuple[float, float, float], tuple[float, float, float, float]]


def mounts(world: wm.World) -> dict[str, list[Mount]]:
    """robot → [(device frame, translation, quaternion xyzw)] of the robot's devices."""
    out: dict[str, list[Mount]] = {}
    for r in world.robots:
        items: list[Mount] = []
        for d in r.devices:
            p = pose_from_model(d.pose)
            t = (float(p.translation[0]), float(p.translation[1]), float(p.translation[2]))
            items.append((f"{r.name}/{d.name}", t, matrix_quaternion(p.rotation)))
        out[r.name] = items
    return out


def quat_from_x(d: np.ndarray) -> tuple[float, float, float, float]:
    """The rotation (x, y, z, w) taking +x onto the unit vector ``d`` (arrows point along +x)."""
    x = np.array([1.0, 0.0, 0.0])
    axis = np.cross(x, d)
    s, c = float(np.linalg.norm(axis)), float(np.dot(x, d))
    if s < 1e-12:
        return (0.0, 0.0, 0.0, 1.0) if c > 0 else (0.0, 0.0, 1.0, 0.0)
    axis /= s
    half = np.arctan2(s, c) / 2.0
    sh = float(np.sin(half))
    return (float(axis[0]) * sh, float(axis[1]) * sh, float(axis[2]) * sh, float(np.cos(half)))
