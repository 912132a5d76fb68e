"""What a .wbt device's rays meet differently here, said at load time.

* A visual device (camera, range finder, lidar, infra-red distance sensor) whose origin lies inside
  one of its robot's closed primitives: Webots never sees that shape (its renderer culls back faces,
  its infra-red picking finds no hit from inside a Box or Sphere), while here every shape that is
  not the device's own (``of_device``) is seen from inside too (README, "a device inside a closed
  shape"). Webots' own range-finder sample mounts its device 1.5 mm under the top of the robot's
  body cylinder: its image was the cylinder's wall, 14 mm away, with no word why.
* A mesh (IndexedFaceSet) around such a device is split instead, so that the device does not see
  the triangles facing away from it, as Webots' culling (renderer and infra-red picking alike)
  makes it: the iRobot Create's four cliff sensors sit within its body's IndexedFaceSet (z within
  ±35 mm, radius under 162 mm) and read its floor plate, 35 mm below, whatever the ground, with no
  word why.
* The image fields of a Camera or RangeFinder that Webots' renderer uses and Sensorium does not
  (motion blur, depth of field, ...): the README lists them; the load report now names the ones a
  world writes.
"""

from __future__ import annotations

import numpy as np

from sensorium.server.world.poses import pose_from_values

RENDERED = {"Camera", "RangeFinder", "Lidar"}        # rasterised in Webots: every closed shape is culled from inside
PICKED = {"box", "sphere"}                           # Webots' infra-red picking: no hit from inside these
CLOSED = {"box", "sphere", "cylinder", "capsule"}
JUDGED = {"type", "size", "radius", "height", "subdivision"}   # the fields of a primitive ``contains`` judges
IMAGERS = {"Camera", "RangeFinder"}                  # their rays start at ``near`` (default NEAR)
NEAR = 0.01
EPS = 1e-9

# field -> (Webots' default, what it does there); a Node-valued field's default is None (NULL)
UNREAD_IMAGE_FIELDS = {
    "Camera": {"focus": (None, "depth of field"),
               "lensFlare": (None, "lens flares"), "bloomThreshold": (-1.0, "bloom"),
               "ambientOcclusionRadius": (0.0, "ambient occlusion")},
}


def unread_image_fields(kind: str, written: dict) -> list[tuple[str, str]]:
    """(field, what it does in Webots) for a Camera's or RangeFinder's fields written with a value
    Webots' renderer uses and Sensorium does not."""
    out = []
    for name, (default, what) in UNREAD_IMAGE_FIELDS.get(kind, {}).items():
        if name not in written:
            continue
        value = written[name]
        if default is None:
            if value is None:
                continue
        elif isinstance(default, float):
            if isinstance(value, (int, float)) and float(value) == default:
                continue
        elif value in (default, (default,), [default]):
            continue
        out.append((name, what))
    return out


def _local(pose: dict, point: np.ndarray) -> np.ndarray:
    p = pose_from_values(pose["translation"], pose.get("rotation"), pose.get("quaternion"))
    return p.rotation.T @ (point - p.translation)


class MeshFaces:
    """A triangle mesh's box, its triangles' first corners and their normals."""

    def __init__(self, vertices: np.ndarray, faces: np.ndarray) -> None:
        v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
        f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
        self.empty = not len(f)
        if self.empty:
            return
        self.low, self.high = v[f].reshape(-1, 3).min(axis=0), v[f].reshape(-1, 3).max(axis=0)
        self.a = v[f[:, 0]]
        self.normals = np.cross(v[f[:, 1]] - self.a, v[f[:, 2]] - self.a)   # front: counter-clockwise

    def around(self, p: np.ndarray) -> bool:
        """Whether ``p`` lies strictly within the mesh's box."""
        return not self.empty and bool(np.all(p > self.low) and np.all(p < self.high))

    def turned_away(self, p: np.ndarray) -> np.ndarray:
        """Each triangle's front turned away from ``p`` (p behind its plane): a ray from p can only
        meet its back, which Webots culls."""
        return np.einsum("ij,ij->i", p - self.a, self.normals) < 0.0


