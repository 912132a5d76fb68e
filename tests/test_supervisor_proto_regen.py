"""A Supervisor setting a PROTO field of a top-level solid builds the solid again, as Webots regenerates a
PROTO node (README "Supervisor"): a field the template reads (``size``, ``round``, the list ``posts``) or one
passing through IS to a node inside (``color``) is seen by every sensor from the next step exactly as the world
file written with that value; the solid keeps its node id, DEF, name, place among the root's children and the
pose a Supervisor gave it; the nodes of its old body read as removed, its new body's are served with new ids; ``simulationReset`` puts it back where the
file put it and keeps the values set (Webots' reset resets no field); a value that does not build is one line
and nothing changes. An imported instance is rebuilt the same way; kinematic contact and the ground robots ride
see the new solid. The same from Python and C controllers.

Sensorium's own PROTO (tests/protos/regen/Obstacle.proto) on tests/worlds/proto/supervisor_proto_regen.wbt;
each variant world is that file with a value written in, in the test's folder."""

from __future__ import annotations

import shutil
import sys

import numpy as np
import pytest
from test_multiprocess import REPO, run_paused

from sensorium.server.daemon import supervisor as sv
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WORLD = REPO / "tests" / "worlds" / "proto" / "supervisor_proto_regen.wbt"
PROTO = REPO / "tests" / "protos" / "regen" / "Obstacle.proto"
DEVICES = ("cam", "depth", "lidar", "ds", "ir")
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=1:exitcode=86", "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"}


def _sim(path=WORLD) -> Simulation:
    sim = Simulation(load_world(path))
    for name in DEVICES:
        sim.device(f"eye/{name}").enable(16)
    sim.device("eye/cam").recognition_enable(16)
    return sim


def _readings(sim: Simulation) -> dict:
    sim.step()
    return {"cam": sim.device("eye/cam").image.copy(), "depth": np.array(sim.device("eye/depth").range_image),
            "lidar": np.array(sim.device("eye/lidar").range_image), "ds": float(sim.device("eye/ds").value),
            "ir": float(sim.device("eye/ir").value),
            "objects": repr(sim.device("eye/cam").objects)}


def _same(a: dict, b: dict) -> bool:
    return all(np.array_equal(a[k], b[k]) for k in DEVICES) and a["objects"] == b["objects"]


def _variant(folder, *changes: tuple[str, str]) -> Simulation:
    """The world file written with those values (each ``(old, new)`` text replaced once), loaded."""
    text = WORLD.read_text().replace('"../../protos/regen/Obstacle.proto"', '"Obstacle.proto"')
    for old, new in changes:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    shutil.copy(PROTO, folder / "Obstacle.proto")
    path = folder / f"variant{len(list(folder.glob('variant*.wbt')))}.wbt"
    path.write_text(text)
    return _sim(path)


def _written(folder, *changes: tuple[str, str]) -> dict:
    """What the world file written with those values sees."""
    return _readings(_variant(folder, *changes))


def obst(sim):
    return sv.find_node(sim, "OBST")


def field(sim, name):
    return sv.get_field(sim, obst(sim), name)["value"]


