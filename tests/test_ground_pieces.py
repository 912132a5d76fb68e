"""The ground a let-go or moved solid lands on (``Simulation.landing_ground``) is made of each solid's and
robot's pieces kept between calls (ground.GroundPieces); after every change that can move ground -- a move,
an import, a removal, a PROTO field set, a reset, a fall, a gripper carrying a solid, a joint moving a robot's
shapes -- it is bit for bit the ground built from scratch (ground.settling_ground, as before the pieces were
kept), and a box dropped there rests on the new top: its centre half its 0.1 m size above it. A wheeled robot
a Supervisor moves settles (``Simulation.settled``) on kept pieces too: bit for bit as on a fresh ground."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.server.daemon import supervisor as sv
from sensorium.server.sim.ground import Ground, settle_pose, settling_ground
from sensorium.server.sim.scene import robot_parts
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.geometry import Pose
from sensorium.server.world.loader import load_world, parse_world

TABLE = """#VRML_SIM R2023b utf8
# a table top of our own whose size a Supervisor sets (no template)
PROTO Table [
  field SFVec3f    translation 0 0 0.4
  field SFRotation rotation    0 0 1 0
  field SFString   name        "table"
  field SFVec3f    size        1 1 0.8
]
{
  Solid {
    translation IS translation
    rotation IS rotation
    name IS name
    boundingObject Box { size IS size }
  }
}
"""

WORLD = """#VRML_SIM R2023b utf8
EXTERNPROTO "Table.proto"
WorldInfo { basicTimeStep 16 }
Solid { name "floor" boundingObject Plane { size 20 20 } }
DEF TABLE Table { }
Solid { translation 0 2 0.15 name "drum" boundingObject Cylinder { radius 0.3 height 0.3 } }
Solid { translation 3 0 0.2 rotation 0 1 0 0.3 name "ramp" boundingObject Box { size 1 1 0.1 } }
DEF CRATE Solid { translation -2 0 0.2 name "crate" boundingObject Box { size 0.4 0.4 0.4 } physics Physics { } }
DEF BOX Solid { translation 5 5 0.05 name "box" boundingObject Box { size 0.1 0.1 0.1 } physics Physics { } }
"""

XS, YS = np.meshgrid(np.linspace(-4.0, 4.0, 161), np.linspace(-4.0, 4.0, 81))


def _sim(tmp_path: Path) -> Simulation:
    (tmp_path / "Table.proto").write_text(TABLE)
    (tmp_path / "w.wbt").write_text(WORLD)
    sim = Simulation(load_world(tmp_path / "w.wbt"))
    sim.landing_ground("box")            # its pieces kept from here: every change below must reach them
    return sim


def _rebuilt(sim: Simulation, solid: str, carrier: int | None = None) -> Ground | None:
    """The landing ground built from scratch, as landing_ground built it before its pieces were kept."""
    floors = [r for r in sim.robots.values() if not r.model.drive_motors and r.index != carrier]
    parts = [[(name, local if r.links is None or (j := getattr(shape, "on_joint", None)) not in r.links.poses
               else r.links.poses[j].compose(local), shape) for name, local, shape in robot_parts(r.model)] for r in floors]
    alive = sim.scene.solid_poses
    return settling_ground([(s, sim.falls.resting(s.name, alive[s.name])) for s in sim.world.solids
                            if s.name in alive and s.name != solid],
                           [(r.model, sim.scene.robot_poses[r.index]) for r in floors], None, parts)


def _same_ground(sim: Simulation, solid: str = "box", carrier: int | None = None) -> None:
    kept, fresh = sim.landing_ground(solid, carrier), _rebuilt(sim, solid, carrier)
    assert (kept is None) == (fresh is None)
    assert kept is not None and fresh is not None
    for ceiling in (math.inf, 0.5, 1.0):
        for a, b in zip(kept.under(XS, YS, ceiling), fresh.under(XS, YS, ceiling)):
            assert np.array_equal(a, b)
    assert len(kept.tops()) == len(fresh.tops())
    for (za, outline_a), (zb, outline_b) in zip(kept.tops(), fresh.tops()):
        assert za == zb and np.array_equal(outline_a, outline_b)


def _rest_height(sim: Simulation, x: float, y: float) -> float:
    """Where the box, put 2.5 m up over (x, y), comes to rest: its centre's height."""
    sim.set_solid_pose("box", [x, y, 2.5])
    fall = sim.falls.falling.get("box")
    pose = sim.scene.solid_poses["box"] if fall is None else fall.landed
    return float(pose.translation[2])


