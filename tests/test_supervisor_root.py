"""The root's ``children`` are the world file's top-level nodes in file order, as Webots' WbWorld
adds them (tests/worlds/root_children.wbt): WorldInfo, Viewpoint and Background (not simulated:
their type and DEF, WorldInfo's fields the model has, Webots' "no value" for the rest), then a
solid before the robot, then a light. Ids are stable: the loaded robots, solids and lights first
(as before), then the other top-level nodes in file order, then imports. A world without a
WorldInfo or Viewpoint (a YAML world, or a .wbt one without them) gets Webots' defaults at places 0
and 1 (WbWorld::checkPresenceOfMandatoryNodes)."""

from __future__ import annotations

import json
import math
import sys

import pytest
from _protos import HEADER
from test_multiprocess import REPO, run_paused
from test_supervisor import A, Live

from sensorium.schemas.wire import ErrorCode
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WORLD = REPO / "tests" / "worlds" / "root_children.wbt"
BOSS, BOX, LAMP, INFO, VIEW, SKY = range(1, 7)      # ids: robots, solids, lights, then the others in file order
FILE_ORDER = [INFO, VIEW, SKY, BOX, BOSS, LAMP]
TYPES_DEFS = [["WorldInfo", "INFO"], ["Viewpoint", "VIEW"], ["Background", "SKY"], ["Solid", "BOX"],
              ["Robot", "BOSS"], ["PointLight", "LAMP"]]


def _live() -> Live:
    lv = Live(Simulation(load_world(WORLD)))
    lv.ok(A, "attach", {"robot": "boss"})
    return lv


def boss(lv: Live, item: str, args: dict | None = None):
    return lv.ok(A, f"/boss/robot/{item}", args)


def children(lv: Live) -> list[int]:
    return boss(lv, "get_field", {"node": 0, "field": "children"})["value"]


def field(lv: Live, node: int, name: str) -> dict:
    return boss(lv, "get_field", {"node": node, "field": name})


def test_the_roots_children_are_the_files_top_level_nodes_in_file_order():
    lv = _live()
    assert children(lv) == FILE_ORDER
    refs = [boss(lv, "get_from_id", {"id": i}) for i in FILE_ORDER]
    assert [[r["type"], r["def_name"]] for r in refs] == TYPES_DEFS
    assert all(r["parent"] == 0 for r in refs)
    assert boss(lv, "get_from_def", {"name": "SKY"})["node"] == SKY
    assert boss(lv, "get_from_id", {"id": SKY + 1})["type"] == ""              # no node past them


def test_world_info_fields_answer_the_worlds_values():
    lv = _live()
    assert field(lv, INFO, "gravity") == {"type": "SFFloat", "value": 3.71}
    assert field(lv, INFO, "basicTimeStep") == {"type": "SFFloat", "value": 16.0}
    assert field(lv, INFO, "title") == {"type": "SFString", "value": "root order"}
    assert field(lv, INFO, "coordinateSystem") == {"type": "SFString", "value": "ENU"}
    assert field(lv, INFO, "gpsCoordinateSystem") == {"type": "SFString", "value": "WGS84"}
    assert field(lv, INFO, "gpsReference") == {"type": "SFVec3f", "value": [46.5, 6.6, 372.0]}
    assert field(lv, INFO, "randomSeed") == {"type": "SFInt32", "value": 0}
    # what the model does not keep: Webots' "no value", never a crash
    assert field(lv, INFO, "info") == {"type": "", "value": []}
    assert field(lv, VIEW, "position") == {"type": "SFVec3f", "value": [0.0, -4.0, 2.0]}     # the file's
    assert field(lv, VIEW, "orientation") == {"type": "SFRotation", "value": [0.0, 0.0, 1.0, 0.0]}   # Webots'
    assert field(lv, SKY, "skyColor") == {"type": "MFColor", "value": [[0.2, 0.3, 0.4]]}
    assert field(lv, VIEW, "lensFlare") == {"type": "", "value": []}
    pose = boss(lv, "get_node_pose", {"node": VIEW})
    assert all(math.isnan(v) for v in pose["position"])
    assert boss(lv, "get_node_velocity", {"node": SKY})["value"] == [0.0] * 6
    msg = lv.err(A, "/boss/robot/set_field", {"node": INFO, "field": "gravity", "value": 1.0},
                 ErrorCode.INVALID_ARGUMENT)
    assert msg == "set_field: field 'gravity' (SFFloat) of WorldInfo 4 is read-only here"
    msg = lv.err(A, "/boss/robot/set_field", {"node": VIEW, "field": "position", "value": [0, 0, 1]},
                 ErrorCode.INVALID_ARGUMENT)
    assert msg == "set_field: field 'position' (SFVec3f) of Viewpoint 5 is read-only here"
    msg = lv.err(A, "/boss/robot/set_field", {"node": SKY, "field": "fogColor", "value": [0, 0, 1]},
                 ErrorCode.INVALID_ARGUMENT)
    assert msg == "set_field: Background 6 has no field 'fogColor' here (fields: skyColor, luminosity)"


