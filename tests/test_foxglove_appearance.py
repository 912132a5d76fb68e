"""The Foxglove scene follows a Supervisor's appearance changes: the live viewer's ``/scene``
(``serve --foxglove``) and a server recording's (``serve --record``) draw a shape in the colour and
transparency a Supervisor set, an ``Appearance`` whose texture a Supervisor took away in its
Material's colour (a textured one is drawn white, as at load), and a reset draws the loaded ones
again. The scene is encoded again only when an appearance changed (a version number), never per step.

Our own world, written in the test's folder: the wall's ``Appearance`` has a Material and the
texture TEX (drawn white while it has an image); the ball's ``PBRAppearance`` BALL_APP is USEd by
the solid "twin"; the pane's Material is translucent; the supervisor "boss" carries a body shape."""

from __future__ import annotations

import pytest

pytest.importorskip("foxglove")
pytest.importorskip("google.protobuf")

from _node import run_script  # noqa: E402
from test_foxglove_viewer import scene_sends  # noqa: E402

from sensorium.server.daemon import supervisor as sv  # noqa: E402
from sensorium.server.recording import scene3d  # noqa: E402
from sensorium.server.sim.simulation import Simulation  # noqa: E402
from sensorium.server.world.loader import load_world  # noqa: E402

WORLD = """#VRML_SIM R2023b utf8
WorldInfo {
  basicTimeStep 16
}
Viewpoint {
}
DEF WALL Solid {
  translation 1 0 0
  name "wall"
  children [
    Shape {
      appearance Appearance {
        material Material {
          diffuseColor 0.25 0.5 0.75
        }
        texture DEF TEX ImageTexture {
          url [
            "a.png"
          ]
        }
      }
      geometry Box {
        size 0.1 1 1
      }
    }
  ]
}
DEF BALL Solid {
  translation 0 3 0
  name "ball"
  children [
    Shape {
      appearance DEF BALL_APP PBRAppearance {
        baseColor 0.75 0.5 0.25
        roughness 0.5
      }
      geometry Sphere {
        radius 0.5
      }
    }
  ]
}
Solid {
  translation 3 3 0
  name "twin"
  children [
    Shape {
      appearance USE BALL_APP
      geometry Box {
        size 1 1 1
      }
    }
  ]
}
DEF PANE Solid {
  translation 0 -3 0
  name "pane"
  children [
    Shape {
      appearance Appearance {
        material DEF PANE_MAT Material {
          diffuseColor 0.125 0.875 0.25
          transparency 0.25
        }
      }
      geometry Cylinder {
        radius 0.5
        height 1
      }
    }
  ]
}
DEF BOSS Robot {
  name "boss"
  supervisor TRUE
  controller "<extern>"
  children [
    Shape {
      appearance DEF BOSS_APP PBRAppearance {
        baseColor 0.5 0.5 0.5
      }
      geometry Box {
        size 0.2 0.2 0.1
      }
    }
  ]
}
"""

# what the loaded world draws: entity -> [(primitive kind, RGBA)]
LOADED = {
    "solid/wall": [("cubes", (1.0, 1.0, 1.0, 1.0))],            # textured Appearance: white, as Webots' texture replaces the diffuse colour
    "solid/ball": [("spheres", (0.75, 0.5, 0.25, 1.0))],
    "solid/twin": [("cubes", (0.75, 0.5, 0.25, 1.0))],
    "solid/pane": [("cylinders", (0.125, 0.875, 0.25, 0.75))],  # alpha 1 - transparency
    "robot/boss": [("cubes", (0.5, 0.5, 0.5, 1.0))],
}


@pytest.fixture
def world(tmp_path):
    from PIL import Image

    Image.new("RGB", (4, 4), (200, 100, 30)).save(tmp_path / "a.png")
    (tmp_path / "world.wbt").write_text(WORLD)
    return tmp_path / "world.wbt"


def _scene_class():
    from foxglove.messages import SceneUpdate
    from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

    schema = SceneUpdate.get_schema()
    pool = descriptor_pool.DescriptorPool()
    for fd in descriptor_pb2.FileDescriptorSet.FromString(bytes(schema.data)).file:
        pool.Add(fd)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(schema.name))


def colours(data: bytes) -> dict[str, list[tuple[str, tuple[float, float, float, float]]]]:
    """A SceneUpdate's shape entities (lights have none here): id -> [(primitive kind, RGBA)]."""
    msg = _scene_class().FromString(data)
    out = {}
    for e in msg.entities:
        prims = [(kind, (p.color.r, p.color.g, p.color.b, p.color.a))
                 for kind in ("cubes", "spheres", "cylinders", "triangles") for p in getattr(e, kind)]
        out[e.id] = prims
    return out


