"""Textured robot bodies in the batched simulation: a camera's or an infra-red sensor's hit on a
robot's textured shape reads its texel as the single simulation reads it.

The single scene numbers its shapes solids first, then every robot's parts in world order (its
body's, then each link's: scene.robot_bodies); the copies' cast numbers a robot's hit ``shape_offset`` (the solids' count) + its part's index among
all robots' parts: the same numbers. So one :class:`~sensorium.server.world.textures.TextureSampler`
over the solids' and the robots' template shapes (the batched scene's, extended) serves every
copy, and a copy's lookup differs from another's only in the shape's world-to-shape pose: the
robot's pose in that copy composed with the part's frame and inverted (``Scene._world_to_shape``'s
``owner.compose(local).inverse()``, the same calls), handed to scene.py's ``surface_colors`` and
``infra_red_terms`` per copy.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from sensorium.schemas import world as wm
from sensorium.server.sim.scene import robot_parts, scene_robot_parts
from sensorium.server.world.geometry import Pose
from sensorium.server.world.textures import TextureSampler

__all__ = ["RobotTextures", "textured_robot"]


def textured_robot(robot: wm.Robot) -> bool:
    """Whether a robot's shapes carry a texture, a roughness, occlusion or emissive map."""
    for _, _, shape in robot_parts(robot):
        a = shape.appearance
        if a is not None and (getattr(a, "texture", None) or getattr(a, "roughness_map", None)
                              or getattr(a, "occlusion_map", None) or getattr(a, "emissive_map", None)):
            return True
    return False


class RobotTextures:
    """The robots' template shapes joined to the batched scene's texture sampler, and each copy's
    world-to-shape poses of them."""

    def __init__(self, sim: Any):
        self.sim = sim
        scene = sim.scene
        self.n_static = sim.n_static_shapes
        parts = [(slot, local, shape) for slot, r in enumerate(sim.world.robots) for _, local, shape in scene_robot_parts(r)]
        self.parts: list[tuple[int, Pose]] = [(slot, local) for slot, local, _ in parts]
        models = [(shape.geometry, shape.appearance) for _, _, shape in parts]
        if scene.textures is None:
            statics = [(m.geometry, m.appearance) for m in (scene.part(i)[2] for i in range(self.n_static))]
            scene.textures = TextureSampler(statics + models, scene.base_dir, given=scene.images)
        else:
            scene.textures.extend(models)
        self.sampler: TextureSampler = scene.textures

    def world_to_shape(self, copy: int) -> Callable[[int], Pose]:
        """Shape id -> its world-to-shape pose in copy ``copy`` now (a solid's as the scene keeps it)."""
        sim, n = self.sim, self.n_static

        def inverse(shape: int) -> Pose:
            if shape < n:
                return sim.scene._world_to_shape(shape)
            slot, local = self.parts[shape - n]
            return sim.pose(copy, slot).compose(local).inverse()

        return inverse