def _node(sim: Simulation, name: str):
    return sv.find_node(sim, name)


def test_as_loaded_the_kept_ground_is_the_built_one_and_the_box_rests_on_the_table(tmp_path) -> None:
    sim = _sim(tmp_path)
    _same_ground(sim)
    assert _rest_height(sim, 0.2, 0.1) == pytest.approx(0.85, abs=1e-12)
    _same_ground(sim)
    assert _rest_height(sim, 0.0, 2.0) == pytest.approx(0.35, abs=1e-12)        # the drum's top
    _same_ground(sim, "crate")


def test_a_table_moved_is_ground_where_it_is_put_and_no_longer_where_it_was(tmp_path) -> None:
    sim = _sim(tmp_path)
    sv.set_field(sim, _node(sim, "TABLE"), "translation", [0.0, -2.5, 0.4])
    _same_ground(sim)
    assert _rest_height(sim, 0.0, -2.5) == pytest.approx(0.85, abs=1e-12)
    assert _rest_height(sim, 0.2, 0.1) == pytest.approx(0.05, abs=1e-12)
    _same_ground(sim)


def test_a_table_imported_is_ground_and_removed_it_is_not(tmp_path) -> None:
    sim = _sim(tmp_path)
    (node,) = sv.import_nodes(sim, sv.ROOT, "children", -1,
                              'Solid { translation 1.5 -2 0.3 name "bench" boundingObject Box { size 1 1 0.6 } }')
    _same_ground(sim)
    assert _rest_height(sim, 1.5, -2.0) == pytest.approx(0.65, abs=1e-12)
    sv.remove_node(sim, sv.node_by_id(sim, node))
    _same_ground(sim)
    assert _rest_height(sim, 1.5, -2.0) == pytest.approx(0.05, abs=1e-12)
    sim.remove_solid("table")
    _same_ground(sim)
    assert _rest_height(sim, 0.2, 0.1) == pytest.approx(0.05, abs=1e-12)


def test_a_table_built_again_taller_by_a_proto_field_set_is_ground_at_its_new_top(tmp_path) -> None:
    sim = _sim(tmp_path)
    sv.set_field(sim, _node(sim, "TABLE"), "size", [1.0, 1.0, 1.2])          # its top from 0.8 to 1.0
    _same_ground(sim)
    assert _rest_height(sim, 0.2, 0.1) == pytest.approx(1.05, abs=1e-12)


def test_after_a_reset_the_table_moved_away_is_ground_where_it_was_loaded(tmp_path) -> None:
    sim = _sim(tmp_path)
    sim.set_solid_pose("table", [0.0, -2.5, 0.4])
    assert _rest_height(sim, 0.2, 0.1) == pytest.approx(0.05, abs=1e-12)
    sim.reset()
    _same_ground(sim)
    assert _rest_height(sim, 0.2, 0.1) == pytest.approx(0.85, abs=1e-12)


def test_a_falling_crate_is_ground_where_it_will_rest_and_where_it_rests(tmp_path) -> None:
    sim = _sim(tmp_path)
    sim.set_solid_pose("crate", [-2.0, 0.0, 1.5])       # it falls back onto the floor, top at 0.4
    assert "crate" in sim.falls.falling
    _same_ground(sim)
    sim.set_solid_pose("crate", [0.0, 0.0, 2.0])        # over the table: it will rest there, top at 1.2
    _same_ground(sim)
    assert _rest_height(sim, 0.1, 0.0) == pytest.approx(1.25, abs=1e-12)
    sim.set_solid_pose("box", [4.0, 4.0, 0.05])
    for _ in range(60):
        sim.step()
    assert "crate" not in sim.falls.falling
    _same_ground(sim)
    assert _rest_height(sim, 0.1, 0.0) == pytest.approx(1.25, abs=1e-12)


