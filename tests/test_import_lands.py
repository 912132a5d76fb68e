"""A solid with ``physics`` a Supervisor imports (``importMFNodeFromString``) falls onto what is under
it from the time it is imported (sim/falling.py), as Webots' physics drops it: the user guide's
tutorial 8 imports a ball 1 m up and turns it red once ``getPosition()`` reads it below 0.2.
Closed forms: its centre at z0 − g t²/2 after t; a sphere of radius r over the floor plane at z 0 rests
at z = r; a cube of side s over a table whose top is at z 0.5 rests at 0.5 + s/2; one without physics
stays where it is imported; nodes of one string land in their order, one over another on it."""

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


def _fallen(sim, steps=40):
    for _ in range(steps):
        if not sim.falls:
            return
        sim.step()
    assert not sim.falls


def _ball(name, x, y, z, physics):
    return (f'Solid {{ translation {x} {y} {z} name "{name}" children [ Shape {{ geometry DEF G Sphere {{ radius 0.2 }} }} ] '
            f'boundingObject USE G {"physics Physics { }" if physics else ""} }}')


def test_an_imported_ball_with_physics_falls_onto_the_floor_and_one_without_stays(tmp_path):
    sim = _world(tmp_path)
    sim.step()
    sim.import_nodes(_ball("ball", 0, 1, 1, True) + " " + _ball("balloon", 0, -1, 1, False))
    assert _z(sim, "ball") == 1.0                                   # imported where the string puts it
    assert sim.initial_solid_pose("ball").translation[2] == pytest.approx(0.2, abs=1e-12)    # where it rests
    # 0.8 m of fall at 9.81 m/s²: 0.404 s, at rest after 13 steps of 32 ms
    for k in range(1, 13):
        sim.step()
        t = k * 0.032
        assert _z(sim, "ball") == pytest.approx(1.0 - 9.81 * t * t / 2.0, abs=1e-12), k
    sim.step()
    assert _z(sim, "ball") == pytest.approx(0.2, abs=1e-12)         # its radius: resting on the floor
    assert list(sim.scene.solid_poses["ball"].translation[:2]) == [0.0, 1.0]
    assert _z(sim, "balloon") == 1.0                                # no physics: no fall (Webots too)
    sim.step()
    assert _z(sim, "ball") == pytest.approx(0.2, abs=1e-12) and not sim.falls


def test_an_imported_box_lands_on_the_table_under_it_and_a_proto_ball_at_its_radius(tmp_path):
    sim = _world(tmp_path)
    sim.import_nodes('Solid { translation 2.1 -0.2 3 name "cube" children [ Shape { geometry DEF C Box { size 0.2 0.2 0.2 } } ] '
                     'boundingObject USE C physics Physics { } }')
    _fallen(sim)
    assert _z(sim, "cube") == pytest.approx(0.6, abs=1e-12)         # the table's top 0.5 + half its side
    sim.import_nodes("DEF P Pellet { translation -1 0 1 }")
    _fallen(sim)
    assert _z(sim, "pellet") == pytest.approx(0.03, abs=1e-12)      # the PROTO's radius
    # a ball imported under the table top (below the middle of its height) lands on the floor beneath
    sim.import_nodes(_ball("low", 2, 0, 0.3, True))
    _fallen(sim)
    assert _z(sim, "low") == pytest.approx(0.2, abs=1e-12)


def test_boxes_of_one_string_land_in_their_order_one_on_another(tmp_path):
    """Two 0.2 m cubes over the floor, the second 1 m above the first: both fall together, the lower one
    rests on the floor and the upper one on it (where it rests, not where it was imported)."""
    sim = _world(tmp_path)
    cube = ('Solid {{ translation -1 0 {z} name "{n}" children [ Shape {{ geometry DEF C Box {{ size 0.2 0.2 0.2 }} }} ] '
            'boundingObject USE C physics Physics {{ }} }}')
    sim.import_nodes(cube.format(z=1.0, n="low") + " " + cube.format(z=2.0, n="high"))
    sim.step()
    assert _z(sim, "high") - _z(sim, "low") == pytest.approx(1.0, abs=1e-12)    # falling together
    _fallen(sim, 60)
    assert _z(sim, "low") == pytest.approx(0.1, abs=1e-12) and _z(sim, "high") == pytest.approx(0.3, abs=1e-12)
