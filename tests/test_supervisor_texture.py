"""A Supervisor changing a texture (domain randomisation, as Webots' texture_change sample does): an
ImageTexture's ``url`` set, inserted into or emptied through ``setMFString``/``insertMFString``/
``removeMF`` is what cameras and infra-red sensors see from the next step, image for image and
reading for reading as the same world written with that url; a texture a DEF names changes in the
shapes that USE it; ``repeatS``/``repeatT`` too; a reset brings the world file's image back; a url
whose image cannot be read is set with one line and the shapes drawn untextured (Webots' rule), one
over the world's texture limits refused with one line and nothing changed. Our own world and images,
written in the test's folder. The same from Python and C controllers."""

from __future__ import annotations

import numpy as np
import pytest
from _serve import run_controller, sensorium
from test_c_client import sanitized_controller
from test_multiprocess import REPO

from sensorium.schemas import world as wm
from sensorium.server.daemon import supervisor as sv
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.limits import WorldLimits
from sensorium.server.world.loader import load_world

AMBIENT = 0.5
A_RGB = (200, 100, 30)             # a.png: one colour
DIFFUSE = (0.2, 0.4, 0.6)          # the wall's Material under its texture
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=1:exitcode=86", "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"}

# the robot "looker" (a supervisor) at the origin looks along +x with an 8 x 8 camera and an infra-red
# distance sensor at the 1 m square face of the wall WALL (x = 1), lit by an ambient-only light; the
# wall's Appearance has a Material and the texture TEX (scaled 1.5 times: the wrap shows); the solid
# "twin", out of view, USEs TEX. The wall casts shadows.
WORLD = """#VRML_SIM R2023b utf8
WorldInfo {
  basicTimeStep 16
}
Viewpoint {
}
DirectionalLight {
  direction 1 0 0
  intensity 0
  ambientIntensity 0.5
}
DEF WALL Solid {
  translation 1 0 0
  name "wall"
  children [
    Shape {
      appearance Appearance {
        material Material {
          diffuseColor 0.2 0.4 0.6
        }
        texture DEF TEX ImageTexture {
          url [
            "a.png"
          ]
        }
        textureTransform TextureTransform {
          scale 1.5 1.5
        }
      }
      geometry Box {
        size 0.1 1 1
      }
    }
  ]
}
Solid {
  translation 0 5 0
  name "twin"
  children [
    Shape {
      appearance Appearance {
        texture USE TEX
      }
      geometry Box {
        size 1 1 1
      }
    }
  ]
}
DEF LOOKER Robot {
  name "looker"
  supervisor TRUE
  controller "<extern>"
  children [
    Camera {
      translation 0.1 0 0
      name "cam"
      width 8
      height 8
      fieldOfView 1.2
    }
    DistanceSensor {
      translation 0.1 0 0
      name "ir"
      type "infra-red"
      lookupTable [
        0 0 0
        4 4000 0
      ]
    }
  ]
}
"""


def _images(folder) -> None:
    from PIL import Image
    Image.new("RGB", (4, 4), A_RGB).save(folder / "a.png")
    rng = np.random.default_rng(7)
    Image.fromarray(rng.integers(0, 256, (4, 4, 3), dtype=np.uint8)).save(folder / "b.png")
    Image.fromarray(rng.integers(0, 256, (8, 2, 3), dtype=np.uint8)).save(folder / "c.jpg", quality=95)
    Image.new("RGBA", (4, 4), (10, 200, 10, 255)).save(folder / "alpha.png")
    Image.new("RGB", (64, 64), (1, 2, 3)).save(folder / "big.png")
    (folder / "sub").mkdir()
    Image.new("RGB", (2, 2), (0, 0, 250)).save(folder / "sub" / "d.png")
    (folder / "notes.png").write_text("not an image")


@pytest.fixture
def folder(tmp_path):
    _images(tmp_path)
    (tmp_path / "world.wbt").write_text(WORLD)
    return tmp_path


def _variant(folder, old: str, new: str, name: str = "variant.wbt"):
    assert old in WORLD
    path = folder / name
    path.write_text(WORLD.replace(old, new))
    return path


def _sim(path, limits: WorldLimits | None = None) -> Simulation:
    sim = Simulation(load_world(path), limits=limits)
    sim.device("looker/cam").enable(16)
    sim.device("looker/ir").enable(16)
    return sim


def _shot(sim: Simulation) -> tuple[np.ndarray, float]:
    sim.run(1)
    return sim.device("looker/cam").image.copy(), float(sim.device("looker/ir").value)


