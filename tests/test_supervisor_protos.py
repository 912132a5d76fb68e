"""Top-level PROTO instances through the Supervisor (tests/worlds/proto/supervisor_protos.wbt, with
Sensorium's own PROTOs in tests/protos/supervisor): ``getTypeName()`` is the PROTO's name (the
outermost one for a PROTO built on another), ``getBaseTypeName()`` the base node type and
``isProto()`` true, as Webots' libController answers (its node's model name); a base node answers
its type for both and false. A Viewpoint's and a Background's written values are read as Webots
users read them (``skyColor`` an MFColor), Webots' defaults for what the file leaves out. A field's
``enableSFTracking`` is accepted silently and its getters keep answering the value of now."""

from __future__ import annotations

import json
import sys

import pytest
from _protos import HEADER
from test_multiprocess import REPO, run_paused
from test_supervisor import A, Live

from sensorium.schemas.wire import ErrorCode
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WORLD = REPO / "tests" / "worlds" / "proto" / "supervisor_protos.wbt"
BOSS, CRATE, BIG, BOX, LAMP, INFO, VIEW, SKY = range(1, 9)     # robots, solids, lights, then the others
# (type name, base type name, isProto, DEF) of the root's children, in file order
NAMES = [["WorldInfo", "WorldInfo", False, ""], ["Viewpoint", "Viewpoint", False, "VIEW"],
         ["Sky", "Background", True, "SKY"], ["Boss", "Robot", True, "BOSS"], ["Crate", "Solid", True, "CRATE"],
         ["BigCrate", "Solid", True, "BIG"], ["Beacon", "PointLight", True, "LAMP"], ["Solid", "Solid", False, "BOX"]]


def _live(world=WORLD) -> Live:
    lv = Live(Simulation(load_world(world)))
    lv.ok(A, "attach", {"robot": "boss"})
    return lv


def boss(lv: Live, item: str, args: dict | None = None):
    return lv.ok(A, f"/boss/robot/{item}", args)


def test_a_proto_instance_is_named_after_its_proto_and_typed_by_its_base():
    lv = _live()
    ids = boss(lv, "get_field", {"node": 0, "field": "children"})["value"]
    assert ids == [INFO, VIEW, SKY, BOSS, CRATE, BIG, LAMP, BOX]
    refs = [boss(lv, "get_from_id", {"id": i}) for i in ids]
    assert [[r["proto"] or r["type"], r["type"], bool(r["proto"]), r["def_name"]] for r in refs] == NAMES
    assert boss(lv, "get_self")["proto"] == "Boss"
    assert boss(lv, "get_from_def", {"name": "big crate"})["proto"] == "BigCrate"     # by name too
    assert boss(lv, "get_from_id", {"id": 0})["proto"] == ""                         # the root


def test_an_imported_proto_instance_is_named_after_its_proto():
    lv = _live()
    added = boss(lv, "import_node_from_string", {"node": 0, "field": "children", "position": -1, "node_string":
                                                 'DEF C2 Crate { name "c2" } Beacon { } Solid { name "plain" }'})
    refs = [boss(lv, "get_from_id", {"id": i}) for i in added["value"]]
    assert [[r["proto"], r["type"], r["def_name"]] for r in refs] == [
        ["Crate", "Solid", "C2"], ["Beacon", "PointLight", ""], ["", "Solid", ""]]


def test_webots_protos_sensorium_builds_in_are_named_as_in_webots(tmp_path):
    """A world without its PROTO files at hand (Webots' URLs, no cache): RectangleArena, WoodenBox and
    TexturedBackgroundLight are built in, TexturedBackground is skipped; each keeps Webots' names."""
    url = "https://raw.githubusercontent.com/cyberbotics/webots/R2023b/projects/objects"
    world = tmp_path / "builtins.wbt"
    world.write_text(HEADER + f'EXTERNPROTO "{url}/backgrounds/protos/TexturedBackground.proto"\n'
                     f'EXTERNPROTO "{url}/backgrounds/protos/TexturedBackgroundLight.proto"\n'
                     f'EXTERNPROTO "{url}/floors/protos/RectangleArena.proto"\n'
                     f'EXTERNPROTO "{url}/factory/containers/protos/WoodenBox.proto"\n'
                     "TexturedBackground { }\nTexturedBackgroundLight { }\nRectangleArena { }\n"
                     "WoodenBox { translation 0.5 0 0.3 }\n"
                     'Robot { name "boss" supervisor TRUE controller "<extern>" }\n')
    lv = _live(world)
    refs = [boss(lv, "get_from_id", {"id": i}) for i in boss(lv, "get_field", {"node": 0, "field": "children"})["value"]]
    assert [[r["proto"], r["type"]] for r in refs] == [
        ["", "WorldInfo"], ["", "Viewpoint"], ["TexturedBackground", "Background"],
        ["TexturedBackgroundLight", "DirectionalLight"], ["RectangleArena", "Solid"], ["WoodenBox", "Solid"],
        ["", "Robot"]]