def contains(geometry: dict, p: np.ndarray) -> bool:
    """Whether ``p`` (in the shape's frame) is strictly inside a closed primitive."""
    t = geometry.get("type")
    if set(geometry) - JUDGED:    # scaled or stretched: not judged
        return False
    if t == "box":
        return bool(np.all(np.abs(p) < np.asarray(geometry["size"], dtype=np.float64) / 2.0 - EPS))
    if t == "sphere":
        return float(np.linalg.norm(p)) < geometry["radius"] - EPS
    if t == "cylinder":
        return float(np.hypot(p[0], p[1])) < geometry["radius"] - EPS and abs(p[2]) < geometry["height"] / 2.0 - EPS
    if t == "capsule":
        z = min(max(p[2], -geometry["height"] / 2.0), geometry["height"] / 2.0)
        return float(np.linalg.norm(p - np.array([0.0, 0.0, z]))) < geometry["radius"] - EPS
    return False


def reach(geometry: dict) -> float:
    """How far the farthest point of a closed primitive is from its centre."""
    t = geometry["type"]
    if t == "box":
        return float(np.linalg.norm(np.asarray(geometry["size"], dtype=np.float64))) / 2.0
    if t == "cylinder":
        return float(np.hypot(geometry["radius"], geometry["height"] / 2.0))
    if t == "capsule":
        return float(geometry["radius"] + geometry["height"] / 2.0)
    return float(geometry["radius"])


def enclosing_shapes(robot: dict, device: dict) -> list[dict]:
    """The robot's shapes (not the device's own, not bounding-only) that hold the device's origin
    and that the device's rays would not see in Webots. A camera's or a range finder's rays start at
    its ``near`` distance, here as in Webots: a shape all within it (a sensor's housing the camera
    sits in, as in Webots' binocular sample) is never seen, so it is not one."""
    kind = device["device"]
    if kind in RENDERED:
        kinds = CLOSED
    elif kind == "DistanceSensor" and device.get("type") == "infra-red":
        kinds = PICKED
    else:
        return []
    origin = np.asarray(device.get("pose", {}).get("translation", (0.0, 0.0, 0.0)), dtype=np.float64)
    out = []
    for part in robot.get("shapes", ()):
        geometry = part.get("geometry", {})
        if part.get("seen_by") == "bounding" or geometry.get("type") not in kinds:
            continue
        if part.get("of_device") == device["name"]:
            continue
        if set(geometry) - JUDGED:    # scaled or stretched: not judged (``contains``)
            continue
        # farther from the shape's centre than its farthest point: outside, whatever its rotation
        # (a robot's shapes times its devices: most pairs end here, before any rotation is made)
        if float(np.linalg.norm(
                origin - np.asarray(part["pose"]["translation"], dtype=np.float64))) > reach(geometry) * (1.0 + 1e-9) + EPS:
            continue
        if not contains(geometry, _local(part["pose"], origin)):
            continue
        if kind in IMAGERS:           # clipped whole by the near plane: no ray meets it
            centre = np.asarray(part["pose"]["translation"], dtype=np.float64)
            if float(np.linalg.norm(centre - origin)) + reach(geometry) < device.get("near", NEAR) - EPS:
                continue
        out.append(part)
    return out


