"""What a .wbt device's rays meet differently here, said at load time.

* A visual device (camera, range finder, lidar, infra-red distance sensor) whose origin lies inside
  one of its robot's closed shapes: Webots never sees that shape (its renderer culls back faces, its
  infra-red picking finds no hit from inside a Box or Sphere and culls a mesh's triangles seen from
  behind), while here every shape that is not the device's own (``of_device``) is seen from inside
  too (README, "a device inside a closed shape"). Webots' own range-finder sample mounts its device
  1.5 mm under the top of the robot's body cylinder: its image was the cylinder's wall, 14 mm away,
  with no word why; the iRobot Create's four cliff sensors sit within its body's IndexedFaceSet
  (z within ±35 mm, radius under 162 mm), whose floor plate they would read whatever the ground.
* The image fields of a Camera or RangeFinder that Webots' renderer uses and Sensorium does not
  (motion blur, depth of field, ...): the README lists them; the load report now names the ones a
  world writes.
"""

from __future__ import annotations

import numpy as np

from sensorium.server.world.poses import pose_from_values

RENDERED = {"Camera", "RangeFinder", "Lidar"}        # rasterised in Webots: every closed shape is culled from inside
PICKED = {"box", "sphere", "triangles"}              # Webots' infra-red picking: no hit from inside these
CLOSED = {"box", "sphere", "cylinder", "capsule", "triangles"}
JUDGED = {"type", "size", "radius", "height", "subdivision"}   # the fields of a primitive ``contains`` judges
MESH_FIELDS = {"type", "vertices", "faces", "tex_coords", "tex_coord_faces"}   # a mesh's, in its shape's frame
# directions a point's crossings of a mesh are counted along (none along an axis, where a CAD mesh's
# edges and faces line up)
PARITY_DIRECTIONS = np.array([[0.5773, 0.5774, 0.5773], [-0.6237, 0.3184, 0.7137], [0.2919, -0.8412, -0.4552]])
IMAGERS = {"Camera", "RangeFinder"}                  # their rays start at ``near`` (default NEAR)
NEAR = 0.01
EPS = 1e-9

# field -> (Webots' default, what it does there); a Node-valued field's default is None (NULL)
UNREAD_IMAGE_FIELDS = {
    "Camera": {"focus": (None, "depth of field"),
               "lensFlare": (None, "lens flares"), "motionBlur": (0.0, "motion blur"),
               "noiseMaskUrl": ("", "a noise mask image"), "bloomThreshold": (-1.0, "bloom"),
               "ambientOcclusionRadius": (0.0, "ambient occlusion")},
    "RangeFinder": {"motionBlur": (0.0, "motion blur")},
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


def shape_name(geometry: dict) -> str:
    """The shape as the world file wrote it: a primitive's type, an IndexedFaceSet for triangles."""
    return "IndexedFaceSet" if geometry["type"] == "triangles" else str(geometry["type"])


def judged(geometry: dict) -> bool:
    """Whether :func:`contains` can tell inside from outside: a primitive as written (not scaled or
    stretched) or an IndexedFaceSet's triangles (the scale already in its vertices)."""
    if geometry.get("type") == "triangles":
        return not set(geometry) - MESH_FIELDS
    return not set(geometry) - JUDGED


class MeshParity:
    """Whether a point is enclosed by a triangle mesh: it crosses the mesh an odd number of times
    along each of three directions (Möller–Trumbore). A closed mesh gives the same parity along
    every direction; an open one (a plate, a bowl) rarely an odd count along all three, so a point
    near an open surface is not called inside. What does not depend on the point is computed once
    per mesh (a robot's devices ask about the same body)."""

    def __init__(self, vertices: np.ndarray, faces: np.ndarray) -> None:
        v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
        f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
        self.empty = not len(f)
        self.reach = float(np.sqrt(np.max(np.einsum("ij,ij->i", v, v)))) if len(v) else 0.0
        if self.empty:
            return
        self.low, self.high = v.min(axis=0), v.max(axis=0)
        self.a = v[f[:, 0]]
        self.e1, self.e2 = v[f[:, 1]] - self.a, v[f[:, 2]] - self.a
        self.rays = []
        for d in PARITY_DIRECTIONS:
            h = np.cross(d, self.e2)
            det = np.einsum("ij,ij->i", self.e1, h)
            ok = np.abs(det) > 1e-300
            self.rays.append((d, h, ok, np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)))

    def inside(self, p: np.ndarray) -> bool:
        if self.empty or np.any(p <= self.low) or np.any(p >= self.high):
            return False
        s = p - self.a
        q = np.cross(s, self.e1)
        t = np.einsum("ij,ij->i", self.e2, q)
        for d, h, ok, inv in self.rays:
            u = np.einsum("ij,ij->i", s, h) * inv
            w = (q @ d) * inv
            crossings = ok & (u >= 0.0) & (w >= 0.0) & (u + w <= 1.0) & (t * inv > EPS)
            if int(np.count_nonzero(crossings)) % 2 == 0:
                return False
        return True


