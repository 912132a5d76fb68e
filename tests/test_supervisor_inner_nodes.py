"""The nodes inside a solid a Supervisor imported (README "Supervisor"), on tests/worlds/supervisor_inner_nodes.wbt:
served as a world file's solid's are: found by DEF (``BOX.INNER`` too) and through ``children`` and SFNode fields,
new ids never reused, their fields read as written; an inner solid's position is the import's pose composed with
its own (closed form); a colour set on an imported shape is what the camera sees, bit for bit as the world file
written with that colour (closed form: an ambient-only light of 0.5 on a flat face, a pixel is
``round(255 (1 - e^(-0.5 albedo))^(1/2.2))``); removed with their solid (one line), let go for good (memory
stays that of the solids there now). The same from a Python controller through ``sensorium serve``, which also
hides the wall (transparency 1), half shows it and shows it again, and from a C and a C++ controller (built with
sanitizers) printing the Python one's lines."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from _serve import run_controller, sensorium
from test_multiprocess import REPO

from sensorium.server.daemon import supervisor as sv
from sensorium.server.daemon import visuals
from sensorium.server.daemon.nested import FIRST_ID
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WORLD = REPO / "tests" / "worlds" / "supervisor_inner_nodes.wbt"
AMBIENT = 0.5

# the wall's face at x = 1.95 fills the camera's view; INNER (with its shape KNOB) stands behind it
WALL = ('DEF BOX Solid { translation 2 0 0 name "wall" children [ '
        'Shape { appearance PBRAppearance { baseColor 1 0 0 roughness 1 metalness 0 } geometry Box { size 0.1 20 20 } } '
        'DEF INNER Solid { translation 0.3 -0.4 1.5 rotation 0 1 0 0.7 name "inner" children [ '
        'DEF KNOB Shape { appearance Appearance { material Material { diffuseColor 0 0 1 } } '
        'geometry Sphere { radius 0.05 } } ] } ] }')
# behind the camera: a turned crate holding a tilted lid
CRATE = ('DEF CRATE Solid { translation -1 3 0.5 rotation 0 0 1 0.5 name "crate" children [ '
         'DEF LID Solid { translation 0.2 0.1 0.3 rotation 1 0 0 0.25 name "lid" } ] }')


def expected_bytes(albedo) -> list[int]:
    """Webots' HDR resolve of an ambient-lit face, RGB bytes."""
    light = AMBIENT * np.asarray(albedo, dtype=np.float64)
    return np.floor(255.0 * (1.0 - np.exp(-light)) ** (1.0 / 2.2) + 0.5).astype(np.int64).tolist()


def _sim(path=WORLD) -> Simulation:
    sim = Simulation(load_world(path))
    sim.device("looker/cam").enable(16)
    return sim


def _shot(sim: Simulation) -> np.ndarray:
    sim.run(1)
    return sim.device("looker/cam").image.copy()


def _written(tmp_path, text: str) -> Simulation:
    """The world file holding ``text`` as its last top-level node."""
    path = tmp_path / f"written{len(list(tmp_path.glob('written*.wbt')))}.wbt"
    path.write_text(WORLD.read_text() + text + "\n")
    return _sim(path)


def field(sim, node, name):
    return sv.get_field(sim, node, name)["value"]


def _imported(text: str = WALL + " " + CRATE) -> tuple[Simulation, list[int]]:
    sim = _sim()
    return sim, sv.import_nodes(sim, sv.ROOT, "children", -1, text)


def rot(axis, angle) -> np.ndarray:
    """Rodrigues: the rotation matrix of Webots' axis-angle."""
    k = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
    cross = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(angle) * cross + (1 - math.cos(angle)) * cross @ cross


