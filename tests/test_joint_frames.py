"""What ROS and Foxglove users see of moving joints (README "Joints", "See it in Foxglove"): a robot with
joints publishes ``sensor_msgs/JointState`` on ``/<robot>/joint_states``; in a recording and in a
ROS 2 export the frame of a device riding a joint, and the link frame its shapes are drawn in,
follow the joint on ``/tf`` (dynamic, as robot_state_publisher publishes a non-fixed joint's child);
a world without joints records and exports exactly the bytes it did before.

Closed form: a camera at (0.1, 0, 0.3) on a pan hinge (axis z through the robot's origin) turned
by q sits at (0.1 cos q, 0.1 sin q, 0.3) with the rotation (0, 0, sin(q/2), cos(q/2))."""

from __future__ import annotations

import hashlib
import math

import msgpack
import numpy as np
import pytest
from _node import require_node, run_script
from _recdata import recorded_simulation

pytest.importorskip("foxglove")

from sensorium.schemas import world as wm  # noqa: E402
from sensorium.server.daemon.topics import Topics  # noqa: E402
from sensorium.server.recording.reader import Recording  # noqa: E402
from sensorium.server.sim.simulation import Simulation  # noqa: E402

QUARTER = math.pi / 2
S = math.sin(QUARTER / 2)

PAN_WORLD = {
    "world_info": {"basic_time_step": 16, "random_seed": 3},
    "solids": [{"name": "wall", "pose": {"translation": [2.0, 0, 0.5]}, "geometry": {"type": "box", "size": [0.1, 4, 1]}}],
    "robots": [{"name": "plain", "controller": "<none>", "pose": {"translation": [0, 1, 0]},
                "devices": [{"device": "DistanceSensor", "name": "ds"}]},
               {"name": "r", "controller": "<none>",
                "shapes": [{"name": "base", "geometry": {"type": "box", "size": [0.2, 0.2, 0.1]}},
                           {"name": "head", "pose": {"translation": [0.1, 0, 0.3]}, "on_joint": "pan",
                            "geometry": {"type": "box", "size": [0.05, 0.05, 0.05]}}],
                "devices": [
                    # maxTorque 1e5, maxVelocity 100: full speed at once, a quarter turn in one step
                    {"device": "RotationalMotor", "name": "pan", "max_velocity": 100.0, "max_torque": 1e5,
                     "axis": [0, 0, 1]},
                    {"device": "PositionSensor", "name": "pan sensor", "motor": "pan"},
                    {"device": "Camera", "name": "cam", "width": 4, "height": 3, "on_joint": "pan",
                     "pose": {"translation": [0.1, 0, 0.3]}},
                    {"device": "DistanceSensor", "name": "fixed", "pose": {"translation": [0.1, 0, 0.1]}}]},
],
}

PLAIN_WORLD = {
    "world_info": {"basic_time_step": 16, "random_seed": 2},
    "solids": [{"name": "wall", "pose": {"translation": [1.0, 0, 0]}, "geometry": {"type": "box", "size": [0.1, 2, 2]},
                "appearance": {"base_color": [0.2, 0.6, 0.9]}}],
    "lights": [{"type": "PointLight", "location": [0.5, 0, 0.5]}],
    "robots": [{"name": "r", "controller": "<none>",
                "shapes": [{"geometry": {"type": "cylinder", "radius": 0.1, "height": 0.05}}],
                "differential_drive": {"wheel_radius": 0.02, "axle_length": 0.05, "max_wheel_speed": 10},
                "devices": [{"device": "DistanceSensor", "name": "ds", "pose": {"translation": [0.1, 0, 0.02]}},
                            {"device": "Camera", "name": "cam", "width": 4, "height": 3,
                             "pose": {"translation": [0.05, 0, 0.1], "rotation": [0, 0, 1, 0.3]}}]}],
}


def _record(path, world: dict, steps: int, turn: float | None = None) -> None:
    sim, topics, rec = recorded_simulation(path, world, "w.yaml")
    for k in range(steps):
        if k == 1 and turn is not None:
            sim.robot("r").motor("pan").set_position(turn)
        if k == 1 and "differential_drive" in world["robots"][0]:
            sim.robot("r").motor("left wheel motor").set_velocity(5.0)
        sim.step()
        topics.publish(sim.time_ms)
    rec.close()


