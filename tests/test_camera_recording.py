"""Camera and range-finder images (issue 23) in recordings: the wire copy is the published body, the
Foxglove view decodes under Foxglove's own readers (Node) as a bgra8 / 32FC1 Image with the device's
bytes, a CameraInfo with its pinhole; a ROS 2 bag export carries both; the layout shows the camera."""

from __future__ import annotations

import math

import msgpack
import pytest
from _node import require_node, run_script
from _recdata import recorded_simulation

pytest.importorskip("foxglove")

from sensorium.server.recording.reader import Recording  # noqa: E402

WORLD = {
    "world_info": {"basic_time_step": 16, "random_seed": 2},
    "solids": [{"name": "wall", "pose": {"translation": [1.0, 0, 0]}, "geometry": {"type": "box", "size": [0.1, 2, 2]},
                "appearance": {"base_color": [0.2, 0.6, 0.9]}}],
    "lights": [{"type": "PointLight", "location": [0.5, 0, 0.5]}],
    "robots": [{"name": "r", "controller": "<none>",
                "devices": [{"device": "Camera", "name": "cam", "width": 8, "height": 6, "field_of_view": 0.8},
                            {"device": "RangeFinder", "name": "depth", "width": 4, "height": 3, "max_range": 5}]}],
}


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    path = tmp_path_factory.mktemp("cam") / "run.mcap"
    sim, topics, rec = recorded_simulation(path, WORLD, "cam.yaml")
    images = []
    for _ in range(3):
        sim.step()
        topics.publish(sim.time_ms)
        images.append((sim.device("r/cam").image.tobytes(), sim.device("r/depth").range_image.tobytes()))
    rec.close()
    return path, images


def test_recorded_images_are_the_devices_bytes(recording):
    path, images = recording
    with Recording(path) as rec:
        types = {t.topic: t.ros_type for t in rec.topics()}
        msgs = [m for m in rec.messages() if m.topic in ("/r/cam/image", "/r/depth/range_image")]
    assert types["/r/cam/image"] == types["/r/depth/range_image"] == "sensor_msgs/msg/Image"
    assert types["/r/cam/camera_info"] == types["/r/depth/camera_info"] == "sensor_msgs/msg/CameraInfo"
    cams = [msgpack.unpackb(m.data, raw=False) for m in msgs if m.topic == "/r/cam/image"]
    assert [c["data"] for c in cams] == [i[0] for i in images] and cams[0]["encoding"] == "bgra8"


def test_foxglove_readers_decode_the_image_views(recording):
    require_node()
    path, images = recording
    got = run_script("read_mcap.js", str(path))[0]
    assert got["errors"] == []
    cam = got["last"]["/r/cam/image"]["msg"]
    assert (cam["encoding"], cam["width"], cam["height"], cam["step"]) == ("bgra8", 8, 6, 32)
    assert bytes(cam["data"]) == images[-1][0]
    depth = got["last"]["/r/depth/range_image"]["msg"]
    assert depth["encoding"] == "32FC1" and bytes(depth["data"]) == images[-1][1]
    info = got["last"]["/r/cam/camera_info"]["msg"]
    assert info["k"][0] == pytest.approx(4.0 / math.tan(0.4)) and info["k"][2] == 3.5


def test_ros2_export_carries_images_and_camera_info(recording, tmp_path):
    from rosbags.highlevel import AnyReader

    from sensorium.server.recording.export import export_ros2
    path, images = recording
    export_ros2(path, tmp_path / "bag", distro="jazzy")
    with AnyReader([tmp_path / "bag"]) as reader:
        conns = {c.topic: c for c in reader.connections}
        assert conns["/r/cam/image"].msgtype == "sensor_msgs/msg/Image"
        last = {}
        for conn, _, raw in reader.messages(connections=[conns["/r/cam/image"], conns["/r/cam/camera_info"]]):
            last[conn.topic] = reader.deserialize(raw, conn.msgtype)
    img = last["/r/cam/image"]
    assert img.encoding == "bgra8" and bytes(img.data) == images[-1][0]
    assert last["/r/cam/camera_info"].width == 8 and last["/r/cam/camera_info"].distortion_model == "plumb_bob"


def test_layout_shows_the_camera_image():
    from sensorium.server.viewer.layout import layout_json
    text = layout_json({"/r/depth/range_image": "sensor_msgs/msg/Image", "/r/cam/image": "sensor_msgs/msg/Image"})
    assert '"imageTopic":"/r/cam/image"' in text.replace(" ", "") and "range_image" not in text
    assert "Camera image" in text


@pytest.mark.slow
def test_live_foxglove_client_sees_the_camera_image():
    """`serve --foxglove`: Foxglove's own client (@foxglove/ws-protocol, Node) subscribes to a camera
    image; it arrives as a bgra8 Image whose bytes are the ones a ZeroMQ subscriber gets."""
    import base64
    import signal
    import time
    from pathlib import Path

    import zmq
    from _node import NodeProcess
    from _serve import serve

    from sensorium.server.recording.export import CdrEncoder
    require_node()
    world = Path(__file__).parent / "worlds" / "images.yaml"
    srv = serve(world, "--precision", "fast", "--watch", "--mode", "fast", "--foxglove", "127.0.0.1:0")
    ctx = zmq.Context()
    node = None
    try:
        node = NodeProcess("live_client.js", srv.fields["foxglove"])
        adv = node.wait_for(lambda e: e["event"] == "advertise", what="advertise")
        chans = {c["topic"]: c for c in adv["channels"]}
        assert chans["/bot/camera/image"]["schemaName"] == "sensor_msgs/msg/Image"
        sub = ctx.socket(zmq.SUB)
        sub.setsockopt(zmq.LINGER, 0)
        sub.connect(srv.fields["pub"])
        sub.setsockopt(zmq.SUBSCRIBE, b"/bot/camera/image\0")
        node.send(cmd="subscribe", topic="/bot/camera/image")
        # both streams are read together until an image seen by both turns up (a loaded machine may
        # make the viewer's bounded queue skip some images, so any common one will do)
        ours: dict[int, bytes] = {}
        theirs: dict[int, dict] = {}
        ev = None
        deadline = time.monotonic() + 120
        while ev is None and time.monotonic() < deadline:
            if sub.poll(50):
                _topic, env, body = sub.recv_multipart()
                ours[msgpack.unpackb(env)["stamp_ns"]] = body
            for e in node.drain():
                if e["event"] == "message" and e["topic"] == "/bot/camera/image":
                    theirs[e["log_time"]] = e
            common = sorted(set(ours) & set(theirs))
            ev = theirs[common[0]] if common else None
            assert node.proc.poll() is None, f"the Node client exited: {node.proc.poll()}"
        sub.close(0)
        assert ev is not None, f"no camera image seen by both in 120 s ({len(ours)} over ZeroMQ, {len(theirs)} in Foxglove)"
        m = ev["msg"]
        body = msgpack.unpackb(ours[ev["log_time"]], raw=False)
        assert (m["encoding"], m["width"], m["height"]) == ("bgra8", 16, 12) and bytes(m["data"]) == body["data"]
        assert base64.b64decode(ev["raw"]) == CdrEncoder("jazzy").encode_generic("sensor_msgs/msg/Image",
                                                                                 ours[ev["log_time"]])
    finally:
        if node is not None:
            node.close()
        code = srv.stop(signal.SIGTERM)
        ctx.destroy(0)
        assert code == 0, srv.stderr()