def test_the_nodes_inside_an_import_are_found_by_def_and_through_their_fields():
    sim, (box_id, crate_id) = _imported()
    box = sv.node_by_id(sim, box_id)
    shape_id, inner_id = field(sim, box, "children")          # file order
    shape, inner = sv.node_by_id(sim, shape_id), sv.node_by_id(sim, inner_id)
    assert (shape.type, inner.type, inner.def_name, inner.name) == ("Shape", "Solid", "INNER", "inner")
    assert all(FIRST_ID <= i < visuals.FIRST_ID for i in (shape_id, inner_id))
    assert sv.find_node(sim, "BOX.INNER") == inner == sv.find_node(sim, "INNER")
    assert sv.node_ref(sim, inner)["parent"] == box_id and sv.node_ref(sim, shape)["parent"] == box_id
    app = sv.node_by_id(sim, field(sim, shape, "appearance"))
    geometry = sv.node_by_id(sim, field(sim, shape, "geometry"))
    assert (app.type, field(sim, app, "baseColor"), field(sim, app, "roughness")) == ("PBRAppearance", [1.0, 0, 0], 1.0)
    assert (geometry.type, field(sim, geometry, "size")) == ("Box", [0.1, 20.0, 20.0])
    # the inner solid's fields as written, its own children
    assert field(sim, inner, "translation") == [0.3, -0.4, 1.5] and field(sim, inner, "name") == "inner"
    assert field(sim, inner, "rotation") == pytest.approx([0.0, 1.0, 0.0, 0.7], abs=1e-15)
    (knob_id,) = field(sim, inner, "children")
    knob = sv.find_node(sim, "BOX.INNER.KNOB")
    assert knob is not None and knob.id == knob_id == sv.find_node(sim, "KNOB").id
    material = sv.node_by_id(sim, field(sim, sv.node_by_id(sim, field(sim, knob, "appearance")), "material"))
    assert (material.type, field(sim, material, "diffuseColor")) == ("Material", [0.0, 0.0, 1.0])
    # the second import's nodes come after the first's
    (lid_id,) = field(sim, sv.node_by_id(sim, crate_id), "children")
    assert lid_id > max(shape_id, inner_id, knob_id, material.id) and sv.find_node(sim, "CRATE.LID").id == lid_id
    assert sv.find_node(sim, "BOX.LID") is None                # a dotted path walks direct children only


def test_an_inner_solids_pose_is_the_imports_pose_composed_with_its_own():
    sim, (_, crate_id) = _imported()
    crate = sv.node_by_id(sim, crate_id)
    lid = sv.find_node(sim, "CRATE.LID")
    for translation, turn in (([-1.0, 3.0, 0.5], 0.5), ([0.5, -2.0, 1.0], -1.2)):
        if turn != 0.5:                                        # the Supervisor moves the crate: the lid follows
            sv.set_field(sim, crate, "translation", translation)
            sv.set_field(sim, crate, "rotation", [0.0, 0.0, 1.0, turn])
        pose = sv.node_pose(sim, lid)
        want = np.asarray(translation) + rot([0, 0, 1], turn) @ np.array([0.2, 0.1, 0.3])
        np.testing.assert_allclose(pose["position"], want, rtol=0, atol=1e-12)
        np.testing.assert_allclose(np.reshape(pose["orientation"], (3, 3)),
                                   rot([0, 0, 1], turn) @ rot([1, 0, 0], 0.25), rtol=0, atol=1e-12)
        assert field(sim, lid, "translation") == [0.2, 0.1, 0.3]   # in its parent's frame: unchanged
    box = sv.find_node(sim, "BOX")
    inner = sv.node_pose(sim, sv.find_node(sim, "BOX.INNER"))
    assert inner["position"] == [2.3, -0.4, 1.5] and field(sim, box, "translation") == [2.0, 0.0, 0.0]


