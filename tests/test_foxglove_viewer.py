"""The Foxglove bridge in-process: addresses, demand bookkeeping, and a stalled viewer that cannot
hold up the step loop (bounded queue, oldest dropped)."""

from __future__ import annotations

import threading
import time
from contextlib import contextmanager
from pathlib import Path

import pytest

pytest.importorskip("foxglove")

from sensorium.server.viewer.bridge import FoxgloveBridge, ViewerError, exposure_warning, parse_address  # noqa: E402
from sensorium.server.world.loader import load_world  # noqa: E402

WORLD = Path(__file__).parent / "worlds" / "server.yaml"
TYPES = {"/bot/ls/value": "sensor_msgs/msg/Illuminance", "/bot/pose": "geometry_msgs/msg/PoseStamped",
         "/free/pose": "geometry_msgs/msg/PoseStamped", "/weird": "no_such_pkg/msg/Thing"}


def test_parse_address():
    assert parse_address("8765") == ("127.0.0.1", 8765)
    assert parse_address("0.0.0.0:0") == ("0.0.0.0", 0)
    assert parse_address("[::1]:9000") == ("::1", 9000)
    for bad, msg in [("host:x", "is not a number"), ("70000", "0..65535"), (":80", "empty host"), ("[::1]9", "[HOST]:PORT")]:
        with pytest.raises(ViewerError, match=msg.replace("[", r"\[").replace("]", r"\]")):
            parse_address(bad)


def test_exposure_warning_only_off_loopback():
    for host in ("127.0.0.1", "127.8.0.1", "::1", "localhost"):
        assert exposure_warning(host) is None, host
    for host in ("0.0.0.0", "::", "192.168.1.5", "simhost.example"):
        assert "no authentication" in (exposure_warning(host) or ""), host


@pytest.fixture()
def bridge():
    demands: list[set[str]] = []
    b = FoxgloveBridge(TYPES, load_world(WORLD).world, WORLD.parent, port=0, on_demand=demands.append,
                       queue_size=4)
    b.demands = demands          # type: ignore[attr-defined]
    yield b
    b.close()


def test_demand_follows_subscriptions(bridge):
    assert bridge.unsupported == {"/weird": "no_such_pkg/msg/Thing"}
    assert set(bridge.channels) == {"/bot/ls/value", "/bot/pose", "/free/pose"}
    bridge.pump()
    assert bridge.demands == []                       # nothing changed, nothing applied
    bridge._subscribed(1, "/bot/ls/value", +1)
    bridge._subscribed(2, "/bot/ls/value", +1)
    bridge.pump()
    assert bridge.demands[-1] == {"/bot/ls/value"}
    bridge._subscribed(1, "/bot/ls/value", -1)
    bridge._subscribed(1, "/bot/ls/value", -1)        # a second unsubscribe of client 1 is ignored
    bridge.pump()
    assert bridge.demands[-1] == {"/bot/ls/value"}    # client 2 still subscribed
    bridge._subscribed(2, "/tf", +1)                   # transforms need every robot pose
    bridge._subscribed(2, "/bot/ls/value", -1)
    bridge.pump()
    assert bridge.demands[-1] == {"/bot/pose", "/free/pose"}
    bridge._subscribed(2, "/tf", -1)
    bridge.pump()
    assert bridge.demands[-1] == set() and bridge.subscriptions() == {}


def test_a_stalled_viewer_never_blocks_record(bridge):
    inside, release = threading.Event(), threading.Event()

    def stuck(*_args):
        inside.set()
        release.wait(30)

    bridge._forward = stuck                           # the worker hangs on its first message
    bridge.record("/bot/ls/value", TYPES["/bot/ls/value"], b"", b"\x80", 1, 0)
    assert inside.wait(30)
    for i in range(10):                               # the step loop goes on publishing
        bridge.record("/bot/ls/value", TYPES["/bot/ls/value"], b"", b"\x80", 2 + i, i + 1)
    assert len(bridge._queue) == 4 and bridge.dropped == 6
    assert [item[3] for item in bridge._queue] == [8, 9, 10, 11]    # the newest are kept
    release.set()
    deadline = time.monotonic() + 30
    while bridge._queue and time.monotonic() < deadline:
        time.sleep(0.01)
    assert not bridge._queue



@contextmanager
def scene_sends(sim):
    """A Foxglove bridge on ``sim``'s core and transport whose scene sends are recorded, not sent:
    yields (bridge, pass_, sent). ``pass_(k)`` runs the transport loop's pass (demand applied,
    poses and removals noted), then waits until ``k`` sends are recorded: a subscriber's id for
    its own copy, None for a broadcast."""
    from sensorium.server.daemon.services import Core
    from sensorium.server.daemon.transport import Transport

    transport = Transport(Core(sim), "tcp://127.0.0.1:0", "tcp://127.0.0.1:0")
    bridge = FoxgloveBridge.for_core(transport.core, transport, "127.0.0.1", 0)
    sent: list[int | None] = []
    bridge._work = lambda: sent.extend(bridge._scene_for) or bridge._scene_for.clear()  # record, do not send

    def pass_(k: int = 0) -> None:
        transport.hooks[0]()
        deadline = time.monotonic() + 30
        while len(sent) < k and time.monotonic() < deadline:
            time.sleep(0.01)

    try:
        yield bridge, pass_, sent
    finally:
        bridge.close()
        transport.close()


