"""The scene and transforms of an exported ROS 2 bag, in standard ROS 2 types.

``sensorium export --ros2`` adds, next to the recorded topics (when the recording's world has them):

* ``/tf_static`` — ``tf2_msgs/msg/TFMessage`` once at the first message time: ``<robot> →
  <robot>/<device>`` for every fixed device mount;
* ``/tf`` — ``tf2_msgs/msg/TFMessage`` per recorded ``/<robot>/pose``: ``world → <robot>``; and
  per recorded ``/<robot>/joint_states``: ``<robot> → <robot>/<device>`` of each device riding a
  joint (then dynamic, left out of ``/tf_static``, as robot_state_publisher does);
* ``/scene`` — ``visualization_msgs/msg/MarkerArray`` once: solids (cube, sphere, cylinder markers;
  capsules and meshes as triangle lists; planes as flat cubes, an infinite one 50 m wide), robot
  bodies in their robot's frame (``frame_locked``), lights as spheres and arrows in their colour.

RViz and Foxglove both display these. Message dicts here are filled up to each distro's definition
by :func:`sensorium.server.recording.export.to_ros`'s converter (fields not set are zero).
"""

from __future__ import annotations

import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import msgpack
import numpy as np

from sensorium.schemas import world as wm

__all__ = ["TF", "MARKER_ARRAY", "recorded_world", "tf_static", "tf_pose", "tf_joints", "marker_array", "pose_robot",
           "joint_states_robot", "joint_positions"]

TF = "tf2_msgs/msg/TFMessage"
MARKER_ARRAY = "visualization_msgs/msg/MarkerArray"
_ARROW, _CUBE, _SPHERE, _CYLINDER, _TRIANGLE_LIST = 0, 1, 2, 3, 11
_FLAT = 1e-3                      # thickness of a plane's cube marker (a zero scale is invalid in RViz)


@contextmanager
def recorded_world(rec: Any) -> Iterator[tuple[wm.World | None, Path]]:
    """The world model attached to a recording, with its attachments unpacked to a temporary
    directory so that mesh files resolve (removed when the context ends), or ``(None, .)`` when it
    is missing or does not load."""
    from sensorium.server.world.loader import WorldError, load_world

    found = rec.world()
    if found is None:
        yield None, Path(".")
        return
    with tempfile.TemporaryDirectory(prefix="sensorium-world-") as unpacked:
        tmp = Path(unpacked)
        world: wm.World | None
        try:
            for a in rec.attachments():
                target = (tmp / a.name).resolve()
                if tmp.resolve() in target.parents and not target.exists():
                    target.parent.mkdir(parents=True, exist_ok=True)
                    target.write_bytes(a.data)
            world = load_world(tmp / found[0]).world
        except (WorldError, OSError, ValueError):
            world = None
        yield (world, tmp) if world is not None else (None, Path("."))


def pose_robot(topic: str, ros_type: str) -> str | None:
    """The robot of a ``/<robot>/pose`` topic, else ``None``."""
    if ros_type == "geometry_msgs/msg/PoseStamped" and topic.endswith("/pose") and topic.count("/") == 2:
        return topic[1:-len("/pose")]
    return None


def joint_states_robot(topic: str, ros_type: str) -> str | None:
    """The robot of a ``/<robot>/joint_states`` topic, else ``None``."""
    if ros_type == "sensor_msgs/msg/JointState" and topic.endswith("/joint_states") and topic.count("/") == 2:
        return topic[1:-len("/joint_states")]
    return None


def joint_positions(body: bytes) -> tuple[list[str], list[float]]:
    """(names, positions) of a recorded JointState body."""
    m = msgpack.unpackb(body, raw=False)
    return [str(n) for n in m["name"]], np.frombuffer(m["position"], dtype="<f8").tolist()