def turn_meshes_away(robot: dict, clockwise: set[int]) -> None:
    """Split each of the robot's visual meshes that has one of its visual devices (camera, range
    finder, lidar, infra-red distance sensor) within its box so that the device is blind to the
    triangles facing away from it, as Webots' back-face culling makes it (its renderer, its
    infra-red picking): a triangle whose front side (counter-clockwise: its normal ``e1 x e2``) is
    turned from the device's origin can only be met from behind. A device inside its robot's body
    mesh (the iRobot Create's cliff sensors) so sees out. Triangles are grouped by the set of
    devices they face away from; each group is a shape of its own (same pose, appearance, node)
    whose ``unseen_by`` lists them. Meshes with no device in their box stay whole, and so do a mesh
    that is also a bounding object (contact sees it whole) and one written ``ccw FALSE``
    (``clockwise``: the ids of those geometries), whose front side is not judged here. The robot's
    radar targets name their shapes by index: they are renumbered, a split mesh's pieces all theirs."""
    shapes = robot.get("shapes")
    devices = [(d, np.asarray(d.get("pose", {}).get("translation", (0.0, 0.0, 0.0)), dtype=np.float64))
               for d in robot.get("devices", ())
               if d["device"] in RENDERED or (d["device"] == "DistanceSensor" and d.get("type") == "infra-red")]
    if not shapes or not devices:
        return
    out: list[dict] = []
    became: list[list[int]] = []        # per shape: its indices in ``out``
    for part in shapes:
        became.append([len(out)])
        geometry = part.get("geometry", {})
        if part.get("seen_by") != "visual" or geometry.get("type") != "triangles" or id(geometry) in clockwise:
            out.append(part)
            continue
        faces = MeshFaces(geometry["vertices"], geometry["faces"])
        away: list[tuple[str, np.ndarray]] = []
        for dev, origin in devices:
            if part.get("of_device") == dev["name"]:
                continue
            local = _local(part["pose"], origin)
            if faces.around(local):
                away.append((dev["name"], faces.turned_away(local)))
        if not away:
            out.append(part)
            continue
        groups: dict[tuple[str, ...], list[int]] = {}
        for t, key in enumerate(zip(*(behind.tolist() for _, behind in away))):
            groups.setdefault(tuple(name for (name, _), b in zip(away, key) if b), []).append(t)
        points = np.asarray(geometry["vertices"], dtype=np.float64).reshape(-1, 3)
        box = np.stack([points.min(axis=0), points.max(axis=0)])        # of all points, used or not
        for j, (names, rows) in enumerate(groups.items()):
            g = geometry if len(groups) == 1 else _piece(geometry, points, box, np.asarray(rows, dtype=np.int64))
            piece = dict(part, geometry=g)
            if j and part.get("node") is not None:      # one Shape node to a Supervisor: the first piece's
                piece["node"] = dict(part["node"], piece=True)
            if names:
                piece["unseen_by"] = sorted(names)
            out.append(piece)
        became[-1] = list(range(became[-1][0], len(out)))
    robot["shapes"] = out
    for target in robot.get("radar_targets", ()):
        target["shapes"] = sorted(k for i in target.get("shapes", ()) for k in became[i])


def _piece(geometry: dict, points: np.ndarray, box: np.ndarray, picked: np.ndarray) -> dict:
    """The triangles ``picked`` of a mesh as a mesh of their own, holding only the points (and
    texture coordinates) they use: a mesh split in k pieces stays about its size, not k times it.
    The whole mesh's box corners (``box``, of all its ``points``) are kept as two unused points, so that Webots' default texture
    mapping (over the box of all points: texcoords.default_triangle_uv) maps each piece as before.
    Texture coordinates indexed by the faces' own indices get their indices written out first."""
    faces = np.asarray(geometry["faces"], dtype=np.int64).reshape(-1, 3)[picked]
    used, renumbered = np.unique(faces, return_inverse=True)
    g = dict(geometry, vertices=np.concatenate([points[used], box]), faces=renumbered.reshape(-1, 3))
    tex = geometry.get("tex_coords")
    if tex is not None and len(tex):
        written = geometry.get("tex_coord_faces")
        tex_faces = (np.asarray(written, dtype=np.int64).reshape(-1, 3)[picked] if written is not None and len(written)
                     else faces)
        used, renumbered = np.unique(tex_faces, return_inverse=True)
        g["tex_coords"] = np.asarray(tex, dtype=np.float64).reshape(-1, 2)[used]
        g["tex_coord_faces"] = renumbered.reshape(-1, 3)
    return g