def test_each_proto_field_set_is_seen_as_the_world_file_written_with_that_value(tmp_path):
    sim = _sim()
    before = _readings(sim)
    assert float(before["lidar"][0, 16]) == pytest.approx(0.8, abs=1e-6)      # 1 - 0.2 / 2 - 0.1 (the lidar's x)
    assert "id=2," in before["objects"]            # recognised as node 2, before and after (the same node)
    changes: list[tuple[str, str]] = []
    steps = [("size", [0.6, 0.4, 0.3], ("size 0.2 0.2 0.2", "size 0.6 0.4 0.3")),      # the template's box
             ("color", [0.9, 0.1, 0.2], ("color 0.5 0.5 0.5", "color 0.9 0.1 0.2")),   # IS to its PBRAppearance
             ("material", "stone", ("round FALSE", 'round FALSE\n  material "stone"')),      # the template's roughness
             ("round", True, ("round FALSE", "round TRUE"))]                             # the template's sphere
    for name, value, change in steps:
        assert sv.set_field(sim, obst(sim), name, value) == []
        changes.append(change)
        assert field(sim, name) == value
        got = _readings(sim)
        assert _same(got, _written(tmp_path, *changes)), name
        assert not _same(got, before)
        before = got
    assert float(before["lidar"][0, 16]) == pytest.approx(0.6, abs=1e-6)      # the sphere of diameter 0.6
    # an MF field's items (insertMF*, setMF*, removeMF): the template's posts
    sv.change_item(sim, obst(sim), "posts", "insert", -1, 0.5)
    sv.change_item(sim, obst(sim), "posts", "insert", 0, 0.25)
    assert field(sim, "posts") == [0.25, 0.5]
    assert _same(_readings(sim), _written(tmp_path, *changes, ("posts [ ]", "posts [ 0.25 0.5 ]")))
    sv.change_item(sim, obst(sim), "posts", "set", -1, 2.0)
    sv.change_item(sim, obst(sim), "posts", "remove", 0, None)
    assert field(sim, "posts") == [2.0]
    assert _same(_readings(sim), _written(tmp_path, *changes, ("posts [ ]", "posts [ 2 ]")))
    assert sim.counters["regenerations"] == 8


def test_the_rebuilt_solid_keeps_its_id_def_name_place_and_the_pose_a_supervisor_gave_it(tmp_path):
    sim = _sim()
    node = obst(sim)
    order = [n.id for n in sv.root_children(sim)]
    shape = sv.get_field(sim, node, "children", level=0)["value"][0]
    assert sv.node_by_id(sim, shape).type == "Shape"
    assert sv.from_proto_def(sim, node, "BODY")[0] is not None
    sv.set_field(sim, node, "translation", [1.5, 0.2, 0.0])
    sv.set_field(sim, node, "size", [0.6, 0.4, 0.3])
    again = obst(sim)
    assert (again.id, again.def_name, again.name, again.proto) == (node.id, "OBST", "obstacle", "Obstacle")
    assert [n.id for n in sv.root_children(sim)] == order
    assert sv.node_pose(sim, again)["position"] == [1.5, 0.2, 0.0]
    assert field(sim, "translation") == [1.5, 0.2, 0.0]
    assert _same(_readings(sim), _written(tmp_path, ("translation 1 0 0\n  size 0.2 0.2 0.2",
                                                     "translation 1.5 0.2 0\n  size 0.6 0.4 0.3")))
    # the old body's nodes are gone (Webots deletes them); its new body's are served, with new ids
    with pytest.raises(ValueError, match=r"node \d+ \(Shape ''\) was removed with 'obstacle' when a PROTO field "
                                         r"set built it again"):
        sv.node_by_id(sim, shape)
    (new_shape,) = sv.get_field(sim, again, "children", level=0)["value"]
    assert new_shape > shape and sv.node_by_id(sim, new_shape).type == "Shape"
    found, line = sv.from_proto_def(sim, again, "BODY")
    assert found is not None and line == "" and found.type == "Box" and found.id > new_shape
    assert sv.get_field(sim, sv.node_by_id(sim, new_shape), "geometry")["value"] == found.id
    assert sv.get_field(sim, found, "size")["value"] == [0.6, 0.4, 0.3]
    assert sv.find_node(sim, "OBST.BODY") is None          # a PROTO body's DEF: getFromProtoDef only
    # a field passing through IS is set as before: the rebuilt solid moves (its face 0.9 - 0.3 m away)
    sv.set_field(sim, again, "translation", [1.0, 0.0, 0.0])
    assert _readings(sim)["ds"] == pytest.approx(600.0, abs=1e-9)


