"""The direct CDR writer (sensorium.server.recording.cdr) against rosbags' serialize_cdr: byte for
byte, on every message type a real simulation publishes, for both distros, and on edge cases."""

from __future__ import annotations

import math
from pathlib import Path

import msgpack
import pytest

pytest.importorskip("rosbags")

from sensorium.schemas.wire import pack  # noqa: E402
from sensorium.server.daemon.topics import Topics  # noqa: E402
from sensorium.server.recording import cdr  # noqa: E402
from sensorium.server.recording.export import CdrEncoder  # noqa: E402
from sensorium.server.sim.simulation import Simulation  # noqa: E402

WORLD = Path(__file__).parent / "worlds" / "server.yaml"


def published(steps: int = 5, sim: Simulation | None = None) -> list[tuple[str, str, bytes]]:
    sim = sim or Simulation.from_file(WORLD, precision="fast")
    topics = Topics(sim)
    got: list[tuple[str, str, bytes]] = []
    topics.set_recorder(lambda t, ty, env, body, ns, seq: got.append((t, ty, body)))
    for _ in range(steps):
        sim.step()
        topics.publish(sim.time_ms)
    return got


def battery_world() -> Simulation:
    from sensorium.server.world.loader import parse_world
    return Simulation(parse_world({"world_info": {"basic_time_step": 32},
                                   "robots": [{"name": "r", "battery": [100.0, 200.0, 0.0], "cpu_consumption": 10.0},
                                              {"name": "unbounded", "battery": [3.0]}]}))


@pytest.mark.parametrize("distro", ["humble", "jazzy"])
@pytest.mark.parametrize("pointcloud2", [True, False])
def test_direct_cdr_is_byte_identical_to_rosbags(distro, pointcloud2):
    enc = CdrEncoder(distro, pointcloud2=pointcloud2)
    msgs = published() + published(sim=battery_world())      # the server world has no battery
    types = set()
    for topic, ros_type, body in msgs:
        typename, fast = enc.encode(ros_type, body)
        assert fast == enc.encode_generic(ros_type, body), (topic, typename)
        types.add(typename)
    direct = set(cdr.FAST_TYPES) - ({"sensor_msgs/msg/PointCloud2"} if not pointcloud2 else set())
    assert direct <= types          # every type with a direct writer was exercised


@pytest.mark.parametrize("distro", ["humble", "jazzy"])
def test_edge_cases_match_rosbags(distro):
    enc = CdrEncoder(distro)
    hdr = {"stamp": {"sec": 3, "nanosec": 5}, "frame_id": "rob/dévice"}
    cases = [
        ("sensor_msgs/msg/LaserScan", {"header": hdr, "angle_min": 1.0, "angle_max": -1.0, "angle_increment": -0.1,
                                       "time_increment": 0.0, "scan_time": 0.032, "range_min": 0.0, "range_max": math.inf,
                                       "ranges": b"", "intensities": b""}),
        ("sensor_msgs/msg/LaserScan", {"header": hdr, "angle_min": 0.0, "angle_max": 0.0, "angle_increment": 0.0,
                                       "time_increment": 0.0, "scan_time": 0.0, "range_min": 0.0, "range_max": 1.0,
                                       "ranges": b"\x00\x00\x80\x7f" * 3, "intensities": b""}),
        ("sensor_msgs/msg/PointCloud", {"header": hdr, "points": b"", "channels": [{"name": "layer", "values": b""}]}),
        ("sensor_msgs/msg/Range", {"header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}, "radiation_type": 1,
                                   "field_of_view": 0.2, "min_range": 0.0, "max_range": 2000.0, "range": 1e-40,
                                   "variance": 0.0}),
        ("sensor_msgs/msg/Image", {"header": hdr, "height": 1, "width": 3, "encoding": "32FC1", "is_bigendian": 0,
                                   "step": 12, "data": bytes(range(12))}),
        ("sensor_msgs/msg/BatteryState", {"header": hdr, "voltage": 12.5, "temperature": math.nan, "current": -0.5,
                                          "charge": 1.0, "capacity": 2.0, "design_capacity": 2.5, "percentage": 0.5,
                                          "power_supply_status": 4, "power_supply_health": 1,
                                          "power_supply_technology": 2, "present": False,
                                          "cell_voltage": b"\x00\x00\x80\x3f" * 3, "cell_temperature": b"",
                                          "location": "slot 1", "serial_number": "sn-ü"}),
    ]
    for ros_type, body in cases:
        b = pack(body)
        assert enc.encode(ros_type, b)[1] == enc.encode_generic(ros_type, b), ros_type


def test_unusual_body_falls_back_to_the_generic_path():
    enc = CdrEncoder("jazzy")
    body = msgpack.packb({"header": None, "illuminance": None})          # nulls: the generic path zero-fills
    assert enc.encode("sensor_msgs/msg/Illuminance", body)[1] == enc.encode_generic("sensor_msgs/msg/Illuminance", body)
