"""A solid with ``physics`` a Supervisor imports (``importMFNodeFromString``) lands at once on what is
under it, as one the world file places in the air settles at load (Webots' physics drops it): the user
guide's tutorial 8 imports a ball 1 m up and turns it red once ``getPosition()`` reads it below 0.2.
Closed forms: a sphere of radius r over the floor plane at z 0 rests at z = r; a cube of side s over a
table whose top is at z 0.5 rests at 0.5 + s/2; one without physics stays where it is imported."""

from __future__ import annotations

import pytest
from _protos import HEADER, proto_file

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world


def _world(folder):
    proto_file(folder / "protos", "Pellet", "[ field SFVec3f translation 0 0 0.1 field SFString name \"pellet\" "
               "field SFColor color 1 0.5 0 field SFFloat radius 0.03 ] { Solid { translation IS translation "
               "name IS name children [ DEF S Shape { appearance PBRAppearance { baseColor IS color } "
               "geometry Sphere { radius IS radius } } ] boundingObject USE S physics Physics { } } }")
    world = folder / "w.wbt"
    world.write_text(HEADER + 'IMPORTABLE EXTERNPROTO "protos/Pellet.proto"\n'
                     'WorldInfo { basicTimeStep 32 }\n'
                     'Solid { name "floor" boundingObject Plane { size 10 10 } }\n'
                     'Solid { translation 2 0 0.45 name "table" children [ Shape { geometry Box { size 1 1 0.1 } } ] '
                     'boundingObject Box { size 1 1 0.1 } }\n'
                     'Robot { name "boss" supervisor TRUE controller "<extern>" }\n')
    return Simulation(load_world(world))


def _z(sim, name):
    return float(sim.scene.solid_poses[name].translation[2])


def _ball(name, x, y, z, physics):
    return (f'Solid {{ translation {x} {y} {z} name "{name}" children [ Shape {{ geometry DEF G Sphere {{ radius 0.2 }} }} ] '
            f'boundingObject USE G {"physics Physics { }" if physics else ""} }}')


def test_an_imported_ball_with_physics_lands_on_the_floor_and_one_without_stays(tmp_path):
    sim = _world(tmp_path)
    sim.step()
    sim.import_nodes(_ball("ball", 0, 1, 1, True) + " " + _ball("balloon", 0, -1, 1, False))
    assert _z(sim, "ball") == pytest.approx(0.2, abs=1e-12)         # its radius: resting on the floor
    assert list(sim.scene.solid_poses["ball"].translation[:2]) == [0.0, 1.0]
    assert _z(sim, "balloon") == 1.0                                # no physics: no fall (Webots too)
    assert sim.initial_solid_pose("ball").translation[2] == pytest.approx(0.2, abs=1e-12)
    sim.step()
    assert _z(sim, "ball") == pytest.approx(0.2, abs=1e-12)


def test_an_imported_box_lands_on_the_table_under_it_and_a_proto_ball_at_its_radius(tmp_path):
    sim = _world(tmp_path)
    sim.import_nodes('Solid { translation 2.1 -0.2 3 name "cube" children [ Shape { geometry DEF C Box { size 0.2 0.2 0.2 } } ] '
                     'boundingObject USE C physics Physics { } }')
    assert _z(sim, "cube") == pytest.approx(0.6, abs=1e-12)         # the table's top 0.5 + half its side
    sim.import_nodes("DEF P Pellet { translation -1 0 1 }")
    assert _z(sim, "pellet") == pytest.approx(0.03, abs=1e-12)      # the PROTO's radius
    # a ball imported under the table top (below the middle of its height) lands on the floor beneath
    sim.import_nodes(_ball("low", 2, 0, 0.3, True))
    assert _z(sim, "low") == pytest.approx(0.2, abs=1e-12)
