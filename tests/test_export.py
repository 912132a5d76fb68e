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


def test_overwrite_replaces_a_file_or_a_bag_only_once_complete(recording, tmp_path):
    """export had no way to replace an existing output (export_ros2(overwrite=True), `--force`): it
    replaces a file or a rosbag2 directory with a complete export, moved over it at the end; a failed
    export leaves the old output as it was and nothing beside it; a directory that is no bag, and the
    recording itself, are never replaced."""
    src, items = recording
    one = tmp_path / "one.mcap"
    one.write_bytes(b"old")
    with pytest.raises(ExportError, match=r"one\.mcap exists already; not overwriting \(--force to replace it\)$"):
        export_ros2(src, one)
    assert one.read_bytes() == b"old"
    export_ros2(src, one, overwrite=True, topics=["/epuck"])
    with open(one, "rb") as f:
        topics = {c.topic for c in make_reader(f).get_summary().channels.values()}
    assert topics == {t for t in TOPICS if t.startswith("/epuck/")}
    bag = tmp_path / "bag"
    export_ros2(src, bag, topics=["/clock"])
    export_ros2(src, bag, overwrite=True, topics=["/epuck"])          # a bag over a bag: files renamed inside
    with AnyReader([bag]) as reader:
        assert {c.topic for c in reader.connections} == {t for t in TOPICS if t.startswith("/epuck/")}
    assert sorted(p.name for p in bag.iterdir()) == ["bag.mcap", "metadata.yaml"]
    export_ros2(src, one, overwrite=True, fmt="bag")                   # a bag where a file was
    assert (one / "metadata.yaml").is_file()

    def fail(done: int, total: int) -> None:
        if done == 5:
            raise RuntimeError("disk on fire")

    before = sorted((p.name, p.stat().st_size) for p in bag.iterdir())
    with pytest.raises(RuntimeError, match="disk on fire"):
        export_ros2(src, bag, overwrite=True, progress=fail)
    assert sorted((p.name, p.stat().st_size) for p in bag.iterdir()) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bag", "one.mcap"]      # no staging directory left
    (tmp_path / "photos").mkdir()
    (tmp_path / "photos" / "cat.jpg").write_bytes(b"cat")
    with pytest.raises(ExportError, match=r"photos is a directory but no rosbag2 bag \(no metadata\.yaml\)"):
        export_ros2(src, tmp_path / "photos", overwrite=True)
    assert (tmp_path / "photos" / "cat.jpg").read_bytes() == b"cat"
    copy = tmp_path / "rec.mcap"
    copy.write_bytes(Path(src).read_bytes())
    with pytest.raises(ExportError, match=r"rec\.mcap is the recording being exported; not replacing it"):
        export_ros2(copy, copy, overwrite=True)
    assert copy.read_bytes() == Path(src).read_bytes()


