"""Camera recognition and segmentation in the batched simulation: every copy's recognised objects
and segmentation images as the single simulation's Camera (sim/cameras.py, on sim/recognition.py's
:class:`Recognizer`) makes them, bit for bit.

Each copy has its own recognition schedule (period, last update), segmentation switch, objects and
segmentation image per camera with a Recognition node. A due camera's pixel-centre rays (the single
``Camera._pixel_objects``: the centre sample of each pixel, limited by ``near`` and ``max_range``) of
every due copy are one cast of their own, as the batched camera's image rays are (``PixelDevices``:
the same stacked ``Pose.compose``, its robot's body met apart for a housed camera), meeting only that
copy's robots. The objects are the single Recognizer's, run per copy on :class:`_CopyScene`: the
world's shapes numbered as the single scene numbers them (solids, then the robots'), the Supervisor's
node ids (robots 1..R, then the top-level solids), each robot's pose in that copy, a shape riding a
joint carried by its robot's pose ∘ that copy's link displacement (once the joint has moved since the
copy's reset: the single scene's ``carrier``). The occlusion rays
(occlusion 1: one per candidate object, to its origin) of every due copy of a camera are one cast,
each ray meeting only its copy's world, its camera's robot excluded, as the single camera casts it
alone.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from sensorium.server.devices import imaging
from sensorium.server.raycast.engine import RayKind
from sensorium.server.sim.batched_camera import own_body_hits
from sensorium.server.sim.batched_depth import PixelDevices
from sensorium.server.sim.recognition import RecognisedObject, Recognizer, occlusion_ray
from sensorium.server.sim.scene import recognisable_owners, robot_bodies, scene_robot_parts
from sensorium.server.sim.sensors import _check_period
from sensorium.server.world.geometry import Pose

__all__ = ["RecognitionDevices"]


class _CopyScene:
    """What a Recognizer reads of its scene, as copy ``copy`` of the batched simulation holds it (the
    batched scene holds the static shapes alone: the robots' are numbered after them, as CopyRays
    reports them and the single scene numbers them)."""

    def __init__(self, sim: Any):
        self.sim = sim
        self.copy = 0
        scene = sim.scene
        self.base_dir = scene.base_dir
        world = sim.world
        self._parts = [scene.part(i) for i in range(sim.n_static_shapes)]
        self._parts += [(r, local, shape) for r, robot in enumerate(world.robots) for _, local, shape in scene_robot_parts(robot)]
        self.shapes = self._parts                     # (a Recognizer counts them)
        self.recognisable = recognisable_owners(world)     # the single scene's Supervisor node ids
        # the shapes riding a joint (the scene's numbering): shape -> that joint's column
        self._link: dict[int, int] = {}
        k = sim.n_static_shapes
        for r, robot in enumerate(world.robots):
            for joint, group in robot_bodies(robot):
                if joint is not None:
                    self._link.update((k + q, sim.joints.of(r, joint)) for q in range(len(group)))
                k += len(group)

    def part(self, shape: int) -> tuple:
        return self._parts[shape]

    def on_link(self, shape: int) -> bool:
        return shape in self._link

    def carrier(self, shape: int) -> Pose:
        """Scene.carrier in this copy: its robot's pose, composed with its link's displacement
        once its joint has moved since the copy's reset (as the single scene holds one then)."""
        owner = self.sim.pose(self.copy, self._parts[shape][0])
        j = self._link[shape]
        joints = self.sim.joints
        if not joints.placed[self.copy, j]:
            return owner
        return owner.compose(Pose._owned(joints.link_rot[self.copy, j].copy(), joints.link_pos[self.copy, j].copy()))

    def owner_pose(self, key: str | int) -> Pose:
        if isinstance(key, str):
            return self.sim.scene.solid_poses[key]
        return self.sim.pose(self.copy, key)


