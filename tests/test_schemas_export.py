"""The committed JSON Schemas (schemas/json/) are exactly what the models export now."""

from __future__ import annotations

import json

import pytest

from sensorium.schemas import export


@pytest.mark.parametrize("name", sorted(export.schemas()))
def test_committed_schema_is_current(name):
    committed = export.DEFAULT_DIR / name
    assert committed.exists(), f"{committed} missing: run `sensorium schemas`"
    assert committed.read_text(encoding="utf-8") == export.render(export.schemas()[name]), (
        f"{committed} is out of date: run `sensorium schemas` and commit the result")


def test_export_all_and_check(tmp_path):
    written = export.export_all(tmp_path / "out")
    assert sorted(p.name for p in written) == ["messages.schema.json", "services.schema.json", "world.schema.json"]
    assert export.stale(tmp_path / "out") == []
    (tmp_path / "out" / "messages.schema.json").write_text("{}\n")
    assert export.stale(tmp_path / "out") == ["messages.schema.json"]


def test_cli(tmp_path, capsys):
    from sensorium.cli import main

    assert main(["schemas", "--out", str(tmp_path)]) == 0
    assert main(["schemas", "--out", str(tmp_path), "--check"]) == 0
    assert main(["schemas", "--out", str(tmp_path / "none"), "--check"]) == 1


def test_documents_cover_every_type():
    docs = export.schemas()
    msgs = docs["messages.schema.json"]
    assert set(msgs["x-ros-types"]) == {"sensor_msgs/msg/Illuminance", "sensor_msgs/msg/Range", "sensor_msgs/msg/Image",
                                        "sensor_msgs/msg/LaserScan", "sensor_msgs/msg/PointCloud", "rosgraph_msgs/msg/Clock",
                                        "geometry_msgs/msg/PoseStamped", "sensor_msgs/msg/JointState", "std_msgs/msg/ColorRGBA",
                                        "geometry_msgs/msg/PointStamped", "geometry_msgs/msg/Vector3Stamped",
                                        "sensor_msgs/msg/NavSatFix", "std_msgs/msg/Float64", "sensor_msgs/msg/Imu",
                                        "sensor_msgs/msg/MagneticField", "sensor_msgs/msg/CameraInfo",
                                        "radar_msgs/msg/RadarScan", "std_msgs/msg/String", "sensor_msgs/msg/BatteryState"}
    for ref in msgs["x-ros-types"].values():
        assert ref.split("/")[-1] in msgs["$defs"]
    svc = docs["services.schema.json"]
    assert svc["x-error-codes"]["TOO_LARGE"] == 8
    for s in svc["x-services"]:
        assert s["args"].split("/")[-1] in svc["$defs"] and s["result"].split("/")[-1] in svc["$defs"]
    json.dumps(docs)   # plain JSON