def test_nodes_not_simulated_cannot_be_removed_and_ids_stay_stable():
    lv = _live()
    for node in (INFO, VIEW, SKY):
        msg = lv.err(A, "/boss/robot/remove_node", {"node": node}, ErrorCode.INVALID_ARGUMENT)
        assert msg.startswith("remove_node: ") and "cannot be removed here" in msg
    boss(lv, "remove_node", {"node": BOX})
    assert children(lv) == [INFO, VIEW, SKY, BOSS, LAMP]
    assert boss(lv, "get_from_id", {"id": SKY})["def_name"] == "SKY"


def test_imports_take_their_webots_position_among_all_the_top_level_nodes():
    lv = _live()
    ball = boss(lv, "import_node_from_string", {"node": 0, "field": "children", "position": 3,
                                                "node_string": 'DEF BALL Solid { name "ball" }'})["value"]
    assert ball == [SKY + 1]                                     # after every node the world loaded with
    assert children(lv) == [INFO, VIEW, SKY, SKY + 1, BOX, BOSS, LAMP]
    spark = boss(lv, "import_node_from_string", {"node": 0, "field": "children", "position": -2,
                                                 "node_string": "PointLight { }"})["value"]
    assert children(lv) == [INFO, VIEW, SKY, SKY + 1, BOX, BOSS, *spark, LAMP]
    boss(lv, "remove_node", {"node": SKY + 1})
    assert children(lv) == [INFO, VIEW, SKY, BOX, BOSS, *spark, LAMP]
    boss(lv, "simulation_reset")                                 # imported nodes go, the file's stay
    assert children(lv) == FILE_ORDER


def test_webots_adds_the_missing_world_info_and_viewpoint_at_places_0_and_1(tmp_path):
    world = tmp_path / "bare.wbt"
    world.write_text(HEADER + 'DEF SKY Background { }\nSolid { name "a" }\n'
                     'Robot { name "boss" supervisor TRUE controller "<extern>" }\n')
    lv = Live(Simulation(load_world(world)))
    lv.ok(A, "attach", {"robot": "boss"})
    refs = [boss(lv, "get_from_id", {"id": i}) for i in children(lv)]
    assert [[r["node"], r["type"], r["def_name"]] for r in refs] == [
        [4, "WorldInfo", ""], [5, "Viewpoint", ""], [3, "Background", "SKY"], [2, "Solid", ""], [1, "Robot", ""]]
    assert field(lv, 4, "gravity") == {"type": "SFFloat", "value": 9.81}           # Webots' defaults
    assert field(lv, 4, "basicTimeStep") == {"type": "SFFloat", "value": 32.0}


GROUPS_WORLD = (HEADER + 'Robot { name "boss" supervisor TRUE controller "<extern>" }\n'
                'DEF CUBES Group {\n  children [ Solid { translation 1 0 0.05 name "cube" } ]\n}\n'
                'DEF LOOKS Group { children [ Shape { geometry Box { size 0.1 0.1 0.1 } } ] }\n'
                'DEF TRIO Pose {\n  translation 1 2 0 rotation 0 0 1 1.5707963267948966\n  children [\n'
                '    Solid { translation 1 0 0.05 name "a" }\n    DEF MID Solid { translation 0 0.5 0 name "b" }\n'
                '    Group { children [ Solid { translation -1 0 0 name "c" } ] }\n  ]\n}\n')


