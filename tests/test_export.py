"""ROS 2 export: write with one library, read back with the other, compare every field."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import msgpack
import numpy as np
import pytest

pytest.importorskip("rosbags")
pytest.importorskip("mcap_ros2")

from _recdata import TOPICS, make_recording  # noqa: E402
from mcap.reader import make_reader  # noqa: E402
from mcap_ros2.decoder import DecoderFactory  # noqa: E402
from rosbags.highlevel import AnyReader  # noqa: E402

from sensorium.server.recording.export import ExportError, export_ros2  # noqa: E402

F32_FIELDS = {"field_of_view", "min_range", "max_range", "range", "angle_min", "angle_max", "angle_increment",
              "time_increment", "scan_time", "range_min", "range_max", "x", "y", "z"}


def f32(a: bytes) -> np.ndarray:
    return np.frombuffer(a, dtype="<f4")


def expected_message(ros_type: str, body: dict, distro: str, pointcloud2: bool) -> tuple[str, dict]:
    """What the exported ROS message must contain, computed here independently of export.py."""
    b = dict(body)
    if ros_type == "sensor_msgs/msg/Range" and distro == "humble":
        b.pop("variance")
    if ros_type == "sensor_msgs/msg/LaserScan":
        b["ranges"] = f32(b["ranges"])
        b["intensities"] = f32(b["intensities"])
    if ros_type == "sensor_msgs/msg/Image":
        b["data"] = bytes(b["data"])
    if ros_type == "sensor_msgs/msg/PointCloud":
        pts = f32(b["points"]).reshape(-1, 3)
        if pointcloud2:
            layer = f32(b["channels"][0]["values"])
            data = np.column_stack([pts, layer]).astype("<f4").tobytes()
            return "sensor_msgs/msg/PointCloud2", {
                "header": b["header"], "height": 1, "width": len(pts),
                "fields": [{"name": n, "offset": 4 * i, "datatype": 7, "count": 1}
                           for i, n in enumerate(["x", "y", "z", "layer"])],
                "is_bigendian": False, "point_step": 16, "row_step": 16 * len(pts), "data": data,
                "is_dense": bool(np.isfinite(pts).all())}
        b["points"] = [{"x": x, "y": y, "z": z} for x, y, z in pts.tolist()]
        b["channels"] = [{"name": c["name"], "values": f32(c["values"])} for c in b["channels"]]
    return ros_type, b


def same_float(a: float, b: float, f32_: bool) -> bool:
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    return a == b if not f32_ else np.float32(a) == np.float32(b)


def compare(expected, actual, path: str = "") -> None:
    """Every field of ``expected`` must be in ``actual`` (an object or dict) with the same value."""
    if isinstance(expected, dict):
        for key, value in expected.items():
            got = actual[key] if isinstance(actual, dict) else getattr(actual, key)
            compare(value, got, f"{path}.{key}")
    elif isinstance(expected, list):
        assert len(actual) == len(expected), path
        for i, (e, a) in enumerate(zip(expected, actual)):
            compare(e, a, f"{path}[{i}]")
    elif isinstance(expected, np.ndarray):
        got = np.asarray(actual, dtype=expected.dtype)
        np.testing.assert_array_equal(got, expected, err_msg=path)
    elif isinstance(expected, bytes):
        got = bytes(actual) if isinstance(actual, (bytes, bytearray, memoryview)) else \
            np.asarray(actual, dtype=np.uint8).tobytes()
        assert got == expected, path
    elif isinstance(expected, bool):
        assert bool(actual) is expected, path
    elif isinstance(expected, float):
        assert same_float(float(actual), expected, path.rsplit(".", 1)[-1] in F32_FIELDS), (path, actual, expected)
    else:
        assert actual == expected, (path, actual, expected)


def check(source_items, decoded, distro: str, pointcloud2: bool) -> None:
    """``decoded``: list of (topic, type, log_time, message object) in file order."""
    by_topic: dict[str, list] = {}
    for topic, typename, t, msg in decoded:
        by_topic.setdefault(topic, []).append((typename, t, msg))
    assert set(by_topic) == {item[0] for item in source_items}
    cursor = {t: 0 for t in by_topic}
    for topic, ros_type, _env, body, stamp_ns, _seq in source_items:
        typename, t, msg = by_topic[topic][cursor[topic]]
        cursor[topic] += 1
        exp_type, exp = expected_message(ros_type, msgpack.unpackb(body), distro, pointcloud2)
        assert typename == exp_type
        assert t == stamp_ns
        compare(exp, msg, topic)
        if ros_type == "sensor_msgs/msg/Range":
            assert hasattr(msg, "variance") == (distro == "jazzy")
    assert all(cursor[t] == len(v) for t, v in by_topic.items())


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    path = tmp_path_factory.mktemp("export") / "rec.mcap"
    items = make_recording(path, steps=24)
    return path, items


@pytest.mark.parametrize("distro", ["humble", "jazzy"])
def test_rosbag2_directory_read_back_with_mcap_ros2(recording, tmp_path, distro):
    src, items = recording
    out = tmp_path / f"bag_{distro}"
    report = export_ros2(src, out, distro=distro)
    assert report.messages == len(items) and not report.skipped
    assert (out / "metadata.yaml").exists()
    files = list(out.glob("*.mcap"))
    assert len(files) == 1
    decoded = []
    with open(files[0], "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        assert reader.get_header().profile == "ros2"
        for schema, channel, message, obj in reader.iter_decoded_messages(log_time_order=False):
            assert channel.message_encoding == "cdr" and schema.encoding == "ros2msg"
            decoded.append((channel.topic, schema.name, message.log_time, obj))
    check(items, decoded, distro, pointcloud2=False)
    text = (out / "metadata.yaml").read_text()
    assert "version: " + ("9" if distro == "jazzy" else "8") in text


@pytest.mark.parametrize("distro", ["humble", "jazzy"])
@pytest.mark.parametrize("pointcloud2", [False, True])
def test_single_file_read_back_with_rosbags(recording, tmp_path, distro, pointcloud2):
    src, items = recording
    out = tmp_path / f"one_{distro}.mcap"
    report = export_ros2(src, out, distro=distro, pointcloud2=pointcloud2)
    assert report.messages == len(items)
    assert report.topics["/scout/lidar/point_cloud"] == ("sensor_msgs/msg/PointCloud2" if pointcloud2
                                                         else "sensor_msgs/msg/PointCloud")
    decoded = []
    with AnyReader([out]) as reader:
        for conn, t, raw in reader.messages():
            decoded.append((conn.topic, conn.msgtype, t, reader.deserialize(raw, conn.msgtype)))
    check(items, decoded, distro, pointcloud2)
    # attachments and metadata travel along
    with open(out, "rb") as f:
        reader = make_reader(f)
        assert [a.name for a in reader.iter_attachments()] == ["synthetic.yaml"]
        meta = {m.name: m.metadata for m in reader.iter_metadata()}
        assert meta["sensorium"]["seed"] == "7" and meta["sensorium"]["distro"] == distro


def test_rosbag2_pointcloud2_read_back(recording, tmp_path):
    src, items = recording
    out = tmp_path / "bag_pc2"
    export_ros2(src, out, distro="jazzy", pointcloud2=True, topics=["/scout/lidar/point_cloud"])
    decoded = []
    with open(next(out.glob("*.mcap")), "rb") as f:
        for schema, channel, message, obj in make_reader(f, decoder_factories=[DecoderFactory()]).iter_decoded_messages():
            decoded.append((channel.topic, schema.name, message.log_time, obj))
    check([i for i in items if i[0] == "/scout/lidar/point_cloud"], decoded, "jazzy", pointcloud2=True)


def test_refuses_to_overwrite_and_unknown_distro(recording, tmp_path):
    src, _ = recording
    (tmp_path / "x").mkdir()
    with pytest.raises(ExportError):
        export_ros2(src, tmp_path / "x")
    with pytest.raises(ExportError):
        export_ros2(src, tmp_path / "y", distro="noetic")


def test_cli_export(recording, tmp_path):
    src, items = recording
    out = tmp_path / "cli_bag"
    proc = subprocess.run([sys.executable, "-m", "sensorium", "export", str(src), str(out), "--ros2",
                           "--distro", "humble", "--topics", "/epuck"], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert "exported" in proc.stdout
    with AnyReader([out]) as reader:
        topics = {c.topic for c in reader.connections}
        assert topics == {t for t in TOPICS if t.startswith("/epuck/")}
        assert reader.message_count == sum(1 for i in items if i[0].startswith("/epuck/"))
    assert Path(out, "metadata.yaml").exists()