def test_a_reset_puts_it_where_the_file_put_it_and_keeps_the_values_set(tmp_path):
    sim = _sim()
    sv.set_field(sim, obst(sim), "translation", [2.0, 0.5, 0.0])
    sv.set_field(sim, obst(sim), "size", [0.6, 0.4, 0.3])
    sim.reset()
    assert field(sim, "size") == [0.6, 0.4, 0.3]          # Webots' simulationReset resets no field
    assert field(sim, "translation") == [1.0, 0.0, 0.0]   # but the solid's pose from the file
    # as the world written with that size, its obstacle moved there and reset (a move and its way back cost the
    # ray engine's moved-body arithmetic a last bit, rebuilt or not)
    ref = _variant(tmp_path, ("size 0.2 0.2 0.2", "size 0.6 0.4 0.3"))
    sv.set_field(ref, obst(ref), "translation", [2.0, 0.5, 0.0])
    ref.reset()
    assert _same(_readings(sim), _readings(ref))
    assert _readings(sim)["ds"] == pytest.approx(600.0, abs=1e-9)


def test_a_value_that_does_not_build_is_one_line_and_nothing_changes():
    sim = _sim()
    before = _readings(sim)
    node = obst(sim)
    for name, value, line in (
            ("size", [0.6, 0.6, 2e9], "field 'size' (SFVec3f) of PROTO Obstacle (Solid 'OBST' (node 2)) not set: the "
             "solid does not build with that value: "),
            ("size", [0.6, 0.6], "field 'size' is an SFVec3f: takes 3 finite numbers, got [0.6, 0.6]"),
            ("round", 1, "field 'round' is an SFBool: takes true or false, got 1"),
            ("posts", [1.0], "field 'posts' is an MFFloat: set it item by item (setMF*, insertMF*, removeMF)"),
            ("name", "rock", "field 'name' (SFString) of PROTO Obstacle (Solid 'obstacle') is read-only here: it passes "
             "to the base node's 'name', which is read-only here; nothing changed")):
        with pytest.raises(ValueError) as exc:
            sv.set_field(sim, node, name, value)
        text = str(exc.value)
        assert text.startswith(line) and "\n" not in text, text
    assert "exceeds the limit of 1e+09" in str(pytest.raises(ValueError, sv.set_field, sim, node, "size",
                                                             [0.6, 0.6, 2e9]).value)
    # a value the PROTO's declaration does not accept; one its template refuses
    with pytest.raises(ValueError) as exc:
        sv.set_field(sim, node, "material", "glass")
    line = WORLD.read_text().splitlines().index("DEF OBST Obstacle {") + 1          # placed at the instance
    assert str(exc.value).endswith(f"supervisor_proto_regen.wbt:{line}:10: Obstacle.material: 'glass' is not an "
                                   'accepted value (one of: "wood", "stone"); nothing changed'), exc.value
    with pytest.raises(ValueError) as exc:
        sv.set_field(sim, node, "size", [60.0, 1.0, 1.0])
    assert "an obstacle is at most 50 m wide" in str(exc.value) and "\n" not in str(exc.value), exc.value
    assert str(exc.value).startswith("field 'size' (SFVec3f) of PROTO Obstacle (Solid 'OBST' (node 2)) not set: ")
    with pytest.raises(ValueError, match=r"field .posts. \(MFFloat\) of .*: the list is empty; nothing changed"):
        sv.change_item(sim, node, "posts", "set", 3, 1.0)
    assert field(sim, "size") == [0.2, 0.2, 0.2] and field(sim, "round") is False
    assert sv.node_by_id(sim, node.id) == node
    assert _same(_readings(sim), before)
    assert sim.counters.get("regenerations", 0) == 0


def test_a_value_webots_corrects_is_corrected_with_its_line(tmp_path):
    sim = _sim()
    lines = sv.set_field(sim, obst(sim), "size", [0.6, -1.0, 0.3])
    assert len(lines) == 1 and "has a component that is not > 0; using 1 1 1 (as Webots does)" in lines[0], lines
    assert field(sim, "size") == [0.6, -1.0, 0.3]
    assert _same(_readings(sim), _written(tmp_path, ("size 0.2 0.2 0.2", "size 0.6 -1 0.3")))