def mesh_parity(geometry: dict, meshes: dict[int, tuple[dict, MeshParity]]) -> MeshParity:
    """The mesh's :class:`MeshParity`, made once per geometry for one ``meshes`` cache."""
    known = meshes.get(id(geometry))
    if known is None or known[0] is not geometry:
        known = meshes[id(geometry)] = (geometry, MeshParity(geometry["vertices"], geometry["faces"]))
    return known[1]


def contains(geometry: dict, p: np.ndarray, meshes: dict[int, tuple[dict, MeshParity]] | None = None) -> bool:
    """Whether ``p`` (in the shape's frame) is strictly inside a closed primitive or mesh."""
    t = geometry.get("type")
    if not judged(geometry):    # scaled or stretched: not judged
        return False
    if t == "triangles":
        return mesh_parity(geometry, {} if meshes is None else meshes).inside(p)
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


def reach(geometry: dict, meshes: dict[int, tuple[dict, MeshParity]] | None = None) -> float:
    """How far the farthest point of a closed primitive (or a mesh's vertex) is from its centre."""
    t = geometry["type"]
    if t == "triangles":
        return mesh_parity(geometry, {} if meshes is None else meshes).reach
    if t == "box":
        return float(np.linalg.norm(np.asarray(geometry["size"], dtype=np.float64))) / 2.0
    if t == "cylinder":
        return float(np.hypot(geometry["radius"], geometry["height"] / 2.0))
    if t == "capsule":
        return float(geometry["radius"] + geometry["height"] / 2.0)
    return float(geometry["radius"])


def enclosing_shapes(robot: dict, device: dict, meshes: dict[int, tuple[dict, MeshParity]] | None = None) -> list[dict]:
    """The robot's shapes (not the device's own, not bounding-only) that hold the device's origin
    and that the device's rays would not see in Webots. A camera's or a range finder's rays start at
    its ``near`` distance, here as in Webots: a shape all within it (a sensor's housing the camera
    sits in, as in Webots' binocular sample) is never seen, so it is not one. ``meshes``: a cache
    of the robot's meshes, shared by the calls for its devices."""
    meshes = {} if meshes is None else meshes
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
        if not judged(geometry):    # scaled or stretched: not judged (``contains``)
            continue
        # farther from the shape's centre than its farthest point: outside, whatever its rotation
        # (a robot's shapes times its devices: most pairs end here, before any rotation is made)
        if float(np.linalg.norm(
                origin - np.asarray(part["pose"]["translation"], dtype=np.float64))) > reach(geometry, meshes) * (1.0 + 1e-9) + EPS:
            continue
        if not contains(geometry, _local(part["pose"], origin), meshes):
            continue
        if kind in IMAGERS:           # clipped whole by the near plane: no ray meets it
            centre = np.asarray(part["pose"]["translation"], dtype=np.float64)
            if float(np.linalg.norm(centre - origin)) + reach(geometry, meshes) < device.get("near", NEAR) - EPS:
                continue
        out.append(part)
    return out
