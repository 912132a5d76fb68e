"""The room the lidar tests scan: a floor, a wall across +x, a post, and one robot ``r`` carrying
lidar ``l`` 0.4 m above its origin (with a body when asked)."""

from __future__ import annotations

import math


def lidar_room(lidar: dict, wall_x: float, body: dict | None = None) -> dict:
    dev = {"device": "Lidar", "name": "l", "pose": {"translation": [0.0, 0.0, 0.4]}, "field_of_view": 2 * math.pi,
           "near": 0.02, **lidar}
    robot: dict = {"name": "r", "pose": {"translation": [0.0, 0.0, 0.05]}, "devices": [dev]}
    if body is not None:
        robot["body"] = body
    return {"world_info": {"basic_time_step": 16, "random_seed": 4}, "solids": [
        {"name": "floor", "geometry": {"type": "plane", "size": None}},
        {"name": "wall", "pose": {"translation": [wall_x, 0.0, 0.5]}, "geometry": {"type": "box", "size": [0.2, 4.0, 1.0]}},
        {"name": "post", "pose": {"translation": [-1.0, 1.0, 0.5]},
         "geometry": {"type": "cylinder", "radius": 0.2, "height": 1.0}},
    ], "robots": [robot]}