class _Centres:
    """One camera's pixel-centre rays (the single Camera._pixel_objects' constants)."""

    def __init__(self, template: Any):
        self.template = template
        c = template.config
        self.height, self.width = int(c.height), int(c.width)
        dirs = imaging.pixel_directions(template.geometry)[0]
        self.dirs = np.ascontiguousarray(dirs.reshape(-1, 3))
        self.n = len(self.dirs)
        self.columns = tuple(np.ascontiguousarray(self.dirs[:, k]) for k in range(3))
        factors = imaging.depth_factors(template.geometry, dirs)
        rng = float(c.recognition.max_range) if c.recognition is not None else math.inf
        self.limits = imaging.clip_limits(template.geometry, factors, c.near, rng)
        self.own: Any = None
        self.own_joint = -1        # a housed camera's link's joint column (-1: its robot's body)
        self.skip: np.ndarray | int | None = None
        self.plan: tuple | None = None


class RecognitionDevices(PixelDevices):
    """The batched cameras' recognition (columns: the cameras' columns): schedules, objects and
    segmentation images per copy."""

    kind = "Camera"

    def __init__(self, sim: Any, cameras: list):
        super().__init__(sim, [_Centres(d) for d in cameras])
        C = sim.copies
        n = len(cameras)
        self.period = np.zeros((C, n), dtype=np.int64)
        self.last = np.zeros((C, n), dtype=np.int64)
        self.segmentation = np.zeros((C, n), dtype=bool)
        self.objects: list[list[list[RecognisedObject]]] = [[[] for _ in range(n)] for _ in range(C)]
        self.images = [np.zeros((C, d.height, d.width, 4), dtype=np.uint8) for d in self.devices]
        for img in self.images:
            img[..., 3] = 255
        self.scene = _CopyScene(sim) if any(d.config.recognition is not None for d in cameras) else None
        self._recognizers: dict[int, Recognizer] = {}
        self._enabled = False

    def reset(self, idx: np.ndarray) -> None:
        """As freshly built devices: recognition off, no objects, a black segmentation image."""
        self.period[idx] = 0
        self.last[idx] = 0
        self.segmentation[idx] = False
        for c in np.asarray(idx).reshape(-1).tolist():
            self.objects[c] = [[] for _ in self.devices]
        for img in self.images:
            img[idx] = 0
            img[idx, :, :, 3] = 255

    # -- controller API (Camera's), per copy
    def enable(self, col: int, period_ms: int, copies: Any) -> None:
        """``recognition_enable(period)`` in the copies (0 disables it, and the segmentation with it)."""
        tpl = self.devices[col].template
        if tpl.config.recognition is None:
            raise ValueError(f"{tpl.path}: this camera has no Recognition node")
        period = _check_period(period_ms)
        self.period[copies, col] = period
        self.last[copies, col] = self.sim.time_ms[copies]
        if period == 0:
            self.segmentation[copies, col] = False
        else:
            self._enabled = True

    def enable_segmentation(self, col: int, on: bool, copies: Any) -> None:
        rc = self.devices[col].template.config.recognition
        path = self.devices[col].template.path
        if on and (rc is None or not rc.segmentation):
            raise ValueError(f"{path}: this camera's Recognition node has no segmentation (segmentation: true)")
        if on and (self.period[copies, col] <= 0).any():
            raise ValueError(f"{path}: the segmentation needs the recognition enabled first (recognition_enable)")
        self.segmentation[copies, col] = bool(on)

    # -- measuring: after the step's images, at the same poses
    def measure(self, live: np.ndarray) -> None:
        if not self._enabled:
            return
        sim = self.sim
        per = self.period[live]
        due = (per > 0) & (sim.time_ms[live][:, None] - self.last[live] >= per)
        ci, cols = due.nonzero()
        copies = live[ci]
        for col in sorted(set(cols.tolist())):
            self._recognise(col, copies[cols == col])

    def _recognise(self, col: int, copies: np.ndarray) -> None:
        sim = self.sim
        dev = self.devices[col]
        tpl = dev.template
        rc = tpl.config.recognition
        rec = self._recognizers.get(col)
        if rec is None:
            assert self.scene is not None
            rec = self._recognizers[col] = Recognizer(self.scene, tpl.robot_index, rc, tpl.geometry)
        segment = self.segmentation[copies, col]
        pixels = self._pixel_objects(col, copies, rec) if (rc.occlusion == 2 or segment.any()) else None
        assert self.scene is not None
        seen = []
        for k, c in enumerate(copies.tolist()):
            self.scene.copy = c
            pose = sim.pose(c, tpl.robot_index).compose(self._local_pose(col, c))      # Device.world_pose
            mine = None if pixels is None else pixels[k]
            seen.append((pose, rec.candidates(pose, mine)))
            if segment[k]:
                assert mine is not None
                self.images[col][c] = rec.segmentation(mine, dev.height, dev.width)
        if rc.occlusion == 1:
            seen = self._occlusion(col, copies, rec, seen)
        for c, (_, found) in zip(copies.tolist(), seen):
            self.objects[c][col] = rec.trim([o for _, o, _ in found])
        self.last[copies, col] = sim.time_ms[copies]

    def _local_pose(self, col: int, copy: int) -> Pose:
        """The camera's pose in its robot's frame in one copy: riding a joint, that copy's
        (batched_joints.py: ``displacement ∘ mount``, as the single device's ``move_with``)."""
        rider = (self.kind, col)
        joints = self.sim.joints
        if rider in joints.riders:
            return Pose(joints.local_rot[rider][copy], joints.local_pos[rider][copy])
        return self.devices[col].template.local_pose

    def _occlusion(self, col: int, copies: np.ndarray, rec: Recognizer, seen: list) -> list:
        """Occlusion 1 of every copy's candidates (Recognizer._origin_visible): their rays to the
        objects' origins, each in its copy alone, its camera's robot excluded, in one cast."""
        sim = self.sim
        rows, origins, dirs, far = [], [], [], []
        for q, (pose, found) in enumerate(seen):
            for i, (_, _, target) in enumerate(found):
                ray = occlusion_ray(pose, target)
                if ray is not None:
                    rows.append((q, i))
                    origins.append(pose.translation)
                    dirs.append(ray[0])
                    far.append(ray[1])
        hidden: set[tuple[int, int]] = set()
        if rows:
            ray_copy = copies[np.array([q for q, _ in rows], dtype=np.int64)]
            h = sim.rays.cast(np.array(origins), np.array(dirs), 0.0, np.array(far), RayKind.VISUAL, ray_copy, sim.rot,
                              sim.pos, self.devices[col].template.robot_index)
            assert h.shape is not None
            for j, (q, i) in enumerate(rows):
                if not rec.reached(seen[q][1][i][0], float(h.distance[j]), int(h.shape[j])):
                    hidden.add((q, i))
        return [(pose, [f for i, f in enumerate(found) if (q, i) not in hidden]) for q, (pose, found) in enumerate(seen)]

    def _pixel_objects(self, col: int, copies: np.ndarray, rec: Recognizer) -> np.ndarray:
        """(copies, H·W): the recognisable object (index, -1 none) each pixel centre's ray sees
        within max_range, in each copy."""
        sim = self.sim
        dev = self.devices[col]
        org, origins, d, d32 = self._beams(col, copies)
        ray_copy, mount, t_near, t_far = self._rows(col, copies)
        h = sim.rays.cast(origins, d, t_near, t_far, RayKind.VISUAL, ray_copy, sim.rot, sim.pos, -1, mount, False,
                          False, d32, True, origin_rows=org, run=dev.n)
        h = own_body_hits(self, col, copies, h)
        assert h.shape is not None
        return np.where(np.isfinite(h.distance), rec.key_of[h.shape], -1).reshape(len(copies), dev.n)