def _written(folder, url_lines: str, name: str = "variant.wbt") -> tuple[np.ndarray, float]:
    """What the world written with that ImageTexture url list sees."""
    return _shot(_sim(_variant(folder, '"a.png"', url_lines, name)))


def field(sim, node, name):
    return sv.get_field(sim, node, name)["value"]


def _linear(byte: int) -> float:
    c = byte / 255.0
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def expected_bytes(albedo) -> list[int]:
    """Webots' HDR resolve of an ambient-lit face, RGB bytes."""
    L = AMBIENT * np.asarray(albedo, dtype=np.float64)
    return np.floor(255.0 * (1.0 - np.exp(-L)) ** (1.0 / 2.2) + 0.5).astype(np.int64).tolist()


def _centre(img: np.ndarray) -> list[int]:
    return img[4, 4, [2, 1, 0]].tolist()


def test_a_url_set_is_seen_as_the_world_file_with_that_url(folder):
    sim = _sim(folder / "world.wbt")
    img, ir = _shot(sim)
    assert _centre(img) == expected_bytes([_linear(c) for c in A_RGB])       # a texel, sRGB-decoded, white material
    tex = sv.find_node(sim, "TEX")
    assert field(sim, tex, "url") == ["a.png"]
    sv.change_item(sim, tex, "url", "set", 0, "b.png")
    assert field(sim, tex, "url") == ["b.png"]
    img2, ir2 = _shot(sim)
    ref_img, ref_ir = _written(folder, '"b.png"')
    assert np.array_equal(img2, ref_img) and ir2 == ref_ir
    assert not np.array_equal(img2, img) and ir2 != ir
    # a JPEG of another size, then an image in a sub-folder (urls relative to the world file)
    for url in ("c.jpg", "sub/d.png"):
        sv.change_item(sim, tex, "url", "set", -1, url)
        got = _shot(sim)
        ref = _written(folder, f'"{url}"')
        assert np.array_equal(got[0], ref[0]) and got[1] == ref[1]


def test_the_shapes_that_use_the_texture_change_with_it(folder):
    sim = _sim(folder / "world.wbt")
    tex = sv.find_node(sim, "TEX")
    twin_shape = field(sim, sv.find_node(sim, "twin"), "children")[0]
    used = sv.node_by_id(sim, field(sim, sv.node_by_id(sim, field(sim, sv.node_by_id(sim, twin_shape), "appearance")),
                                    "texture"))
    assert (used.type, used.def_name, field(sim, used, "url")) == ("ImageTexture", "", ["a.png"])
    table = sv._table(sim)
    k_wall, k_twin = table.get(tex.id).shape.index, table.get(used.id).shape.index
    sv.change_item(sim, used, "url", "set", 0, "b.png")      # through the USE: the DEF's shape too
    assert field(sim, tex, "url") == ["b.png"]
    from PIL import Image
    b = np.asarray(Image.open(folder / "b.png").convert("RGB"))
    sampler = sim.scene.textures
    assert np.array_equal(sampler.shapes[k_wall].base.rgb, b) and np.array_equal(sampler.shapes[k_twin].base.rgb, b)
    got = _shot(sim)
    ref = _written(folder, '"b.png"')
    assert np.array_equal(got[0], ref[0]) and got[1] == ref[1]


def test_inserting_and_removing_urls_follows_the_first_one(folder):
    sim = _sim(folder / "world.wbt")
    tex = sv.find_node(sim, "TEX")
    before = _shot(sim)
    sv.change_item(sim, tex, "url", "insert", 1, "b.png")        # a second url: Webots reads the first only
    assert field(sim, tex, "url") == ["a.png", "b.png"]
    got = _shot(sim)
    assert np.array_equal(got[0], before[0]) and got[1] == before[1]
    sv.change_item(sim, tex, "url", "remove", 0, None)           # b.png comes first
    got = _shot(sim)
    ref = _written(folder, '"b.png"')
    assert np.array_equal(got[0], ref[0]) and got[1] == ref[1]
    # no url left: the shape untextured, its Material's diffuse colour seen, as Webots and the world file with url []
    sv.change_item(sim, tex, "url", "remove", -1, None)
    assert field(sim, tex, "url") == []
    got = _shot(sim)
    ref = _written(folder, "", "empty.wbt")
    assert np.array_equal(got[0], ref[0]) and got[1] == ref[1]
    assert _centre(got[0]) == expected_bytes(DIFFUSE)
    # an empty string likewise; then a url again, read with the world file's TextureTransform
    sv.change_item(sim, tex, "url", "insert", 0, "")
    got2 = _shot(sim)
    assert np.array_equal(got2[0], got[0]) and got2[1] == got[1]
    sv.change_item(sim, tex, "url", "set", 0, "c.jpg")
    got = _shot(sim)
    ref = _written(folder, '"c.jpg"')
    assert np.array_equal(got[0], ref[0]) and got[1] == ref[1]


