"""A Solid's mass and centre of mass from its ``Physics`` node, by Webots' rules (WbPhysics, WbSolid).

``mass`` > 0 is the mass (``density`` then unused); ``mass`` -1 takes ``density`` × the volume of the
``boundingObject``. ``centerOfMass`` (its one item) is the centre in the Solid's frame; left empty, the
centre is the bounding object's centroid (every part of the same density), or the Solid's origin when
it has none. Values Webots would not use are reset as Webots resets them, one warning at the field's line:
``density`` <= 0 (but -1 with a positive mass) becomes 1000, ``mass`` <= 0 other than -1 becomes -1.

Volumes: Box, Sphere, Cylinder and Capsule in closed form; an IndexedFaceSet's from its faces (the
signed tetrahedra from the origin to each triangle of a fan: a closed mesh's volume and centroid);
an ElevationGrid or a Plane adds none. A Mesh's file is read by the loader, later: the import records
the Physics as a ``pending_mass`` (the other shapes' volume and centroid, the density, the mesh files
where they are) and the loader completes it (:func:`completed_mass`), each file's triangles weighed as
ODE's dMassSetTrimesh weighs them (:func:`trimesh_volume`). Poses and Transforms place (and a
Transform's scale scales) what they hold; Groups and Shapes hold geometries.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from sensorium.server.world.poses import axis_angle_matrix, matrix_quaternion
from sensorium.server.world.wbt.parser import Node

DENSITY = 1000.0
"""Webots' Physics ``density`` default and reset value (kg/m³)."""


def solid_mass(conv: Any, solid: Node) -> dict:
    """The fields a Solid with a ``Physics`` node adds to its entry: ``{"mass": {"kg", "center"}}`` (the
    centre in the Solid's frame), or ``{"pending_mass": ...}`` when mesh files in its bounding object
    count (the loader completes it); ``{}`` without Physics, or when its mass comes from a density and
    its bounding object has no volume here (said in a warning)."""
    physics = conv.fields(solid).node_("physics")
    if physics is None or physics.type != "Physics":
        return {}
    f = conv.fields(physics)
    mass = f.num("mass", -1.0)
    density = f.num("density", DENSITY)
    if (mass <= 0 and density <= 0) or (density <= 0 and density != -1):
        density = f.used("density", density, DENSITY, "is not > 0" if density != -1 else
                         "is -1 while the mass is not > 0")
    if mass <= 0 and mass != -1:
        mass = f.used("mass", mass, -1.0, "is not > 0 (nor -1: computed from the density)")
    centers = f.rows("centerOfMass", 3, [])
    if len(centers) > 1:                # Webots keeps the first
        conv.warn_once(physics, f"Physics.centerOfMass: {len(centers)} items; it holds 0 or 1: the first is used "
                                "(as Webots does)")
    if mass > 0 and centers:            # all given: the bounding object is not needed
        return {"mass": {"kg": float(mass), "center": [float(v) for v in centers[0]]}}
    meshes: list[dict] = []
    volume, centroid = _volume(conv, conv.fields(solid).node_("boundingObject"), np.eye(3), np.zeros(3), 1.0, meshes)
    if meshes:
        pending: dict[str, Any] = {"volume": float(volume), "centroid": [float(v) for v in centroid],
                                   "meshes": meshes}
        if mass > 0:
            pending["kg"] = float(mass)
        else:
            pending["density"] = float(density)
        if centers:
            pending["center"] = [float(v) for v in centers[0]]
        return {"pending_mass": pending}
    if mass > 0:
        kg = mass
    elif volume > 0:
        kg = density * volume
    else:
        conv.warn_once(physics, "Physics: mass -1 takes density × the boundingObject's volume, and it has no volume here "
                                "(give a mass): it counts for no mass (getCenterOfMass reads it as without physics)")
        return {}
    center = centers[0] if centers else centroid if volume > 0 else (0.0, 0.0, 0.0)
    return {"mass": {"kg": float(kg), "center": [float(v) for v in center]}}