def test_a_colour_set_on_an_imported_shape_is_seen_as_a_world_file_with_that_colour(tmp_path):
    sim, _ = _imported(WALL)
    red = _shot(sim)
    assert np.array_equal(red, _shot(_written(tmp_path, WALL)))
    assert red[2, 2, :3][::-1].tolist() == expected_bytes([1, 0, 0])     # BGRA
    shape = sv.node_by_id(sim, field(sim, sv.find_node(sim, "BOX"), "children")[0])
    app = sv.node_by_id(sim, field(sim, shape, "appearance"))
    sv.set_field(sim, app, "baseColor", [0.2, 0.6, 0.9])
    assert field(sim, app, "baseColor") == [0.2, 0.6, 0.9]
    seen = _shot(sim)
    assert np.array_equal(seen, _shot(_written(tmp_path, WALL.replace("baseColor 1 0 0", "baseColor 0.2 0.6 0.9"))))
    assert seen[2, 2, :3][::-1].tolist() == expected_bytes([0.2, 0.6, 0.9]) != expected_bytes([1, 0, 0])
    # half transparent: as the file saying so
    sv.set_field(sim, app, "transparency", 0.5)
    assert np.array_equal(_shot(sim), _shot(_written(tmp_path, WALL.replace(
        "baseColor 1 0 0", "baseColor 0.2 0.6 0.9 transparency 0.5"))))


def test_a_texture_url_set_on_an_imported_shape_is_seen_as_the_world_file_with_that_url(tmp_path):
    from PIL import Image

    Image.new("RGB", (4, 4), (200, 100, 30)).save(tmp_path / "a.png")
    Image.fromarray(np.random.default_rng(7).integers(0, 256, (4, 4, 3), dtype=np.uint8)).save(tmp_path / "b.png")
    textured = WALL.replace("PBRAppearance { baseColor 1 0 0 roughness 1 metalness 0 }",
                            'Appearance { material Material { } texture ImageTexture { url [ "a.png" ] } }')
    (tmp_path / "world.wbt").write_text(WORLD.read_text())
    sim = _sim(tmp_path / "world.wbt")                     # urls resolve against the world file's folder
    sv.import_nodes(sim, sv.ROOT, "children", -1, textured)
    shape = sv.node_by_id(sim, field(sim, sv.find_node(sim, "BOX"), "children")[0])
    texture = sv.node_by_id(sim, field(sim, sv.node_by_id(sim, field(sim, shape, "appearance")), "texture"))
    assert (texture.type, field(sim, texture, "url")) == ("ImageTexture", ["a.png"])
    assert np.array_equal(_shot(sim), _shot(_written(tmp_path, textured)))
    sv.change_item(sim, texture, "url", "set", 0, "b.png")
    assert field(sim, texture, "url") == ["b.png"]
    seen = _shot(sim)
    assert np.array_equal(seen, _shot(_written(tmp_path, textured.replace("a.png", "b.png"))))
    assert not np.array_equal(seen, _shot(_written(tmp_path, textured)))


def test_a_removed_imports_inner_nodes_read_as_removed_and_their_ids_are_never_given_again():
    sim, (box_id, _) = _imported()
    inner = sv.find_node(sim, "BOX.INNER")
    knob = sv.find_node(sim, "KNOB")
    sv.remove_node(sim, sv.node_by_id(sim, box_id))
    for gone in (inner, knob):
        assert sv.node_from_id(sim, gone.id) is None
        with pytest.raises(ValueError) as err:
            sv.node_by_id(sim, gone.id)
        assert str(err.value) == f"node {gone.id} was removed with the imported or rebuilt solid holding it"
    assert sv.find_node(sim, "INNER") is None and sv.find_node(sim, "BOX.INNER") is None
    assert sv.find_node(sim, "CRATE.LID") is not None                 # the other import's are still there
    (again,) = sv.import_nodes(sim, sv.ROOT, "children", -1, WALL)
    new_inner = sv.find_node(sim, "BOX.INNER")
    assert sv.find_node(sim, "BOX").id == again and new_inner.id > knob.id      # new ids, never the removed ones'
    assert sv.node_pose(sim, new_inner)["position"] == [2.3, -0.4, 1.5]
    sim.reset()                                      # Webots' reset removes what a Supervisor imported
    assert sv.node_from_id(sim, new_inner.id) is None and sv.find_node(sim, "LID") is None