def _stamp(ns: int) -> dict:
    return {"sec": int(ns) // 1_000_000_000, "nanosec": int(ns) % 1_000_000_000}


def _tf(parent: str, child: str, ns: int, t, q) -> dict:
    return {"header": {"stamp": _stamp(ns), "frame_id": parent}, "child_frame_id": child,
            "transform": {"translation": dict(zip("xyz", (float(v) for v in t))),
                          "rotation": dict(zip("xyzw", (float(v) for v in q)))}}


def tf_static(world: wm.World, ns: int, moving: frozenset[str] = frozenset()) -> dict | None:
    """Every device mount but the frames of ``moving`` (devices riding a joint whose states were
    recorded: dynamic, on ``/tf``), or ``None`` if that leaves none."""
    from sensorium.server.recording.frames import mounts

    items = [_tf(robot, frame, ns, t, q) for robot, ms in mounts(world).items() for frame, t, q in ms
             if frame not in moving]
    return {"transforms": items} if items else None


def tf_joints(robot: str, robot_mounts: list, ns: int) -> dict:
    """``robot → robot/device`` for the devices a joint moves (``frames.JointFrames.update``)."""
    return {"transforms": [_tf(robot, frame, ns, t, q) for frame, t, q in robot_mounts]}


def tf_pose(robot: str, pose_body: bytes, ns: int) -> dict:
    """``world → robot`` from a recorded PoseStamped body."""
    p = msgpack.unpackb(pose_body, raw=False)["pose"]
    return {"transforms": [_tf("world", robot, ns, (p["position"][k] for k in "xyz"),
                               (p["orientation"][k] for k in "xyzw"))]}


def _color(shape: Any, ghost: bool) -> dict:
    from sensorium.server.recording.frames import shape_rgba

    return dict(zip("rgba", shape_rgba(shape, ghost)))


def _ros_pose(t, q) -> dict:
    return {"position": dict(zip("xyz", (float(v) for v in t))), "orientation": dict(zip("xyzw", (float(v) for v in q)))}


def _shape_marker(shape: wm.Shape, frame: str, ns_name: str, mid: int, t, q, stamp: int, base_dir: Path,
                  locked: bool, ghost: bool = False) -> dict:
    from sensorium.server.recording.frames import INFINITE_PLANE_SIZE
    from sensorium.server.sim.scene import primitive_from_model
    from sensorium.server.world import geometry as geo

    g = shape.geometry
    m: dict[str, Any] = {"header": {"stamp": _stamp(stamp), "frame_id": frame}, "ns": ns_name, "id": mid, "action": 0,
                         "pose": _ros_pose(t, q), "color": _color(shape, ghost), "frame_locked": locked,
                         "scale": {"x": 1.0, "y": 1.0, "z": 1.0}}
    if isinstance(g, wm.Box):
        m.update(type=_CUBE, scale=dict(zip("xyz", (float(v) for v in g.size))))
    elif isinstance(g, wm.Sphere):
        d = 2.0 * g.radius
        m.update(type=_SPHERE, scale={"x": d, "y": d, "z": d})
    elif isinstance(g, wm.Cylinder):
        d = 2.0 * g.radius
        m.update(type=_CYLINDER, scale={"x": d, "y": d, "z": g.height})
    elif isinstance(g, wm.Plane):
        sx, sy = g.size if g.size is not None else (INFINITE_PLANE_SIZE, INFINITE_PLANE_SIZE)
        m.update(type=_CUBE, scale={"x": float(sx), "y": float(sy), "z": _FLAT})
    else:
        v, f = geo.tessellate(primitive_from_model(g, base_dir))
        tri = np.asarray(v, dtype=np.float64)[np.asarray(f, dtype=np.int64).reshape(-1)]
        m.update(type=_TRIANGLE_LIST, points=[{"x": x, "y": y, "z": z} for x, y, z in tri.tolist()])
    return m


def marker_array(world: wm.World, base_dir: str | Path, stamp: int) -> dict | None:
    """The world as markers (one namespace per solid, robot body or light), or ``None`` if empty."""
    from sensorium.server.recording.frames import bodies, lights, quat_from_x
    from sensorium.server.world.poses import matrix_quaternion

    base = Path(base_dir)
    markers = []
    for body in bodies(world):
        for k, (shape, pose, ghost) in enumerate(body.parts):
            markers.append(_shape_marker(shape, body.frame_id, body.entity_id, k, pose.translation,
                                         matrix_quaternion(pose.rotation), stamp, base, body.frame_locked, ghost))
    for entity_id, frame_id, locked, light in lights(world):
        c = {"r": float(light.color[0]), "g": float(light.color[1]), "b": float(light.color[2]),
             "a": 1.0 if light.on else 0.3}
        hdr = {"stamp": _stamp(stamp), "frame_id": frame_id}
        loc = getattr(light, "location", None)
        if loc is not None:
            markers.append({"header": hdr, "ns": entity_id, "id": 0, "type": _SPHERE, "action": 0,
                            "pose": _ros_pose(loc, (0, 0, 0, 1)), "scale": {"x": 0.1, "y": 0.1, "z": 0.1}, "color": c,
                            "frame_locked": locked})
        direction = getattr(light, "direction", None)
        if direction is not None:
            d = np.asarray(direction, dtype=np.float64)
            q = quat_from_x(d / np.linalg.norm(d))
            markers.append({"header": hdr, "ns": entity_id, "id": 1, "type": _ARROW, "action": 0,
                            "pose": _ros_pose(loc if loc is not None else (0.0, 0.0, 1.0), q),
                            "scale": {"x": 0.25, "y": 0.02, "z": 0.02}, "color": c, "frame_locked": locked})
    return {"markers": markers} if markers else None