REFERENCE_DENSITY = 1000.0
"""Webots weighs a bounding object at this density, then scales to the Physics' mass or density: a mesh whose
mass properties fail counts as 1 kg at it (WbSolidUtilities' default mass), 0.001 m³ beside the others."""


def trimesh_volume(vertices: np.ndarray, faces: np.ndarray) -> tuple[float, np.ndarray] | None:
    """(volume, centroid) of triangles as ODE's dMassSetTrimesh weighs them (Mirtich's integrals over the
    faces as wound, outward counter-clockwise): the flux of x e_x through them is the volume, of x_i² e_i / 2
    the first moments. For a closed mesh wound outward, its volume and centroid; an open or inward-wound
    one gives what the formula gives. None where Webots gives up on it (a mass <= 0 or an inertia about
    the centre that is not positive definite, after ODE's own translation of it)."""
    v = np.asarray(vertices, dtype=np.float64)
    t = v[np.asarray(faces, dtype=np.int64).reshape(-1, 3)]          # (m, 3 corners, 3 axes)
    if len(t) == 0:
        return None
    half_n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]) / 2.0     # n dA integrated: the area vector
    s1 = t.sum(axis=1)                                                # sums of corner values per axis
    s2 = (t * t).sum(axis=1)
    s3 = (t ** 3).sum(axis=1)
    mean1 = s1 / 3.0                                                  # means over a triangle of linear,
    mean2 = (s2 + s1 * s1) / 12.0                                     # quadratic and cubic monomials
    mean3 = (s1 ** 3 + 3.0 * s1 * s2 + 2.0 * s3) / 60.0
    volume = float(np.sum(half_n[:, 0] * mean1[:, 0]))
    moments = (half_n * mean2).sum(axis=0) / 2.0
    squares = (half_n * mean3).sum(axis=0) / 3.0                      # the integrals of x², y², z² over the volume
    b = t[:, :, [1, 2, 0]]                                            # the means of x²y, y²z, z²x
    sb = b.sum(axis=1)
    mean_aab = (s1 * s1 * sb + s2 * sb + 2.0 * (t * b).sum(axis=1) * s1 + 2.0 * (t * t * b).sum(axis=1)) / 60.0
    products = (half_n * mean_aab).sum(axis=0) / 2.0
    mass = REFERENCE_DENSITY * volume
    if not mass > 0.0:
        return None
    centre = moments / volume
    inertia = REFERENCE_DENSITY * np.array([
        [squares[1] + squares[2], -products[0], -products[2]],
        [-products[0], squares[2] + squares[0], -products[1]],
        [-products[2], -products[1], squares[0] + squares[1]]])
    inertia += mass * (float(centre @ centre) * np.eye(3) - np.outer(centre, centre))    # ODE's dMassTranslate
    try:
        np.linalg.cholesky(inertia)
    except np.linalg.LinAlgError:
        return None
    return volume, centre


def completed_mass(pending: Any, volumes: list[tuple[float, np.ndarray]]) -> dict:
    """A ``pending_mass``'s ``{"kg", "center"}`` with the volume and centroid of each of its meshes (in
    the node's frame), by Webots' rules: one density over the bounding object."""
    total = pending.volume + sum(v for v, _ in volumes)
    centroid = (pending.volume * np.asarray(pending.centroid) + sum(v * c for v, c in volumes)) / total
    kg = pending.kg if pending.kg is not None else pending.density * total
    center = pending.center if pending.center is not None else centroid
    return {"kg": float(kg), "center": [float(x) for x in center]}


def _volume(conv: Any, node: Node | None, rot: np.ndarray, at: np.ndarray, scale: float, meshes: list[dict]
            ) -> tuple[float, tuple]:
    """The volume of what ``node`` holds and its centroid in the Solid's frame (``rot``, ``at`` and
    ``scale`` place the node's frame there); its mesh files appended to ``meshes`` (``MassMesh``)."""
    parts = _parts(conv, node, rot, at, scale, meshes)
    total = sum(v for v, _ in parts)
    if total <= 0:
        return 0.0, (0.0, 0.0, 0.0)
    with np.errstate(invalid="ignore", over="ignore"):      # an infinite volume: a mass the load refuses
        c = sum(v * np.asarray(p) for v, p in parts) / total
    return total, tuple(float(x) for x in c)


