"""A PROTO file written before R2022a (y up) is said to be, since its poses may come out wrong here;
one whose body places nothing along an axis (Webots' VehicleLights: LEDs in a Group, its header
R2021b) has no pose to get wrong, and no longer gets the line."""

from __future__ import annotations

from pathlib import Path

from sensorium.server.world.loader import load_world


def test_an_old_proto_is_said_only_when_it_places_something(tmp_path: Path) -> None:
    (tmp_path / "Lights.proto").write_text(
        "#VRML_SIM R2021b utf8\n# a rotation in a comment places nothing\n"
        "PROTO Lights [ field MFNode front [ ] ]\n"
        "{ Group { children [ LED { children IS front name \"front_lights\" color [ 0.5 0.5 0.5 ] } ] } }\n")
    (tmp_path / "Post.proto").write_text(
        "#VRML_SIM R2021b utf8\nPROTO Post [ field SFVec3f translation 0 0 0 ]\n"
        "{ Solid { translation IS translation children [ Shape { geometry Cylinder { height 1 radius 0.05 } } ] } }\n")
    world = tmp_path / "w.wbt"
    world.write_text('#VRML_SIM R2023b utf8\nEXTERNPROTO "Lights.proto"\nEXTERNPROTO "Post.proto"\n'
                     'Robot { name "car" controller "<extern>" children [ Lights { } ] }\nPost { translation 1 0 0 }\n')
    w = load_world(world)
    said = [x for x in w.warnings if "before R2022a" in x]
    assert len(said) == 1 and "PROTO Post was written for Webots R2021b" in said[0], said
    assert [d.name for d in w.world.robots[0].devices] == ["front_lights"]