def _crane_world() -> Simulation:
    """A robot without a drive whose lift (a LinearMotor along z) carries a 0.4 m platform at 0.5 m and a
    cup holding a 0.2 m crate at (1, 0), the crate's centre at 1.0; a 0.1 m box with physics aside."""
    on_lift = {"seen_by": "bounding", "on_joint": "lift"}
    crane = {"name": "crane",
             "shapes": [{"pose": {"translation": [0.0, 0.0, 0.5]}, "geometry": {"type": "box", "size": [0.4, 0.4, 0.1]},
                         **on_lift},
                        {"pose": {"translation": [1.0, 0.0, 1.11]}, "geometry": {"type": "cylinder", "radius": 0.05,
                                                                                 "height": 0.02}, **on_lift, "of_device": "cup"}],
             "devices": [{"device": "LinearMotor", "name": "lift", "axis": [0, 0, 1], "max_velocity": 10.0, "max_force": 100.0,
                          "min_position": -1.0, "max_position": 1.0},
                         {"device": "VacuumGripper", "name": "cup", "is_on": True, "pose": {"translation": [1.0, 0.0, 1.11]},
                          "on_joint": "lift"}]}
    solids = [{"name": "floor", "geometry": {"type": "plane"}},
              {"name": "crate", "pose": {"translation": [1.0, 0.0, 1.0]}, "geometry": {"type": "box", "size": [0.2, 0.2, 0.2]},
               "physics": True},
              {"name": "box", "pose": {"translation": [3.0, 3.0, 0.05]}, "geometry": {"type": "box", "size": [0.1, 0.1, 0.1]},
               "physics": True}]
    sim = Simulation(parse_world({"world_info": {"basic_time_step": 16}, "solids": solids, "robots": [crane]}),
                     precision="exact")
    sim.step()
    assert sim.device("crane/cup").held == "crate"                      # type: ignore[attr-defined]
    sim.landing_ground("box")
    return sim


def test_a_lift_raising_its_platform_and_the_crate_its_cup_holds_moves_their_ground() -> None:
    sim = _crane_world()
    _same_ground(sim)
    assert _rest_height(sim, 0.0, 0.0) == pytest.approx(0.6, abs=1e-12)          # the platform's top, 0.55
    assert _rest_height(sim, 1.08, 0.0) == pytest.approx(1.15, abs=1e-12)        # the crate's top (beside the cup)
    sim.set_solid_pose("box", [3.0, 3.0, 0.05])
    sim.robot("crane").motors["lift"].set_position(0.25)
    for _ in range(10):
        sim.step()
    assert float(sim.robot("crane").motors["lift"].position) == pytest.approx(0.25, abs=1e-12)
    _same_ground(sim)
    _same_ground(sim, "crate", carrier=0)          # the ground under the held crate, its carrier left out
    assert _rest_height(sim, 0.0, 0.0) == pytest.approx(0.85, abs=1e-12)
    assert _rest_height(sim, 1.08, 0.0) == pytest.approx(1.40, abs=1e-12)


def test_a_floor_robot_moved_by_a_supervisor_moves_its_ground() -> None:
    sim = _crane_world()
    sim.robot("crane").set_pose([-2.0, 0.0, 0.0])
    _same_ground(sim)
    assert _rest_height(sim, -2.0, 0.0) == pytest.approx(0.6, abs=1e-12)
    assert _rest_height(sim, 0.0, 0.0) == pytest.approx(0.05, abs=1e-12)


def test_a_wheeled_robot_moved_after_each_change_settles_as_on_a_ground_built_afresh() -> None:
    """test_settle's world of a deck, a table and a driveless robot holding a floor box (its closed forms are
    there): after each change, the settled pose of robot 'r' put at points over all of them is the one a
    ground built from scratch gives, bit for bit."""
    from test_settle import _moves_world, _split
    from test_settle import _sim as settle_sim

    sim = settle_sim(*_split(_moves_world()))
    model = sim.robot("r").model
    points = [(x, y) for x in np.linspace(-3.0, 5.0, 17) for y in np.linspace(-1.0, 5.0, 13)]

    def check() -> None:
        alive = sim.scene.solid_poses
        fresh = settling_ground([(s, alive[s.name]) for s in sim.world.solids if s.name in alive],
                                [(r.model, sim.scene.robot_poses[r.index]) for r in sim.robots.values()
                                 if not r.model.drive_motors], None)
        for x, y in points:
            pose = Pose.from_axis_angle([0, 0, 1], 0.4, [x, y, 0.9])
            kept, built = sim.settled(model, pose), settle_pose(model, pose, fresh, None)
            assert np.array_equal(kept.translation, built.translation) and np.array_equal(kept.rotation, built.rotation)

    check()
    sim.set_solid_pose("deck", [0.5, 0.5, 0.3])
    check()
    sim.robot("keeper").set_pose([4.0, 4.0, 0.1])
    check()
    sim.remove_solid("table")
    check()
    sim.reset()
    check()
    assert sim.settled(model, Pose.from_axis_angle([0, 0, 1], 0.4, [2.1, 0.2, 0.9])).translation[2] > 0.2
