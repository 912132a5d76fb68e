"""Property tests (Hypothesis, derandomized) of the paths sweeps 30 to 32 added, each failing case found fixed
with a regression test naming it (tests/test_props_round30*.py fuzz round 30's).

Texture urls of a PROTO's field: a world folder and a PROTO file at random places (beside the world, in a
sub-folder, in the project's protos/, in a folder beside the worlds'), one-colour images written at random
among the urls below both, a default url in the PROTO, a value the world writes for it or none, then a
Supervisor's sets of the url and simulationReset (which keeps the value set) in random order: the shape shows the image of the first of
the PROTO's folder and the world's folder that holds the url's file, the path cleaned first as Webots'
QDir::cleanPath does (``tex/../t.png`` is ``t.png``), the world's only while the path stays in it; or none,
drawn untextured."""

from __future__ import annotations

import gc
import itertools
import os
import shutil
from pathlib import Path

import pytest
from _fuzz import example_counts
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image
from test_fuzz_core import SETTINGS
from test_supervisor import A, Live

from sensorium.server.daemon.services import Core
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

# ---------------------------------------------------------------- texture urls of a PROTO's field
#
# PLATE: a Solid "plate" whose Box's ImageTexture url IS its textureUrl field; BOSS a supervisor robot.

PLATE = """#VRML_SIM R2023b utf8
PROTO Plate [
  field SFVec3f  translation 0 0 0.5
  field SFString name "plate"
  field MFString textureUrl "{default}"
]
{{
  Solid {{
    translation IS translation
    children [ Shape {{ appearance Appearance {{ texture ImageTexture {{ url IS textureUrl }} }}
                       geometry Box {{ size 1 1 1 }} }} ]
    name IS name
  }}
}}
"""
PLATE_WORLD = """#VRML_SIM R2023b utf8
EXTERNPROTO "{proto}"
WorldInfo {{ basicTimeStep 16 }}
DEF P Plate {{ {field} }}
Robot {{ name "boss" supervisor TRUE controller "<extern>" }}
"""
WORLD_DIRS = ["w", "proj/worlds", "a/b/w"]
PROTO_PLACES = ["Plate.proto", "protos/Plate.proto", "p/q/Plate.proto", "../protos/Plate.proto", "../x/Plate.proto"]
URLS = ["t.png", "./t.png", "tex/t.png", "tex/../t.png", "tex/../../t.png", "../t.png", "u.png", "tex/u.png"]


def expected_file(url: str, proto: Path, world_dir: Path) -> Path | None:
    """The file Webots' WbUrl reads for a relative ``url`` of a PROTO's field (the path cleaned, then beside
    the PROTO, then in the world's folder), as Sensorium confines it: beside the PROTO within its project
    (the protos folder's parent), in the world's folder only while the path stays in it; None if neither."""
    beside = Path(os.path.normpath(proto.parent / url))
    if beside.is_file() and beside.is_relative_to(proto.parent.parent):
        return beside
    in_world = Path(os.path.normpath(world_dir / url))
    if in_world.is_file() and in_world.is_relative_to(world_dir):
        return in_world
    return None


def textures_follow_webots_lookup(root: Path, world_rel: str, proto_rel: str, files: list[tuple[bool, str]],
                                  default: str, written: str | None, ops: list[str | None]) -> None:
    shutil.rmtree(root, ignore_errors=True)
    world_dir = (root / world_rel)
    world_dir.mkdir(parents=True)
    world_dir = world_dir.resolve()
    proto = Path(os.path.normpath(world_dir / proto_rel))
    proto.parent.mkdir(parents=True, exist_ok=True)
    proto.write_text(PLATE.format(default=default))
    colours: dict[Path, tuple[int, int, int]] = {}
    for k, (beside, url) in enumerate(files):       # a colour per file: the image tells which one is shown
        path = Path(os.path.normpath((proto.parent if beside else world_dir) / url))
        if path not in colours and path.is_relative_to(root):
            colours[path] = (10 + 20 * k, 250 - 15 * k, 5 * k)
            path.parent.mkdir(parents=True, exist_ok=True)
            Image.new("RGB", (2, 2), colours[path]).save(path)
    world = world_dir / "plate.wbt"
    world.write_text(PLATE_WORLD.format(proto=proto_rel, field=f'textureUrl "{written}"' if written else ""))

    sim = Simulation(load_world(world), "exact")
    lv = Live(sim)
    n = itertools.count()
    lv.core = Core(sim, new_token=lambda: f"s{next(n)}", log=lambda line: None)
    lv.ok(A, "attach", {"robot": "boss"})
    node = lv.ok(A, "/boss/robot/get_from_def", {"name": "P"})["node"]

    def shown() -> tuple[int, int, int] | None:
        (shape,) = sim.scene.solid_shapes("plate")
        texture = sim.scene.shape_model(shape).appearance.texture
        if texture is None:
            return None
        file = Path(os.path.normpath(world_dir / texture.url))
        image = Image.open(file).convert("RGB")
        return image.getpixel((0, 0))

    def want(url: str) -> tuple[int, int, int] | None:
        file = expected_file(url, proto, world_dir)
        return None if file is None else colours[file]

    url = written or default
    assert shown() == want(url), (url, "at load")
    for op in ops:
        if op is None:      # the url set stays (README: Webots' reset resets no field)
            lv.ok(A, "/boss/robot/simulation_reset")
        else:
            lv.ok(A, "/boss/robot/set_field", {"node": node, "field": "textureUrl", "value": op, "index": 0})
            url = op
        sim.step()
        assert shown() == want(url), (url, op)


file_places = st.lists(st.tuples(st.booleans(), st.sampled_from(URLS)), max_size=8)
url_ops = st.lists(st.one_of(st.none(), st.sampled_from(URLS)), max_size=4)


@pytest.mark.parametrize("examples", example_counts(300, 10))
def test_a_proto_fields_texture_is_read_beside_the_proto_then_in_the_worlds_folder(tmp_path, examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(st.sampled_from(WORLD_DIRS), st.sampled_from(PROTO_PLACES), file_places, st.sampled_from(URLS),
           st.one_of(st.none(), st.sampled_from(URLS)), url_ops)
    def run(world_rel: str, proto_rel: str, files: list, default: str, written: str | None, ops: list) -> None:
        try:
            textures_follow_webots_lookup(tmp_path / "case", world_rel, proto_rel, files, default, written, ops)
        finally:
            gc.collect()          # each Simulation's Embree device freed

    run()


def test_regression_a_cleaned_url_names_the_file_beside_the_proto_without_its_folder(tmp_path) -> None:
    """``tex/../t.png`` written for a PROTO's field names the t.png beside the PROTO (Webots cleans the path
    before it looks), where the folder tex missing there made it look in the world's folder only."""
    textures_follow_webots_lookup(tmp_path / "case", "w", "protos/Plate.proto",
                                  [(True, "t.png"), (False, "t.png"), (False, "tex/u.png")],
                                  "u.png", "tex/../t.png", ["tex/../t.png", None])
