"""The demo's recording opens in Foxglove: validated (CRCs, indexes) and fully decoded by Foxglove's
TypeScript MCAP reader (@mcap/core) and independent decoders (@foxglove/rosmsg2-serialization,
protobufjs) under Node; the decoded values match our own reader's; replay stays byte-exact."""

from __future__ import annotations

import os
import subprocess
import sys
from collections import Counter
from pathlib import Path

import msgpack
import numpy as np
import pytest
from _node import require_node, run_script

pytest.importorskip("foxglove")

from sensorium.server.recording.foxglove_views import WIRE_PREFIX  # noqa: E402
from sensorium.server.recording.reader import Recording  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SUPPORTED = {("cdr", "ros2msg"), ("protobuf", "protobuf")}


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    require_node()
    out = tmp_path_factory.mktemp("demo")
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    res = subprocess.run([sys.executable, "-m", "sensorium", "demo", "--duration", "4", "--out", str(out), "--json"],
                         capture_output=True, text=True, timeout=300, env=env)
    assert res.returncode == 0, res.stderr
    return out / "demo.mcap"


def test_demo_recording_decodes_in_foxglove_readers(demo):
    got = run_script("read_mcap.js", str(demo))[0]
    assert got["errors"] == []
    chans = {c["topic"]: c for c in got["channels"]}
    for c in got["channels"]:
        assert (c["messageEncoding"], c["schemaEncoding"]) in SUPPORTED, c
    with Recording(demo) as rec:
        assert rec.metadata()["sensorium"]["format"] == "2"
        infos = {t.topic: t for t in rec.topics()}
        last: dict[str, object] = {}
        poses = 0
        for m in rec.messages():
            last[m.topic] = m
            poses += m.topic.endswith("/pose")
    # every recorded topic: a lossless wire channel and a Foxglove view with the same count
    assert set(chans) == {WIRE_PREFIX + t for t in infos} | set(infos) | {"/tf", "/scene"}
    for topic, info in infos.items():
        assert chans[WIRE_PREFIX + topic]["count"] == chans[topic]["count"] == info.count > 0, topic
        want = "sensor_msgs/msg/PointCloud2" if info.ros_type == "sensor_msgs/msg/PointCloud" else info.ros_type
        assert chans[topic]["schemaName"] == want
    assert chans["/tf"]["count"] == poses and chans["/scene"]["count"] == 1
    assert got["messages"] == sum(c["count"] for c in got["channels"])

    def body(topic: str) -> dict:
        return msgpack.unpackb(last[topic].data, raw=False)

    # the wire copy decoded by the independent CDR reader is the published body, byte for byte
    for topic in ("/epuck/ls0/value", "/scout/lidar/laser_scan"):
        assert bytes(got["last"][WIRE_PREFIX + topic]["msg"]["body"]) == last[topic].data
    # field by field against our own reader
    ls = got["last"]["/epuck/ls0/value"]
    assert ls["log_time"] == last["/epuck/ls0/value"].stamp_ns
    assert ls["msg"]["illuminance"] == body("/epuck/ls0/value")["illuminance"]
    ps = got["last"]["/epuck/ps0/value"]["msg"]
    assert ps["range"] == float(np.float32(body("/epuck/ps0/value")["range"])) and ps["radiation_type"] == 1
    scan, ours = got["last"]["/scout/lidar/laser_scan"]["msg"], body("/scout/lidar/laser_scan")
    assert scan["ranges"] == np.frombuffer(ours["ranges"], "<f4").astype(float).tolist()
    assert scan["header"]["frame_id"] == "scout/lidar"
    pc_topic = next(t for t in infos if t.endswith("/point_cloud"))
    pc, ours = got["last"][pc_topic]["msg"], body(pc_topic)
    rec4 = np.frombuffer(bytes(pc["data"]), "<f4").reshape(-1, 4)
    assert np.array_equal(rec4[:, :3], np.frombuffer(ours["points"], "<f4").reshape(-1, 3), equal_nan=True)
    # /tf: the last transforms place the last robot pose, with its device mounts
    tf = got["last"]["/tf"]["msg"]["transforms"]
    robot = tf[0]["child_frame_id"]
    pose = body(f"/{robot}/pose")["pose"]
    assert tf[0]["parent_frame_id"] == "world"
    assert [tf[0]["translation"][k] for k in "xyz"] == [pose["position"][k] for k in "xyz"]
    assert {t["child_frame_id"] for t in tf[1:]} == {f"{robot}/{d}" for d in
                                                      {t.split("/")[2] for t in infos if t.startswith(f"/{robot}/")
                                                       and t != f"/{robot}/pose"}}
    # /scene: every solid, both robot bodies following their frames, the three lights
    ents = {e["id"]: e for e in got["last"]["/scene"]["msg"]["entities"]}
    kinds = Counter(e["metadata"][0]["value"] for e in ents.values())
    assert kinds == {"solid": 11, "robot": 2, "light:PointLight": 1, "light:SpotLight": 1, "light:DirectionalLight": 1}
    assert ents["robot/epuck"]["frame_id"] == "epuck" and ents["robot/epuck"]["frame_locked"] is True
    assert ents["solid/ball"]["spheres"][0]["size"]["x"] == pytest.approx(0.24)
    assert len(ents["solid/rock"]["triangles"][0]["indices"]) % 3 == 0 and ents["solid/bollard"]["triangles"]
    pillar = ents["solid/pillar"]["cylinders"][0]
    assert (pillar["size"]["x"], pillar["size"]["z"]) == (pytest.approx(0.2), pytest.approx(0.4))


