"""Property test of emissive colours in camera images (sim/scene.py, sim/cameras.py; README "Cameras"), on the
wall of tests/test_camera_emissive.py lit by the ambient term alone (0.3: every pixel lit alike). For a random
base colour d, emissive colour e, texel t of a one-colour texture (sRGB-decoded, as WREN's shaders decode
it) and texel m of a one-colour emissiveColorMap (taken as stored), every pixel reads Webots' resolve of:

- a Phong surface (Appearance) textured: ``0.3·d·t + e·t`` (phong.frag multiplies the glow by the texel);
- a PBR surface textured or not: ``0.3·d(·t) + e``, with an emissive map ``0.3·d(·t) + m/255``.

Within one byte of the float64 closed form (the resolve of a value at a rounding edge), both precisions."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from _fuzz import example_counts
from hypothesis import given, settings
from hypothesis import strategies as st
from test_camera_emissive import _linear, world
from test_camera_light_radius import AMBIENT, BOTH, byte
from test_fuzz_core import SETTINGS

from sensorium.server.sim.simulation import Simulation

colour = st.tuples(*[st.floats(0.0, 1.0).map(lambda x: 0.0 if x < 1e-30 else x)] * 3)
texel = st.tuples(*[st.integers(0, 255)] * 3)


@pytest.mark.parametrize("precision", BOTH)
@pytest.mark.parametrize("examples", example_counts(120))
def test_a_flat_lit_glowing_surface_reads_the_emissive_rule(tmp_path_factory, precision: str, examples: int) -> None:
    from PIL import Image

    folder = tmp_path_factory.mktemp("glow")

    @settings(SETTINGS, max_examples=examples)
    @given(d=colour, e=colour, t=texel, m=texel, kind=st.sampled_from(["phong", "pbr", "pbr plain", "map", "map plain"]))
    def run(d, e, t, m, kind) -> None:
        Image.fromarray(np.full((2, 2, 3), t, dtype=np.uint8), "RGB").save(folder / "t.png")
        Image.fromarray(np.full((2, 2, 3), m, dtype=np.uint8), "RGB").save(folder / "m.png")
        appearance = {"base_color": list(d), "emissive_color": list(e), "phong": kind == "phong"}
        if "plain" not in kind:
            appearance["texture"] = "t.png"
        if kind.startswith("map"):
            appearance["emissive_map"] = "m.png"
        sim = Simulation(world([AMBIENT], appearance), precision=precision, base_dir=folder)
        cam = sim.device("r/cam")
        cam.enable(16)
        sim.run(1)
        got = cam.image[:, :, [2, 1, 0]].astype(np.int64)
        tex = np.array([_linear(v) for v in t]) if "plain" not in kind else np.ones(3)
        glow = np.asarray(e) * tex if kind == "phong" else np.asarray(m) / 255.0 if kind.startswith("map") else np.asarray(e)
        want = byte(0.3 * np.asarray(d) * tex + glow)
        assert np.abs(got - want).max() <= 1, (kind, got[3, 4].tolist(), want.tolist())
        assert (got == got[3, 4]).all()                  # flat: every pixel alike
    run()


def test_the_emissive_rule_tells_a_map_from_the_colour_it_replaces(tmp_path: Path) -> None:
    # a map's texel (0, 255, 0) over an emissive colour (1, 0, 0) in the dark: green alone glows (m/255)
    from PIL import Image

    Image.fromarray(np.full((2, 2, 3), (0, 255, 0), dtype=np.uint8), "RGB").save(tmp_path / "m.png")
    sim = Simulation(world([], {"base_color": [1.0, 1.0, 1.0], "emissive_color": [1.0, 0.0, 0.0],
                                "emissive_map": "m.png"}), base_dir=tmp_path)
    cam = sim.device("r/cam")
    cam.enable(16)
    sim.run(1)
    assert cam.image[3, 4, [2, 1, 0]].tolist() == byte(np.array([0.0, 1.0, 0.0])).tolist()


@pytest.mark.parametrize("url, refused", [
    ("nope.png", None), ("notes.png", None), ("", None), ("sub", None),
    ("bomb.png", "has 100000x100000 = 10,000,000,000 pixels, more than the limit of 16,777,216"),
    ("../outside.png", "leaves the world's folder"),
])
def test_an_emissive_color_map_not_loaded_is_one_line_and_glows_its_emissive_color(tmp_path: Path, url, refused):
    """An emissiveColorMap whose url is missing, no image, empty or a folder: the world's one line of textures
    not loaded, naming the map and saying it reads as its emissiveColor (Webots draws no map: the colour
    glows, ``0.3·d + e``); one declaring a huge size or outside the world's folder: the load's one line."""
    from PIL import Image
    from test_camera_emissive import DIFFUSE, GLOW, WBT
    from test_fuzz_texture_url import _png_header

    from sensorium.server.world.loader import WorldError, load_world

    folder = tmp_path / "w"
    (folder / "sub").mkdir(parents=True)
    Image.fromarray(np.full((2, 2, 3), 9, dtype=np.uint8), "RGB").save(tmp_path / "outside.png")
    (folder / "notes.png").write_text("no image")
    (folder / "bomb.png").write_bytes(_png_header(100_000, 100_000))
    path = folder / "glow.wbt"
    path.write_text(WBT.format(appearance="PBRAppearance { baseColor 0.6 0.3 0.15 metalness 0 emissiveColor 0.05 0.4 "
                                          f'0.7 emissiveColorMap ImageTexture {{ url "{url}" }} }}'))
    if refused:
        with pytest.raises(WorldError) as err:
            load_world(path)
        assert refused in str(err.value) and "emissive_map" in str(err.value) and "\n" not in str(err.value)
        return
    lw = load_world(path)
    said = [w for w in lw.warnings if "texture" in w]
    assert len(said) == 1 and "\n" not in said[0]
    assert "(first: emissiveColorMap: " in said[0] and said[0].endswith(", an emissiveColorMap as its emissiveColor")
    sim = Simulation(lw)
    cam = sim.device("robot/cam")
    cam.enable(16)
    sim.run(1)
    got = cam.image[:, :, [2, 1, 0]].astype(np.int64)
    np.testing.assert_array_equal(got, np.broadcast_to(byte(0.3 * np.asarray(DIFFUSE) + np.asarray(GLOW)), got.shape))


@pytest.mark.parametrize("examples", example_counts(120))
def test_a_chargers_glow_reads_its_energys_colour(examples: int) -> None:
    """A camera in the dark facing a Charger's box (its own emissive colour c0), no robot near: the Charger
    holds E = min(E0 + n·s·dt, Emax) after n steps (Emax when it loaded above), and the box reads the
    resolve of WbCharger's colour: full (E >= Emax, a maximum of 0 too) its emissiveColor f; else, gradual,
    ``c0 + (f − c0)·E/Emax``, not gradual c0."""
    from test_camera_emissive import _charger_world

    amount = st.just(0.0) | st.floats(1e-3, 5.0)

    @settings(SETTINGS, max_examples=examples)
    @given(e0=amount, emax=amount, speed=amount, c0=colour, full=colour, gradual=st.booleans(), n=st.integers(1, 6))
    def run(e0, emax, speed, c0, full, gradual, n) -> None:
        w = _charger_world(gradual, c0)
        charger = w.chargers[0].model_copy(update={"battery": [e0, emax, speed], "emissive_color": full})
        sim = Simulation(w.model_copy(update={"chargers": [charger]}))
        cam = sim.device("r/cam")
        cam.enable(16)
        energy = e0
        for _ in range(n):
            energy = min(energy + speed * 16 * 0.001, emax)
        sim.run(n)
        assert sim.chargers[0].energy == pytest.approx(energy, rel=1e-12, abs=1e-12)
        f, c = np.asarray(full), np.asarray(c0)
        glow = f if energy >= emax else (c + (f - c) * (energy / emax) if gradual else c)
        got = cam.image[:, :, [2, 1, 0]].astype(np.int64)
        assert np.abs(got - byte(glow)).max() <= 1, (got[3, 4].tolist(), byte(glow).tolist())
    run()