def test_a_texture_the_world_file_could_not_load_takes_a_url_set_later(folder):
    sim = _sim(_variant(folder, '"a.png"', '"missing.png"', "missing.wbt"))
    assert _centre(_shot(sim)[0]) == expected_bytes(DIFFUSE)     # Webots: a warning, the shape untextured
    tex = sv.find_node(sim, "TEX")
    sv.change_item(sim, tex, "url", "set", 0, "b.png")
    got = _shot(sim)
    ref = _written(folder, '"b.png"')
    assert np.array_equal(got[0], ref[0]) and got[1] == ref[1]


def test_an_image_texture_without_url_takes_one(folder):
    path = folder / "bare.wbt"
    path.write_text(WORLD.replace('DEF TEX ImageTexture {\n          url [\n            "a.png"\n          ]', "ImageTexture {")
                    .replace("texture USE TEX", ""))
    assert "a.png" not in path.read_text() and "TEX" not in path.read_text()
    sim = _sim(path)
    assert _centre(_shot(sim)[0]) == expected_bytes(DIFFUSE)
    shape = sv.node_by_id(sim, field(sim, sv.find_node(sim, "WALL"), "children")[0])
    tex = sv.node_by_id(sim, field(sim, sv.node_by_id(sim, field(sim, shape, "appearance")), "texture"))
    assert tex.type == "ImageTexture"
    assert field(sim, tex, "url") == []
    sv.change_item(sim, tex, "url", "insert", -1, "b.png")
    got = _shot(sim)
    ref = _written(folder, '"b.png"')
    assert np.array_equal(got[0], ref[0]) and got[1] == ref[1]


def test_repeat_and_filtering(folder):
    sim = _sim(folder / "world.wbt")
    tex = sv.find_node(sim, "TEX")
    sv.change_item(sim, tex, "url", "set", 0, "b.png")
    repeating = _shot(sim)
    sv.set_field(sim, tex, "repeatS", False)
    sv.set_field(sim, tex, "repeatT", False)
    assert (field(sim, tex, "repeatS"), field(sim, tex, "repeatT")) == (False, False)
    got = _shot(sim)
    path = folder / "norepeat.wbt"
    path.write_text(WORLD.replace('"a.png"', '"b.png"').replace(
        "ImageTexture {", "ImageTexture {\n          repeatS FALSE\n          repeatT FALSE\n          filtering 2"))
    ref = _shot(_sim(path))
    assert np.array_equal(got[0], ref[0]) and got[1] == ref[1] and not np.array_equal(got[0], repeating[0])
    sv.set_field(sim, tex, "filtering", 2)            # kept and read back; sensors read the nearest texel
    assert field(sim, tex, "filtering") == 2
    assert np.array_equal(_shot(sim)[0], ref[0])
    with pytest.raises(ValueError, match=r"'filtering' \(SFInt32\) of ImageTexture 'TEX' .*from 0 to 5, got 9"):
        sv.set_field(sim, tex, "filtering", 9)
    assert field(sim, tex, "filtering") == 2


def test_a_reset_brings_the_world_files_image_back(folder):
    sim = _sim(folder / "world.wbt")
    first = _shot(sim)
    tex = sv.find_node(sim, "TEX")
    sv.change_item(sim, tex, "url", "set", 0, "b.png")
    sv.set_field(sim, tex, "repeatS", False)
    assert not np.array_equal(_shot(sim)[0], first[0])
    sim.reset()
    assert (field(sim, tex, "url"), field(sim, tex, "repeatS")) == (["a.png"], True)
    again = _shot(sim)
    assert np.array_equal(again[0], first[0]) and again[1] == first[1]
    sv.change_item(sim, tex, "url", "remove", 0, None)            # untextured, then reset: textured again
    sim.reset()
    again = _shot(sim)
    assert np.array_equal(again[0], first[0]) and again[1] == first[1]


def _overwrite(path, seed: int) -> None:
    from PIL import Image
    Image.fromarray(np.random.default_rng(seed).integers(0, 256, (4, 4, 3), dtype=np.uint8)).save(path)