def test_moved_solid_resends_the_scene_to_everyone():
    from sensorium.server.sim.simulation import Simulation

    sim = Simulation.from_file(WORLD, precision="fast")
    with scene_sends(sim) as (bridge, pass_, sent):
        before = bridge.scene_bytes()
        bridge._subscribed(7, "/scene", +1)
        pass_()
        sim.set_solid_pose("wall", (1.5, 0.0, 0.25))
        pass_(2)
        assert sent == [7, None]                       # the subscriber's own copy, then a broadcast
        assert bridge.scene_bytes() != before          # the wall is drawn at its new place
        pass_()                                        # pump queues synchronously, so this is final
        assert sent == [7, None] and not bridge._scene_for   # nothing moved since: nothing resent



def test_meshes_over_the_triangle_budget_are_drawn_as_bounding_boxes():
    import numpy as np

    from sensorium.server.recording.scene3d import fit_budget
    from sensorium.server.sim.scene import primitive_from_model
    from sensorium.server.world import geometry as geo
    from sensorium.server.world.loader import default_world_path

    loaded = load_world(default_world_path())
    rock = next(s for s in loaded.world.solids if s.name == "rock")
    v, f = geo.tessellate(primitive_from_model(rock.geometry, loaded.base_dir))
    budget = [len(f)]
    assert fit_budget(v, f, budget)[1] is f and budget == [0]          # fits exactly: drawn, budget used up
    bv, bf = fit_budget(v, f, budget)                                   # nothing left: its bounding box
    assert len(bf) == 12 and budget == [0]
    np.testing.assert_allclose(bv.min(axis=0), v.min(axis=0), atol=1e-12)
    np.testing.assert_allclose(bv.max(axis=0), v.max(axis=0), atol=1e-12)


def test_layout_command(tmp_path):
    import json
    import os
    import subprocess
    import sys

    root = Path(__file__).resolve().parents[1]
    env = dict(os.environ, PYTHONPATH=str(root))
    out = tmp_path / "layout.json"
    run = lambda *a: subprocess.run([sys.executable, "-m", "sensorium", "layout", *a], capture_output=True,
                                    text=True, env=env, timeout=120)
    r = run(str(WORLD), "-o", str(out))
    assert r.returncode == 0, r.stderr
    lay = json.loads(out.read_text())
    three_d, side = lay["content"]["items"][0]["content"], lay["content"]["items"][1]["content"]["items"]
    assert three_d["panelType"] == "ThreeDee" and three_d["config"]["fixedFrame"] == "world"
    assert set(three_d["config"]["topics"]) == {"/scene", "/bot/lidar/laser_scan", "/bot/lidar/point_cloud",
                                                "/bot/lidar2/point_cloud"}
    *side, windows = side                                       # last: the robots' windows, one tab each
    panels = {item["content"]["panelType"]: item["content"]["config"] for item in side}
    assert [(t["title"], t["content"]["panelType"], t["content"]["config"]) for t in windows["content"]["tabs"]] == \
        [(r, "RawMessages", {"topicPath": f"/{r}/robot_window"}) for r in ("bot", "bot2", "free", "rover")]
    assert [p["value"] for p in panels["Plot"]["paths"]] == ["/bot/ds/value.range", "/bot/ls/value.illuminance",
                                                             "/free/ls/value.illuminance"]
    assert panels["Image"]["imageMode"]["imageTopic"] == "/bot/lidar/range_image"
    assert panels["RawMessages"]["topicPath"] == "/clock"
    again = run(str(WORLD), "-o", str(out))                     # never overwrite without being asked
    assert again.returncode == 1 and again.stderr.strip().endswith("not overwriting (--force to replace it)")
    missing = run(str(tmp_path / "nope.mcap"))
    assert missing.returncode == 1 and missing.stderr.strip().startswith(
        f"sensorium layout: {tmp_path / 'nope.mcap'}: no such file (nor a bundled world: arena")
    bundled = run("arena", "-o", str(tmp_path / "arena.json"))             # a bundled name, from any directory
    assert bundled.returncode == 0, bundled.stderr
    assert "/scout/lidar/laser_scan" in json.loads((tmp_path / "arena.json").read_text())["content"]["items"][0][
        "content"]["config"]["topics"]
    # an output that cannot be written: one line (it was a FileNotFoundError / IsADirectoryError traceback)
    for bad, why in ((tmp_path / "no" / "such" / "dir.json", "No such file or directory"), (tmp_path, "Is a directory")):
        r = run("arena", "-o", str(bad), "--force")
        assert r.returncode == 1 and r.stderr.strip().splitlines() == [f"sensorium layout: cannot write {bad}: {why}"]


