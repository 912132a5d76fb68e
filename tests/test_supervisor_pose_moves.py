"""A Supervisor's set of a Pose's translation or rotation inside a top-level solid that only moves shapes within it
(tests/worlds/pose_moves.wbt): its shapes placed anew, the solid not built again (sim/regenerate.py ``move_posed``),
with readings bit for bit those of the rebuild (a twin simulation with ``rebuild_pose_sets``): lidar ranges, camera
images and recognition objects, the distance sensor's value and every Pose's world pose and fields, through nested
Poses, a turned and a moved solid, a set back and forth, a Pose a Supervisor imported, a colour set before,
saveState/loadState and simulationReset; a Pose holding a light is built again (the fallback), the same readings
still.

Closed form (the world file's comment places everything): M1 set 0.3 m back along BOARD's x puts its box at
(2 − 0.3 cos 0.3, −0.3 sin 0.3, 0.1)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from test_multiprocess import REPO
from test_supervisor import A, Live

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WORLD = REPO / "tests" / "worlds" / "pose_moves.wbt"
POSED = ("M1", "OUTER", "INNER", "T", "LAMPED")


def _world(tmp_path) -> Path:
    """pose_moves.wbt with M1's box textured (8 x 8 seeded random texels, written here): the cameras read its
    texels through the shape's place (Scene ``_world_to_shape``)."""
    from PIL import Image

    texels = np.random.default_rng(3).integers(0, 256, (8, 8, 3), dtype=np.uint8)
    Image.fromarray(texels, "RGB").save(tmp_path / "checker.png")
    text = WORLD.read_text().replace("material Material {", 'texture ImageTexture { url [ "checker.png" ] }\n'
                                     "            material Material {", 1)
    assert "checker.png" in text
    (tmp_path / WORLD.name).write_text(text)
    return tmp_path / WORLD.name


def _live(rebuild: bool, path: Path) -> Live:
    lv = Live(Simulation(load_world(path)))
    lv.sim.rebuild_pose_sets = rebuild
    lv.ok(A, "attach", {"robot": "probe"})
    bot = lv.sim.robot("probe")
    for device in ("lidar", "camera", "ds"):
        bot.device(device).enable(8)
    bot.device("camera").recognition_enable(8)
    return lv


def call(lv: Live, item: str, args: dict | None = None):
    return lv.ok(A, f"/probe/robot/{item}", args)


def node(lv: Live, name: str) -> int:
    return call(lv, "get_from_def", {"name": name})["node"]


def readings(lv: Live) -> tuple:
    """Every device's reading after a step, and the world pose of every Pose (and of what it holds: NaN for a
    shape, as in Webots) and its translation and rotation fields, as bytes."""
    lv.step(A, "probe")
    bot = lv.sim.robot("probe")
    poses = []
    for name in POSED:
        n = node(lv, name)
        for m in [n, *call(lv, "get_field", {"node": n, "field": "children"})["value"]]:
            pose = call(lv, "get_node_pose", {"node": m})
            poses.append(np.asarray(pose["position"] + pose["orientation"], dtype=np.float64).tobytes())
        own = [call(lv, "get_field", {"node": n, "field": f})["value"] for f in ("translation", "rotation")]
        poses.append(np.asarray(own[0] + own[1], dtype=np.float64).tobytes())
    objects = bot.device("camera").objects
    assert len(objects) == 1                                    # BOARD recognised
    return (np.asarray(bot.device("lidar").range_image, dtype=np.float64).tobytes(),
            np.asarray(bot.device("camera").image).tobytes(), np.float64(bot.device("ds").value).tobytes(),
            repr([o.as_dict() for o in objects]), *poses)


class Twins:
    """The same calls on a simulation placing shapes anew and on one building the solid again."""

    def __init__(self, path: Path) -> None:
        self.fast, self.rebuilt = _live(False, path), _live(True, path)

    def set(self, name: str, field: str, value: list[float]) -> None:
        for lv in (self.fast, self.rebuilt):
            call(lv, "set_field", {"node": node(lv, name), "field": field, "value": value})

    def call(self, item: str, name: str, args: dict) -> None:
        for lv in (self.fast, self.rebuilt):
            call(lv, item, {"node": node(lv, name), **args})

    def same(self) -> tuple:
        fast, rebuilt = readings(self.fast), readings(self.rebuilt)
        assert fast == rebuilt
        return fast

    def regenerations(self) -> tuple[int, int]:
        return tuple(lv.sim.counters.get("regenerations", 0) for lv in (self.fast, self.rebuilt))