def test_an_image_written_again_under_its_url_is_read_again_when_the_url_changes(folder):
    """Webots' updateUrl reads the first url's file again on any change of the list (an item set to another
    value, one inserted or removed), not when an item is set to the value it has: the world's own image
    overwritten on disk is seen once the url changes, bit for bit as a world loaded with the new file; a
    reset brings back the image as loaded."""
    sim = _sim(folder / "world.wbt")
    first = _shot(sim)
    tex = sv.find_node(sim, "TEX")
    k = sv._table(sim).get(tex.id).shape.index
    _overwrite(folder / "a.png", 11)
    sv.change_item(sim, tex, "url", "set", 0, "a.png")           # the same value: no change, nothing read
    assert np.array_equal(_shot(sim)[0], first[0])
    sv.change_item(sim, tex, "url", "set", 0, "b.png")
    sv.change_item(sim, tex, "url", "set", 0, "a.png")           # back: the file as it is now
    got, written = _shot(sim), _shot(_sim(folder / "world.wbt"))
    assert np.array_equal(got[0], written[0]) and got[1] == written[1]
    assert not np.array_equal(got[0], first[0])
    _overwrite(folder / "a.png", 12)
    sv.change_item(sim, tex, "url", "insert", -1, "c.jpg")       # the first item unchanged, the list changed
    got, written = _shot(sim), _shot(_sim(folder / "world.wbt"))
    assert np.array_equal(got[0], written[0]) and got[1] == written[1]
    sim.reset()
    again = _shot(sim)
    assert np.array_equal(again[0], first[0]) and again[1] == first[1]
    assert sim.scene.textures.shapes[k].base.rgb is sim.scene.images["a.png"][1][0]    # the loaded image itself


def test_an_unchanged_file_named_again_is_the_image_held_not_a_second_copy(folder):
    sim = _sim(folder / "world.wbt")
    tex = sv.find_node(sim, "TEX")
    k = sv._table(sim).get(tex.id).shape.index
    sv.change_item(sim, tex, "url", "set", 0, "b.png")
    held = sim.scene.textures.shapes[k].base.rgb
    sv.change_item(sim, tex, "url", "insert", -1, "a.png")       # read again: the same pixels, the same array
    assert sim.scene.textures.shapes[k].base.rgb is held
    sv.change_item(sim, tex, "url", "set", 0, "a.png")
    assert sim.scene.textures.shapes[k].base.rgb is sim.scene.images["a.png"][1][0]
    _overwrite(folder / "b.png", 13)                                # a Supervisor's file written again, read again
    sv.change_item(sim, tex, "url", "set", 0, "b.png")
    got = _shot(sim)
    ref = _written(folder, '"b.png"')
    assert np.array_equal(got[0], ref[0]) and got[1] == ref[1]


def _untextured(sim, tex, url: str, problem: str) -> None:
    """Setting ``url``, whose image is not read, sets the field with one line naming the problem, and the
    shapes are drawn untextured: what the world written with no url shows (its Material's diffuse colour)."""
    lines = sv.change_item(sim, tex, "url", "set", 0, url)
    assert len(lines) == 1 and "\n" not in lines[0], lines
    assert lines[0].startswith(f"field 'url' (MFString) of ImageTexture 'TEX' (node {tex.id}): ") and \
        problem in lines[0] and lines[0].endswith("the shape is drawn without its texture (as Webots draws an "
                                                   "image it cannot load)"), lines[0]
    assert field(sim, tex, "url") == [url]
    got = _shot(sim)
    ref = _written(sim.scene.base_dir, "", "empty.wbt")
    assert np.array_equal(got[0], ref[0]) and got[1] == ref[1]
    assert _centre(got[0]) == expected_bytes(DIFFUSE)


def test_a_file_overwritten_with_no_image_leaves_the_shapes_untextured_when_named_again(folder):
    sim = _sim(folder / "world.wbt")
    tex = sv.find_node(sim, "TEX")
    sv.change_item(sim, tex, "url", "set", 0, "b.png")
    (folder / "a.png").write_bytes(b"\x89PNG\r\n\x1a\n" + b"broken" * 10)
    _untextured(sim, tex, "a.png", "a.png")
    # the world written with that url loads untextured too (one load line), as the Supervisor's set leaves it
    got = _shot(sim)
    ref = _written(folder, '"a.png"', "broken.wbt")
    assert np.array_equal(got[0], ref[0]) and got[1] == ref[1]


