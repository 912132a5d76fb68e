"""Where PROTO files (and assets) are found, never downloading: relative to the declaring file,
siblings by bare file name, ``webots://`` and raw.githubusercontent.com urls against a fake Webots
installation (WEBOTS_HOME) and proto_path folders (a tree, Webots' asset-cache layout, a project's
protos/), built-in stand-ins, and the one-line message when a file is nowhere."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest
from _protos import HEADER, expanded, proto_file, webots_home, world_file

from sensorium.server.world.loader import WorldError, load_world
from sensorium.server.world.proto import ProtoError, ProtoSearch, asset_roots, resolve_url
from sensorium.server.world.proto.resolve import logical_location

RAW = "https://raw.githubusercontent.com/cyberbotics/webots"


def fake_webots(root: Path, version: str = "R2023b") -> Path:
    """A Webots installation tree: a robot PROTO using a sibling by bare name and a webots:// device."""
    protos = root / "projects" / "robots" / "acme" / "bot" / "protos"
    proto_file(protos, "AcmeBot", """[ field SFString name "acme" field MFNode extensionSlot [ ] ]
{ Robot { name IS name children [ AcmeEye { } Group { children IS extensionSlot } ] } }""",
               header='EXTERNPROTO "AcmeEye.proto"\n')
    proto_file(protos, "AcmeEye", "[ ] { LightSensor { name \"eye\" } }")
    devices = root / "projects" / "devices" / "acme" / "protos"
    proto_file(devices, "AcmeRanger", "[ ] { DistanceSensor { name \"ranger\" } }")
    return webots_home(root, version=version)


def test_webots_and_raw_github_urls_map_to_the_installation(tmp_path: Path, monkeypatch) -> None:
    home = fake_webots(tmp_path / "webots")
    monkeypatch.setenv("WEBOTS_HOME", str(home))
    w = world_file(tmp_path / "project" / "worlds", 'AcmeBot { extensionSlot [ AcmeRanger { } ] }\n', [
        f"{RAW}/R2023b/projects/robots/acme/bot/protos/AcmeBot.proto",
        "webots://projects/devices/acme/protos/AcmeRanger.proto"])
    (robot,) = load_world(w).world.robots
    assert [d.name for d in robot.devices] == ["eye", "ranger"]
    uses = {u.name: u.path for u in expanded(w).protos}
    assert uses == {"AcmeBot": str(home / "projects/robots/acme/bot/protos/AcmeBot.proto"),
                    "AcmeEye": str(home / "projects/robots/acme/bot/protos/AcmeEye.proto"),
                    "AcmeRanger": str(home / "projects/devices/acme/protos/AcmeRanger.proto")}


