"""A PROTO file written before R2022a (y up) is said to be (up to R2021b its body is converted at each
instance, as Webots does; an R2021c one is read as written, as by Webots);
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
    # a camera alone places nothing by a field, yet Webots' conversion turns it: said
    (tmp_path / "Eye.proto").write_text('#VRML_SIM R2021b utf8\nPROTO Eye [ ]\n{ Camera { name "eye" } }\n')
    world = tmp_path / "w.wbt"
    world.write_text('#VRML_SIM R2023b utf8\nEXTERNPROTO "Lights.proto"\nEXTERNPROTO "Post.proto"\n'
                     'EXTERNPROTO "Eye.proto"\nRobot { name "car" controller "<extern>" children [ Lights { } Eye { } ] }\n'
                     'Post { translation 1 0 0 }\n')
    w = load_world(world)
    said = sorted(x for x in w.warnings if "before R2022a" in x)
    assert len(said) == 2 and "PROTO Eye was written for Webots R2021b" in said[0], said
    assert "PROTO Post was written for Webots R2021b" in said[1], said
    assert [d.name for d in w.world.robots[0].devices] == ["front_lights", "eye"]


def test_a_proto_without_a_header_loads_as_a_current_one(tmp_path: Path) -> None:
    """Webots needs the header line of worlds only: a PROTO file without one (Webots' tutorial
    FourWheelsRobot.proto once had none) is read with a warning, as a z-up PROTO; it was refused."""
    (tmp_path / "Rover.proto").write_text(
        "PROTO Rover [ field SFVec3f translation 0 0 0 field SFString name \"rover\" ]\n"
        "{ Robot { translation IS translation name IS name controller \"<extern>\" children [\n"
        "  DistanceSensor { translation 0.1 0 0 name \"front\" } ] } }\n")
    # a leading comment that is not a header: still read; its comments are the header's (JavaScript template)
    (tmp_path / "Pair.proto").write_text(
        "# template language: javascript\nPROTO Pair [ field SFInt32 count 2 ]\n"
        "{ Robot { name \"pair\" controller \"<extern>\" children [\n"
        "%< for (let i = 0; i < fields.count.value; ++i) { >%\n"
        "  DistanceSensor { name \"ds%<= i >%\" }\n%< } >%\n] } }\n")
    world = tmp_path / "w.wbt"
    world.write_text('#VRML_SIM R2023b utf8\nEXTERNPROTO "Rover.proto"\nEXTERNPROTO "Pair.proto"\n'
                     "Rover { translation 0.3 -0.2 0.1 }\nPair { count 3 }\n")
    w = load_world(world)
    rover, pair = w.world.robots
    assert rover.name == "rover" and rover.pose.translation == (0.3, -0.2, 0.1)
    assert [d.name for d in rover.devices] == ["front"]
    assert [d.name for d in pair.devices] == ["ds0", "ds1", "ds2"]
    said = [x for x in w.warnings if "no '#VRML_SIM R20xxy utf8' header" in x]
    assert len(said) == 2 and any("Rover.proto:1:1: PROTO Rover" in x for x in said), w.warnings
    assert not any("before R2022a" in x for x in w.warnings)