@pytest.fixture(scope="module")
def pan_recording(tmp_path_factory):
    path = tmp_path_factory.mktemp("pan") / "pan.mcap"
    _record(path, PAN_WORLD, 3, turn=QUARTER)
    return path


def _turned_cam(q: float) -> tuple[list[float], list[float]]:
    return [0.1 * math.cos(q), 0.1 * math.sin(q), 0.3], [0.0, 0.0, math.sin(q / 2), math.cos(q / 2)]


def test_joint_states_carry_every_joint_of_a_robot_with_joints_only():
    sim = Simulation(wm.World.model_validate(PAN_WORLD))
    topics = Topics(sim)
    assert "/r/joint_states" in topics.by_name and "/plain/joint_states" not in topics.by_name
    got = []
    topics.set_recorder(lambda t, ty, env, body, ns, seq: got.append((t, ty, msgpack.unpackb(body, raw=False))),
                        ["/r/joint_states"])
    sim.step()
    topics.publish(sim.time_ms)
    sim.robot("r").motor("pan").set_position(QUARTER)
    sim.step()
    topics.publish(sim.time_ms)
    sim.step()
    topics.publish(sim.time_ms)
    assert [(t, ty) for t, ty, _ in got] == [("/r/joint_states", "sensor_msgs/msg/JointState")] * 3
    states = [b for _, _, b in got]
    assert [s["name"] for s in states] == [["pan"]] * 3
    assert [np.frombuffer(s["position"], "<f8").tolist() for s in states] == [[0.0], [QUARTER], [QUARTER]]
    # the velocity over the step: a quarter turn in 16 ms, then still
    assert [np.frombuffer(s["velocity"], "<f8").tolist() for s in states] == [[0.0], [QUARTER / 0.016], [0.0]]
    assert all(s["effort"] == b"" for s in states)
    assert [s["header"]["stamp"] for s in states] == [{"sec": 0, "nanosec": n * 16_000_000} for n in (1, 2, 3)]


def test_joint_states_are_computed_only_on_demand():
    sim = Simulation(wm.World.model_validate(PAN_WORLD))
    topics = Topics(sim)
    got = []
    topics.set_recorder(lambda t, *a: got.append(t), ["/r/pose"])
    sim.step()
    assert topics.publish(sim.time_ms) == [] and got == ["/r/pose"]
    assert topics.subscription(b"\x01/r/joint_states")
    sim.step()
    frames = topics.publish(sim.time_ms)
    assert [f[0] for f in frames] == [b"/r/joint_states\x00"]


def test_recording_tf_follows_the_pan_joint_in_foxglove_readers(pan_recording):
    require_node()
    got = run_script("read_mcap.js", str(pan_recording))[0]
    assert got["errors"] == []
    chans = {c["topic"]: c for c in got["channels"]}
    assert chans["/r/joint_states"]["schemaName"] == "sensor_msgs/msg/JointState"
    js = got["last"]["/r/joint_states"]["msg"]
    assert js["name"] == ["pan"] and js["position"] == [QUARTER] and js["velocity"] == [0.0] and js["effort"] == []
    # /tf: per pose (world -> robot, every mount) and per joint state (the riding frames only)
    with Recording(pan_recording) as rec:
        counts = {t.topic: t.count for t in rec.topics()}
    assert chans["/tf"]["count"] == counts["/r/pose"] + counts["/plain/pose"] + counts["/r/joint_states"]
    tf = got["last"]["/tf"]["msg"]["transforms"]          # the last pose's: the robot, then its mounts
    assert (tf[0]["parent_frame_id"], tf[0]["child_frame_id"]) == ("world", "r")
    last = {t["child_frame_id"]: t for t in tf[1:]}
    assert set(last) == {"r/pan", "r/pan sensor", "r/cam", "r/fixed", "r/pan/link"}
    t, q = _turned_cam(QUARTER)
    cam = last["r/cam"]
    assert cam["parent_frame_id"] == "r"
    assert [cam["translation"][k] for k in "xyz"] == pytest.approx(t, abs=1e-12)
    assert [cam["rotation"][k] for k in "xyzw"] == pytest.approx(q, abs=1e-12)
    link = last["r/pan/link"]
    assert [link["translation"][k] for k in "xyz"] == pytest.approx([0, 0, 0], abs=1e-12)
    assert [link["rotation"][k] for k in "xyzw"] == pytest.approx([0, 0, S, S], abs=1e-12)
    # /scene: the head is drawn in the link frame (where the file places it), the base on the robot
    ents = {e["id"]: e for e in got["last"]["/scene"]["msg"]["entities"]}
    head, base = ents["robot/r/pan"], ents["robot/r"]
    assert (head["frame_id"], head["frame_locked"], head["metadata"][0]["value"]) == ("r/pan/link", True, "link")
    assert [head["cubes"][0]["pose"]["position"][k] for k in "xyz"] == pytest.approx([0.1, 0, 0.3])
    assert base["frame_id"] == "r" and len(base["cubes"]) == 1


