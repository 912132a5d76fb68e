"""A Display's image in a recording: the MCAP carries /<robot>/<display>/image as a bgra8
sensor_msgs/Image with the server's pixels, Foxglove's own readers (Node) decode its view, and a
ROS 2 bag export carries it, as for a camera image."""

from __future__ import annotations

import msgpack
import numpy as np
import pytest
from _node import require_node, run_script
from _recdata import recorded_simulation

pytest.importorskip("foxglove")

from sensorium.server.recording.reader import Recording  # noqa: E402

WORLD = {"world_info": {"basic_time_step": 16},
         "robots": [{"name": "r", "controller": "<none>",
                     "devices": [{"device": "Display", "name": "screen", "width": 6, "height": 4}]}]}


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    path = tmp_path_factory.mktemp("disp") / "run.mcap"
    sim, topics, rec = recorded_simulation(path, WORLD, "disp.yaml")
    d = sim.device("r/screen")
    shown = []
    for k in range(3):
        d.apply(d.check([["color", 0x102030 * (k + 1)], ["line", 0, k, 5, k]]), sim.time_ms)
        sim.step()
        topics.publish(sim.time_ms)
        shown.append(d.pixels.astype("<u4").tobytes())
    rec.close()
    return path, shown


def test_the_recording_has_each_drawn_image(recording):
    path, shown = recording
    with Recording(path) as rec:
        types = {t.topic: t.ros_type for t in rec.topics()}
        msgs = [msgpack.unpackb(m.data, raw=False) for m in rec.messages() if m.topic == "/r/screen/image"]
    assert types["/r/screen/image"] == "sensor_msgs/msg/Image"
    assert [m["data"] for m in msgs] == shown and msgs[0]["encoding"] == "bgra8"
    row = np.frombuffer(shown[-1], dtype="<u4").reshape(4, 6)[2]
    assert (row == 0xFF000000 | 0x306090).all()


def test_foxglove_readers_decode_the_display_image(recording):
    require_node()
    path, shown = recording
    got = run_script("read_mcap.js", str(path))[0]
    assert got["errors"] == []
    img = got["last"]["/r/screen/image"]["msg"]
    assert (img["encoding"], img["width"], img["height"], img["step"]) == ("bgra8", 6, 4, 24)
    assert bytes(img["data"]) == shown[-1]


def test_ros2_export_carries_the_display_image(recording, tmp_path):
    from rosbags.highlevel import AnyReader

    from sensorium.server.recording.export import export_ros2
    path, shown = recording
    export_ros2(path, tmp_path / "bag", distro="jazzy")
    with AnyReader([tmp_path / "bag"]) as reader:
        conn = next(c for c in reader.connections if c.topic == "/r/screen/image")
        last = [reader.deserialize(raw, conn.msgtype) for _, _, raw in reader.messages(connections=[conn])][-1]
    assert last.encoding == "bgra8" and bytes(last.data) == shown[-1]