def with_colour(entity: str, rgba: tuple[float, ...], base: dict | None = None) -> dict:
    got = dict(base or LOADED)
    got[entity] = [(got[entity][0][0], tuple(rgba))]
    return got


@pytest.fixture
def encodes(monkeypatch):
    """How many times the scene was encoded (scene3d.scene_update called)."""
    calls = []
    real = scene3d.scene_update

    def counting(*args, **kw):
        calls.append(1)
        return real(*args, **kw)

    monkeypatch.setattr(scene3d, "scene_update", counting)
    return calls


def test_the_live_scene_draws_the_appearance_a_supervisor_set_and_a_reset_the_loaded_one(world, encodes):
    sim = Simulation(load_world(world), precision="fast")
    with scene_sends(sim) as (bridge, pass_, sent):
        first = bridge.scene_bytes()
        assert colours(first) == LOADED and len(encodes) == 1
        bridge._subscribed(7, "/scene", +1)
        pass_(1)
        assert sent == [7]

        # a PBRAppearance's baseColor: the ball and the twin that USEs it, nothing else; one broadcast
        sv.set_field(sim, sv.find_node(sim, "BALL_APP"), "baseColor", [0.25, 0.5, 1.0])
        pass_(2)
        assert sent == [7, None]
        now = with_colour("solid/twin", (0.25, 0.5, 1.0, 1.0), with_colour("solid/ball", (0.25, 0.5, 1.0, 1.0)))
        assert colours(bridge.scene_bytes()) == now and len(encodes) == 2

        # two changes between two passes: a Material's transparency and the robot's own shape; one broadcast
        sv.set_field(sim, sv.find_node(sim, "PANE_MAT"), "transparency", 0.5)
        sv.set_field(sim, sv.find_node(sim, "BOSS_APP"), "baseColor", [0.0, 0.25, 0.5])
        pass_(3)
        assert sent == [7, None, None]
        now = with_colour("robot/boss", (0.0, 0.25, 0.5, 1.0), with_colour("solid/pane", (0.125, 0.875, 0.25, 0.5), now))
        assert colours(bridge.scene_bytes()) == now and len(encodes) == 3

        # the texture taken away: the wall shows its Material's diffuse colour; given back: white again
        tex = sv.find_node(sim, "TEX")
        sv.change_item(sim, tex, "url", "remove", 0, None)
        pass_(4)
        assert colours(bridge.scene_bytes()) == with_colour("solid/wall", (0.25, 0.5, 0.75, 1.0), now)
        sv.change_item(sim, tex, "url", "insert", 0, "a.png")
        pass_(5)
        assert sent == [7, None, None, None, None]
        assert colours(bridge.scene_bytes()) == now and len(encodes) == 5

        # nothing changed (steps, passes, the same colour again, fields not drawn): not encoded, not sent
        for _ in range(3):
            sim.step()
            pass_()
        sv.set_field(sim, sv.find_node(sim, "BALL_APP"), "baseColor", [0.25, 0.5, 1.0])
        sv.set_field(sim, sv.find_node(sim, "BALL_APP"), "metalness", 0.5)
        pass_()
        for _ in range(3):
            bridge.scene_bytes()
        assert len(encodes) == 5 and sent == [7, None, None, None, None] and not bridge._scene_for

        # a reset: the loaded appearances, byte for byte the first scene
        sim.reset()
        pass_(6)
        assert sent == [7, None, None, None, None, None]
        assert bridge.scene_bytes() == first and len(encodes) == 6
        pass_()
        bridge.scene_bytes()
        assert len(encodes) == 6 and len(sent) == 6


def test_an_appearance_changed_while_nobody_watches_is_in_the_next_subscribers_scene(world):
    sim = Simulation(load_world(world), precision="fast")
    with scene_sends(sim) as (bridge, pass_, sent):
        sv.set_field(sim, sv.find_node(sim, "PANE_MAT"), "diffuseColor", [1.0, 0.5, 0.0])
        pass_()
        assert sent == []                                  # nobody subscribed: nothing broadcast
        bridge._subscribed(3, "/scene", +1)
        pass_(1)
        assert sent == [3]
        assert colours(bridge.scene_bytes()) == with_colour("solid/pane", (1.0, 0.5, 0.0, 0.75))


def _scenes(path) -> list[tuple[int, dict]]:
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        return [(m.log_time, colours(m.data)) for _s, _c, m in make_reader(f).iter_messages(["/scene"])]