def test_recording_tf_per_pose_carries_the_turned_mounts(pan_recording):
    """Our own reader of the protobuf view: each pose's /tf places the camera where the joint is."""
    pytest.importorskip("google.protobuf")
    from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
    from mcap.reader import make_reader

    with open(pan_recording, "rb") as f:
        records = list(make_reader(f).iter_messages(["/tf"]))
    pool = descriptor_pool.DescriptorPool()
    for fd in descriptor_pb2.FileDescriptorSet.FromString(records[0][0].data).file:
        pool.Add(fd)
    cls = message_factory.GetMessageClass(pool.FindMessageTypeByName(records[0][0].name))
    tfs = [(m.log_time, cls.FromString(m.data)) for _s, _c, m in records]
    per_pose = [(ns, {x.child_frame_id: x for x in tf.transforms}) for ns, tf in tfs
                if tf.transforms[0].child_frame_id == "r"]
    assert [ns for ns, _ in per_pose] == [16_000_000, 32_000_000, 48_000_000]
    for ns, frames in per_pose:
        q = 0.0 if ns == 16_000_000 else QUARTER
        t, rot = _turned_cam(q)
        cam = frames["r/cam"]
        assert [cam.translation.x, cam.translation.y, cam.translation.z] == pytest.approx(t, abs=1e-12)
        assert [cam.rotation.x, cam.rotation.y, cam.rotation.z, cam.rotation.w] == pytest.approx(rot, abs=1e-12)
        fixed = frames["r/fixed"]               # on the body: where the file puts it, always
        assert (fixed.translation.x, fixed.translation.z, fixed.rotation.w) == (0.1, 0.1, 1.0)


def test_ros2_export_publishes_the_riding_frames_on_tf(pan_recording, tmp_path):
    from rosbags.highlevel import AnyReader

    from sensorium.server.recording.export import export_ros2

    report = export_ros2(pan_recording, tmp_path / "bag", distro="jazzy")
    assert not report.skipped
    with AnyReader([tmp_path / "bag"]) as reader:
        by_topic: dict[str, list] = {}
        for conn, _t, raw in reader.messages():
            by_topic.setdefault(conn.topic, []).append(reader.deserialize(raw, conn.msgtype))
    (static,) = by_topic["/tf_static"]
    assert {x.child_frame_id for x in static.transforms} == {"r/pan", "r/pan sensor", "r/fixed", "plain/ds"}
    joint_tfs = [m for m in by_topic["/tf"] if m.transforms[0].header.frame_id == "r"]
    assert len(joint_tfs) == 3 and len(by_topic["/tf"]) == 3 + 6
    for m, q in zip(joint_tfs, (0.0, QUARTER, QUARTER)):
        frames = {x.child_frame_id: x.transform for x in m.transforms}
        t, rot = _turned_cam(q)
        cam = frames["r/cam"]
        assert [cam.translation.x, cam.translation.y, cam.translation.z] == pytest.approx(t, abs=1e-12)
        assert [cam.rotation.x, cam.rotation.y, cam.rotation.z, cam.rotation.w] == pytest.approx(rot, abs=1e-12)
        assert frames["r/pan/link"].rotation.z == pytest.approx(math.sin(q / 2), abs=1e-12)
    (scene,) = by_topic["/scene"]                          # RViz draws the head in the link frame
    head = next(mk for mk in scene.markers if mk.ns == "robot/r/pan")
    assert (head.header.frame_id, head.frame_locked, head.pose.position.x) == ("r/pan/link", True, 0.1)
    js = by_topic["/r/joint_states"][-1]
    assert list(js.name) == ["pan"] and js.position.tolist() == [QUARTER] and js.effort.tolist() == []
    # exported without the joint states, the riding frames stay static (there is nothing to move them)
    export_ros2(pan_recording, tmp_path / "nojs", distro="jazzy", topics=["/r/pose", "/r/cam"])
    with AnyReader([tmp_path / "nojs"]) as reader:
        msgs = [(c.topic, reader.deserialize(raw, c.msgtype)) for c, _t, raw in reader.messages()]
    (static,) = [m for topic, m in msgs if topic == "/tf_static"]
    assert {"r/cam", "r/pan/link"} <= {x.child_frame_id for x in static.transforms}
    assert all(m.transforms[0].header.frame_id == "world" for topic, m in msgs if topic == "/tf")