def test_sets_that_move_shapes_read_bit_for_bit_as_the_rebuild_without_building_the_solid_again(tmp_path):
    t = Twins(_world(tmp_path))
    loaded = t.same()
    t.set("M1", "translation", [-0.3, 0.0, 0.0])
    moved = t.same()
    assert moved[0] != loaded[0] and moved[1] != loaded[1]      # the lidar and the camera see the box move
    at = call(t.fast, "get_node_pose", {"node": node(t.fast, "M1")})["position"]
    assert at == pytest.approx([2.0 - 0.3 * math.cos(0.3), -0.3 * math.sin(0.3), 0.1], abs=1e-15)
    t.set("INNER", "translation", [0.0, -0.1, 0.05])            # a Pose inside a Pose
    t.same()
    t.set("OUTER", "rotation", [0.0, 0.0, 1.0, -0.7])           # a Pose holding a Pose and a Group
    t.same()
    t.set("T", "translation", [-0.2, -0.2, 0.0])                # an unscaled Transform
    t.same()
    assert t.regenerations() == (0, 4)
    t.set("M1", "translation", [0.0, 0.0, 0.0])                 # back where it was loaded
    t.set("M1", "translation", [-0.3, 0.0, 0.0])                # and forth
    t.same()
    t.set("LAMPED", "translation", [0.0, -0.5, 0.0])            # holds a light: built again on both
    assert t.regenerations() == (1, 7)
    t.same()
    t.set("M1", "rotation", [0.0, 1.0, 0.0, 0.5])               # after a rebuild, placed anew again
    assert t.regenerations() == (1, 8)
    t.same()
    t.call("import_node_from_string", "OUTER", {"field": "children", "position": -1, "node_string":
           "DEF NEW Pose { translation -0.4 0 0 children [ Shape { geometry Box { size 0.1 0.3 0.1 } } ] }"})
    assert t.regenerations() == (2, 9)                          # an import builds the solid again
    t.same()
    t.set("NEW", "translation", [-0.2, -0.3, 0.0])              # a Pose a Supervisor imported
    t.set("OUTER", "translation", [0.0, 0.1, 0.0])              # one holding it
    assert t.regenerations() == (2, 11)
    t.same()


def test_a_turned_moved_solid_a_colour_set_before_saved_states_and_a_reset(tmp_path):
    t = Twins(_world(tmp_path))
    loaded = t.same()
    t.call("set_field", "BOARD", {"field": "translation", "value": [2.2, 0.1, 0.1]})
    t.call("set_field", "BOARD", {"field": "rotation", "value": [0.0, 0.0, 1.0, -0.5]})
    for lv in (t.fast, t.rebuilt):
        shape = call(lv, "get_field", {"node": node(lv, "M1"), "field": "children"})["value"][0]
        appearance = call(lv, "get_field", {"node": shape, "field": "appearance"})["value"]
        material = call(lv, "get_field", {"node": appearance, "field": "material"})["value"]
        call(lv, "set_field", {"node": material, "field": "diffuseColor", "value": [0.0, 0.0, 1.0]})
    t.set("M1", "translation", [-0.2, 0.1, 0.0])
    t.set("OUTER", "translation", [0.1, 0.2, 0.0])
    saved = t.same()
    t.call("save_node_state", "BOARD", {"state": "s"})
    t.set("M1", "translation", [0.3, -0.2, 0.1])
    t.set("INNER", "rotation", [1.0, 0.0, 0.0, 0.3])
    assert t.same() != saved
    t.call("load_node_state", "BOARD", {"state": "s"})
    assert t.same() == saved
    assert t.regenerations()[0] == 0
    for lv in (t.fast, t.rebuilt):
        call(lv, "simulation_reset")
    assert t.same() == loaded
    t.set("M1", "translation", [-0.3, 0.0, 0.0])                # after the reset (which built the solid again)
    t.same()
