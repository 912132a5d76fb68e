"""An appearance PROTO of Webots' (``projects/appearances/protos/``: SandyGround, Parquetry, ...) whose
file is not on this machine stands in as a plain PBRAppearance (0.5 grey × its colorOverride,
roughness 0.5, metalness 0), with one note, instead of refusing the world: the robot and its devices
load, and a camera and an infra-red sensor read the floor exactly as a world that writes that
PBRAppearance itself. With the PROTO's file found, that file is used; a missing PROTO that is not an
appearance is refused as before. All world and PROTO files here are our own."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from _protos import HEADER, expanded, proto_file

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, load_world
from sensorium.server.world.proto import ProtoError
from sensorium.server.world.proto.resolve import webots_path

RAW = "https://raw.githubusercontent.com/cyberbotics/webots"
SANDY = "webots://projects/appearances/protos/SandyGround.proto"

FLOOR_LOOK = """SandyGround {
        colorOverride 0.5 1 1
        textureTransform TextureTransform { scale 4 4 }
        IBLStrength 2
      }"""
PLAIN_LOOK = "PBRAppearance { baseColor 0.25 0.5 0.5 roughness 0.5 metalness 0 }"   # 0.5 × (0.5 1 1)


def world_text(look: str, decls: list[str] = ()) -> str:
    """A floor (a 4 m plane at z = 0) whose appearance is ``look``, and a robot 0.1 m above it with a
    camera and an infra-red sensor looking straight down."""
    return HEADER + "".join(f'EXTERNPROTO "{u}"\n' for u in decls) + f"""WorldInfo {{ basicTimeStep 16 }}