def _parts(conv: Any, node: Node | None, rot: np.ndarray, at: np.ndarray, scale: np.ndarray | float,
           meshes: list[dict]) -> list[tuple[float, np.ndarray]]:
    if node is None:
        return []
    f = conv.fields(node)
    t = node.type
    if t in ("Group", "Pose", "Transform"):
        if t != "Group":
            r = f.vec("rotation", (0.0, 0.0, 1.0, 0.0))
            inner_at = at + rot @ (np.asarray(f.vec("translation", (0.0, 0.0, 0.0))) * scale)
            inner_rot = rot @ axis_angle_matrix(r[:3], r[3])
            inner_scale = scale * np.asarray(f.vec("scale", (1.0, 1.0, 1.0))) if t == "Transform" else scale
        else:
            inner_at, inner_rot, inner_scale = at, rot, scale
        return [p for child in f.nodes("children")
                for p in _parts(conv, child, inner_rot, inner_at, inner_scale, meshes)]
    if t == "Shape":
        return _parts(conv, f.node_("geometry"), rot, at, scale, meshes)
    s = np.broadcast_to(np.asarray(scale, dtype=np.float64), (3,))
    factor = float(abs(s[0] * s[1] * s[2]))     # a Transform's scale over a geometry (Webots keeps it uniform)
    if t in ("Box", "Sphere", "Cylinder", "Capsule"):
        # the sizes the shape has: Webots' defaults, and its resets of a non-positive one (said at the field)
        g, _ = conv.base_geometry(node, 1.0)
        if t == "Box":
            size = g["size"]
            return [(size[0] * size[1] * size[2] * factor, at)]
        r = g["radius"]
        cube = r * r * r        # (not r ** 3: a radius of 1e308 overflows to inf, refused as the mass, not raised)
        if t == "Sphere":
            return [(4.0 / 3.0 * math.pi * cube * factor, at)]
        h = g["height"]
        cap = 4.0 / 3.0 * math.pi * cube if t == "Capsule" else 0.0
        return [((math.pi * r * r * h + cap) * factor, at)]
    if t == "IndexedFaceSet":
        return _mesh_part(conv, node, rot, at, s)
    if t == "Mesh":
        mesh, _ = conv.base_geometry(node, 1.0)     # (a file left out is said where its shape is: it adds nothing)
        if mesh is not None:
            placed = {"translation": [float(x) for x in at]}
            if not np.array_equal(rot, np.eye(3)):
                placed["quaternion"] = [float(x) for x in matrix_quaternion(rot)]
            meshes.append({"mesh": {**mesh, "scale": [float(x) for x in s]}, "pose": placed})
    return []


def _mesh_part(conv: Any, node: Node, rot: np.ndarray, at: np.ndarray, s: np.ndarray
               ) -> list[tuple[float, np.ndarray]]:
    """A closed IndexedFaceSet's volume and centroid: the signed tetrahedra from the origin to each
    triangle of every face's fan (either winding)."""
    f = conv.fields(node)
    coord = f.node_("coord")
    if coord is None:
        return []
    points = conv.fields(coord).row_array("point", 3)
    index = np.asarray(f.index_array("coordIndex"), dtype=np.int64)
    if len(points) == 0 or len(index) == 0 or index.max() >= len(points):
        return []
    world = (points * s) @ rot.T + at
    volume, moment = 0.0, np.zeros(3)
    face: list[int] = []
    for k in list(index) + [-1]:
        if k >= 0:
            face.append(int(k))
            continue
        for i in range(1, len(face) - 1):
            a, b, c = world[face[0]], world[face[i]], world[face[i + 1]]
            v = float(np.dot(a, np.cross(b, c))) / 6.0
            volume += v
            moment += v * (a + b + c) / 4.0
        face = []
    if abs(volume) < 1e-300:
        conv.warn_once(node, "an IndexedFaceSet in a boundingObject that encloses no volume: it adds no mass")
        return []
    return [(abs(volume), moment / volume)]     # faces turned inward (ccw FALSE): the same solid