def test_a_top_level_group_of_solids_is_a_node_holding_them(tmp_path):
    """Webots' robotbenchmark obstacle-avoidance referee asks getFromDef("CUBE_OBSTACLES") for a
    top-level DEF Group of solids, then walks its children: such a Group (or Pose, Transform) is a
    root child whose ``children`` are its solids (the same ids their own DEFs and names give), and they
    are no longer the root's; a Pose's pose is the file's (closed form: a quarter turn about z, then
    (1, 2, 0)); a DEF Group of shapes only is still a (visual) node. Loading says nothing about them."""
    world = tmp_path / "groups.wbt"
    world.write_text(GROUPS_WORLD)
    loaded = load_world(world)
    assert not any("Group" in w for w in loaded.warnings)
    lv = Live(Simulation(loaded))
    lv.ok(A, "attach", {"robot": "boss"})
    cubes = boss(lv, "get_from_def", {"name": "CUBES"})
    assert [cubes["type"], cubes["def_name"], cubes["parent"]] == ["Group", "CUBES", 0]
    cube = boss(lv, "get_from_def", {"name": "cube"})
    assert field(lv, cubes["node"], "children") == {"type": "MFNode", "value": [cube["node"]]}
    trio = boss(lv, "get_from_def", {"name": "TRIO"})
    assert trio["type"] == "Pose"
    inside = field(lv, trio["node"], "children")["value"]
    assert len(inside) == 3
    assert inside[1] == boss(lv, "get_from_def", {"name": "MID"})["node"] == \
        boss(lv, "get_from_def", {"name": "TRIO.MID"})["node"]
    assert [boss(lv, "get_from_id", {"id": i})["def_name"] for i in inside] == ["", "MID", ""]
    assert [boss(lv, "get_from_id", {"id": i})["parent"] for i in inside] == [trio["node"]] * 3   # getParentNode
    assert cube["parent"] == cubes["node"] and trio["parent"] == 0
    roots = children(lv)
    assert cubes["node"] in roots and trio["node"] in roots and not set(inside) & set(roots)
    # world positions: (1, 2, 0) + Rz(90°) applied to each solid's translation (c through a plain Group)
    want = [[1.0, 3.0, 0.05], [0.5, 2.0, 0.0], [1.0, 1.0, 0.0]]
    for i, w in zip(inside, want):
        assert boss(lv, "get_node_pose", {"node": i})["position"] == pytest.approx(w, abs=1e-9)
    assert field(lv, trio["node"], "translation") == {"type": "SFVec3f", "value": [1.0, 2.0, 0.0]}
    assert field(lv, trio["node"], "rotation")["value"] == pytest.approx([0, 0, 1, math.pi / 2])
    pose = boss(lv, "get_node_pose", {"node": trio["node"]})
    assert pose["position"] == [1.0, 2.0, 0.0]
    assert pose["orientation"] == pytest.approx([0, -1, 0, 1, 0, 0, 0, 0, 1], abs=1e-12)
    assert all(math.isnan(v) for v in boss(lv, "get_node_pose", {"node": cubes["node"]})["position"])
    msg = lv.err(A, "/boss/robot/set_field", {"node": trio["node"], "field": "translation", "value": [0, 0, 1]},
                 ErrorCode.INVALID_ARGUMENT)
    assert msg == ("set_field: field 'translation' (SFVec3f) of Pose 'TRIO' is read-only here: a top-level group's "
                   "solids are moved one by one (getMFNode(i) of its children); nothing changed")
    looks = boss(lv, "get_from_def", {"name": "LOOKS"})
    assert looks["type"] == "Group"
    assert field(lv, looks["node"], "children") == {"type": "", "value": []}


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_webots_supervisor_walks_the_roots_children(tmp_path):
    """tests/controllers/root_children.py through ``sensorium serve``: getMFNode(0) is WorldInfo, its
    gravity read, as Webots' samples do."""
    ctl = run_paused(WORLD, tmp_path, "root_children.py", "boss")
    out = json.loads(ctl.out[-1])
    assert out["before"] == TYPES_DEFS
    assert out["world_info"] == [True, pytest.approx(3.71), 16.0, "root order", "WGS84",
                                 pytest.approx([46.5, 6.6, 372.0]), "ENU"]
    assert out["no_value"] == [[0.0, -4.0, 2.0], True]
    assert out["imported"] == [*TYPES_DEFS[:3], ["Solid", "BALL"], *TYPES_DEFS[3:5], ["PointLight", "SPARK"],
                               TYPES_DEFS[5]]
    assert out["removed"] == TYPES_DEFS


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_webots_supervisor_walks_a_top_level_group_of_solids(tmp_path):
    """tests/controllers/top_groups.py through ``sensorium serve`` on tests/worlds/top_groups.wbt: the DEF
    Pose is a Pose node of three solids at (1, 2, 0) + Rz(90°)·their translations, the DEF'd one the
    same node as getFromDef("MID") gives."""
    ctl = run_paused(REPO / "tests" / "worlds" / "top_groups.wbt", tmp_path, "top_groups.py", "boss")
    out = json.loads(ctl.out[-1])
    assert out["group"] == [True, "Pose", "TRIO"]
    assert out["count"] == 3
    assert out["positions"] == [pytest.approx(p, abs=1e-9) for p in ([1, 3, 0.05], [0.5, 2, 0], [1, 1, 0])]
    assert out["same"] is True
    assert out["translation"] == [1.0, 2.0, 0.0]
    assert out["trio_position"] == [1.0, 2.0, 0.0]