DirectionalLight {{ direction 0 0 -1 ambientIntensity 1 intensity 0.5 }}
Solid {{
  children [
    Shape {{
      appearance {look}
      geometry Plane {{ size 4 4 }}
    }}
  ]
  boundingObject Plane {{ size 4 4 }}
  name "floor"
}}
Robot {{
  translation 0 0 0.1
  children [
    Camera {{ rotation 0 1 0 1.5707963267948966 name "cam" width 8 height 6 }}
    DistanceSensor {{ rotation 0 1 0 1.5707963267948966 name "ir" type "infra-red" lookupTable [ 0 0 0, 0.5 500 0 ] }}
  ]
  name "bot"
  controller "<none>"
}}
"""


def write(folder: Path, text: str, name: str = "w.wbt") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    p = folder / name
    p.write_text(text)
    return p


def readings(loaded) -> tuple[np.ndarray, float]:
    sim = Simulation(loaded.world, precision="exact")
    cam, ir = sim.device("bot/cam"), sim.device("bot/ir")
    cam.enable(16)
    ir.enable(16)
    sim.run(1)
    return np.array(cam.image), ir.value


def notes(loaded) -> list[str]:
    return [w for w in loaded.warnings if "PROTO files not found" in w]


@pytest.fixture(autouse=True)
def _no_installation(monkeypatch) -> None:
    monkeypatch.delenv("WEBOTS_HOME", raising=False)
    monkeypatch.delenv("SENSORIUM_PROTO_PATH", raising=False)


def test_a_missing_appearance_proto_stands_in_as_a_plain_pbr_appearance(tmp_path: Path) -> None:
    w = write(tmp_path / "stand_in", world_text(FLOOR_LOOK, [SANDY]))
    loaded = load_world(w)
    (robot,) = loaded.world.robots
    assert robot.name == "bot" and sorted(d.name for d in robot.devices) == ["cam", "ir"]
    assert notes(loaded) == [
        f"{w}:2:1: PROTO files not found: plain PBRAppearances stand in for the appearances SandyGround (0.5 grey × "
        "its colorOverride or baseColor, other fields ignored: cameras and infra-red distance sensors see that colour, not the texture; "
        "lidars, range finders and other distance sensors are unaffected) (give --webots-home or WEBOTS_HOME to use "
        "Webots' own)"]
    assert [x for x in loaded.warnings if "SandyGround" in x] == notes(loaded)     # its other fields: no word
    # the camera and the infra-red sensor see exactly what a world writing the PBRAppearance sees
    plain = load_world(write(tmp_path / "plain", world_text(PLAIN_LOOK)))
    image, ir = readings(loaded)
    want_image, want_ir = readings(plain)
    assert image.tobytes() == want_image.tobytes() and ir == want_ir
    # (closed form for the sensor: 0.1 m over red 0.25, roughness 0.5: D / (0.2 + 0.8 · 0.25 · 0.75) → 500 · D' / 0.5)
    assert ir == pytest.approx(1000.0 * 0.1 / (0.2 + 0.8 * 0.25 * 0.75), rel=1e-9)
    # and not what a white floor gives (the colour is the instance's, scaled)
    white = load_world(write(tmp_path / "white", world_text("PBRAppearance { roughness 0.5 metalness 0 }")))
    assert readings(white)[0].tobytes() != image.tobytes()


def test_the_stand_in_is_listed_as_a_built_in_stand_in(tmp_path: Path) -> None:
    w = write(tmp_path, world_text(FLOOR_LOOK, [SANDY]))
    (use,) = [u for u in expanded(w).protos if u.name == "SandyGround"]
    assert use.builtin and use.instances == 1 and use.path == "" and use.url == SANDY
    assert use.license == "Sensorium's built-in stand-in: a plain PBRAppearance (no Webots file used)"
    shapes = [n for n in expanded(w).nodes if n.type == "Solid"][0].fields["children"]
    look = shapes[0].fields["appearance"]
    assert (look.type, look.proto, look.fields) == ("PBRAppearance", "SandyGround", {
        "baseColor": (0.25, 0.5, 0.5), "roughness": 0.5, "metalness": 0.0})


def test_the_real_file_is_used_when_it_is_found(tmp_path: Path) -> None:
    # our own SandyGround in a --proto-path tree laid out as Webots' (projects/appearances/protos)
    tree = tmp_path / "assets"
    proto_file(tree / "projects" / "appearances" / "protos", "SandyGround",
               "[ field SFColor colorOverride 1 1 1 field SFNode textureTransform NULL field SFFloat IBLStrength 1 ] "
               "{ PBRAppearance { baseColor IS colorOverride roughness 1 metalness 0 IBLStrength IS IBLStrength "
               "textureTransform IS textureTransform } }")
    w = write(tmp_path / "worlds", world_text(FLOOR_LOOK, [SANDY]))
    loaded = load_world(w, proto_path=[tree])
    assert notes(loaded) == []
    (use,) = [u for u in expanded(w, proto_path=[tree]).protos if u.name == "SandyGround"]
    assert not use.builtin and use.path == str(tree / "projects/appearances/protos/SandyGround.proto")
    ir = readings(loaded)[1]
    assert ir == pytest.approx(1000.0 * 0.1 / (0.2 + 0.8 * 0.5 * 0.5), rel=1e-9)     # its red 0.5, roughness 1


@pytest.mark.parametrize("url", [f"{RAW}/R2023b/projects/appearances/protos/SandyGround.proto",
                                 f"{RAW}/R2025a/projects/appearances/protos/SandyGround.proto",
                                 "webots://projects/appearances/protos/SandyGround.proto"])
def test_webots_and_raw_github_urls_of_any_tag_are_recognised(tmp_path: Path, url: str) -> None:
    loaded = load_world(write(tmp_path, world_text(FLOOR_LOOK, [url])))
    assert len(notes(loaded)) == 1 and loaded.world.robots[0].name == "bot"


def test_a_missing_proto_that_is_not_an_appearance_is_refused_as_before(tmp_path: Path) -> None:
    # a robot's PROTO, a PROTO of another folder used as an appearance, a local file of the same name
    for url, body in [("webots://projects/robots/acme/protos/AcmeBot.proto", "AcmeBot { }\n"),
                      ("webots://projects/objects/floors/protos/Sandy.proto", world_text("Sandy { }")[len(HEADER):]),
                      ("protos/SandyGround.proto", world_text(FLOOR_LOOK)[len(HEADER):])]:
        name = url.rsplit("/", 1)[1][:-6]
        w = write(tmp_path, HEADER + f'EXTERNPROTO "{url}"\n' + body)
        with pytest.raises(WorldError, match=rf'EXTERNPROTO {name}: "{url}" not found'):
            load_world(w)


def test_stand_in_colours_and_bad_values(tmp_path: Path) -> None:
    # no colorOverride: 0.5 grey; a colour outside [0, 1] is clamped with a line, as Webots clamps it
    w = write(tmp_path, world_text("SandyGround { }", [SANDY]))
    look = [n for n in expanded(w).nodes if n.type == "Solid"][0].fields["children"][0].fields["appearance"]
    assert look.fields["baseColor"] == (0.5, 0.5, 0.5)
    w = write(tmp_path, world_text("SandyGround { colorOverride 2 0.5 -1 }", [SANDY]))
    exp = expanded(w)
    look = [n for n in exp.nodes if n.type == "Solid"][0].fields["children"][0].fields["appearance"]
    assert look.fields["baseColor"] == (0.5, 0.25, 0.0)
    assert f"{w}:8:32: SandyGround.colorOverride: 2 0.5 -1 is outside [0, 1]; using 1 0.5 0 (as Webots does)" in exp.warnings
    # a paint's colour is its baseColor (MattePaint, GlossyCarPaint, ...)
    w = write(tmp_path, world_text("MattePaint { baseColor 0.2 0.4 1 }", ["webots://projects/appearances/protos/MattePaint.proto"]))
    look = [n for n in expanded(w).nodes if n.type == "Solid"][0].fields["children"][0].fields["appearance"]
    assert (look.proto, look.fields["baseColor"]) == ("MattePaint", (0.1, 0.2, 0.5))
    # a colorOverride that is no colour: one line naming it
    w = write(tmp_path, world_text('SandyGround { colorOverride "red" }', [SANDY]))
    with pytest.raises(ProtoError, match=r':8:32: SandyGround.colorOverride: SFColor expects'):
        expanded(w)


def test_a_stand_in_inside_a_found_proto_and_as_its_field_value(tmp_path: Path) -> None:
    # our own robot PROTO (found) whose body uses an appearance PROTO that is not: relative to the url the
    # robot's file stands for, and passed in through a field restricted to PBRAppearance
    tree = tmp_path / "assets"
    proto_file(tree / "projects" / "robots" / "acme" / "protos", "AcmeBot",
               "[ field SFNode{PBRAppearance { }} look PBRAppearance { } ] { Robot { name \"acme\" children [ "
               "Shape { appearance Parquetry { colorOverride 1 0 0 } geometry Box { size 0.1 0.1 0.1 } } "
               "Shape { appearance IS look geometry Sphere { radius 0.05 } } ] } }",
               header='EXTERNPROTO "../../../appearances/protos/Parquetry.proto"\n')
    w = write(tmp_path / "worlds", HEADER + 'EXTERNPROTO "webots://projects/robots/acme/protos/AcmeBot.proto"\n'
              f'EXTERNPROTO "{SANDY}"\nAcmeBot {{ look SandyGround {{ colorOverride 0 1 0 }} }}\n')
    exp = expanded(w, proto_path=[tree])
    looks = [s.fields["appearance"] for s in exp.nodes[0].fields["children"]]
    assert [(a.type, a.proto, a.fields["baseColor"]) for a in looks] == [
        ("PBRAppearance", "Parquetry", (0.5, 0.0, 0.0)), ("PBRAppearance", "SandyGround", (0.0, 0.5, 0.0))]
    (note,) = [x for x in exp.warnings if "PROTO files not found" in x]
    assert "stand in for the appearances Parquetry, SandyGround (" in note


def test_webots_path() -> None:
    assert webots_path(SANDY, "/w/w.wbt") == "projects/appearances/protos/SandyGround.proto"
    assert webots_path(f"{RAW}/R2023b/projects/x/A.proto", "/w/w.wbt") == "projects/x/A.proto"
    assert webots_path("../../appearances/protos/B.proto", "webots://projects/robots/x/A.proto") == \
        "projects/appearances/protos/B.proto"
    assert webots_path("B.proto", f"{RAW}/R2023b/projects/robots/x/A.proto") == "projects/robots/x/B.proto"
    assert webots_path("protos/B.proto", "/w/w.wbt") is None
    assert webots_path("https://example.com/projects/appearances/protos/B.proto", "/w/w.wbt") is None
    assert webots_path("webots://../../etc/B.proto", "/w/w.wbt") is None


def test_a_supervisor_sees_the_plain_pbr_appearance_named_by_its_proto(tmp_path: Path) -> None:
    from sensorium.server.daemon import supervisor as sv

    w = write(tmp_path, world_text("DEF LOOK " + FLOOR_LOOK, [SANDY]))
    sim = Simulation(load_world(w))
    look = sv.find_node(sim, "LOOK")
    assert (look.proto, look.type) == ("SandyGround", "PBRAppearance")
    assert sv.get_field(sim, look, "baseColor")["value"] == [0.25, 0.5, 0.5]     # its fields are the PBRAppearance's
    assert sv.get_field(sim, look, "roughness")["value"] == 0.5
    with pytest.raises(ValueError, match="has no field 'colorOverride' here"):
        sv.set_field(sim, look, "colorOverride", [1.0, 0.0, 0.0])


def test_validate_accepts_the_world_and_info_lists_the_stand_in(tmp_path: Path, capsys) -> None:
    from sensorium.cli import main as cli

    w = write(tmp_path, world_text(FLOOR_LOOK, [SANDY]))
    assert cli(["validate", str(w)]) == 0
    captured = capsys.readouterr()
    assert f"{w}: OK" in captured.out and "stand in for the appearances SandyGround" in captured.err
    assert cli(["info", str(w)]) == 0
    assert (f"proto     SandyGround x1: Sensorium's built-in stand-in: a plain PBRAppearance (no Webots file used) "
            f"({SANDY})") in capsys.readouterr().out
