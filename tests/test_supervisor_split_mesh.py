"""A mesh the .wbt import splits around a device inside it (wbt/inside.turn_meshes_away: the triangles
facing away from the device are hidden from it) is one Shape node to a Supervisor, as in Webots: the
robot's children, getFromDef and the node ids are those of the world file, and a colour, transparency
or texture url set on the Shape's nodes reaches every piece -- two cameras, one seeing each piece, see
the change bit for bit as the same world written with the new value -- and removing the Shape removes every
piece. Our own world and images."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sensorium.server.daemon import supervisor as sv
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

# The body BODY of robot "r" is two 1 m squares facing -x: one at x = 1, in front of the camera "inner" at
# the robot's origin (which sees it), one at x = -1, behind that camera (its front turned away: hidden from
# it), which the camera "outer" of robot "watcher" at x = -3 sees. The inner camera is within the mesh's
# box, so the import splits the mesh in two pieces. No DEF inside the Shape: a DEF'd node is shared by the
# shapes that hold it already, pieces or not.
WORLD = """#VRML_SIM R2023b utf8
WorldInfo {{ basicTimeStep 16 }}
DirectionalLight {{ direction 1 0 0 intensity 0 ambientIntensity 0.6 }}
Robot {{
  name "r"
  supervisor TRUE
  children [
    DEF BODY Shape {{
      appearance Appearance {{
        material Material {{ diffuseColor {diffuse} transparency {transparency} }}
        {texture}
      }}
      geometry IndexedFaceSet {{
        coord Coordinate {{ point [ 1 -0.5 -0.5, 1 0.5 -0.5, 1 0.5 0.5, 1 -0.5 0.5,
                                   -1 -0.5 -0.5, -1 0.5 -0.5, -1 0.5 0.5, -1 -0.5 0.5 ] }}
        coordIndex [ 0 3 2 1 -1 4 7 6 5 -1 ]
      }}
    }}
    Camera {{ name "inner" width 8 height 8 fieldOfView 1.2 }}
  ]
}}
Robot {{
  translation -3 0 0
  name "watcher"
  children [
    Camera {{ name "outer" width 8 height 8 fieldOfView 1.2 }}
  ]
}}
"""

DIFFUSE = "0.8 0.2 0.1"


def _world(folder: Path, name: str, diffuse: str = DIFFUSE, transparency: float = 0.0, url: str | None = None,
           body: bool = True) -> Path:
    texture = "" if url is None else f'texture ImageTexture {{ url [ "{url}" ] }}'
    text = WORLD.format(diffuse=diffuse, transparency=transparency, texture=texture)
    if not body:         # the world written without the Shape
        start = text.index("    DEF BODY Shape")
        text = text[:start] + text[text.index("    Camera {"):]
    path = folder / name
    path.write_text(text)
    return path


def _sim(path: Path) -> Simulation:
    sim = Simulation(load_world(path))
    sim.device("r/inner").enable(16)
    sim.device("watcher/outer").enable(16)
    return sim


def _images(sim: Simulation) -> tuple[bytes, bytes]:
    sim.step()
    return sim.device("r/inner").image.tobytes(), sim.device("watcher/outer").image.tobytes()


def _node(sim: Simulation, parent: sv.Node, *path: str) -> sv.Node:
    for field in path:
        parent = sv.node_by_id(sim, sv.get_field(sim, parent, field)["value"])
    return parent


@pytest.fixture
def images(tmp_path: Path) -> Path:
    from PIL import Image
    Image.new("RGB", (4, 4), (200, 100, 30)).save(tmp_path / "a.png")
    rng = np.random.default_rng(3)
    Image.fromarray(rng.integers(0, 256, (4, 4, 3), dtype=np.uint8)).save(tmp_path / "b.png")
    return tmp_path


def test_the_split_mesh_is_the_world_files_one_shape(tmp_path: Path) -> None:
    w = load_world(_world(tmp_path, "w.wbt"))
    assert len(w.world.robots[0].shapes) == 2                  # split: each camera sees one piece
    assert [s.unseen_by for s in w.world.robots[0].shapes] == [[], ["inner"]]
    sim = _sim(tmp_path / "w.wbt")
    robot = sv.find_node(sim, "r")
    kids = sv.get_field(sim, robot, "children")["value"]
    assert [sv.node_by_id(sim, i).type for i in kids] == ["Shape", "Camera"]
    body = sv.find_node(sim, "BODY")
    assert body is not None and body.id == kids[0]
    shapes = [n for n in sv._table(sim).nodes if n.type == "Shape"]
    assert len(shapes) == 1 and shapes[0].shape.peers == (0, 1)
    ids = [n.id for n in sv._table(sim).nodes]
    assert ids == list(range(ids[0], ids[0] + len(ids)))       # no id left out for a second piece


@pytest.mark.parametrize(("field", "value", "written"), [
    ("diffuseColor", [0.1, 0.7, 0.3], {"diffuse": "0.1 0.7 0.3"}),
    ("transparency", 0.5, {"transparency": 0.5}),
    ("transparency", 1.0, {"transparency": 1.0}),
])
def test_a_material_set_on_the_split_shape_reaches_every_piece(tmp_path: Path, field: str, value, written) -> None:
    sim = _sim(_world(tmp_path, "w.wbt"))
    before = _images(sim)
    sv.set_field(sim, _node(sim, sv.find_node(sim, "BODY"), "appearance", "material"), field, value)
    got = _images(sim)
    expect = _images(_sim(_world(tmp_path, "expect.wbt", **written)))
    assert got[0] != before[0] and got[1] != before[1]          # each camera sees its piece change
    assert got == expect


def test_a_texture_url_set_on_the_split_shape_reaches_every_piece(images: Path) -> None:
    sim = _sim(_world(images, "w.wbt", url="a.png"))
    before = _images(sim)
    tex = _node(sim, sv.find_node(sim, "BODY"), "appearance", "texture")
    sv.change_item(sim, tex, "url", "set", 0, "b.png")
    assert sv.get_field(sim, tex, "url")["value"] == ["b.png"]
    got = _images(sim)
    assert got[0] != before[0] and got[1] != before[1]
    assert got == _images(_sim(_world(images, "expect.wbt", url="b.png")))
    sim.reset()
    assert _images(sim) == before


def test_removing_the_split_shape_removes_every_piece(tmp_path: Path) -> None:
    sim = _sim(_world(tmp_path, "w.wbt"))
    before = _images(sim)
    body = sv.find_node(sim, "BODY")
    inside = [body.id + k for k in (1, 2, 3)]                    # its Appearance, Material, IndexedFaceSet
    assert [sv.node_by_id(sim, i).type for i in inside] == ["Appearance", "Material", "IndexedFaceSet"]
    sv.remove_node(sim, body)
    got = _images(sim)
    expect = _images(_sim(_world(tmp_path, "bare.wbt", body=False)))
    assert got[0] != before[0] and got[1] != before[1]
    assert got == expect
    assert sv.find_node(sim, "BODY") is None
    kids = sv.get_field(sim, sv.find_node(sim, "r"), "children")["value"]
    assert [sv.node_by_id(sim, i).type for i in kids] == ["Camera"]
    for i in [body.id, *inside]:
        assert sv.node_from_id(sim, i) is None                   # read as removed, never given again
    with pytest.raises(ValueError):
        sv.node_by_id(sim, body.id)
    sim.reset()                                                  # Webots' reset keeps a removed node removed
    assert _images(sim) == expect


def test_a_removed_shapes_shared_material_set_later_leaves_it_removed(tmp_path: Path) -> None:
    """Two Shapes share a DEF'd Material: one removed, a colour or transparency set through the other's
    changes that one only."""
    text = _world(tmp_path, "w.wbt").read_text()
    text = text.replace("material Material", "material DEF MAT Material").replace(
        '    Camera { name "inner"',
        "    Pose { translation 0 0 5 children [ Shape { appearance Appearance { material USE MAT } "
        "geometry Box { size 0.1 0.1 0.1 } } ] }\n    Camera { name \"inner\"")
    (tmp_path / "w.wbt").write_text(text)
    sim = _sim(tmp_path / "w.wbt")
    sv.remove_node(sim, sv.find_node(sim, "BODY"))
    gone = _images(sim)
    assert sv.find_node(sim, "MAT") is None                       # the DEF was inside the removed Shape
    (mat,) = [sv.node_by_id(sim, n.id) for n in sv._table(sim).nodes           # the USE: a node of its own
              if n.type == "Material" and sv.node_from_id(sim, n.id) is not None]
    sv.set_field(sim, mat, "diffuseColor", [0.0, 1.0, 0.0])
    sv.set_field(sim, mat, "transparency", 0.0)                  # (would show the removed pieces again)
    assert _images(sim) == gone
    assert sv.get_field(sim, mat, "diffuseColor")["value"] == [0.0, 1.0, 0.0]