def test_export_carries_scene_and_transforms(demo, tmp_path):
    from rosbags.highlevel import AnyReader

    from sensorium.server.recording.export import export_ros2

    report = export_ros2(demo, tmp_path / "bag", distro="jazzy")
    with Recording(demo) as rec:
        poses = [m for m in rec.messages() if m.topic.endswith("/pose")]
        assert report.messages == sum(t.count for t in rec.topics()) and not report.skipped
    assert report.views == len(poses) + 2
    with AnyReader([tmp_path / "bag"]) as reader:
        by_topic: dict[str, list] = {}
        for conn, t, raw in reader.messages():
            by_topic.setdefault(conn.topic, []).append((conn.msgtype, t, reader.deserialize(raw, conn.msgtype)))
    assert by_topic["/tf"][0][0] == "tf2_msgs/msg/TFMessage" and len(by_topic["/tf"]) == len(poses)
    last_pose = msgpack.unpackb(poses[-1].data, raw=False)["pose"]["position"]
    tf = by_topic["/tf"][-1][2].transforms[0]
    assert (tf.header.frame_id, tf.child_frame_id) == ("world", poses[-1].topic.split("/")[1])
    assert [tf.transform.translation.x, tf.transform.translation.y] == [last_pose["x"], last_pose["y"]]
    (static,) = by_topic["/tf_static"]
    ps0 = next(x for x in static[2].transforms if x.child_frame_id == "epuck/ps0")
    assert ps0.header.frame_id == "epuck"
    assert (ps0.transform.translation.x, ps0.transform.translation.y) == (0.0343, -0.0099)
    ((typ, _t, scene),) = by_topic["/scene"]
    assert typ == "visualization_msgs/msg/MarkerArray"
    markers = {(m.ns, m.id): m for m in scene.markers}
    assert len(markers) == 11 + 2 + 4                  # solids, robot bodies, lamp + spot (sphere, arrow) + sun
    ball = next(m for (ns, _), m in markers.items() if ns == "solid/ball")
    assert ball.type == 2 and ball.scale.x == pytest.approx(0.24)
    epuck = next(m for (ns, _), m in markers.items() if ns == "robot/epuck")
    assert epuck.header.frame_id == "epuck" and epuck.frame_locked and epuck.type == 3
    rock = next(m for (ns, _), m in markers.items() if ns == "solid/rock")
    assert rock.type == 11 and len(rock.points) % 3 == 0 and rock.points
    # and the single-file export is read and fully decoded by Foxglove's own reader
    export_ros2(demo, tmp_path / "one.mcap", distro="jazzy")
    got = run_script("read_mcap.js", str(tmp_path / "one.mcap"))[0]
    assert got["errors"] == [] and {"/tf", "/tf_static", "/scene"} <= {c["topic"] for c in got["channels"]}
    assert len(got["last"]["/scene"]["msg"]["markers"]) == 17


def test_info_says_whether_a_recording_is_foxglove_ready(demo, tmp_path):
    from _recdata import make_recording

    env = dict(os.environ, PYTHONPATH=str(ROOT))
    plain = tmp_path / "plain.mcap"
    make_recording(plain, steps=3, foxglove=False)
    out = {}
    for name, path in (("demo", demo), ("plain", plain)):
        r = subprocess.run([sys.executable, "-m", "sensorium", "info", str(path)], capture_output=True, text=True,
                           env=env, timeout=60)
        assert r.returncode == 0, r.stderr
        out[name] = next(line for line in r.stdout.splitlines() if line.startswith("Foxglove:"))
    assert out["demo"].split(None, 1)[1].startswith("ready")
    assert out["plain"].split(None, 1)[1].startswith("no")


def test_a_body_without_a_view_is_still_kept_and_reported(tmp_path):
    from sensorium.server.recording.writer import McapRecorder

    odd = msgpack.packb([1, 2])                        # not a map: no CDR view can be made of it
    with McapRecorder(tmp_path / "x.mcap", b"", "w.yaml", {}) as rec:
        rec.record("/a/b/value", "sensor_msgs/msg/Range", b"", odd, 5, 0)
    with Recording(tmp_path / "x.mcap") as r:
        assert [(m.topic, m.data) for m in r.messages()] == [("/a/b/value", odd)]
        assert r.metadata()["foxglove_view_errors"] == {"/a/b/value": "ExportError: body is not a msgpack map"}


def test_subscriber_recording_with_world_file_carries_the_scene(tmp_path):
    from mcap.reader import make_reader

    from sensorium.server.recording.live import LiveRecorder
    from sensorium.server.world.loader import default_world_path

    out = tmp_path / "sub.mcap"
    live = LiveRecorder(out, connect=None, pub="tcp://127.0.0.1:9", world=str(default_world_path()),
                        log=lambda s: None)
    live.open()                                         # nothing is published: only the world is written
    live.close()
    with open(out, "rb") as f:
        summary = make_reader(f).get_summary()
    chans = {c.topic: c for c in summary.channels.values()}
    assert summary.schemas[chans["/scene"].schema_id].name == "foxglove.SceneUpdate"
    assert summary.statistics.channel_message_counts[chans["/scene"].id] == 1
    got = run_script("read_mcap.js", str(out))[0]
    assert got["errors"] == []
    assert len(got["last"]["/scene"]["msg"]["entities"]) == 11 + 2 + 3
