"""Poses, Transforms and Groups inside a top-level solid as Supervisor nodes (tests/worlds/solid_poses.wbt): found
by DEF (dotted paths too), by id and by their parent's ``children`` in file order; their parents, types and DEFs;
their fields and world poses; a Pose's or Transform's translation and rotation set moving what it holds exactly
as the world file written with that value (node ids kept, simulationReset restoring the loaded value);
exportString and worldSave; remove() taking what they hold out of the sensors' view, exactly as the world file
written without them; one line for what is refused.

Closed forms (the world file's comment places everything): the lidar's one beam runs along +x from the origin and
meets MARKER's near face at x = 1.8; the light sensor at the origin looks up at LAMP, 2 cd at (2, 0, 1) with
attenuation 0 0 1: 2·(1/√5)/5."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_multiprocess import REPO
from test_supervisor import A, Live

from sensorium.schemas.wire import ErrorCode
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WORLD = REPO / "tests" / "worlds" / "solid_poses.wbt"
LAMP_READING = 2.0 * (1.0 / math.sqrt(5.0)) / 5.0
QUARTER = [0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]     # a quarter turn about z, row-major


def _live(path=WORLD) -> Live:
    lv = Live(Simulation(load_world(path)))
    lv.ok(A, "attach", {"robot": "probe"})
    bot = lv.sim.robot("probe")
    bot.device("lidar").enable(8)
    bot.device("ls").enable(8)
    bot.device("camera").enable(8)
    return lv


def call(lv: Live, item: str, args: dict | None = None):
    return lv.ok(A, f"/probe/robot/{item}", args)


def node(lv: Live, name: str) -> int:
    return call(lv, "get_from_def", {"name": name})["node"]


def get(lv: Live, n: int, field: str):
    return call(lv, "get_field", {"node": n, "field": field})["value"]


def readings(lv: Live) -> tuple[float, float]:
    lv.step(A, "probe")
    bot = lv.sim.robot("probe")
    return float(np.asarray(bot.device("lidar").range_image).reshape(-1)[0]), bot.device("ls").value


def image(lv: Live) -> bytes:
    return np.asarray(lv.sim.robot("probe").device("camera").image).tobytes()


def test_found_by_def_dotted_paths_id_and_their_parents_children():
    lv = _live()
    table, other = node(lv, "TABLE"), node(lv, "OTHER")
    found = {n: call(lv, "get_from_def", {"name": n}) for n in ("LEG", "TOP", "MARKER", "LAMP", "G", "T", "INNER")}
    assert {n: (r["type"], r["def_name"]) for n, r in found.items()} == {
        "LEG": ("Shape", "LEG"), "TOP": ("Pose", "TOP"), "MARKER": ("Shape", "MARKER"), "LAMP": ("PointLight", "LAMP"),
        "G": ("Group", "G"), "T": ("Transform", "T"), "INNER": ("Solid", "INNER")}
    ids = {n: r["node"] for n, r in found.items()}
    # Webots' parents: the Pose holds its shape and light, the Group its Transform, the Transform its solid
    assert {n: r["parent"] for n, r in found.items()} == {
        "LEG": table, "TOP": table, "MARKER": ids["TOP"], "LAMP": ids["TOP"], "G": table, "T": ids["G"],
        "INNER": ids["T"]}
    # every child counted, in file order
    assert get(lv, table, "children") == [ids["LEG"], ids["TOP"], ids["G"], other]
    assert get(lv, ids["TOP"], "children") == [ids["MARKER"], ids["LAMP"]]
    assert get(lv, ids["G"], "children") == [ids["T"]]
    assert get(lv, ids["T"], "children") == [ids["INNER"]]
    # a dotted path names direct children from the first DEF on (Webots' getNodeFromDEF)
    assert node(lv, "TABLE.TOP") == ids["TOP"] and node(lv, "TABLE.TOP.MARKER") == ids["MARKER"]
    assert node(lv, "TABLE.G.T.INNER") == ids["INNER"] and node(lv, "G.T") == ids["T"]
    assert node(lv, "TABLE.INNER") == 0 and node(lv, "TABLE.T") == 0
    for n, r in found.items():
        assert call(lv, "get_from_id", {"id": r["node"]}) == r, n


def test_fields_as_written_and_world_poses_that_follow_the_solid():
    lv = _live()
    top, g, t, inner, table = (node(lv, n) for n in ("TOP", "G", "T", "INNER", "TABLE"))
    assert get(lv, top, "translation") == [0.0, 0.0, 1.0]
    assert get(lv, top, "rotation") == [0.0, 0.0, 1.0, 1.5707963267948966]
    assert get(lv, t, "translation") == [0.0, 0.5, 1.0] and get(lv, t, "scale") == [1.0, 1.0, 1.0]
    assert get(lv, inner, "translation") == [0.1, 0.0, 0.0]           # in T's frame, as Webots
    # a Group has no translation (Webots' node lacks it) and no pose (NaN)
    assert call(lv, "get_field", {"node": g, "field": "translation"}).get("absent") is True
    assert all(math.isnan(v) for v in call(lv, "get_node_pose", {"node": g})["position"])

    def pose(n: int) -> tuple[list[float], list[float]]:
        p = call(lv, "get_node_pose", {"node": n})
        return p["position"], p["orientation"]

    position, orientation = pose(top)
    assert position == pytest.approx([2.0, 0.0, 0.0], abs=1e-15)
    assert orientation == pytest.approx(QUARTER, abs=1e-15)
    assert pose(t) == ([2.0, 0.5, 0.0], [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0])
    assert pose(inner)[0] == pytest.approx([2.1, 0.5, 0.0], abs=1e-15)
    # the table moves 1 m along x and turns half a turn about z: the Pose, and the marker the lidar sees, with it
    call(lv, "set_field", {"node": table, "field": "translation", "value": [3.0, 0.0, -1.0]})
    call(lv, "set_field", {"node": table, "field": "rotation", "value": [0.0, 0.0, 1.0, math.pi]})
    position, orientation = pose(top)
    assert position == pytest.approx([3.0, 0.0, 0.0], abs=1e-15)
    assert orientation == pytest.approx([0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0], abs=1e-15)
    assert pose(t)[0] == pytest.approx([3.0, -0.5, 0.0], abs=1e-15)
    assert get(lv, top, "translation") == [0.0, 0.0, 1.0]          # its own field: in the table's frame
    lidar, ls = readings(lv)
    assert lidar == pytest.approx(2.8, abs=1e-6)                    # (float32 ranges)
    assert ls == pytest.approx(2.0 * (1.0 / math.sqrt(10.0)) / 10.0, rel=1e-12)   # LAMP at (3, 0, 1)


def test_readings_see_what_they_hold_and_remove_takes_it_out_as_a_world_without_it(tmp_path):
    lv = _live()
    top, marker, lamp, table = (node(lv, n) for n in ("TOP", "MARKER", "LAMP", "TABLE"))
    lidar, ls = readings(lv)
    assert lidar == pytest.approx(1.8, abs=1e-6) and ls == pytest.approx(LAMP_READING, rel=1e-12)
    call(lv, "remove_node", {"node": top})
    text = WORLD.read_text()
    start = text.index("    DEF TOP Pose {")
    end = text.index("    DEF G Group {")
    without = tmp_path / "without_top.wbt"
    without.write_text(text[:start] + text[end:])
    seen = _live()
    readings(seen)
    marker_seen = image(seen)
    twin = _live(without)
    expected = readings(twin)
    assert readings(lv) == expected and expected[1] == 0.0 and expected[0] > 1.8   # bit for bit
    assert image(lv) == image(twin) != marker_seen        # the camera too
    assert node(lv, "TOP") == 0 and node(lv, "MARKER") == 0 and node(lv, "LAMP") == 0
    for gone in (top, marker, lamp):                  # NULL by id, one line as a node
        assert call(lv, "get_from_id", {"id": gone})["node"] == 0
        message = lv.err(A, "/probe/robot/get_field", {"node": gone, "field": "translation"},
                         ErrorCode.INVALID_ARGUMENT)
        assert "was removed" in message and "\n" not in message
    assert len(get(lv, table, "children")) == 3
    assert "TOP" not in call(lv, "node_export_string", {"node": table})["value"]
    call(lv, "simulation_reset")                      # removed nodes stay removed (Webots)
    assert readings(lv) == expected


def test_export_writes_them_where_the_file_does():
    lv = _live()
    text = call(lv, "node_export_string", {"node": node(lv, "TOP")})["value"]
    assert text.splitlines()[:4] == ["DEF TOP Pose {", "  translation 0 0 1", "  rotation 0 0 1 1.5707963267948966",
                                     "  children ["]
    assert "    DEF MARKER Shape {" in text and "    DEF LAMP PointLight {" in text
    group = call(lv, "node_export_string", {"node": node(lv, "G")})["value"]
    assert group.startswith("DEF G Group {\n  children [\n    DEF T Transform {\n      translation 0 0.5 1\n")
    assert "    DEF TOP Pose {\n      translation 0 0 1\n" in call(lv, "world_save")["value"]


def test_refused_in_one_line_and_nothing_changes():
    lv = _live()
    top, g, t = node(lv, "TOP"), node(lv, "G"), node(lv, "T")
    before = readings(lv)
    for args, words in (({"node": t, "field": "scale", "value": [2.0, 2.0, 2.0]}, "it holds a Solid"),
                        ({"node": top, "field": "translation", "value": [0.0, math.inf, 2.0]}, "finite"),
                        ({"node": top, "field": "rotation", "value": [0.0, 0.0, 0.0, 1.0]}, "axis must not be zero")):
        message = lv.err(A, "/probe/robot/set_field", args, ErrorCode.INVALID_ARGUMENT)
        assert words in message and "\n" not in message, message
    message = lv.err(A, "/probe/robot/remove_node", {"node": g}, ErrorCode.INVALID_ARGUMENT)
    assert "holds Solid 'inner'" in message and "\n" not in message, message
    assert get(lv, top, "translation") == [0.0, 0.0, 1.0] and node(lv, "INNER") != 0
    assert readings(lv) == before


TABLE_PROTO = """#VRML_SIM R2023b utf8
PROTO Table [
  field SFVec3f translation 0 0 0
]
{
  Solid {
    translation IS translation
    children [
      DEF TOP Pose {
        translation 0 0 1
        children [ DEF PLATE Shape { geometry Box { size 1 1 0.1 } } ]
      }
    ]
  }
}
"""


def test_a_protos_pose_is_found_by_get_from_proto_def_and_not_removed(tmp_path):
    (tmp_path / "protos").mkdir()
    (tmp_path / "protos" / "Table.proto").write_text(TABLE_PROTO)
    world = tmp_path / "table.wbt"
    world.write_text('#VRML_SIM R2023b utf8\nEXTERNPROTO "protos/Table.proto"\nWorldInfo { }\n'
                     'DEF PROBE Robot { name "probe" supervisor TRUE controller "<extern>" }\n'
                     'DEF T1 Table { translation 1 0 0 }\n')
    lv = Live(Simulation(load_world(world)))
    lv.ok(A, "attach", {"robot": "probe"})
    table = node(lv, "T1")
    assert node(lv, "TOP") == 0                       # a PROTO's internal DEF (Webots)
    found = call(lv, "get_from_proto_def", {"node": table, "name": "TOP"})
    assert (found["type"], found["parent"]) == ("Pose", table)
    assert call(lv, "get_node_pose", {"node": found["node"]})["position"] == [1.0, 0.0, 1.0]
    plate = call(lv, "get_from_proto_def", {"node": table, "name": "PLATE"})
    assert plate["parent"] == found["node"]
    message = lv.err(A, "/probe/robot/set_field", {"node": found["node"], "field": "translation",
                                                    "value": [0.0, 0.0, 2.0]}, ErrorCode.INVALID_ARGUMENT)
    assert "PROTO internal field" in message and "\n" not in message, message
    message = lv.err(A, "/probe/robot/remove_node", {"node": found["node"]}, ErrorCode.INVALID_ARGUMENT)
    assert message == ("remove_node: Node 'DEF TOP Pose' is internal to a PROTO and therefore cannot be deleted from "
                       "a Supervisor.")


def test_an_imported_solids_pose_is_a_node_too():
    lv = _live()
    before = readings(lv)
    call(lv, "import_node_from_string", {"node": 0, "field": "children", "position": -1, "node_string":
                                         "DEF BOX Solid { translation 1 0 0 children [ DEF P Pose { children [ "
                                         "DEF S Shape { geometry Box { size 0.2 0.2 0.2 } } ] } ] }"})
    box, pose, shape = node(lv, "BOX"), node(lv, "BOX.P"), node(lv, "BOX.P.S")
    assert call(lv, "get_from_id", {"id": pose})["parent"] == box and get(lv, pose, "children") == [shape]
    assert get(lv, box, "children") == [pose]
    assert readings(lv)[0] == pytest.approx(0.9, abs=1e-6)        # the box's near face, 0.1 m before x = 1
    call(lv, "remove_node", {"node": pose})
    assert readings(lv) == before and node(lv, "BOX.P") == 0


def _written(tmp_path, name: str, old: str, new: str):
    text = WORLD.read_text()
    assert text.count(old) == 1
    path = tmp_path / name
    path.write_text(text.replace(old, new))
    return path


TOP_AT = "      translation 0 0 1\n      rotation 0 0 1 1.5707963267948966\n"


def test_a_set_moves_what_it_holds_as_the_world_file_written_with_that_value(tmp_path):
    lv = _live()
    ids = {n: node(lv, n) for n in ("TABLE", "LEG", "TOP", "MARKER", "LAMP", "G", "T", "INNER", "OTHER")}
    children = get(lv, ids["TABLE"], "children")
    readings(lv)
    loaded_image = image(lv)
    call(lv, "set_field", {"node": ids["TOP"], "field": "translation", "value": [0.5, 0.0, 1.0]})
    lidar, ls = readings(lv)
    # the marker's near face 0.5 m further, at 2.3; the lamp at (2.5, 0, 1): 2 / 7.25^1.5
    assert lidar == pytest.approx(2.3, abs=1e-6) and ls == pytest.approx(2.0 / 7.25 ** 1.5, rel=1e-12)
    call(lv, "set_field", {"node": ids["TOP"], "field": "rotation", "value": [0.0, 0.0, 1.0, 0.0]})
    lidar, ls = readings(lv)
    assert lidar == pytest.approx(2.4, abs=1e-6)       # unturned: 0.2 m along x, its near face at 2.5 - 0.1
    twin = _live(_written(tmp_path, "top.wbt", TOP_AT, "      translation 0.5 0 1\n      rotation 0 0 1 0\n"))
    assert (lidar, ls) == readings(twin) and image(lv) == image(twin) != loaded_image       # bit for bit
    # every handle still names its node; the fields read the values set; its world pose and its shape's follow
    assert {n: node(lv, n) for n in ids} == ids and get(lv, ids["TABLE"], "children") == children
    assert get(lv, ids["TOP"], "children") == [ids["MARKER"], ids["LAMP"]]
    assert get(lv, ids["TOP"], "translation") == [0.5, 0.0, 1.0]
    assert get(lv, ids["TOP"], "rotation") == [0.0, 0.0, 1.0, 0.0]
    assert call(lv, "get_node_pose", {"node": ids["TOP"]})["position"] == [2.5, 0.0, 0.0]
    assert get(lv, ids["LAMP"], "location") == [0.0, 0.0, 1.0]       # in its Pose's frame, as written
    # exportString and worldSave write the values set
    assert call(lv, "node_export_string", {"node": ids["TOP"]})["value"].splitlines()[:3] == [
        "DEF TOP Pose {", "  translation 0.5 0 1", "  rotation 0 0 1 0"]
    assert "    DEF TOP Pose {\n      translation 0.5 0 1\n" in call(lv, "world_save")["value"]
    # a reset puts the loaded value back (WbPose::reset), handles still valid
    call(lv, "simulation_reset")
    assert readings(lv) == readings(_live()) and image(lv) == loaded_image
    assert get(lv, ids["TOP"], "translation") == [0.0, 0.0, 1.0] and node(lv, "TABLE.TOP.MARKER") == ids["MARKER"]
    assert "translation 0 0 1" in call(lv, "node_export_string", {"node": ids["TOP"]})["value"]


def test_a_transform_set_moves_the_solid_it_holds_and_a_moved_table_stays_where_it_was(tmp_path):
    lv = _live()
    table, top, t, inner = (node(lv, n) for n in ("TABLE", "TOP", "T", "INNER"))
    call(lv, "set_field", {"node": table, "field": "translation", "value": [2.0, 0.0, -2.0]})
    call(lv, "set_field", {"node": top, "field": "translation", "value": [0.0, 0.0, 3.0]})  # the marker off the beam
    # T at (2 - 0.6, 0, 0): the sphere INNER (r 0.05) at x = 1.5, its near face at 1.45
    call(lv, "set_field", {"node": t, "field": "translation", "value": [-0.6, 0.0, 2.0]})
    assert call(lv, "get_node_pose", {"node": inner})["position"] == pytest.approx([1.5, 0.0, 0.0], abs=1e-15)
    assert call(lv, "get_node_pose", {"node": table})["position"] == [2.0, 0.0, -2.0]
    lidar, _ = readings(lv)
    assert lidar == pytest.approx(1.45, abs=1e-6)
    text = WORLD.read_text().replace("  translation 2 0 -1\n", "  translation 2 0 -2\n").replace(
        TOP_AT, "      translation 0 0 3\n      rotation 0 0 1 1.5707963267948966\n").replace(
        "          translation 0 0.5 1\n", "          translation -0.6 0 2\n")
    (tmp_path / "t.wbt").write_text(text)
    twin = _live(tmp_path / "t.wbt")
    assert readings(lv) == readings(twin) and image(lv) == image(twin)
    call(lv, "simulation_reset")
    assert readings(lv) == readings(_live())
    assert call(lv, "get_node_pose", {"node": inner})["position"] == pytest.approx([2.1, 0.5, 0.0], abs=1e-15)


def test_a_shapes_colour_set_before_stays_and_a_reset_brings_back_both(tmp_path):
    lv = _live()
    top, marker = node(lv, "TOP"), node(lv, "MARKER")
    readings(lv)
    loaded_image = image(lv)
    material = get(lv, get(lv, marker, "appearance"), "material")
    call(lv, "set_field", {"node": material, "field": "emissiveColor", "value": [0.0, 1.0, 0.0]})
    call(lv, "set_field", {"node": top, "field": "translation", "value": [0.5, 0.0, 1.0]})
    assert get(lv, material, "emissiveColor") == [0.0, 1.0, 0.0]
    twin = _live(_green_moved(tmp_path))
    assert readings(lv) == readings(twin) and image(lv) == image(twin)
    call(lv, "simulation_reset")
    readings(lv)
    assert image(lv) == loaded_image and get(lv, material, "emissiveColor") == [1.0, 0.0, 0.0]


def _green_moved(tmp_path):
    path = tmp_path / "green_moved.wbt"
    path.write_text(WORLD.read_text().replace("emissiveColor 1 0 0", "emissiveColor 0 1 0").replace(
        TOP_AT, "      translation 0.5 0 1\n      rotation 0 0 1 1.5707963267948966\n"))
    return path


def test_a_set_is_refused_in_one_line_where_a_rebuild_would_undo_other_changes():
    for undone in ({"node": "LAMP", "field": "intensity", "value": 1.0}, "LEG"):
        lv = _live()
        top = node(lv, "TOP")
        if isinstance(undone, dict):
            call(lv, "set_field", {**undone, "node": node(lv, undone["node"])})
        else:
            call(lv, "remove_node", {"node": node(lv, undone)})
        before = readings(lv)
        message = lv.err(A, "/probe/robot/set_field", {"node": top, "field": "translation",
                                                        "value": [0.5, 0.0, 1.0]}, ErrorCode.INVALID_ARGUMENT)
        assert "would undo" in message and "\n" not in message, message
        assert get(lv, top, "translation") == [0.0, 0.0, 1.0] and readings(lv) == before


def test_an_imported_solids_pose_set_moves_its_shape():
    lv = _live()
    call(lv, "set_field", {"node": node(lv, "TOP"), "field": "translation", "value": [0.0, 0.0, 3.0]})
    call(lv, "import_node_from_string", {"node": 0, "field": "children", "position": -1, "node_string":
                                         "DEF BOX Solid { translation 1 0 0 children [ DEF P Pose { children [ "
                                         "DEF S Shape { geometry Box { size 0.2 0.2 0.2 } } ] } ] }"})
    pose, shape = node(lv, "BOX.P"), node(lv, "BOX.P.S")
    assert readings(lv)[0] == pytest.approx(0.9, abs=1e-6)
    call(lv, "set_field", {"node": pose, "field": "translation", "value": [0.5, 0.0, 0.0]})
    assert readings(lv)[0] == pytest.approx(1.4, abs=1e-6)          # the box's near face, 0.1 m before x = 1.5
    assert node(lv, "BOX.P") == pose and node(lv, "BOX.P.S") == shape and get(lv, pose, "children") == [shape]
    assert "DEF P Pose {\n      translation 0.5 0 0\n" in call(lv, "node_export_string", {"node": node(lv, "BOX")})["value"]


def _recognised(text: str) -> str:
    """The world with TABLE recognised (red), INNER a radar target and the camera recognising."""
    for old, new in (('  name "table"\n', '  name "table"\n  recognitionColors [ 1 0 0 ]\n'),
                     ('              name "inner"\n', '              name "inner"\n              radarCrossSection 1\n'),
                     ('      name "camera"\n', '      name "camera"\n      recognition Recognition { }\n')):
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    return text


def _seen(lv: Live) -> tuple[list, dict]:
    cam = lv.sim.robot("probe").device("camera")
    cam.recognition_enable(8)
    lv.step(A, "probe")
    scene = lv.sim.scene
    targets = {str(k): (scene.target_pose(k).translation.tolist(), scene.target_pose(k).rotation.tolist())
               for k in scene.radar_targets}
    return [o.as_dict() for o in cam.objects], targets


def test_recognition_and_radar_targets_follow_as_the_world_file_written_so(tmp_path):
    (tmp_path / "r.wbt").write_text(_recognised(WORLD.read_text()))
    lv = _live(tmp_path / "r.wbt")
    loaded = _seen(lv)
    call(lv, "set_field", {"node": node(lv, "TOP"), "field": "rotation", "value": [0.0, 0.0, 1.0, 0.3]})
    call(lv, "set_field", {"node": node(lv, "T"), "field": "translation", "value": [-0.6, 0.0, 1.2]})
    moved = _seen(lv)
    (tmp_path / "twin.wbt").write_text(_recognised(WORLD.read_text()).replace(
        TOP_AT, "      translation 0 0 1\n      rotation 0 0 1 0.3\n").replace(
        "          translation 0 0.5 1\n", "          translation -0.6 0 1.2\n"))
    assert moved == _seen(_live(tmp_path / "twin.wbt")) != loaded
    assert len(moved[0]) == 1 and len(moved[1]) == 1      # the table recognised, INNER a target
    assert list(moved[1].values())[0][0] == pytest.approx([1.5, 0.0, 0.2], abs=1e-15)   # (2, 0, -1) + T + 0.1 x
    call(lv, "simulation_reset")
    assert _seen(lv) == loaded


def test_a_solids_saved_state_keeps_the_poses_inside_it_as_set() -> None:
    """saveState of TABLE with TOP set 0.5 m along x keeps TOP's place (Webots' WbNode::save covers every field
    below the node): after TOP is set elsewhere, loadState puts it back (the lidar on the marker's near face at
    2.3 again, the field read as set); loadState("__init__") puts the loaded value back, the readings the
    loaded world's."""
    lv = _live()
    table, top = node(lv, "TABLE"), node(lv, "TOP")
    loaded = readings(lv)
    call(lv, "set_field", {"node": top, "field": "translation", "value": [0.5, 0.0, 1.0]})
    moved = readings(lv)
    assert moved[0] == pytest.approx(2.3, abs=1e-6)
    call(lv, "save_node_state", {"node": table, "state": "moved"})
    call(lv, "set_field", {"node": top, "field": "translation", "value": [0.0, 0.0, 3.0]})
    call(lv, "set_field", {"node": top, "field": "rotation", "value": [0.0, 0.0, 1.0, 0.3]})
    assert readings(lv) != moved
    call(lv, "load_node_state", {"node": table, "state": "moved"})
    assert readings(lv) == moved
    assert get(lv, top, "translation") == [0.5, 0.0, 1.0]
    assert get(lv, top, "rotation") == pytest.approx([0.0, 0.0, 1.0, math.pi / 2], abs=1e-15)
    call(lv, "load_node_state", {"node": table, "state": "__init__"})
    assert readings(lv) == loaded and get(lv, top, "translation") == [0.0, 0.0, 1.0]