def test_cli_export_force(recording, tmp_path):
    """`sensorium export ... --force` (documented in --help, as convert's, record's and recover's)."""
    src, _ = recording
    out = tmp_path / "out.mcap"
    out.write_bytes(b"old")
    cmd = [sys.executable, "-m", "sensorium", "export", str(src), str(out), "--ros2", "--topics", "/clock"]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 1 and proc.stderr.strip() == (f"sensorium export: {out} exists already; not "
                                                            "overwriting (--force to replace it)")
    assert out.read_bytes() == b"old"
    proc = subprocess.run([*cmd, "--force"], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert out.read_bytes()[:8] == b"\x89MCAP0\r\n"
    helped = subprocess.run([sys.executable, "-m", "sensorium", "export", "--help"], capture_output=True, text=True,
                            timeout=60)
    assert "--force" in helped.stdout and "overwrite OUT if it exists" in " ".join(helped.stdout.split())


def test_topics_that_match_nothing_are_refused(recording, tmp_path):
    """A typo in --topics wrote an empty bag and exited 0."""
    src, _ = recording
    with pytest.raises(ExportError, match=r"--topics /epuck/ps9/value: no topic of .* matches it \(closest: /epuck/"):
        export_ros2(src, tmp_path / "bag", topics=["/scout", "/epuck/ps9/value"])
    assert not (tmp_path / "bag").exists()


def test_a_ros2_bag_is_refused_not_exported_empty(recording, tmp_path):
    """Exporting a ROS 2 bag (what export writes, or ros2 bag record) wrote an empty bag, exit 0."""
    src, _ = recording
    bag = tmp_path / "ros2.mcap"
    export_ros2(src, bag)
    with pytest.raises(ExportError, match=r"ros2\.mcap is not a Sensorium recording \(MCAP profile 'ros2'; channels "):
        export_ros2(bag, tmp_path / "again")
    assert not (tmp_path / "again").exists()


def test_info_says_a_ros2_bag_is_no_sensorium_recording(recording, tmp_path, capsys):
    """`sensorium info` of a ROS 2 bag said 'Messages: 0' (its thousands of CDR messages are not
    published bodies) without saying why."""
    from sensorium.cli.recording import print_info

    src, _ = recording
    bag = tmp_path / "ros2.mcap"
    export_ros2(src, bag)
    capsys.readouterr()
    assert print_info(bag) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert first.startswith(f"Not Sensorium:     {bag} is not a Sensorium recording (MCAP profile 'ros2'"), first
    assert print_info(src) == 0 and "Not Sensorium" not in capsys.readouterr().out


def test_end_before_start_is_refused(recording, tmp_path):
    """export --start 5 --end 1 wrote an empty bag and exited 0 (replay refuses the same)."""
    src, _ = recording
    with pytest.raises(ExportError, match="^--end is before --start$"):
        export_ros2(src, tmp_path / "bag", start_ns=5_000_000_000, end_ns=1_000_000_000)
    assert not (tmp_path / "bag").exists()


class _Terminated(Exception):
    """What SIGTERM raises in these tests when the command under test does not handle it."""


@pytest.mark.parametrize("replacing", [False, True])
@pytest.mark.parametrize("name", ["bag", "one.mcap"])
def test_sigterm_mid_export_removes_the_output(recording, tmp_path, monkeypatch, capsys, name, replacing):
    """README: 'export removes what it wrote if it fails or is interrupted; only SIGKILL or a power
    loss can leave a half-written bag'. SIGTERM (systemd, docker stop, timeout) killed export at
    once, leaving the half-written bag behind. With --force over an existing output, that output is
    left as it was (the new one was being written beside it)."""
    import argparse
    import os
    import signal

    from sensorium.cli import progress
    from sensorium.cli.recording import export_cmd

    class SignalAtFirstMessage(progress._Quiet):
        def update(self, n: float = 1) -> None:
            if (tmp_path / name).exists():           # the output is being written: SIGTERM now
                os.kill(os.getpid(), signal.SIGTERM)

    def terminated(signum, frame):
        raise _Terminated

    monkeypatch.setattr(progress, "bar", lambda *a, **k: SignalAtFirstMessage())
    if replacing:
        old = tmp_path / name if name.endswith(".mcap") else tmp_path / name / "metadata.yaml"
        old.parent.mkdir(exist_ok=True)
        old.write_bytes(b"old")
    previous = signal.signal(signal.SIGTERM, terminated)     # without the fix the test fails, not pytest
    try:
        src, _ = recording
        args = argparse.Namespace(file=str(src), out=str(tmp_path / name), ros2=True, distro="jazzy", format=None,
                                  pointcloud2=False, no_views=True, topics=None, start=None, end=None,
                                  force=replacing)
        assert export_cmd(args) == 130
    finally:
        assert signal.signal(signal.SIGTERM, previous) is terminated        # put back after the export
    if replacing:
        assert old.read_bytes() == b"old" and [p.name for p in tmp_path.iterdir()] == [name]
    else:
        assert not (tmp_path / name).exists()
    kept = "left as it was" if replacing else "removed"
    assert capsys.readouterr().err.strip().splitlines()[-1] == (f"sensorium export: interrupted; {tmp_path / name} "
                                                                f"{kept} (nothing partial is kept)")


MESH_WORLD = b"""world_info: {name: meshy, basic_time_step: 32, random_seed: 7}
solids: [{name: tri, pose: {translation: [1, 0, 0.1]}, geometry: {type: mesh, url: tri.obj}}]
robots: [{name: epuck, devices: [{device: LightSensor, name: ls0}]}]
"""

# The child runs `sensorium export` as python -m sensorium does, with an import hook that holds it
# inside the import of MODULE: it says so with a file, then waits for the file saying the test has
# sent SIGINT. So the signal lands inside that import every time, without guessing at timings.
_HELD_IMPORT = """
import os, sys, time
module, ready, sent = sys.argv.pop(1), sys.argv.pop(1), sys.argv.pop(1)
class Hold:
    def find_spec(self, name, path=None, target=None):
        if name == module:
            sys.meta_path.remove(self)
            open(ready, "w").close()
            while not os.path.exists(sent):
                time.sleep(0.005)
            time.sleep(0.05)
        return None
sys.meta_path.insert(0, Hold())
from sensorium.cli import main
sys.exit(main())
"""


@pytest.fixture(scope="module")
def mesh_recording(tmp_path_factory):
    """A recording whose world has a mesh: exporting its /scene imports trimesh."""
    from _recdata import published

    from sensorium.server.recording.writer import McapRecorder

    path = tmp_path_factory.mktemp("mesh") / "mesh.mcap"
    with McapRecorder(path, MESH_WORLD, "meshy.yaml", {"seed": "7", "world": "meshy"}, None, 4096) as rec:
        rec._writer.add_attachment(create_time=0, log_time=0, name="tri.obj", media_type="model/obj",
                                   data=b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
        for item in published(8, TOPICS):
            rec.record(*item)
    return path


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT to a child process")
@pytest.mark.parametrize("module, existing, line", [
    # the CLI's own imports (cli/recording.py's) ended in a traceback
    ("sensorium.server.recording.live", False, "sensorium export: interrupted"),
    # trimesh imports trimesh.path under `except BaseException`: the interrupt was swallowed and the
    # export ran to its end, exit 0
    ("trimesh.path", False, "sensorium export: interrupted; {out} removed (nothing partial is kept)"),
    ("trimesh.path", True, "sensorium export: interrupted; {out} left as it was (nothing partial is kept)"),
])
def test_ctrl_c_inside_an_import_exits_130_with_one_line(mesh_recording, tmp_path, module, existing, line):
    """Ctrl-C at any moment of `sensorium export`, here inside an import: exit 130, one line, no
    partial output (an existing one replaced with --force left as it was)."""
    import os
    import signal
    import time

    out = tmp_path / "out.mcap"
    if existing:
        out.write_bytes(b"old")
    ready, sent = tmp_path / "ready", tmp_path / "sent"
    p = subprocess.Popen([sys.executable, "-c", _HELD_IMPORT, module, str(ready), str(sent), "export",
                          str(mesh_recording), str(out), "--ros2", *(["--force"] if existing else [])],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        while not ready.exists():                   # the child is inside the import
            assert p.poll() is None and time.monotonic() < deadline, p.communicate()
            time.sleep(0.01)
        p.send_signal(signal.SIGINT)
        sent.touch()
        stdout, stderr = p.communicate(timeout=60)
    finally:
        if p.poll() is None:
            p.kill()
            p.communicate()
    assert p.returncode == 130, stderr
    assert stderr.strip().splitlines() == [line.format(out=out)] and stdout == ""
    assert (out.read_bytes() == b"old") if existing else not out.exists()
    assert sorted(os.listdir(tmp_path)) == sorted(["ready", "sent", *(["out.mcap"] if existing else [])])


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


# --------------------------------------------------------------------------------------------
# QoS profiles in metadata.yaml: checked against rosbag2's own format (rules read in rosbag2's
# rosbag2_storage/include/rosbag2_storage/yaml.hpp and src/rosbag2_storage/qos.cpp, written here
# independently), then read back with rosbags' reader and, for the MCAP channels, the mcap package.

RMW_NAMES = {   # rmw's *_policy_to_str names, what version >= 9 writes
    "history": {"system_default", "keep_last", "keep_all", "unknown"},
    "reliability": {"system_default", "reliable", "best_effort", "unknown", "best_available"},
    "durability": {"system_default", "transient_local", "volatile", "unknown", "best_available"},
    "liveliness": {"system_default", "automatic", "manual_by_topic", "unknown", "best_available"},
}
RMW_INTS = {"reliability": {"reliable": 1, "best_effort": 2}, "durability": {"transient_local": 1, "volatile": 2},
            "history": {"keep_last": 1}, "liveliness": {"automatic": 1}}


def rosbag2_qos_list(value, version: int) -> list[dict]:
    """Decode ``offered_qos_profiles`` as rosbag2 of metadata ``version`` does; every policy as a name."""
    import yaml

    if version <= 8:
        assert isinstance(value, str), f"version {version}: offered_qos_profiles must be a YAML string, got {value!r}"
        items = yaml.safe_load(value) if value else []
    else:
        assert isinstance(value, list), f"version {version}: offered_qos_profiles must be a YAML list, got {value!r}"
        items = value
    out = []
    for q in items:
        assert set(q) == {"history", "depth", "reliability", "durability", "deadline", "lifespan", "liveliness",
                          "liveliness_lease_duration", "avoid_ros_namespace_conventions"}, q
        named = {}
        for policy in ("history", "reliability", "durability", "liveliness"):
            v = q[policy]
            if version <= 8 and policy != "history":
                assert isinstance(v, int) and not isinstance(v, bool), (policy, v)     # node.as<int>()
                named[policy] = {i: n for n, i in RMW_INTS[policy].items()}.get(v, f"int {v}")
            elif isinstance(v, int):
                assert policy == "history", (policy, v)
                named[policy] = {i: n for n, i in RMW_INTS[policy].items()}.get(v, f"int {v}")
            else:
                assert v in RMW_NAMES[policy], (policy, v)                               # rmw_*_from_str
                named[policy] = v
        assert isinstance(q["depth"], int) and q["depth"] >= 0
        for d in ("deadline", "lifespan", "liveliness_lease_duration"):
            assert set(q[d]) == {"sec", "nsec"} and all(isinstance(x, int) and x >= 0 for x in q[d].values()), q[d]
        assert isinstance(q["avoid_ros_namespace_conventions"], bool)
        named["depth"] = q["depth"]
        out.append(named)
    return out


def check_rosbag2_metadata(text: str) -> dict[str, list[dict]]:
    """metadata.yaml as rosbag2's decoder reads it, field by field per version; topic → QoS list."""
    import yaml

    doc = yaml.safe_load(text)
    info = doc["rosbag2_bagfile_information"]
    version = info["version"]
    assert isinstance(version, int)
    uint = lambda v: isinstance(v, int) and not isinstance(v, bool) and v >= 0
    assert isinstance(info["storage_identifier"], str) and info["storage_identifier"] == "mcap"
    assert uint(info["duration"]["nanoseconds"]) and uint(info["starting_time"]["nanoseconds_since_epoch"])
    assert uint(info["message_count"])
    assert all(isinstance(p, str) for p in info["relative_file_paths"])
    if version >= 3:
        assert isinstance(info["compression_format"], str) and isinstance(info["compression_mode"], str)
    if version >= 5:
        for f in info["files"]:
            assert isinstance(f["path"], str) and uint(f["message_count"])
            assert uint(f["starting_time"]["nanoseconds_since_epoch"]) and uint(f["duration"]["nanoseconds"])
    if version >= 6:
        assert all(isinstance(k, str) and isinstance(v, str) for k, v in (info["custom_data"] or {}).items())
    if version >= 8:
        assert isinstance(info["ros_distro"], str)
    qos = {}
    for t in info["topics_with_message_count"]:
        meta = t["topic_metadata"]
        assert uint(t["message_count"])
        assert all(isinstance(meta[k], str) for k in ("name", "type", "serialization_format"))
        if version >= 7:
            assert isinstance(meta["type_description_hash"], str) and meta["type_description_hash"].startswith("RIHS01_")
        qos[meta["name"]] = rosbag2_qos_list(meta["offered_qos_profiles"], version)
    return qos


EXPECTED_QOS = {   # what a live driver offers (tf2's broadcasters, rclcpp's SensorDataQoS / ClockQoS / default)
    "/tf_static": ("reliable", "transient_local", 1), "/scene": ("reliable", "transient_local", 1),
    "/tf": ("reliable", "volatile", 100), "/clock": ("best_effort", "volatile", 1),
}


def expected_qos(topic: str, typename: str) -> tuple[str, str, int]:
    if topic in EXPECTED_QOS:
        return EXPECTED_QOS[topic]
    if typename.startswith("sensor_msgs/msg/"):
        return ("best_effort", "volatile", 5)
    return ("reliable", "volatile", 10)


VIEWS_WORLD = b"""world_info: {name: views, basic_time_step: 32, random_seed: 7}
solids: [{name: box, pose: {translation: [1, 0, 0.1]}, geometry: {type: box, size: [0.2, 0.2, 0.2]}}]
robots:
  - name: epuck
    shapes: [{geometry: {type: cylinder, radius: 0.035, height: 0.05}}]
    devices: [{device: LightSensor, name: ls0, pose: {translation: [0.03, 0, 0.02]}}]
"""


@pytest.fixture(scope="module")
def views_recording(tmp_path_factory):
    """A recording whose attached world gives /tf_static, /scene and (from /epuck/pose) /tf."""
    from _recdata import TOPICS as BASE
    from _recdata import header, published

    from sensorium.server.recording.writer import McapRecorder

    def pose(t_ns: int, i: int) -> dict:
        return {"header": header(t_ns, "world"), "pose": {"position": {"x": 0.001 * i, "y": 0.0, "z": 0.0},
                                                         "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}}}

    topics = dict(BASE, **{"/epuck/pose": ("geometry_msgs/msg/PoseStamped", pose, 1)})
    path = tmp_path_factory.mktemp("views") / "views.mcap"
    with McapRecorder(path, VIEWS_WORLD, "views.yaml", {"seed": "7", "world": "views"}, None, 4096) as rec:
        for item in published(8, topics):
            rec.record(*item)
    return path


@pytest.mark.parametrize("distro,version", [("humble", 8), ("jazzy", 9)])
def test_rosbag2_metadata_has_the_qos_a_live_driver_offers(views_recording, tmp_path, distro, version):
    src = views_recording
    out = tmp_path / f"qos_{distro}"
    report = export_ros2(src, out, distro=distro)
    assert "/tf_static" in report.topics and "/scene" in report.topics      # the recorded world's views
    qos = check_rosbag2_metadata((out / "metadata.yaml").read_text())
    assert set(qos) == set(report.topics)
    for topic, typename in report.topics.items():
        (profile,) = qos[topic]
        rel, dur, depth = expected_qos(topic, typename)
        assert (profile["reliability"], profile["durability"], profile["depth"], profile["history"]) == \
               (rel, dur, depth, "keep_last"), topic
    # rosbags' reader sees the same profiles
    from rosbags.interfaces import QosDurability, QosReliability
    from rosbags.rosbag2 import Reader

    with Reader(out) as reader:
        for conn in reader.connections:
            (q,) = conn.ext.offered_qos_profiles
            rel, dur, depth = expected_qos(conn.topic, conn.msgtype)
            assert (q.reliability, q.durability, q.depth) == (QosReliability[rel.upper()], QosDurability[dur.upper()],
                                                              depth), conn.topic
    # the MCAP channels carry them too (rosbag2's MCAP plugin plays from these), in the same version's encoding
    with open(next(out.glob("*.mcap")), "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        meta = {m.name: m.metadata for m in reader.iter_metadata()}
        import yaml

        mcap_version = yaml.safe_load(meta["rosbag2"]["serialized_metadata"])["version"] if "rosbag2" in meta else 8
        assert mcap_version == version
        for channel in summary.channels.values():
            raw = channel.metadata["offered_qos_profiles"]
            listed = raw if mcap_version <= 8 else yaml.safe_load(raw)
            (profile,) = rosbag2_qos_list(listed, mcap_version)
            schema = summary.schemas[channel.schema_id].name
            assert (profile["reliability"], profile["durability"]) == expected_qos(channel.topic, schema)[:2]


def test_single_file_channels_carry_the_qos(views_recording, tmp_path):
    src = views_recording
    out = tmp_path / "qos.mcap"
    export_ros2(src, out, distro="jazzy")
    with open(out, "rb") as f:
        summary = make_reader(f).get_summary()
    topics = {c.topic: c for c in summary.channels.values()}
    assert "/tf_static" in topics
    for topic, channel in topics.items():
        # no rosbag2 metadata record: rosbag2's MCAP plugin reads the channels as version 8
        (profile,) = rosbag2_qos_list(channel.metadata["offered_qos_profiles"], 8)
        assert (profile["reliability"], profile["durability"], profile["depth"]) == \
               expected_qos(topic, summary.schemas[channel.schema_id].name), topic


def test_the_recorded_worlds_unpacked_files_are_removed_after_export(views_recording, tmp_path, monkeypatch):
    """The attached world (and its meshes) are unpacked to a temporary folder for the scene and
    transform views; it is removed once the export ends (each export used to leave a
    sensorium-world-* folder behind)."""
    import tempfile

    scratch = tmp_path / "scratch"
    scratch.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    report = export_ros2(views_recording, tmp_path / "bag", distro="jazzy")
    assert {"/tf_static", "/scene"} <= set(report.topics)          # the world was unpacked and used
    assert [p.name for p in scratch.iterdir() if p.name.startswith("sensorium-world-")] == []
