"""What makes a recording open in Foxglove: per-topic CDR views, ``/tf``, ``/scene``, and the
lossless wire channels they sit next to.

Layout of a Foxglove-ready recording (``sensorium`` metadata ``format = "2"``):

* ``/sensorium/wire<topic>`` — the published msgpack body, byte for byte, wrapped as the ROS 2
  message ``sensorium_msgs/msg/WireBody`` (``uint8[] body``: a 4-byte CDR header and a 4-byte length
  before the bytes, nothing re-encoded). Channel metadata ``sensorium.topic`` and ``sensorium.type``
  name the topic and its ROS type; ``log_time``/``sequence`` carry the envelope exactly as in
  format 1. Replay, export and ``info`` read only these channels, so replay stays byte-exact.
* ``<topic>`` — the same message as ROS 2 CDR with its ``ros2msg`` schema (the bytes of
  :class:`~sensorium.server.recording.export.CdrEncoder`, as ``sensorium export`` and the live
  viewer produce them; ``PointCloud`` as ``PointCloud2``): what Foxglove's panels plot and draw.
* ``/tf`` — ``foxglove.FrameTransforms`` per robot pose (``world → robot`` and the device mounts),
  and per ``/<robot>/joint_states`` the mounts of the devices riding its joints, moved with them;
  ``/scene`` — one ``foxglove.SceneUpdate`` of the world at time 0 (robot bodies follow ``/tf``).

Views need rosbags and foxglove-sdk (the ``foxglove`` extra); without them a recorder writes format 1
(msgpack channels only) and says so.
"""

from __future__ import annotations

import struct
from pathlib import Path
from typing import Any

import msgpack

from sensorium.server.recording.ros_views import joint_positions, joint_states_robot, pose_robot

__all__ = ["WIRE_PREFIX", "WIRE_SCHEMA", "WIRE_MSGDEF", "wire_wrap", "wire_unwrap", "available", "FoxgloveViews"]

WIRE_PREFIX = "/sensorium/wire"
WIRE_SCHEMA = "sensorium_msgs/msg/WireBody"
WIRE_MSGDEF = "# A Sensorium topic message exactly as published (msgpack body, PROTOCOL.md section 4)\nuint8[] body\n"
_CDR_LE = b"\x00\x01\x00\x00"


def wire_wrap(body: bytes) -> bytes:
    """msgpack body → CDR ``WireBody`` (header, uint32 length, the bytes)."""
    return _CDR_LE + struct.pack("<I", len(body)) + body


def wire_unwrap(data: bytes) -> bytes:
    """CDR ``WireBody`` → the msgpack body (checks header and length)."""
    if len(data) < 8 or data[:2] != b"\x00\x01":
        raise ValueError("not a little-endian CDR WireBody")
    (n,) = struct.unpack_from("<I", data, 4)
    if 8 + n > len(data):
        raise ValueError(f"WireBody says {n} bytes, has {len(data) - 8}")
    return bytes(data[8:8 + n])


def available() -> str | None:
    """``None`` if the views can be written, else why not."""
    try:
        import foxglove.messages  # noqa: F401
        import rosbags.typesys  # noqa: F401
    except ImportError as exc:
        return f"{exc.name} is not installed (pip install 'sensorium[foxglove]')"
    return None


class FoxgloveViews:
    """Per message, the extra Foxglove-readable records: ``views(topic, type, body, ns)`` →
    ``[(channel topic, schema name, schema encoding, schema data, message encoding, data)]``.
    Messages that do not convert are counted in ``errors`` (the wire copy is always kept)."""

    def __init__(self, world: Any = None, base_dir: str | Path = ".", distro: str = "jazzy"):
        from sensorium.server.recording import scene3d as fxscene
        from sensorium.server.recording.export import CdrEncoder
        from sensorium.server.recording.frames import JointFrames, mounts

        self._scene = fxscene
        self.encoder = CdrEncoder(distro, pointcloud2=True)
        self.world = world
        self.base_dir = Path(base_dir)
        self.mounts = mounts(world) if world is not None else {}
        self.joint_frames = JointFrames(world) if world is not None else None
        self.errors: dict[str, str] = {}
        from foxglove.messages import FrameTransforms, SceneUpdate
        self._tf_schema = FrameTransforms.get_schema()
        self._scene_schema = SceneUpdate.get_schema()

    def scene(self, drawn: dict[int, Any] | None = None) -> tuple[str, str, str, bytes, str, bytes] | None:
        """The ``/scene`` record, or ``None`` without a world. ``drawn``: the shapes a Supervisor
        recoloured (``Scene.drawn_models``), drawn as they look now."""
        if self.world is None:
            return None
        data = self._scene.scene_update(self.world, self.base_dir, 0, drawn=drawn).encode()
        s = self._scene_schema
        return ("/scene", s.name, s.encoding, bytes(s.data), "protobuf", data)

    def views(self, topic: str, ros_type: str, body: bytes, stamp_ns: int) -> list[tuple[str, str, str, bytes, str, bytes]]:
        out = []
        try:
            typename, data = self.encoder.encode(ros_type, body)
        except Exception as exc:  # noqa: BLE001 - a body that does not convert keeps only its wire copy
            self.errors.setdefault(topic, f"{type(exc).__name__}: {exc}")
        else:
            out.append((topic, typename, "ros2msg", self.encoder.msgdef(typename).encode(), "cdr", data))
        robot = pose_robot(topic, ros_type)
        if robot is not None:
            try:
                p = msgpack.unpackb(body, raw=False)["pose"]
                t = (p["position"]["x"], p["position"]["y"], p["position"]["z"])
                q = (p["orientation"]["x"], p["orientation"]["y"], p["orientation"]["z"], p["orientation"]["w"])
            except (KeyError, TypeError, ValueError) as exc:
                self.errors.setdefault("/tf", f"{topic}: {type(exc).__name__}: {exc}")
            else:
                s = self._tf_schema
                data = self._scene.frame_transforms(robot, stamp_ns, t, q, self.mounts.get(robot, [])).encode()
                out.append(("/tf", s.name, s.encoding, bytes(s.data), "protobuf", data))
        robot = joint_states_robot(topic, ros_type)
        if robot is not None and self.joint_frames is not None and robot in self.joint_frames.robots:
            try:
                moved = self.joint_frames.update(robot, *joint_positions(body))
            except (KeyError, TypeError, ValueError) as exc:
                self.errors.setdefault("/tf", f"{topic}: {type(exc).__name__}: {exc}")
            else:        # the riding devices' frames move now, and the next poses' /tf carries them too
                at = {m[0]: m for m in moved}
                self.mounts[robot] = [at.get(m[0], m) for m in self.mounts[robot]]
                s = self._tf_schema
                data = self._scene.mount_transforms(robot, stamp_ns, moved).encode()
                out.append(("/tf", s.name, s.encoding, bytes(s.data), "protobuf", data))
        return out
