"""A Supervisor's ``importMFNodeFromString`` (Webots' ``wb_supervisor_field_import_mf_node_from_string``)
into the root's children, against the closed forms tests/worlds/supervisor_remove.yaml explains (the
boss's devices at (0, 0, 0.1) look along +x; the wall's face is at x = 3): a box imported with its
face at x = 1.5 is seen by every ray kind from the next step (and not before), stops a robot, and
removing it restores the readings; an imported light is counted by light sensors; imported nodes get
new ids (never a removed node's), are found by DEF, are listed at their position, and a reset removes
them (Webots' reset matrix); robots and bad strings are refused with one line naming where, and the
simulation is unchanged."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from _protos import HEADER, proto_file
from test_multiprocess import run_paused
from test_supervisor import A, Live
from test_supervisor_remove import (
    BOSS,
    BULB,
    CRATE,
    GATE,
    LAMP,
    NULL,
    ROVER,
    SCENERY,
    WALL,
    WORLD,
    _live,
    boss,
    readings,
)

from sensorium.schemas.wire import ErrorCode
from sensorium.server.sim.imports import ImportRefused
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.limits import WorldLimits
from sensorium.server.world.loader import load_world

# a box whose face is at x = 1.5 (wide: every lidar ray and the range finder's centre rows meet it)
BOX = ("DEF BALL Solid { translation 1.6 0 0.25 name \"ball\" recognitionColors [ 0 1 0 ] "
       "children [ Shape { geometry Box { size 0.2 4 0.5 } } ] boundingObject Box { size 0.2 4 0.5 } }")
# a light on the sensors' axis, 0.25 m ahead: 1 / 0.25^2 = 16 (attenuation 0 0 1)
LIGHT = "DEF SPARK PointLight { location 0.25 0 0.1 intensity 1 attenuation 0 0 1 }"
FIRST = 10                                  # the first imported node's id: after the 9 the world loaded with


def imports(lv: Live, text: str, position: int = -1) -> list[int]:
    return boss(lv, "import_node_from_string", {"node": 0, "field": "children", "position": position,
                                                "node_string": text})["value"]


def refused(lv: Live, text: str, position: int = -1, node: int = 0, field: str = "children") -> str:
    msg = lv.err(A, "/boss/robot/import_node_from_string", {"node": node, "field": field, "position": position,
                                                             "node_string": text}, ErrorCode.INVALID_ARGUMENT)
    assert msg.startswith("import_node_from_string: ") and "\n" not in msg and "Traceback" not in msg
    return msg[len("import_node_from_string: "):]


def children(lv: Live) -> list[int]:
    return boss(lv, "get_field", {"node": 0, "field": "children"})["value"]


@pytest.mark.parametrize("precision", ["exact", "fast"])
def test_every_ray_kind_sees_an_imported_box_from_the_next_step(precision):
    lv = _live(precision)
    boss(lv, "remove_node", {"node": CRATE})
    before = readings(lv)
    assert before["ds"] == pytest.approx(3.0, abs=1e-9) and before["seen"] == []
    assert imports(lv, BOX) == [FIRST]
    assert lv.sim.device("boss/ds").value == pytest.approx(3.0, abs=1e-9)     # not before the next measurement
    got = readings(lv)
    assert got["ds"] == pytest.approx(1.5, abs=1e-9)
    np.testing.assert_allclose(got["lidar"], 0.5 * before["lidar"], rtol=1e-6)    # the same rays, x = 1.5 not 3
    assert got["depth"] == pytest.approx(1.5, abs=1e-6)
    assert got["seen"] == [FIRST]                                   # its recognition colour, as node FIRST
    assert (got["eye"], got["shaded"]) == (pytest.approx(7.0), pytest.approx(4.0))   # the lamp now behind it
    boss(lv, "remove_node", {"node": FIRST})
    after = readings(lv)
    assert after["ds"] == before["ds"] and after["depth"] == before["depth"] and after["seen"] == []
    np.testing.assert_array_equal(after["lidar"], before["lidar"])
    assert (after["eye"], after["shaded"]) == (before["eye"], before["shaded"])


def test_an_imported_light_is_counted_and_removed_again():
    lv = _live()
    assert (readings(lv)["eye"], readings(lv)["shaded"]) == (pytest.approx(7.0), pytest.approx(4.0))
    assert imports(lv, LIGHT) == [FIRST]
    got = readings(lv)
    assert (got["eye"], got["shaded"]) == (pytest.approx(23.0), pytest.approx(20.0))
    spark = boss(lv, "get_from_def", {"name": "SPARK"})
    assert (spark["node"], spark["type"]) == (FIRST, "PointLight")
    assert boss(lv, "get_field", {"node": FIRST, "field": "location"})["value"] == [0.25, 0.0, 0.1]
    boss(lv, "set_field", {"node": FIRST, "field": "intensity", "value": 2.0})        # its fields, as any light's
    assert readings(lv)["eye"] == pytest.approx(39.0)
    boss(lv, "remove_node", {"node": FIRST})
    assert readings(lv)["eye"] == pytest.approx(7.0)


def test_imported_nodes_have_new_ids_their_def_and_their_place_in_the_children():
    lv = _live()
    assert children(lv) == [*SCENERY, BOSS, ROVER, WALL, CRATE, GATE, LAMP, BULB]
    assert imports(lv, BOX + "\n" + LIGHT, 0) == [FIRST, FIRST + 1]          # both nodes, in order, first
    assert children(lv) == [FIRST, FIRST + 1, *SCENERY, BOSS, ROVER, WALL, CRATE, GATE, LAMP, BULB]
    ball = boss(lv, "get_from_def", {"name": "BALL"})
    assert ball == {"node": FIRST, "type": "Solid", "name": "ball", "def_name": "BALL", "parent": 0, "proto": ""}
    assert boss(lv, "get_from_id", {"id": FIRST}) == ball
    assert boss(lv, "get_field", {"node": FIRST, "field": "translation"})["value"] == [1.6, 0.0, 0.25]
    boss(lv, "remove_node", {"node": FIRST})
    assert boss(lv, "get_from_id", {"id": FIRST}) == NULL and boss(lv, "get_from_def", {"name": "BALL"}) == NULL
    # imported again: a new id (8 is never reused), a new name (Webots' clash rule: 'ball' was taken)
    assert imports(lv, BOX, -2) == [FIRST + 2]                                # before the last
    again = boss(lv, "get_from_def", {"name": "BALL"})
    assert (again["node"], again["name"]) == (FIRST + 2, "ball(1)")
    assert children(lv) == [FIRST + 1, *SCENERY, BOSS, ROVER, WALL, CRATE, GATE, LAMP, FIRST + 2, BULB]
    assert imports(lv, 'Solid { name "crate" }', 99) == [FIRST + 3]         # past the end: appended
    assert boss(lv, "get_from_id", {"id": FIRST + 3})["name"] == "crate(1)"  # the loaded crate keeps its name
    assert children(lv)[-1] == FIRST + 3
    assert imports(lv, 'Solid { name "first" }', -99) == [FIRST + 4]        # past the start: first
    assert children(lv)[0] == FIRST + 4


def test_a_robot_is_stopped_by_an_imported_box():
    """Kinematic contact: the rover (radius 0.2) drives along y = -2 at 0.5 m/s; with the gate removed
    and a box imported whose face is at x = 1.5, it stops at 1.3."""
    lv = _live()
    boss(lv, "remove_node", {"node": GATE})
    imports(lv, BOX.replace("translation 1.6 0 0.25", "translation 1.6 -2 0.25"))
    rover = lv.sim.robot("rover")
    for m in rover.motors.values():
        m.target_position, m.velocity = math.inf, 5.0
    for _ in range(250):                                                  # 4 s: 2 m, the box at 1.3
        lv.step(A, "boss", {"duration": 16})
    assert rover.pose.translation[0] == pytest.approx(1.3, abs=1e-9)


def test_simulation_reset_removes_imported_nodes():
    lv = _live()
    imports(lv, BOX + " " + LIGHT)
    boss(lv, "remove_node", {"node": CRATE})
    assert readings(lv)["ds"] == pytest.approx(1.5, abs=1e-9)
    boss(lv, "simulation_reset")
    got = readings(lv)
    assert got["ds"] == pytest.approx(3.0, abs=1e-9)              # the box gone, the crate still removed
    assert got["eye"] == pytest.approx(7.0)                        # the imported light gone
    assert children(lv) == [*SCENERY, BOSS, ROVER, WALL, GATE, LAMP, BULB]
    assert boss(lv, "get_from_id", {"id": FIRST}) == NULL and boss(lv, "get_from_def", {"name": "SPARK"}) == NULL
    assert imports(lv, BOX) == [FIRST + 2]                         # ids go on after a reset


def _unchanged(lv: Live) -> tuple:
    sim = lv.sim
    return (children(lv), sorted(sim.scene.solid_poses), len(sim.scene.top_lights()), sim.scene.triangle_count,
            len(sim.scene.shapes), len(sim.world.solids), sim.next_node_id())


@pytest.mark.parametrize("text, expected", [
    ("Robot { name \"spy\" }", "node string:1:1: Robot: a robot cannot be imported here: a departure from Webots, "
                               "which imports robots too (write it in the world file)"),
    ("Solid { children [ Robot { name \"rider\" } ] }", "node string:1:1: Solid: a robot cannot be imported here "
                                                         "(it holds robot 'rider')"),
    ("Solid {\n  translation 1 2\n}", "node string:2:3: Solid.translation: expected 3 numbers, got 2"),
    ("Solid { children [ Shape { geometry Box { size 1 1 1 } ]", "node string:1:"),
    ("Crate { }", "node string:1:1: Crate: not a built-in node or PROTO here."),
    ("Transform { scale 2 2 2 children [ Shape { geometry Box { } } ] }",
     "node string:1:1: Transform: not importable here"),
    ("Group { children [ Shape { geometry Box { } } PointLight { } ] }", "node string:1:1: Group: not importable here"),
    ("WorldInfo { }", "node string:1:1: WorldInfo: not importable here"),
    ("Solid {\n children [ PointLight { attenuation 0 0 0 } ] }",
     "node string:2:13 (PointLight, converted as solids[0].lights[0].attenuation): attenuation 0 0 0 would give"),
    ("Solid { children [ USE WHEEL ] }", "node string:1:24: USE WHEEL: no DEF WHEEL before this point"),
    ('EXTERNPROTO "Crate.proto"\nCrate { }', "node string:1:1: a node string declares no PROTO"),
    ("", "node string: no node in it"),
    ("Solid { } Robot { }", "node string:1:11: Robot: a robot cannot be imported here"),
])
def test_bad_strings_are_refused_with_one_line_and_nothing_changes(text, expected):
    lv = _live()
    imports(lv, LIGHT)                       # the next id after a refusal is still the next one
    was = _unchanged(lv)
    assert refused(lv, text).startswith(expected)
    assert _unchanged(lv) == was
    assert imports(lv, BOX) == [FIRST + 1]


@pytest.mark.parametrize("kind", ["Pose", "Transform"])
def test_a_pose_of_shapes_is_imported_as_a_solid_that_moves(kind):
    """Webots' supervisor sample imports ``Pose { children [ Shape { ... Sphere ... } ] }`` and then
    moves it in a circle by its translation (the root's last child). It is imported as a Solid of
    its shapes (one line in the server's log): here a 0.2 m cube, moved to (1.1, 0, 0.1) with the
    crate removed, puts its face 1 m ahead of the range finder, which read the wall at 3 m."""
    lv = _live()
    logged: list[str] = []
    lv.core.log = logged.append
    boss(lv, "remove_node", {"node": CRATE})
    assert readings(lv)["depth"] == pytest.approx(3.0, abs=1e-6)
    (node,) = imports(lv, f"{kind} {{ children [ Shape {{ geometry Box {{ size 0.2 0.2 0.2 }} }} ] }}")
    assert children(lv)[-1] == node
    assert boss(lv, "get_from_id", {"id": node})["type"] == "Solid"
    assert logged == [f"robot 'boss': import_node_from_string: node string:1:1: {kind} imported as a Solid of its "
                      "shapes (getTypeName() answers 'Solid'): Sensorium imports solids and lights"]
    boss(lv, "set_field", {"node": node, "field": "translation", "value": [1.1, 0.0, 0.1]})
    assert readings(lv)["depth"] == pytest.approx(1.0, abs=1e-6)
    assert boss(lv, "get_field", {"node": node, "field": "translation"})["value"] == [1.1, 0.0, 0.1]


def test_a_value_webots_resets_is_reset_on_import_as_in_a_world_file():
    """A node string reads as a .wbt world does: a Box size Webots resets is 1 1 1 (world/wbt/resets.py),
    and the server's log says so once, placed in the string (Webots prints it in its console)."""
    lv = _live()
    logged: list[str] = []
    lv.core.log = logged.append
    imports(lv, 'Solid { name "odd" children [ Shape { geometry Box { size 1 -1 1 } } ] }')
    (odd,) = [s for s in lv.sim.world.solids if s.name == "odd"]
    assert odd.shapes[0].geometry.size == (1.0, 1.0, 1.0)
    assert logged == ["robot 'boss': import_node_from_string: node string:1:54: Box.size: 1 -1 1 has a component "
                      "that is not > 0; using 1 1 1 (as Webots does)"]
    imports(lv, 'Solid { name "fine" children [ Shape { geometry Box { size 1 1 1 } } ] }')
    assert len(logged) == 1                 # a string with nothing to correct logs nothing


def test_in_process_imports_give_their_corrections():
    sim = _live().sim
    corrected: list[str] = []
    sim.import_nodes('Solid { name "ball" children [ Shape { geometry Sphere { radius 0 } } ] }', corrected)
    assert corrected == ["node string:1:58: Sphere.radius: 0 is not > 0; using 1 (as Webots does)"]
    (ball,) = [s for s in sim.world.solids if s.name == "ball"]
    assert ball.shapes[0].geometry.radius == 1.0


def test_only_the_roots_and_a_wbt_worlds_solids_children_take_nodes():
    lv = _live()
    assert refused(lv, BOX, node=WALL, field="children") == (
        "field 'children' of Solid 'wall' (node 3): nothing imported: solid 'wall' was not loaded from a .wbt world "
        "file's Solid kept here (a PROTO instance's children are its body's, or a solid a Supervisor imported)")
    assert refused(lv, BOX, field="translation") == (
        "field 'translation' of the root: nodes are imported into the 'children' of the root, of a top-level Solid "
        "and of the Poses, Transforms, Groups and Solids inside one only here")
    assert lv.err(A, "/boss/robot/import_node_from_string", {"node": 0, "field": "children", "position": 0},
                  ErrorCode.INVALID_ARGUMENT) == "/boss/robot/import_node_from_string: missing argument 'node_string'"


def test_the_worlds_limits_bound_what_is_imported():
    lv = _live(limits=WorldLimits(solids=4, lights=3))
    was = _unchanged(lv)
    assert refused(lv, BOX + " " + BOX) == ("importing it would bring the world to 5 solids (nested children "
                                            "included) (3 now, 2 added), more than the limit of 4 (raise the limits "
                                            "with --allow-large)")
    assert refused(lv, LIGHT + " " + LIGHT).startswith("importing it would bring the world to 4 lights (2 now, 2 added)")
    assert _unchanged(lv) == was
    assert imports(lv, BOX) == [FIRST]
    boss(lv, "remove_node", {"node": FIRST})                # a removed solid no longer counts
    assert imports(lv, BOX) == [FIRST + 1]
    tri = _live().sim.scene.triangle_count
    lv2 = _live(limits=WorldLimits(triangles=tri + 10))
    assert refused(lv2, "Solid { children [ Shape { geometry Box { size 1 1 1 } } ] }") == (
        f"importing it would bring the world to {tri + 12:,} triangles ({tri:,} now, 12 added), more than the "
        f"limit of {tri + 10:,} (raise the limits with --allow-large)")
    assert refused(lv2, "Solid { children [ Shape { geometry Sphere { } } ] }").startswith(
        "node string: the world's triangles: 1,280 exceeds the limit of")         # the string alone, already
    big = "Solid { children [ Shape { geometry Box { size 1 1 1 } } ] }" * 10
    assert refused(_live(limits=WorldLimits(file_bytes=100)), big).startswith(
        f"a node string of {len(big):,} bytes, more than the world file limit of 100")


def _wbt_world(folder: Path) -> Path:
    """A .wbt twin of the boss's distance sensor before the wall, with PROTOs it declares for imports."""
    proto_file(folder / "protos", "Crate", "[ field SFVec3f translation 0 0 0 field SFString name \"crate\" ] "
               "{ Solid { translation IS translation name IS name children [ Shape { geometry Box { size 0.2 4 0.5 } } ] "
               "boundingObject Box { size 0.2 4 0.5 } } }")
    proto_file(folder / "protos", "Drone", "[ field SFString name \"drone\" ] { Robot { name IS name } }")
    world = folder / "w.wbt"
    world.write_text(HEADER + 'IMPORTABLE EXTERNPROTO "protos/Crate.proto"\nEXTERNPROTO "protos/Drone.proto"\n'
                     'WorldInfo { basicTimeStep 16 }\n'
                     'Solid { translation 3.1 0 0.25 name "wall" boundingObject Box { size 0.2 8 0.5 } }\n'
                     'Robot { name "boss" supervisor TRUE controller "<extern>" children [ DistanceSensor { '
                     'translation 0 0 0.1 name "ds" lookupTable [ 0 0 0 5 5 0 ] } ] }\n')
    return world


def test_a_proto_the_world_declares_is_imported_as_its_solid(tmp_path):
    sim = Simulation(load_world(_wbt_world(tmp_path)))
    ds = sim.device("boss/ds")
    ds.enable(16)
    sim.step()
    assert ds.value == pytest.approx(3.0, abs=1e-9)
    # ids: boss 1, wall 2, the file's WorldInfo 3, the Viewpoint Webots adds 4: the crate is 5
    assert sim.import_nodes("DEF C Crate { translation 1.6 0 0.25 }") == [("Solid", "crate", 5)]
    sim.step()
    assert ds.value == pytest.approx(1.5, abs=1e-9)
    with pytest.raises(ImportRefused, match=r"^node string:1:1: Drone \(a Robot\): a robot cannot be imported here"):
        sim.import_nodes("Drone { }")
    with pytest.raises(ImportRefused, match=r"^node string:1:3: Box2: not a built-in node or PROTO here\..*"
                                            r"\(a PROTO must be declared in the world file: IMPORTABLE EXTERNPROTO\)$"):
        sim.import_nodes("  Box2 { }")
    with pytest.raises(ImportRefused, match=r"^node string:1:9: Crate.translation: SFVec3f expects 3 numbers, got 1"):
        sim.import_nodes("Crate { translation 1 }")


def test_the_foxglove_scene_draws_imported_nodes():
    from test_supervisor_remove import _top_fields

    from sensorium.server.recording.scene3d import scene_update

    sim = Simulation(load_world(WORLD))

    def entities() -> list[bytes]:
        fields = _top_fields(scene_update(sim.world, sim.loaded.base_dir, 0, dict(sim.scene.solid_poses),
                                          sim.scene.removed_lights).encode())
        return [p for f, p in fields if f == 2]

    assert not any(b"solid/ball" in e for e in entities())
    sim.import_nodes(BOX + " " + LIGHT)
    drawn = entities()                               # Webots' lights have no name: the third light of the world
    assert sum(b"solid/ball" in e for e in drawn) == 1 and sum(b"light/light2" in e for e in drawn) == 1
    sim.reset()                                      # removed again: deleted from the viewer
    fields = _top_fields(scene_update(sim.world, sim.loaded.base_dir, 0, dict(sim.scene.solid_poses),
                                      sim.scene.removed_lights).encode())
    assert any(f == 1 and b"solid/ball" in p for f, p in fields) and any(f == 1 and b"light/light2" in p
                                                                          for f, p in fields)


def test_the_live_viewer_resends_the_scene_when_a_node_is_imported():
    from test_foxglove_viewer import scene_sends  # (skips this test without foxglove-sdk)

    sim = Simulation(load_world(WORLD), precision="fast")
    with scene_sends(sim) as (bridge, pass_, sent):
        first = bridge.scene_bytes()
        bridge._subscribed(7, "/scene", +1)
        pass_()
        expected: list[int | None] = [7]
        for text in (BOX, LIGHT):
            sim.import_nodes(text)
            expected.append(None)
            pass_(len(expected))
            assert sent == expected
        pass_()
        assert sent == expected and len(bridge.scene_bytes()) > len(first)


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_webots_supervisor_controller_imports_nodes(tmp_path):
    """tests/controllers/supervisor_import.py through ``sensorium serve``: as written for Webots."""
    ctl = run_paused(WORLD, tmp_path, "supervisor_import.py", "boss")
    out = json.loads(ctl.out[-1])
    assert out["before"] == [pytest.approx(1.0, abs=1e-9), 9]
    assert out["imported"] == [pytest.approx(1.0, abs=1e-9), 10]          # the value of the last step
    assert out["after"] == [pytest.approx(0.5, abs=1e-9), pytest.approx(23.0), 11, FIRST, FIRST + 1, "BALL"]
    assert out["removed"] == [pytest.approx(1.0, abs=1e-9), pytest.approx(7.0), 9, True]
    err = ctl.stderr()
    assert ("Error: wb_supervisor_field_import_mf_node_from_string(): import_node_from_string: node string:1:1: "
            "Robot: a robot cannot be imported here") in err
    assert "Error: wb_supervisor_field_import_mf_node_from_string(): import_node_from_string: node string:1:" in err
    assert err.count("Error: ") == 3

