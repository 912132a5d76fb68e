"""Synthetic recordings for the recording/replay/export tests: bodies shaped like the live
server's (PROTOCOL.md §4: msgpack maps with ROS field names, little-endian bin arrays)."""

from __future__ import annotations

import math

import msgpack
import numpy as np

from sensorium.server.recording.envelope import pack_envelope
from sensorium.server.recording.writer import McapRecorder

WORLD = b"world_info: {name: synthetic, basic_time_step: 32, random_seed: 7}\n"
STEP_NS = 32_000_000


def header(t_ns: int, frame: str) -> dict:
    return {"stamp": {"sec": t_ns // 1_000_000_000, "nanosec": t_ns % 1_000_000_000}, "frame_id": frame}


def illuminance(t_ns: int, i: int) -> dict:
    return {"header": header(t_ns, "epuck/ls0"), "illuminance": 100.0 + 0.5 * i, "variance": 0.0}


def range_(t_ns: int, i: int) -> dict:
    r = float("inf") if i % 7 == 3 else 0.01 * (i % 50)
    return {"header": header(t_ns, "epuck/ps0"), "radiation_type": 1, "field_of_view": 0.3,
            "min_range": 0.0, "max_range": 0.5, "range": r, "variance": 0.25}


def laser_scan(t_ns: int, i: int, n: int = 90) -> dict:
    ranges = np.linspace(0.2, 3.0, n, dtype="<f4") + np.float32(0.001 * i)
    ranges[5] = np.inf
    ranges[6] = np.nan
    return {"header": header(t_ns, "scout/lidar"), "angle_min": math.pi, "angle_max": -math.pi,
            "angle_increment": -2 * math.pi / (n - 1), "time_increment": 0.064 / n, "scan_time": 0.064,
            "range_min": 0.1, "range_max": 8.0, "ranges": ranges.astype("<f4").tobytes(), "intensities": b""}


def range_image(t_ns: int, i: int, layers: int = 2, width: int = 16) -> dict:
    img = (np.arange(layers * width, dtype="<f4") * 0.1 + i).astype("<f4")
    return {"header": header(t_ns, "scout/lidar"), "height": layers, "width": width, "encoding": "32FC1",
            "is_bigendian": 0, "step": 4 * width, "data": img.tobytes()}


def point_cloud(t_ns: int, i: int, n: int = 24) -> dict:
    pts = (np.arange(n * 3, dtype="<f4").reshape(n, 3) * 0.01 + i).astype("<f4")
    pts[2, 0] = np.inf
    layer = (np.arange(n) % 2).astype("<f4")
    return {"header": header(t_ns, "scout/lidar"), "points": pts.tobytes(),
            "channels": [{"name": "layer", "values": layer.tobytes()}]}


def clock(t_ns: int, i: int) -> dict:
    return {"clock": {"sec": t_ns // 1_000_000_000, "nanosec": t_ns % 1_000_000_000}}


TOPICS = {
    "/epuck/ls0/value": ("sensor_msgs/msg/Illuminance", illuminance, 1),
    "/epuck/ps0/value": ("sensor_msgs/msg/Range", range_, 1),
    "/epuck/ps1/value": ("sensor_msgs/msg/Range", range_, 2),
    "/scout/lidar/laser_scan": ("sensor_msgs/msg/LaserScan", laser_scan, 2),
    "/scout/lidar/range_image": ("sensor_msgs/msg/Image", range_image, 2),
    "/scout/lidar/point_cloud": ("sensor_msgs/msg/PointCloud", point_cloud, 4),
    "/clock": ("rosgraph_msgs/msg/Clock", clock, 1),
}


def published(steps: int, topics: dict | None = None):
    """What a server would publish over ``steps`` basic steps, in publication order:
    (topic, type, envelope, body, stamp_ns, seq)."""
    topics = topics or TOPICS
    seqs = {t: 0 for t in topics}
    for k in range(1, steps + 1):
        t_ns = k * STEP_NS
        for topic, (ros_type, make, every) in topics.items():
            if k % every:
                continue
            seq = seqs[topic]
            seqs[topic] += 1
            body = msgpack.packb(make(t_ns, seq))
            yield topic, ros_type, pack_envelope(ros_type, seq, t_ns), body, t_ns, seq


def make_recording(path, steps: int = 50, topics=None, record_topics=None, chunk_size: int = 4096, **kw):
    """Write a recording; returns the list of everything 'published' (recorded or not)."""
    out = list(published(steps, topics))
    with McapRecorder(path, WORLD, "synthetic.yaml", {"seed": "7", "basic_time_step_ms": "32", "world": "synthetic"},
                      record_topics, chunk_size, **kw) as rec:
        for item in out:
            rec.record(*item)
    return out


def recorded_simulation(path, world: dict, name: str):
    """A Simulation of ``world`` whose topics record each publish into the MCAP file ``path`` (the world's
    JSON as its world text, ``name`` as its file name): (sim, topics, recorder), the recorder to close."""
    import json

    from sensorium.schemas import world as wm
    from sensorium.server.daemon.topics import Topics
    from sensorium.server.sim.simulation import Simulation

    w = wm.World.model_validate(world)
    sim = Simulation(w)
    topics = Topics(sim)
    rec = McapRecorder(path, json.dumps(world), name, world=w, flush_interval=None, background_flush=False)
    topics.set_recorder(rec)
    return sim, topics, rec