def test_viewpoint_and_background_fields_answer_the_world_files_values_and_webots_defaults():
    lv = _live()

    def field(node: int, name: str) -> dict:
        return boss(lv, "get_field", {"node": node, "field": name})

    assert field(VIEW, "position") == {"type": "SFVec3f", "value": [1.0, 2.0, 3.0]}
    assert field(VIEW, "orientation") == {"type": "SFRotation", "value": [0.0, 0.0, 1.0, 1.5]}
    assert field(VIEW, "fieldOfView") == {"type": "SFFloat", "value": 0.5}
    assert field(VIEW, "description") == {"type": "SFString", "value": "top"}
    assert field(VIEW, "near") == {"type": "SFFloat", "value": 0.05}           # not written: Webots' default
    assert field(VIEW, "far") == {"type": "SFFloat", "value": 0.0}
    assert field(SKY, "skyColor") == {"type": "MFColor", "value": [[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]]}
    assert field(SKY, "luminosity") == {"type": "SFFloat", "value": 0.5}       # the PROTO's default
    assert field(VIEW, "lensFlare") == {"type": "", "value": []}
    msg = lv.err(A, "/boss/robot/set_field", {"node": VIEW, "field": "position", "value": [0, 0, 1]},
                 ErrorCode.INVALID_ARGUMENT)
    assert msg == "set_field: field 'position' (SFVec3f) of Viewpoint 7 is read-only here"


def test_a_viewpoint_webots_adds_answers_webots_defaults(tmp_path):
    world = tmp_path / "bare.wbt"
    world.write_text(HEADER + 'Background { skyColor [ 1 0 0 ] }\n'
                     'Robot { name "boss" supervisor TRUE controller "<extern>" }\n')
    lv = _live(world)
    _, view, sky, _ = boss(lv, "get_field", {"node": 0, "field": "children"})["value"]
    assert boss(lv, "get_from_id", {"id": view})["type"] == "Viewpoint"
    assert boss(lv, "get_field", {"node": view, "field": "position"})["value"] == [-10.0, 0.0, 0.0]
    assert boss(lv, "get_field", {"node": view, "field": "fieldOfView"})["value"] == 0.785398
    assert boss(lv, "get_field", {"node": sky, "field": "skyColor"})["value"] == [[1.0, 0.0, 0.0]]
    assert boss(lv, "get_field", {"node": sky, "field": "luminosity"})["value"] == 1.0


def test_a_viewpoint_value_that_does_not_read_is_a_warning_not_a_failed_load(tmp_path):
    world = tmp_path / "odd.wbt"
    world.write_text(HEADER + 'Viewpoint { position 1 2 fieldOfView 0.3 }\n'
                     'Robot { name "boss" supervisor TRUE controller "<extern>" }\n')
    loaded = load_world(world)
    assert any("Viewpoint.position: expected 3 numbers" in w for w in loaded.warnings), loaded.warnings
    lv = _live(world)
    view = boss(lv, "get_field", {"node": 0, "field": "children"})["value"][1]
    assert boss(lv, "get_field", {"node": view, "field": "position"})["value"] == [-10.0, 0.0, 0.0]
    assert boss(lv, "get_field", {"node": view, "field": "fieldOfView"})["value"] == 0.3


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_webots_supervisor_reads_proto_names_scenery_values_and_tracks_a_field(tmp_path):
    """tests/controllers/supervisor_protos.py through ``sensorium serve``."""
    ctl = run_paused(WORLD, tmp_path, "supervisor_protos.py", "boss")
    out = json.loads(ctl.out[-1])
    assert out["names"] == NAMES
    assert out["self"] == "Boss" and out["types"] == [True, True]
    assert out["viewpoint"] == [[1.0, 2.0, 3.0], [0.0, 0.0, 1.0, 1.5], 0.5, 0.05, "top"]
    assert out["background"] == ["MFColor", 2, [0.1, 0.2, 0.3], [0.4, 0.5, 0.6], 0.5]
    assert out["seed"] == 0
    assert out["tracked"] == [[1.0, 0.0, 0.1], [1.0, 0.5, 0.1]]
    err = ctl.stderr()
    assert "not served" not in err and "Error" not in err, err


def test_a_proto_built_on_another_solid_node_is_named_after_its_proto(tmp_path):
    """Webots' ratslife feeder is a PROTO whose base node is a Charger (a Solid node kept here as a
    solid): it was named 'Solid'; like a PROTO built on a Fluid or on a device outside any robot, it
    now answers its PROTO's name, as a PROTO built on a Solid does."""
    world = tmp_path / "feeders.wbt"
    world.write_text(HEADER + 'PROTO Feeder [ field SFVec3f translation 0 0 0 ] '
                     '{ Charger { translation IS translation children [ Shape { geometry Box { size 0.1 0.1 0.1 } } ] } }\n'
                     'PROTO Pond [ ] { Fluid { children [ Shape { geometry Box { size 1 1 0.1 } } ] } }\n'
                     'PROTO Beacon [ ] { Emitter { translation 0 1 0 children [ Shape { geometry Sphere { radius 0.05 } } ] } }\n'
                     'DEF F Feeder { translation 1 0 0 }\nDEF P Pond { }\nDEF B Beacon { }\n'
                     'Robot { name "boss" supervisor TRUE controller "<extern>" }\n')
    lv = _live(world)
    refs = [boss(lv, "get_from_def", {"name": name}) for name in ("F", "P", "B")]
    assert [[r["proto"], r["type"]] for r in refs] == [["Feeder", "Solid"], ["Pond", "Solid"], ["Beacon", "Solid"]]