def test_many_import_and_remove_cycles_keep_the_table_the_size_of_what_is_there():
    sim = _sim()
    table = sv._table(sim)

    def size() -> tuple[int, int, int, int]:
        return len(table.added), len(table.by_owner), len(table.by_parent), len(table.inner or {})

    fresh = size()
    ids = []
    for k in range(300):
        (box,) = sv.import_nodes(sim, sv.ROOT, "children", -1, WALL)
        inner = sv.find_node(sim, "BOX.INNER")              # looked at: numbered
        ids.append(inner.id)
        shape = sv.node_by_id(sim, field(sim, sv.node_by_id(sim, box), "children")[0])
        sv.set_field(sim, sv.node_by_id(sim, field(sim, shape, "appearance")), "baseColor", [0.1, 0.01 * (k % 50), 0])
        sv.remove_node(sim, sv.node_by_id(sim, box))
    sv.find_node(sim, "BOX")
    assert size() == fresh and sv._table(sim) is table
    assert ids == sorted(set(ids))                        # never reused
    (box,) = sv.import_nodes(sim, sv.ROOT, "children", -1, WALL)
    assert sv.find_node(sim, "BOX.INNER").id > ids[-1]
    # one wall there: its 8 nodes (Shape, PBRAppearance, Box, INNER, KNOB, Appearance, Material, Sphere) under
    # 5 parents (the wall, its Shape, INNER, KNOB, the Appearance)
    assert size() == (fresh[0] + 8, fresh[1] + 1, fresh[2] + 5, fresh[3])


EXPECTED = [
    "children 2 Shape Solid",
    "inner INNER inner 1",
    f"position {2.3:.6f} {-0.4:.6f} {1.5:.6f}",
    "lid " + " ".join(f"{v:.6f}" for v in np.array([-1, 3, 0.5]) + rot([0, 0, 1], 0.5) @ np.array([0.2, 0.1, 0.3])),
    "before " + " ".join(map(str, expected_bytes([1, 0, 0]))),
    "after " + " ".join(map(str, expected_bytes([0.2, 0.6, 0.9]))),
    "hidden 0 0 0",                                   # transparency 1: the world's black background
    "half " + " ".join(map(str, expected_bytes([0.1, 0.3, 0.45]))),      # 0.5: half the face's light
    "shown " + " ".join(map(str, expected_bytes([0.2, 0.6, 0.9]))),
    "removed 1 1",
]


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_python_supervisor_reaches_the_nodes_inside_what_it_imported() -> None:
    lines, err = run_controller(WORLD, lambda url: sensorium(
        "controller", "--url", url, str(REPO / "tests" / "controllers" / "supervisor_inner_nodes.py")), robot="looker")
    assert lines == EXPECTED, err


@pytest.fixture(scope="module")
def c_supervisors(tmp_path_factory) -> dict[str, str]:
    """tests/c/supervisor_inner_nodes.c and its C++ twin linked to the library built with sanitizers."""
    import shutil
    import subprocess

    from test_c_client import CLIB, TESTS_C, _make, sanitized_controller

    c_exe = sanitized_controller(tmp_path_factory, TESTS_C / "supervisor_inner_nodes.c")
    if shutil.which("c++") is None:
        pytest.skip("needs a C++ toolchain")
    build = Path(c_exe).parent
    cpp_exe = build / "supervisor_inner_nodes_cpp"
    done = subprocess.run(["c++", "-std=c++11", "-Wall", "-Wextra", "-Werror", "-g", "-fsanitize=address,undefined",
                           f"-I{CLIB / 'include'}", str(TESTS_C / "supervisor_inner_nodes_cpp.cpp"), "-o", str(cpp_exe),
                           str(build / "libController.a"), *_make("libs").split()],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return {"c": c_exe, "cpp": str(cpp_exe)}


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
@pytest.mark.parametrize("language", ["c", "cpp"])
def test_a_c_or_cpp_supervisor_prints_what_the_python_one_prints(c_supervisors, language) -> None:
    from test_c_client import SAN_ENV

    lines, err = run_controller(WORLD, lambda url: [c_supervisors[language]], env=SAN_ENV, robot="looker")
    assert "Sanitizer" not in err and "runtime error" not in err, err
    assert lines == EXPECTED, err