# sha256 of a no-joint world's views (/tf, /scene of the recording; /tf, /tf_static, /scene of the
# ROS 2 export), as the code before joint frames wrote them
PLAIN_DIGEST = "fd6877e2e629fb252671d010df417154042198af4f1b510d22594d620444303f"


def _plain_digest(tmp_path) -> str:
    from mcap.reader import make_reader

    from sensorium.server.recording.export import export_ros2

    path = tmp_path / "plain.mcap"
    _record(path, PLAIN_WORLD, 4)
    h = hashlib.sha256()
    seen: list[str] = []
    with open(path, "rb") as f:
        for _s, c, m in make_reader(f).iter_messages(["/tf", "/scene"]):
            h.update(c.topic.encode() + m.log_time.to_bytes(8, "little") + m.data)
            seen.append(c.topic)
    export_ros2(path, tmp_path / "plain.bag.mcap", distro="jazzy")
    with open(tmp_path / "plain.bag.mcap", "rb") as f:
        for _s, c, m in make_reader(f).iter_messages(["/tf", "/tf_static", "/scene"]):
            h.update(c.topic.encode() + m.log_time.to_bytes(8, "little") + m.data)
            seen.append("export" + c.topic)
    assert sorted(seen) == sorted(["/scene"] + ["/tf"] * 4 + ["export/tf_static", "export/scene"] + ["export/tf"] * 4)
    return h.hexdigest()


def test_a_world_without_joints_records_and_exports_the_same_bytes(tmp_path):
    assert _plain_digest(tmp_path) == PLAIN_DIGEST
    with Recording(tmp_path / "plain.mcap") as rec:
        assert not any(t.topic.endswith("/joint_states") for t in rec.topics())


def _frame_transforms_class():
    pytest.importorskip("google.protobuf")
    from foxglove.messages import FrameTransforms
    from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

    schema = FrameTransforms.get_schema()
    pool = descriptor_pool.DescriptorPool()
    for fd in descriptor_pb2.FileDescriptorSet.FromString(bytes(schema.data)).file:
        pool.Add(fd)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(schema.name))


def test_live_viewer_tf_demands_joint_states_and_moves_the_riding_frames():
    from sensorium.server.viewer.bridge import FoxgloveBridge

    w = wm.World.model_validate(PAN_WORLD)
    sim = Simulation(w)
    topics = Topics(sim)
    bodies: dict[str, bytes] = {}
    topics.set_recorder(lambda t, ty, env, body, ns, seq: bodies.__setitem__(t, body), ["/r/joint_states", "/r/pose"])
    sim.robot("r").motor("pan").set_position(QUARTER)
    sim.step()
    topics.publish(sim.time_ms)
    demands: list[set[str]] = []
    b = FoxgloveBridge({t.name: t.type for t in topics.topics}, w, ".", port=0, on_demand=demands.append)
    try:
        b._subscribed(1, "/tf", +1)
        b.pump()
        assert demands[-1] == {"/plain/pose", "/r/pose", "/r/joint_states"}
        cls = _frame_transforms_class()
        moved = {x.child_frame_id: x for x in cls.FromString(b.joint_transforms_bytes("r", bodies["/r/joint_states"],
                                                                                         16_000_000)).transforms}
        assert set(moved) == {"r/cam", "r/pan/link"}
        posed = {x.child_frame_id: x for x in cls.FromString(b.transforms_bytes("r", bodies["/r/pose"],
                                                                                16_000_000)).transforms}
        t, rot = _turned_cam(QUARTER)
        for cam in (moved["r/cam"], posed["r/cam"]):
            assert [cam.translation.x, cam.translation.y, cam.translation.z] == pytest.approx(t, abs=1e-12)
            assert [cam.rotation.x, cam.rotation.y, cam.rotation.z, cam.rotation.w] == pytest.approx(rot, abs=1e-12)
    finally:
        b.close()