def test_explicit_webots_home_and_macos_bundle(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.delenv("WEBOTS_HOME", raising=False)
    app = tmp_path / "Webots.app"
    fake_webots(app / "Contents")
    w = world_file(tmp_path, "AcmeRanger { }\n", ["webots://projects/devices/acme/protos/AcmeRanger.proto"])
    with pytest.raises(WorldError, match="not found"):
        load_world(w)
    robot_less = expanded(w, webots_home=app).nodes
    assert robot_less[0].type == "DistanceSensor"
    assert asset_roots(ProtoSearch.create(tmp_path, app)) == [(app / "Contents").resolve()]


def test_a_different_installed_version_is_noted(tmp_path: Path) -> None:
    home = fake_webots(tmp_path / "webots", version="R2025a")
    w = world_file(tmp_path, "AcmeRanger { }\n", ["webots://projects/devices/acme/protos/AcmeRanger.proto"])
    notes = [x for x in expanded(w, webots_home=home).warnings if "installation" in x]
    assert notes == [f"{w}: PROTOs of Webots R2023b are read from the Webots R2025a installation at {home} "
                     "(its PROTOs may differ from R2023b's)"]


def test_relative_and_sibling_urls(tmp_path: Path) -> None:
    lib = tmp_path / "lib" / "protos"
    proto_file(lib, "Wheel", "[ ] { Solid { name \"wheel\" } }")
    proto_file(lib, "Cart", "[ ] { Group { children [ Wheel { } Wheel { } ] } }", header='EXTERNPROTO "Wheel.proto"\n')
    w = world_file(tmp_path / "worlds", "Cart { }\n", ["../lib/protos/Cart.proto"])
    assert [s.name for s in load_world(w).world.solids] == ["wheel", "wheel(1)"]


def test_proto_path_tree_cache_layout_and_project_protos(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.delenv("WEBOTS_HOME", raising=False)
    # 1. a folder holding a copy of Webots' tree
    tree = fake_webots(tmp_path / "copy")
    # 2. Webots' asset-cache layout (an unpacked assets-R2023b.zip): files named by the SHA-1 of their raw url;
    #    the PROTO's relative EXTERNPROTO and mesh urls resolve against that url
    cache = tmp_path / "assets-R2023b"
    cache.mkdir()
    url = f"{RAW}/R2023b/projects/objects/acme/protos/Crate.proto"
    sibling = f"{RAW}/R2023b/projects/objects/acme/protos/Lid.proto"
    mesh = f"{RAW}/R2023b/projects/objects/acme/protos/meshes/crate.obj"
    (cache / hashlib.sha1(url.encode()).hexdigest()).write_text(
        HEADER + 'EXTERNPROTO "Lid.proto"\nPROTO Crate [ ] { Group { children [ Lid { } ] } }\n')
    (cache / hashlib.sha1(sibling.encode()).hexdigest()).write_text(HEADER + 'PROTO Lid [ ] { Solid { name "lid" } }\n')
    (cache / hashlib.sha1(mesh.encode()).hexdigest()).write_text("v 0 0 0\n")
    # 3. a project's protos/ folder: found by file name, however deep
    proto_file(tmp_path / "project" / "protos" / "deep" / "er", "Shelf", "[ ] { Solid { name \"shelf\" } }")
    w = world_file(tmp_path / "w", "AcmeRanger { }\nCrate { }\nShelf { }\n", [
        "webots://projects/devices/acme/protos/AcmeRanger.proto",
        "webots://projects/objects/acme/protos/Crate.proto",
        "https://example.org/users/someone/Shelf.proto"])
    search = dict(proto_path=[tree, cache, tmp_path / "project" / "protos"])
    nodes = expanded(w, **search).nodes
    assert [n.type for n in nodes] == ["DistanceSensor", "Group", "Solid"]
    assert nodes[1].fields["children"][0].fields["name"] == "lid" and nodes[2].fields["name"] == "shelf"
    # an asset named relative to the cached PROTO resolves to its cached file too
    crate = cache / hashlib.sha1(url.encode()).hexdigest()
    assert logical_location(crate) == url
    s = ProtoSearch.create(w.parent, proto_path=search["proto_path"], version="R2023b")
    assert resolve_url("meshes/crate.obj", crate, s) == cache / hashlib.sha1(mesh.encode()).hexdigest()
    # the same through the environment variable the CLI flags set
    monkeypatch.setenv("SENSORIUM_PROTO_PATH", f"{tree}:{cache}:{tmp_path / 'project' / 'protos'}")
    assert [n.type for n in expanded(w).nodes] == ["DistanceSensor", "Group", "Solid"]


def test_meshes_in_webots_asset_cache_are_read(tmp_path: Path, monkeypatch) -> None:
    # a cached file has no suffix (its name is the SHA-1 of its url): its format is read from its
    # first bytes; the world was refused ("unsupported mesh format ''")
    import struct

    monkeypatch.delenv("WEBOTS_HOME", raising=False)
    cache = tmp_path / "assets-R2023b"
    cache.mkdir()
    base = f"{RAW}/R2023b/projects/objects/acme/protos"
    (cache / hashlib.sha1(f"{base}/Crate.proto".encode()).hexdigest()).write_text(
        HEADER + 'PROTO Crate [ ] { Solid { name "crate" children [ Shape { geometry Mesh { url "meshes/crate.obj" } } '
        'Pose { translation 0 0 1 children [ Shape { geometry Mesh { url "meshes/lid.stl" } } ] } ] } }\n')
    (cache / hashlib.sha1(f"{base}/meshes/crate.obj".encode()).hexdigest()).write_text(
        "# a tetrahedron\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")
    triangle = struct.pack("<12f", 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 2, 0) + b"\0\0"     # binary STL: one triangle
    (cache / hashlib.sha1(f"{base}/meshes/lid.stl".encode()).hexdigest()).write_bytes(
        b"solid header that is not ascii".ljust(80, b" ") + struct.pack("<I", 1) + triangle)
    w = world_file(tmp_path / "w", "Crate { }\n", ["webots://projects/objects/acme/protos/Crate.proto"])
    loaded = load_world(w, proto_path=[cache])
    assert not loaded.report.losses
    (crate,) = loaded.world.solids
    assert [s.pose.translation for s in crate.shapes] == [(0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]
    from sensorium.server.sim.simulation import Simulation
    from sensorium.server.world.meshes import load_mesh

    Simulation(loaded)                  # the scene reads the same files

    obj, stl = (load_mesh(s.geometry.url) for s in crate.shapes)
    assert (len(obj.faces), len(stl.faces)) == (4, 1)
    assert stl.vertices.max(axis=0).tolist() == [2.0, 2.0, 0.0]
    # a cached file that is no mesh is one line naming the url
    lid = cache / hashlib.sha1(f"{base}/meshes/lid.stl".encode()).hexdigest()
    lid.write_bytes(b"\x00\x01 not a mesh")
    with pytest.raises(WorldError) as exc:
        load_world(w, proto_path=[cache])
    assert str(exc.value).startswith(f"{w}: line 3, column 1 (Mesh of PROTO Crate, converted as solids[0].shapes[1]."
                                     f"geometry.url): mesh file {lid} has no suffix and is not a mesh format read here")


def test_cache_log_names_the_urls(tmp_path: Path) -> None:
    """A cache folder's log.txt ('HASH URL' lines, as Webots writes it) tells what a file stands for."""
    cache = tmp_path / "assets"
    cache.mkdir()
    url = f"{RAW}/R2023b/projects/x/protos/Y.proto"
    h = hashlib.sha1(url.encode()).hexdigest()
    (cache / h).write_text("x")
    (cache / "log.txt").write_text(f"Cache generated with tag R2023b\n\n{h} {url}\n")
    assert logical_location(cache / h) == url


def test_missing_file_is_one_line_naming_url_places_tag_and_remedy(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.delenv("WEBOTS_HOME", raising=False)
    monkeypatch.delenv("SENSORIUM_PROTO_PATH", raising=False)
    home = fake_webots(tmp_path / "webots")
    w = world_file(tmp_path, "Nope { }\n", [f"{RAW}/R2023a/projects/robots/nope/protos/Nope.proto"])
    with pytest.raises(ProtoError) as exc:
        expanded(w, webots_home=home, proto_path=[tmp_path / "extra"])
    msg = str(exc.value)
    assert "\n" not in msg and msg.startswith(f"{w}:2:1: EXTERNPROTO Nope: ")
    assert f'"{RAW}/R2023a/projects/robots/nope/protos/Nope.proto" not found (Webots R2023a)' in msg
    assert f"looked in: {home}/projects/robots/nope/protos/Nope.proto, {tmp_path}/extra/projects/robots/nope/protos/Nope.proto" in msg
    assert "nothing is downloaded" in msg and "--webots-home" in msg and "WEBOTS_HOME" in msg and "--proto-path" in msg
    # without any installation, the message says so
    with pytest.raises(ProtoError, match="looked in: nothing .no Webots installation, no --proto-path folder.*WEBOTS_HOME is not set"):
        expanded(w)


def test_a_mistyped_webots_home_is_named_in_the_missing_file_line(tmp_path: Path, monkeypatch) -> None:
    """--webots-home /usr/local/webot (a typo) made the line say "give --webots-home DIR" to a user who
    had given one: it now says what is wrong with the one given; a real installation adds nothing."""
    monkeypatch.delenv("SENSORIUM_PROTO_PATH", raising=False)
    w = world_file(tmp_path, "Gone { }\n", ["webots://projects/robots/gone/protos/Gone.proto"])
    typo = tmp_path / "webot"
    with pytest.raises(ProtoError) as exc:
        expanded(w, webots_home=typo)
    assert f"nothing is downloaded: the Webots installation given (--webots-home or WEBOTS_HOME) {typo} is not a " \
           "folder; give --webots-home DIR" in str(exc.value)
    (tmp_path / "notwebots").mkdir()
    with pytest.raises(ProtoError, match="notwebots has no projects/ folder, so it is no Webots installation; give"):
        expanded(w, webots_home=tmp_path / "notwebots")
    with pytest.raises(ProtoError) as exc:
        expanded(w, webots_home=fake_webots(tmp_path / "webots"))
    assert "the Webots installation given" not in str(exc.value)
    assert "nothing is downloaded: give --webots-home DIR" in str(exc.value)


def test_missing_relative_file_names_the_place(tmp_path: Path) -> None:
    w = world_file(tmp_path, "Gone { }\n", ["protos/Gone.proto"])
    with pytest.raises(ProtoError, match=rf'"protos/Gone.proto" not found \(Webots R2023b\); looked in: {tmp_path}/protos/Gone.proto'):
        expanded(w)


def test_builtin_stand_ins_when_the_file_is_missing_and_the_real_one_when_found(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.delenv("WEBOTS_HOME", raising=False)
    body = "RectangleArena { floorSize 2 2 }\nTexturedBackground { }\n"
    decls = [f"{RAW}/R2023b/projects/objects/floors/protos/RectangleArena.proto",
             f"{RAW}/R2023b/projects/objects/backgrounds/protos/TexturedBackground.proto"]
    w = world_file(tmp_path, body, decls)
    loaded = load_world(w)
    assert loaded.world.solids[0].name == "rectangle arena"
    notes = [x for x in loaded.warnings if "PROTO files not found" in x]
    assert notes == [f"{w}:2:1: PROTO files not found: Sensorium's built-in stand-ins used for RectangleArena; "
                     "TexturedBackground skipped (cameras see the flat sky colour, not its sky box) (give --webots-home or WEBOTS_HOME to "
                     "use Webots' own)"]
    uses = {u.name: u for u in expanded(w).protos}
    assert uses["RectangleArena"].builtin and uses["RectangleArena"].license.startswith("Sensorium's built-in stand-in")
    # with an installation holding a (our own) RectangleArena, that file is used
    home = tmp_path / "webots"
    proto_file(home / "projects" / "objects" / "floors" / "protos", "RectangleArena",
               "[ field SFVec2f floorSize 1 1 ] { Solid { name \"real arena\" } }")
    loaded = load_world(w, webots_home=home)
    assert loaded.world.solids[0].name == "real arena"
    assert not [x for x in loaded.warnings if "RectangleArena" in x]
    # an installation was given but does not hold TexturedBackground: the note says where it looked
    # (it used to ask for the --webots-home the user had just given)
    notes = [x for x in loaded.warnings if "PROTO files not found" in x]
    assert notes == [f"{w}:3:1: PROTO files not found: TexturedBackground skipped (cameras see the flat sky colour, not its sky box) (not in "
                     f"the Webots installation {home} nor the --proto-path folders: a complete installation (or "
                     "--proto-path) gives Webots' own)"]


def test_unused_declarations_that_are_missing_are_a_warning(tmp_path: Path) -> None:
    w = world_file(tmp_path, "Solid { }\n", ["protos/Unused.proto"])
    (tmp_path / "w2").mkdir()
    warnings = expanded(w).warnings
    assert len(warnings) == 1 and warnings[0].startswith(f"{w}:2:1: EXTERNPROTO Unused (not used by the world): ")
    w.write_text(HEADER + 'IMPORTABLE EXTERNPROTO "protos/Unused.proto"\nSolid { }\n')
    assert expanded(w).warnings == []


def test_resolve_url_for_assets(tmp_path: Path) -> None:
    home = tmp_path / "webots"
    (home / "projects" / "meshes").mkdir(parents=True)
    (home / "projects" / "meshes" / "m.obj").write_text("v 0 0 0\n")
    (tmp_path / "local.obj").write_text("v 0 0 0\n")
    s = ProtoSearch.create(tmp_path, home, version="R2023b")
    world = tmp_path / "w.wbt"
    assert resolve_url("local.obj", world, s) == tmp_path / "local.obj"
    assert resolve_url(str(tmp_path / "local.obj"), world, s) == tmp_path / "local.obj"
    assert resolve_url("webots://projects/meshes/m.obj", world, s) == home / "projects/meshes/m.obj"
    assert resolve_url(f"{RAW}/R2023b/projects/meshes/m.obj", world, s) == home / "projects/meshes/m.obj"
    with pytest.raises(ProtoError, match='"webots://projects/meshes/none.obj" not found'):
        resolve_url("webots://projects/meshes/none.obj", world, s)
    assert asset_roots(s) == [home.resolve()]


def test_cli_flags_and_info_list_the_protos_with_their_licences(tmp_path: Path, monkeypatch, capsys) -> None:
    from sensorium.cli import main as cli

    monkeypatch.delenv("WEBOTS_HOME", raising=False)          # restored after the test (the flags set it)
    monkeypatch.delenv("SENSORIUM_PROTO_PATH", raising=False)
    home = fake_webots(tmp_path / "webots")
    extra = tmp_path / "mine"
    proto_file(extra, "Gadget", "[ ] { Solid { name \"gadget\" } }", header="# license: MIT\n")
    w = world_file(tmp_path / "w", "AcmeBot { }\nGadget { }\n",
                   [f"{RAW}/R2023b/projects/robots/acme/bot/protos/AcmeBot.proto", "https://example.org/x/Gadget.proto"])
    assert cli(["validate", str(w)]) == 1
    assert "not found" in capsys.readouterr().err
    assert cli(["info", str(w), "--webots-home", str(home), "--proto-path", str(extra)]) == 0
    out = capsys.readouterr().out
    assert "proto     AcmeBot x1: no license line" in out and "proto     AcmeEye x1: no license line" in out
    assert f"proto     Gadget x1: MIT ({extra / 'Gadget.proto'})" in out
    assert cli(["validate", str(w)]) == 0                     # the flags now hold for this process


TETRA = "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"


def test_mesh_urls_of_protos_and_webots_assets_load_read_only(tmp_path: Path, monkeypatch) -> None:
    """A PROTO's mesh url is relative to the PROTO file, webots:// comes from the installation; both
    are read where they are (the world's folder does not hold them); a missing one is a warning."""
    home = webots_home(tmp_path / "webots", monkeypatch)
    (home / "projects" / "meshes").mkdir(parents=True)
    (home / "projects" / "meshes" / "cone.obj").write_text(TETRA)
    protos = tmp_path / "project" / "protos"
    (protos / "meshes").mkdir(parents=True)
    (protos / "meshes" / "shell.obj").write_text(TETRA)
    proto_file(protos, "Shell", """[ field SFString name "shell" ]
{ Solid { name IS name children [
    Shape { geometry Mesh { url "meshes/shell.obj" } }
    Shape { geometry Mesh { url "webots://projects/meshes/cone.obj" } }
    Shape { geometry Mesh { url "meshes/missing.obj" } } ] } }""")
    w = world_file(tmp_path / "project" / "worlds", 'Shell { }\n', ["../protos/Shell.proto"])
    loaded = load_world(w)
    (solid,) = loaded.world.solids
    urls = [s.geometry.url for s in solid.shapes]
    assert urls == [str((protos / "meshes" / "shell.obj").resolve()), str((home / "projects/meshes/cone.obj").resolve())]
    (warning,) = [m for m in loaded.warnings if "missing.obj" in m]
    assert f"Shell.proto:6:22 (in PROTO Shell at {w}:3:1): mesh file " in warning
    assert '"meshes/missing.obj" not found' in warning and "this shape is left out" in warning
    from sensorium.server.sim.summary import world_summary

    assert world_summary(w)["triangles"] == 8       # both meshes read from where they are: 4 + 4 faces
    # a world file naming a file outside its folder is still refused (the PROTO assets are the exception)
    bad = world_file(tmp_path / "project" / "worlds", f'Solid {{ children [ Shape {{ geometry Mesh {{ url "{home}/projects/meshes/cone.obj" }} }} ] }}\n', name="bad.wbt")
    with pytest.raises(WorldError, match="leaves the world's folder"):
        load_world(bad)


def test_texture_urls_of_protos_and_webots_assets_load_read_only(tmp_path: Path, monkeypatch) -> None:
    """Textures as meshes: a PROTO's url relative to the PROTO file, webots:// from the installation,
    read where they are; infra-red reads their texels (a red and a blue image: red channel 1 and 0)."""
    from PIL import Image

    home = webots_home(tmp_path / "webots", monkeypatch)
    (home / "projects" / "textures").mkdir(parents=True)
    Image.new("RGB", (2, 2), (0, 0, 255)).save(home / "projects" / "textures" / "blue.png")
    protos = tmp_path / "project" / "protos"
    (protos / "textures").mkdir(parents=True)
    Image.new("RGB", (2, 2), (255, 0, 0)).save(protos / "textures" / "red.png")
    proto_file(protos, "Tiles", """[ ]
{ Solid { children [
    Shape { appearance PBRAppearance { baseColorMap ImageTexture { url "textures/red.png" } } geometry Box { } }
    Pose { translation 0 0 5 children [ Shape { appearance PBRAppearance { baseColorMap ImageTexture {
      url "webots://projects/textures/blue.png" } } geometry Sphere { } } ] } ] } }""")
    w = world_file(tmp_path / "project" / "worlds", 'Tiles { }\n', ["../protos/Tiles.proto"])
    loaded = load_world(w)
    urls = [s.appearance.texture.url for s in loaded.world.solids[0].shapes]
    assert urls == [str((protos / "textures" / "red.png").resolve()), str((home / "projects/textures/blue.png").resolve())]
    assert not [m for m in loaded.warnings if "texture" in m]
    from sensorium.server.sim.scene import Scene

    scene = Scene(loaded.world, loaded.base_dir)
    import numpy as np

    o, d = np.array([[5.0, 0, 0], [5.0, 0, 5.0]]), np.array([[-1.0, 0, 0], [-1.0, 0, 0]])
    hits = scene.engine.cast(o, d, kind=1)
    assert hits.shape.tolist() == [0, 1]
    red, _, _ = scene.infra_red_terms(hits.shape, o, d, hits.distance)
    assert red.tolist() == [1.0, 0.0]
    # the world file itself naming a file outside its folder is still refused
    bad = world_file(tmp_path / "project" / "worlds", 'Solid { children [ Shape { appearance PBRAppearance { '
                     f'baseColorMap ImageTexture {{ url "{protos}/textures/red.png" }} }} geometry Box {{ }} }} ] }}\n',
                     name="bad.wbt")
    with pytest.raises(WorldError, match="leaves the world's folder"):
        load_world(bad)


def test_messages_about_proto_nodes_name_the_proto_file_and_the_instance(tmp_path: Path) -> None:
    proto_file(tmp_path, "Odd", '[ ] { Robot { name "odd" children [ Wobbler { } ] } }')
    w = world_file(tmp_path, 'Pose { children [ Odd { } ] }\n', ["Odd.proto"])
    (line,) = [m for m in load_world(w).warnings if "Wobbler" in m]
    assert line.startswith(f"{tmp_path / 'Odd.proto'}:2:47 (in PROTO Odd at {w}:3:19): Wobbler: not a built-in node")


def test_every_command_reading_a_world_file_takes_the_proto_options() -> None:
    """`sensorium snapshot WORLD.wbt OUT --webots-home DIR` was refused ('unrecognized arguments'):
    every command with a world argument finds a .wbt world's PROTOs the same way."""
    import argparse

    from sensorium.cli import build_parser

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    reading = {name: p for name, p in sub.choices.items() if any(a.dest == "world" for a in p._actions)}
    assert {"validate", "snapshot", "probe", "serve", "convert"} <= set(reading)
    for name, p in reading.items():
        dests = {a.dest for a in p._actions}
        assert {"webots_home", "proto_path"} <= dests, name


def test_a_world_before_r2022b_finds_its_protos_by_name(tmp_path: Path, monkeypatch) -> None:
    """Webots R2022a had no EXTERNPROTO: a world (and its PROTOs) named a PROTO by its type, found as
    TYPE.proto in the project's protos folder or the installation (Webots' own youbot.wbt of that
    release: Youbot, KukaBox). It used to lose the robot; R2022b and later worlds must declare them."""
    monkeypatch.delenv("SENSORIUM_PROTO_PATH", raising=False)
    home = fake_webots(tmp_path / "webots", version="R2022a")
    project = tmp_path / "project"
    proto_file(project / "protos" / "parts", "Knob", "[ ] { Solid { name \"knob\" boundingObject Box { } } }")
    proto_file(project / "protos", "Gadget", "[ ] { Solid { name \"gadget\" children [ Knob { } ] } }")
    body = "AcmeBot { }\nGadget { }\n"
    w = world_file(project / "worlds", body)
    w.write_text(w.read_text().replace("R2023b", "R2022a"))
    loaded = load_world(w, webots_home=home)
    assert [r.name for r in loaded.world.robots] == ["acme"] and not loaded.losses
    assert [d.name for d in loaded.world.robots[0].devices] == ["eye"]
    (gadget,) = loaded.world.solids
    assert gadget.name == "gadget" and [c.name for c in gadget.children] == ["knob"]
    # since R2022b a file must declare them: Webots says which line to add and loads them (found by name)
    w.write_text(w.read_text().replace("R2022a", "R2023b"))
    later = load_world(w, webots_home=home)
    assert [r.name for r in later.world.robots] == ["acme"] and not later.losses
    missing = [x for x in later.warnings if "missing declaration" in x]
    acme = next(home.rglob("AcmeBot.proto")).relative_to(home).as_posix()
    assert missing == [f"{w}:2:1: missing declaration for AcmeBot: add 'EXTERNPROTO \"webots://{acme}\"' to the file "
                       "(found by its file name, as Webots finds it and says so)",
                       f"{w}:3:1: missing declaration for Gadget: add 'EXTERNPROTO \"../protos/Gadget.proto\"' to the "
                       "file (found by its file name, as Webots finds it and says so)",
                       f"{project / 'protos' / 'Gadget.proto'}:2:53: missing declaration for Knob: add 'EXTERNPROTO "
                       "\"parts/Knob.proto\"' to the file (found by its file name, as Webots finds it and says so)"
                       ], later.warnings


def test_snapshot_takes_the_proto_flags_its_messages_name(tmp_path: Path, monkeypatch, capsys) -> None:
    """A world whose PROTO is in a Webots installation: `snapshot` said "give --webots-home DIR" and
    then refused that option; it takes --webots-home and --proto-path as the other world commands do."""
    from sensorium.cli import main as cli

    monkeypatch.delenv("WEBOTS_HOME", raising=False)
    monkeypatch.delenv("SENSORIUM_PROTO_PATH", raising=False)
    home = fake_webots(tmp_path / "webots")
    w = world_file(tmp_path / "w", "AcmeBot { }\n", [f"{RAW}/R2023b/projects/robots/acme/bot/protos/AcmeBot.proto"])
    out = tmp_path / "shot.png"
    assert cli(["snapshot", str(w), str(out)]) == 1
    assert "--webots-home" in capsys.readouterr().err
    assert cli(["snapshot", str(w), str(out), "--webots-home", str(home), "--size", "32x24"]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