def test_a_server_recording_writes_the_scene_again_when_an_appearance_changes(world, tmp_path):
    """serve --record: /scene at time 0, then at the first message after each change or reset only."""
    from sensorium.server.daemon.services import Core
    from sensorium.server.recording.writer import recorder_for_server

    sim = Simulation(load_world(world), precision="fast")
    core = Core(sim)
    rec = recorder_for_server(tmp_path / "run.mcap", core)
    stamps = []
    try:
        for k in range(8):
            if k == 2:
                sv.set_field(sim, sv.find_node(sim, "BALL_APP"), "baseColor", [0.25, 0.5, 1.0])
            if k == 4:
                sim.reset()
            if k == 6:
                sv.change_item(sim, sv.find_node(sim, "TEX"), "url", "remove", 0, None)
            sim.step()
            stamps.append(sim.time_ms * 1_000_000)
            core.topics.publish(sim.time_ms)
    finally:
        rec.close()
    scenes = _scenes(tmp_path / "run.mcap")
    ball = with_colour("solid/twin", (0.25, 0.5, 1.0, 1.0), with_colour("solid/ball", (0.25, 0.5, 1.0, 1.0)))
    bare = with_colour("solid/wall", (0.25, 0.5, 0.75, 1.0))
    assert scenes == [(0, LOADED), (stamps[2], ball), (stamps[4], LOADED), (stamps[6], bare)]
    # Foxglove's own MCAP reader and an independent protobuf decoder read the last one alike
    got = run_script("read_mcap.js", str(tmp_path / "run.mcap"))[0]
    assert got["errors"] == [] and got["last"]["/scene"]["log_time"] == stamps[6]
    wall = {e["id"]: e for e in got["last"]["/scene"]["msg"]["entities"]}["solid/wall"]
    c = wall["cubes"][0]["color"]
    assert (c["r"], c["g"], c["b"], c["a"]) == (0.25, 0.5, 0.75, 1.0)


def _rgba(entity: dict, kind: str) -> tuple[float, float, float, float]:
    c = entity[kind][0]["color"]
    return (c["r"], c["g"], c["b"], c["a"])


def test_a_viewer_we_did_not_write_sees_a_supervisors_colour_and_the_reset(world):
    """serve --foxglove end to end: Foxglove's own client (Node) subscribed to /scene gets the scene
    again after a supervisor's set_field over the wire, and again after simulation_reset."""
    import signal

    import zmq
    from _node import NodeProcess
    from _serve import serve
    from test_foxglove_live import Rpc

    srv = serve(world, "--precision", "fast", "--heartbeat-ms", "2000", "--foxglove", "127.0.0.1:0")
    ctx = zmq.Context()
    node = None
    try:
        node = NodeProcess("live_client.js", srv.fields["foxglove"])
        node.wait_for(lambda e: e["event"] == "advertise", what="advertise")
        node.send(cmd="subscribe", topic="/scene")

        def scene(k: int) -> dict:
            """The k-th /scene message (0: the subscriber's own copy), entities by id."""
            node.find(lambda e: sum(x["event"] == "message" and x["topic"] == "/scene" for x in node.seen) > k,
                      what=f"/scene #{k}")
            msgs = [e for e in node.seen if e["event"] == "message" and e["topic"] == "/scene"]
            return {e["id"]: e for e in msgs[k]["msg"]["entities"]}

        assert _rgba(scene(0)["solid/ball"], "spheres") == (0.75, 0.5, 0.25, 1.0)
        rpc = Rpc(ctx, srv.fields["rpc"])
        rpc.session = rpc.ok("attach", {"robot": "boss"})["session"]
        app = rpc.ok("/boss/robot/get_from_def", {"name": "BALL_APP"})["node"]
        rpc.ok("/boss/robot/set_field", {"node": app, "field": "baseColor", "value": [0.25, 0.5, 1.0]})
        rpc.ok("/boss/robot/step")
        changed = scene(1)
        assert _rgba(changed["solid/ball"], "spheres") == _rgba(changed["solid/twin"], "cubes") == (0.25, 0.5, 1.0, 1.0)
        assert _rgba(changed["solid/pane"], "cylinders") == (0.125, 0.875, 0.25, 0.75)
        rpc.ok("/boss/robot/simulation_reset")
        rpc.ok("/boss/robot/step")
        assert _rgba(scene(2)["solid/ball"], "spheres") == (0.75, 0.5, 0.25, 1.0)
        for _ in range(3):
            rpc.ok("/boss/robot/step")
        node.drain()                                # (kept in node.seen)
        assert sum(e["event"] == "message" and e["topic"] == "/scene" for e in node.seen) == 3
        assert not [e for e in node.seen if e["event"] == "error"]
    finally:
        if node is not None:
            node.close()
        code = srv.stop(signal.SIGTERM)
        ctx.destroy(0)
        assert code == 0, srv.stderr()