def test_an_imported_instance_is_rebuilt_the_same_way(tmp_path):
    sim = _sim()
    sv.remove_node(sim, obst(sim))
    (added,) = sv.import_nodes(sim, sv.ROOT, "children", -1, "DEF OBST Obstacle { translation 1 0 0 }")
    body, _ = sv.from_proto_def(sim, sv.node_by_id(sim, added), "BODY")     # the import's body is served
    assert body is not None and sv.get_field(sim, body, "size")["value"] == [0.2, 0.2, 0.2]
    sv.set_field(sim, sv.node_by_id(sim, added), "size", [0.6, 0.4, 0.3])
    again = obst(sim)
    assert (again.id, again.proto) == (added, "Obstacle")
    assert sv.node_from_id(sim, body.id) is None                # the old body's nodes removed, the new one's served
    new_body, _ = sv.from_proto_def(sim, again, "BODY")
    assert new_body is not None and new_body.id > body.id and sv.get_field(sim, new_body, "size")["value"] == [0.6, 0.4, 0.3]
    assert sv.get_field(sim, again, "size")["value"] == [0.6, 0.4, 0.3]
    got, ref = _readings(sim), _written(tmp_path, ("size 0.2 0.2 0.2", "size 0.6 0.4 0.3"))
    assert all(np.array_equal(got[k], ref[k]) for k in DEVICES)
    assert got["objects"] == ref["objects"].replace("id=2,", f"id={added},")     # recognised as the imported node
    sim.reset()                                   # Webots' reset removes what a Supervisor imported
    assert obst(sim) is None


EXPECTED = """before 0.80000001 0.20000000000000001 0.20000000000000001 0.20000000000000001
size 0.60000002 0.59999999999999998 0.40000000000000002 0.29999999999999999 same 1 def OBST
moved 1.5 0.20000000000000001 0
posts 1 0.5
round 1 0.5
material stone
refused 0.59999999999999998 0.40000000000000002 0.29999999999999999
reset 1 0 0 0.59999999999999998""".splitlines()


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_webots_python_supervisor_randomises_the_obstacle(tmp_path):
    """tests/controllers/supervisor_proto_regen.py through ``sensorium serve``."""
    ctl = run_paused(WORLD, tmp_path, "supervisor_proto_regen.py", "eye")
    assert ctl.out == EXPECTED
    _check_lines(ctl.stderr())


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_c_supervisor_randomises_the_obstacle(tmp_path, tmp_path_factory):
    """tests/c/supervisor_proto_regen.c (the library with AddressSanitizer and UBSan)."""
    from test_c_client import sanitized_controller

    exe = sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "supervisor_proto_regen.c")
    ctl = run_paused(WORLD, tmp_path, exe, "eye", env=SAN_ENV)
    assert ctl.out == EXPECTED
    _check_lines(ctl.stderr())


def _check_lines(err: str) -> None:
    assert "Sanitizer" not in err and "runtime error" not in err and "Traceback" not in err, err
    errors = [x for x in err.splitlines() if x.startswith("Error")]
    assert len(errors) == 1 and "not set: the solid does not build with that value" in errors[0], err


ROVER_WORLD = """#VRML_SIM R2023b utf8
EXTERNPROTO "Obstacle.proto"
WorldInfo {
  basicTimeStep 16
}
DEF OBST Obstacle {
  translation 1 0 0.1
  size 0.2 2 0.2
}
Robot {
  name "rover"
  children [
    HingeJoint {
      jointParameters HingeJointParameters { axis 0 1 0 anchor 0 0.05 0.03 }
      device [ RotationalMotor { name "left" } ]
      endPoint Solid { translation 0 0.05 0.03 children [ Shape { geometry Cylinder { radius 0.03 height 0.01 } } ] }
    }
    HingeJoint {
      jointParameters HingeJointParameters { axis 0 1 0 anchor 0 -0.05 0.03 }
      device [ RotationalMotor { name "right" } ]
      endPoint Solid { translation 0 -0.05 0.03 children [ Shape { geometry Cylinder { radius 0.03 height 0.01 } } ] }
    }
  ]
  boundingObject Pose { translation 0 0 0.06 children [ Box { size 0.2 0.2 0.06 } ] }
}
"""


def _rover_run(sim: Simulation) -> float:
    rover = sim.robot("rover")
    for m in rover.motors.values():
        m.target_position, m.velocity = float("inf"), 10.0
    for _ in range(200):                                  # 3.2 s at 0.3 m/s: stopped at the obstacle
        sim.step()
    return float(rover.pose.translation[0])