def test_grown_world_format_is_drawn_where_rays_see_it():
    """Nested children, multi-shape solids and robots, attached lights (tests/worlds/wbt/full.yaml):
    the markers of the ROS export and the Foxglove scene come from the same bodies()/lights()."""
    import math

    import numpy as np

    from sensorium.server.recording.ros_views import marker_array

    full = Path(__file__).parent / "worlds" / "wbt" / "full.yaml"
    loaded = load_world(full)
    markers = marker_array(loaded.world, loaded.base_dir, 0)["markers"]
    by_ns: dict[str, list] = {}
    for m in markers:
        by_ns.setdefault(m["ns"], []).append(m)
    pos = lambda m: [m["pose"]["position"][k] for k in "xyz"]
    # obstacle: rotated 0.3 about z at (0.8, 0.3, 0); box 0.1 up, sphere 0.25 up, child cap 0.4 up (its
    # visual capsule, and the bounding-only twin, Webots' invisible boundingObject, translucent)
    obstacle = by_ns["solid/obstacle"]
    assert [m["type"] for m in obstacle] == [1, 2, 11, 11]
    assert [m["color"]["a"] for m in obstacle[2:]] == [1.0, 0.25]
    for m, z in zip(obstacle, (0.1, 0.25, 0.4, 0.4)):
        np.testing.assert_allclose(pos(m), [0.8, 0.3, z], atol=1e-12)
    q = obstacle[0]["pose"]["orientation"]
    assert (q["z"], q["w"]) == (pytest.approx(math.sin(0.15)), pytest.approx(math.cos(0.15)))
    assert obstacle[1]["color"] == {"r": 0.3, "g": 0.9, "b": 0.1, "a": pytest.approx(0.8)}
    mesh = by_ns["solid/mesh"]                       # the mesh, and its bounding-only box drawn translucent
    assert [m["type"] for m in mesh] == [11, 1] and [m["color"]["a"] for m in mesh] == [1.0, 0.25]
    assert len(by_ns["solid/faces"][0]["points"]) == 6 * 3                             # six triangles
    assert [m["type"] for m in by_ns["solid/rectangle arena"]] == [1] * 5             # floor plane + 4 walls
    # the robot: three shapes in its own frame, moving with it
    bot = by_ns["robot/bot"]
    assert len(bot) == 3 and all(m["header"]["frame_id"] == "bot" and m["frame_locked"] for m in bot)
    np.testing.assert_allclose(pos(bot[1]), [0, 0.026, 0.02], atol=1e-12)
    # lights: the spot on the obstacle placed and turned with it; the robot's lamp rides in its frame
    spot = by_ns["light/obstacle/light0"]
    np.testing.assert_allclose(pos(spot[0]), [0.8, 0.3, 0.5], atol=1e-12)
    arrow = spot[1]["pose"]["orientation"]                                            # +x turned by 0.3 about z
    assert (arrow["z"], arrow["w"]) == (pytest.approx(math.sin(0.15)), pytest.approx(math.cos(0.15)))
    lamp = by_ns["light/bot/light0"][0]
    assert lamp["header"]["frame_id"] == "bot" and lamp["frame_locked"] and pos(lamp) == [0.05, 0.0, 0.1]
    assert by_ns["light/light0"][0]["type"] == 0 and by_ns["light/light0"][0]["header"]["frame_id"] == "world"
    # the Foxglove scene is built from the same bodies and lights (decoded field by field in the Node tests)
    from sensorium.server.recording.scene3d import scene_update

    assert len(scene_update(loaded.world, loaded.base_dir).encode()) > 1000


def test_closing_with_a_viewer_connected_logs_no_traceback(caplog):
    """Stopping the server while a viewer was connected printed asyncio's 'Exception in callback'
    traceback (its cancelled connection task) once per viewer."""
    import base64
    import logging
    import os
    import socket

    b = FoxgloveBridge(TYPES, load_world(WORLD).world, WORLD.parent, port=0)
    try:
        # a viewer: the WebSocket upgrade by hand (no client library in the test extras)
        with socket.create_connection(("127.0.0.1", b.port), timeout=10) as ws:
            key = base64.b64encode(os.urandom(16)).decode()
            ws.sendall((f"GET / HTTP/1.1\r\nHost: 127.0.0.1:{b.port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                        f"Sec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n"
                        "Sec-WebSocket-Protocol: foxglove.sdk.v1\r\n\r\n").encode())
            got = b""
            while b"\r\n\r\n" not in got or len(got) <= got.index(b"\r\n\r\n") + 4:   # the head, then serverInfo
                chunk = ws.recv(65536)
                assert chunk, got
                got += chunk
            assert got.startswith(b"HTTP/1.1 101"), got[:200]
            with caplog.at_level(logging.ERROR, logger="asyncio"):
                b.close()
                time.sleep(0.5)                               # (late callbacks would log within it)
    finally:
        b.close()
    assert not [r for r in caplog.records if r.name == "asyncio"], [r.getMessage() for r in caplog.records]