@pytest.mark.parametrize(("url", "problem"), [
    ("nope.png", "texture file 'nope.png' not found"),
    ("notes.png", "texture file 'notes.png' is not a PNG or JPEG image"),
    ("../outside.png", "texture url '../outside.png' leaves the world's folder"),
    ("https://example.com/t.png", "only local image files are read here"),
    ("webots://projects/default/worlds/textures/stone.jpg",
     '"webots://projects/default/worlds/textures/stone.jpg" not found (Webots); looked in: nothing'),
    ("ftp://example.com/t.png", "only local image files are read here"),
])
def test_a_url_whose_image_is_not_read_is_set_and_the_shapes_drawn_untextured(folder, url, problem, monkeypatch):
    """Webots' WbImageTexture sets the url, warns and draws the shape without its texture when the image
    cannot be loaded (missing, not an image, a failed download); here too, a download never tried and a
    file outside the world's folder never read. A valid url set after brings the image back."""
    monkeypatch.delenv("WEBOTS_HOME", raising=False)
    monkeypatch.delenv("SENSORIUM_PROTO_PATH", raising=False)
    (folder.parent / "outside.png").write_bytes((folder / "a.png").read_bytes())
    sim = _sim(folder / "world.wbt")
    before = _shot(sim)
    tex = sv.find_node(sim, "TEX")
    _untextured(sim, tex, url, problem)
    assert sv.change_item(sim, tex, "url", "set", 0, "a.png") == []
    got = _shot(sim)
    assert np.array_equal(got[0], before[0]) and got[1] == before[1]


def test_an_image_over_the_texture_limits_is_refused_and_nothing_changes(folder):
    """A limit of the world's, not Webots' rule: an image over it is refused with one line (raise the limits
    with --allow-large), the field and the image shown as before."""
    sim = _sim(folder / "world.wbt", limits=WorldLimits(texture_pixels=1000))
    before = _shot(sim)
    tex = sv.find_node(sim, "TEX")
    with pytest.raises(ValueError) as err:
        sv.change_item(sim, tex, "url", "set", 0, "big.png")
    line = str(err.value)
    assert line.startswith("field 'url' (MFString) of ImageTexture 'TEX' (node ") and \
        "'big.png' has 64x64 = 4,096 pixels, more than the limit of 1,000" in line, line
    assert line.endswith("nothing changed") and "\n" not in line
    assert field(sim, tex, "url") == ["a.png"]
    got = _shot(sim)
    assert np.array_equal(got[0], before[0]) and got[1] == before[1]


def _home(tmp_path):
    """A Webots installation of ours holding one texture (a 4 x 4 image of random colours)."""
    from PIL import Image
    home = tmp_path / "home"
    textures = home / "projects" / "default" / "worlds" / "textures"
    textures.mkdir(parents=True)
    rng = np.random.default_rng(11)
    Image.fromarray(rng.integers(0, 256, (4, 4, 3), dtype=np.uint8)).save(textures / "stone.png")
    return home


def test_a_webots_url_of_the_installation_is_read_from_it(folder, tmp_path, monkeypatch):
    """Webots' texture_change how-to sets webots:// urls its world file never writes: with
    --webots-home (WEBOTS_HOME) the image is read from the installation, and the camera and the
    infra-red sensor see what they see in the world written with that file; one the installation
    lacks is set with one line naming where it looked, the shapes drawn untextured."""
    home = _home(tmp_path)
    monkeypatch.setenv("WEBOTS_HOME", str(home))
    monkeypatch.delenv("SENSORIUM_PROTO_PATH", raising=False)
    (folder / "copy.png").write_bytes((home / "projects/default/worlds/textures/stone.png").read_bytes())
    sim = _sim(folder / "world.wbt")
    before = _shot(sim)
    tex = sv.find_node(sim, "TEX")
    url = "webots://projects/default/worlds/textures/stone.png"
    sv.change_item(sim, tex, "url", "set", 0, url)
    assert field(sim, tex, "url") == [url]
    got = _shot(sim)
    ref = _written(folder, '"copy.png"')
    assert np.array_equal(got[0], ref[0]) and got[1] == ref[1]
    assert not np.array_equal(got[0], before[0])
    none = "webots://projects/default/worlds/textures/none.png"
    _untextured(sim, tex, none, f'"{none}" not found')
    (line,) = sv.change_item(sim, tex, "url", "set", 0, none + "x")
    assert str(home) in line, line