def test_kinematic_contact_stops_a_robot_at_the_rebuilt_obstacle(tmp_path):
    shutil.copy(PROTO, tmp_path / "Obstacle.proto")
    (tmp_path / "rover.wbt").write_text(ROVER_WORLD)
    (tmp_path / "wide.wbt").write_text(ROVER_WORLD.replace("size 0.2 2 0.2", "size 0.6 2 0.2"))
    sim = Simulation(load_world(tmp_path / "rover.wbt"), contact=True)
    assert sim.contact is not None
    sv.set_field(sim, obst(sim), "size", [0.6, 2.0, 0.2])      # its face from x = 0.9 to x = 0.7
    got = _rover_run(sim)
    assert got == _rover_run(Simulation(load_world(tmp_path / "wide.wbt"), contact=True))
    assert got == pytest.approx(0.6, abs=1e-6)                   # the rover's half length 0.1 before the face


def test_the_rebuilt_obstacle_is_ground_as_the_world_files_box_tops_are(tmp_path):
    """In a world with a terrain, a box top is ground: the rebuilt obstacle's new top, as the world file's."""
    shutil.copy(PROTO, tmp_path / "Obstacle.proto")
    terrain = ('Solid { translation -5 -5 0 name "field" children [ Shape { geometry ElevationGrid { xDimension 2 '
               'yDimension 2 xSpacing 10 ySpacing 10 height [ 0 0 0 0 ] } } ] boundingObject ElevationGrid { '
               'xDimension 2 yDimension 2 xSpacing 10 ySpacing 10 height [ 0 0 0 0 ] } }\n')
    (tmp_path / "rover.wbt").write_text(ROVER_WORLD + terrain)
    (tmp_path / "tall.wbt").write_text(ROVER_WORLD.replace("size 0.2 2 0.2", "size 0.2 2 0.4") + terrain)
    sim = Simulation(load_world(tmp_path / "rover.wbt"))
    assert sim.ground is not None and sim.ground.at(1.0, 0.0) == (0.2, 0.0, 0.0)      # 0.1 + 0.2 / 2
    sv.set_field(sim, obst(sim), "size", [0.2, 2.0, 0.4])
    tall = Simulation(load_world(tmp_path / "tall.wbt"))
    # the 0.4 m box (physics) at z 0.1 is sunk 0.1 into the terrain: it settles onto it, both rebuilt and
    # loaded (a world file's solid with physics settles at load), its top at 0.4
    assert sim.ground.at(1.0, 0.0) == tall.ground.at(1.0, 0.0) == pytest.approx((0.4, 0.0, 0.0), abs=1e-12)
    assert sim.scene.solid_poses["obstacle"].translation.tolist() == [1.0, 0.0, 0.2]


def test_the_live_viewer_draws_the_rebuilt_obstacle_each_time():
    """The Foxglove scene is encoded again after each set, the obstacle keeping its name and pose (free loopback
    ports)."""
    pytest.importorskip("foxglove")
    from sensorium.server.daemon.services import Core
    from sensorium.server.daemon.transport import Transport
    from sensorium.server.recording.scene3d import scene_update
    from sensorium.server.viewer.bridge import FoxgloveBridge

    sim = Simulation(load_world(WORLD), precision="fast")
    transport = Transport(Core(sim), "tcp://127.0.0.1:0", "tcp://127.0.0.1:0")
    bridge = FoxgloveBridge.for_core(transport.core, transport, "127.0.0.1", 0)
    try:
        drawn = [bridge.scene_bytes()]
        for size in ([0.6, 0.4, 0.3], [1.0, 0.4, 0.3]):        # the second time the obstacle is already last
            sv.set_field(sim, obst(sim), "size", size)
            transport.hooks[0]()
            drawn.append(bridge.scene_bytes())
            assert drawn[-1] == scene_update(sim.world, sim.loaded.base_dir, 0, dict(sim.scene.solid_poses),
                                             sim.scene.removed_lights).encode()
        assert len(set(drawn)) == 3
    finally:
        bridge.close()
        transport.close()