def test_bad_indices_and_values_are_one_line(folder):
    sim = _sim(folder / "world.wbt")
    tex = sv.find_node(sim, "TEX")
    with pytest.raises(ValueError, match=r"'url' \(MFString\) .*out-of-bound index 1 \(should be between -1 and 0\); "
                                         "nothing changed"):
        sv.change_item(sim, tex, "url", "set", 1, "b.png")
    with pytest.raises(ValueError, match=r"out-of-bound index 3 \(should be between -2 and 1\)"):
        sv.change_item(sim, tex, "url", "insert", 3, "b.png")
    with pytest.raises(ValueError, match="takes a string, got 5; nothing changed"):
        sv.change_item(sim, tex, "url", "set", 0, 5)
    with pytest.raises(ValueError, match=r"'url' \(MFString\) of ImageTexture 'TEX' .* is changed item by item "
                                         r"\(setMFString, insertMFString, removeMF\), not set as a whole; nothing changed"):
        sv.set_field(sim, tex, "url", ["b.png"])
    assert field(sim, tex, "url") == ["a.png"]


def _yaml_world(texture) -> wm.World:
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 16},
        "lights": [{"type": "DirectionalLight", "direction": [1, 0, 0], "intensity": 0.0, "ambient_intensity": AMBIENT}],
        "solids": [{"name": "wall", "pose": {"translation": [1.0, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.1, 1, 1]},
                    "appearance": {"base_color": [0.5, 1.0, 1.0], "texture": texture}}],
        "robots": [{"name": "r", "supervisor": True, "devices": [{"device": "Camera", "name": "cam", "width": 8,
                                                                   "height": 8, "field_of_view": 1.2}]}]})


def test_a_yaml_worlds_base_colour_map(folder):
    sim = Simulation(_yaml_world({"url": "a.png", "repeat_t": False}), base_dir=folder)
    sim.device("r/cam").enable(16)
    (shape,) = field(sim, sv.find_node(sim, "wall"), "children")
    app = sv.node_by_id(sim, field(sim, sv.node_by_id(sim, shape), "appearance"))
    texture = sv.node_by_id(sim, field(sim, app, "baseColorMap"))
    sv.change_item(sim, texture, "url", "set", 0, "b.png")
    assert (field(sim, texture, "url"), field(sim, texture, "repeatT")) == (["b.png"], False)
    sim.run(1)
    ref = Simulation(_yaml_world({"url": "b.png", "repeat_t": False}), base_dir=folder)
    ref.device("r/cam").enable(16)
    ref.run(1)
    assert np.array_equal(sim.device("r/cam").image, ref.device("r/cam").image)
    # no url: the PBRAppearance's baseColor alone
    sv.change_item(sim, texture, "url", "remove", 0, None)
    sim.run(1)
    assert sim.device("r/cam").image[4, 4, [2, 1, 0]].tolist() == expected_bytes([0.5, 1.0, 1.0])


# ---------------------------------------------------------------------- Python and C controllers
def _expected_lines() -> list[str]:
    a = expected_bytes([_linear(c) for c in A_RGB])
    diffuse = expected_bytes(DIFFUSE)
    return [f"before a.png {a[0]} {a[1]} {a[2]}",
            "set b.png 1",
            f"removed 0 {diffuse[0]} {diffuse[1]} {diffuse[2]}",
            f"inserted a.png {a[0]} {a[1]} {a[2]}",
            f"missing nope.png {diffuse[0]} {diffuse[1]} {diffuse[2]}"]


@pytest.fixture(scope="module")
def c_controller(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "texture_change.c")


def test_a_python_controller_changes_a_texture_its_camera_sees(folder) -> None:
    log: list[str] = []
    lines, err = run_controller(folder / "world.wbt", lambda url: sensorium(
        "controller", "--url", url, str(REPO / "tests" / "controllers" / "texture_change.py")), robot="looker",
        server_log=log)
    assert lines == _expected_lines(), err
    # the url set to a missing file: one line in the server's log (Webots' console), none for the controller
    assert "nope.png" not in err, err
    assert log[0].count("texture file 'nope.png' not found") == 1, log[0]


def test_a_c_controller_does_the_same(folder, c_controller: str) -> None:
    log: list[str] = []
    lines, err = run_controller(folder / "world.wbt", lambda url: [c_controller], env=SAN_ENV, robot="looker",
                                server_log=log)
    assert "Sanitizer" not in err and "runtime error" not in err, err
    assert lines == _expected_lines(), err
    assert "nope.png" not in err, err
    assert log[0].count("texture file 'nope.png' not found") == 1, log[0]
