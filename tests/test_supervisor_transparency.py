"""A Supervisor's ``transparency`` set across 0 and 1 (opaque ↔ translucent ↔ invisible): from the
next step every sensor reads the shape exactly as a world file written with that value -- cameras
(shadows included), range finders, lidars, infra-red, sonar and laser distance sensors, a light sensor
behind it, a camera's recognition and segmentation -- for a static solid's shape and for a robot's
own shape (a moving body, seen by its own infra-red sensor and lidar); ``USE``d appearances follow; a reset brings the loaded value back; hiding
and showing a shape again and again keeps the engine's tables bounded. A texture url whose image's
pixel format has alpha (or no longer has it) changes the shape's shadows the same way."""

from __future__ import annotations

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.daemon import supervisor as sv
from sensorium.server.sim.simulation import Simulation

TABLE = [[0.0, 0.0, 0.0], [10.0, 1000.0, 0.0]]
DEVICES = ("cam", "rf", "lidar", "ir", "sonar", "laser", "ls")
READINGS = (*DEVICES, "objects", "segmentation")       # and the camera's recognition
CHAIN = (0.0, 0.5, 1.0, 0.0, 1.0, 0.5, 0.0)      # every ordered crossing of 0 and 1 once: 0→½→1→0→1→½→0
BLUE = [0.3, 0.6, 0.9]


def world(transparency: float, target: str) -> wm.World:
    """A wall 2 m ahead lit by a shadow-casting lamp, a block 1 m ahead casting its shadow on it, a
    robot's visor 0.5 m ahead of its own sensors (a shape of the robot's body), a light sensor between
    block and wall facing the lamp (the block occludes it); ``target`` ("block" or "visor") takes the
    ``transparency``."""
    def app(name):
        return {"base_color": BLUE, "transparency": transparency if target == name else 0.0}

    return wm.World.model_validate({
        "world_info": {"basic_time_step": 16, "random_seed": 3},
        "lights": [{"type": "PointLight", "location": [0.3, 0.0, 0.05], "intensity": 1.0, "ambient_intensity": 0.2,
                    "cast_shadows": True}],
        "solids": [{"name": "wall", "pose": {"translation": [2.0, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.1, 20, 20]},
                    "appearance": {"base_color": [0.8, 0.5, 0.2]}},
                   {"name": "block", "pose": {"translation": [1.0, 0.0, 0.0]}, "recognition_colors": [[1, 0, 0]],
                    "geometry": {"type": "box", "size": [0.1, 0.4, 0.4]}, "appearance": app("block")},
                   {"name": "ball", "pose": {"translation": [1.8, 0.1, 0.0]}, "recognition_colors": [[0, 1, 0]],
                    "geometry": {"type": "sphere", "radius": 0.05}}],
        "robots": [{"name": "r", "supervisor": True,
                    "shapes": [{"name": "visor", "pose": {"translation": [0.5, 0.1, 0.0]},
                                "geometry": {"type": "box", "size": [0.02, 0.2, 0.3]}, "appearance": app("visor")},
                               # housings behind the camera, range finder and lidar: those devices then
                               # keep their rays' hits on their robot's body between casts (own_shapes.py)
                               *({"name": f"{d}_housing", "of_device": d, "pose": {"translation": [-0.05, 0.0, 0.0]},
                                  "geometry": {"type": "box", "size": [0.02, 0.02, 0.02]}} for d in ("cam", "rf", "lidar"))],
                    "devices": [
                        {"device": "Camera", "name": "cam", "width": 21, "height": 21, "field_of_view": 1.0,
                         "recognition": {"occlusion": 1, "segmentation": True}},
                        {"device": "RangeFinder", "name": "rf", "width": 11, "height": 11, "field_of_view": 1.0,
                         "max_range": 10},
                        {"device": "Lidar", "name": "lidar", "horizontal_resolution": 32, "field_of_view": 1.0,
                         "number_of_layers": 4, "vertical_field_of_view": 0.4, "max_range": 10},
                        {"device": "DistanceSensor", "name": "ir", "type": "infra-red", "lookup_table": TABLE,
                         "number_of_rays": 3, "aperture": 0.3},
                        {"device": "DistanceSensor", "name": "sonar", "type": "sonar", "lookup_table": TABLE,
                         "number_of_rays": 3, "aperture": 0.3},
                        {"device": "DistanceSensor", "name": "laser", "type": "laser", "lookup_table": TABLE},
                        {"device": "LightSensor", "name": "ls", "occlusion": True, "lookup_table": TABLE,
                         "pose": {"translation": [1.5, 0.0, 0.0], "rotation": [0, 0, 1, 3.141592653589793]}}]}]})


def _sim(w: wm.World, precision: str) -> Simulation:
    sim = Simulation(w, precision=precision)
    for d in DEVICES:
        sim.device(f"r/{d}").enable(16)
    sim.device("r/cam").recognition_enable(16)
    sim.device("r/cam").enable_segmentation(True)
    return sim


def readings(sim: Simulation) -> dict[str, object]:
    dev = {d: sim.device(f"r/{d}") for d in DEVICES}
    return {"cam": dev["cam"].image.copy(), "rf": dev["rf"].range_image.copy(), "lidar": dev["lidar"].range_image.copy(),
            **{d: float(dev[d].value) for d in ("ir", "sonar", "laser", "ls")},
            "objects": repr(dev["cam"].objects), "segmentation": dev["cam"].segmentation_image.copy()}


def same(a: dict, b: dict) -> list[str]:
    """The devices whose readings differ (NaN equal to NaN; arrays bit for bit)."""
    return [d for d in READINGS if not (a[d] == b[d] if isinstance(a[d], str) else
                                        np.array_equal(np.asarray(a[d]), np.asarray(b[d]), equal_nan=True))]


def _appearance(sim: Simulation, target: str):
    if target == "block":
        (shape,) = sv.get_field(sim, sv.find_node(sim, "block"), "children")["value"]
    else:
        shape = [i for i in sv.get_field(sim, sv.find_node(sim, "r"), "children")["value"]
                 if sv.node_by_id(sim, i).type == "Shape"][0]
    return sv.node_by_id(sim, sv.get_field(sim, sv.node_by_id(sim, shape), "appearance")["value"])


@pytest.mark.parametrize("precision", ["exact", "fast"])
@pytest.mark.parametrize("target", ["block", "visor"])
def test_each_crossing_reads_as_the_world_file_with_that_transparency(target: str, precision: str):
    refs: dict[float, dict] = {}
    steps = 0
    sim = _sim(world(CHAIN[0], target), precision)
    app = _appearance(sim, target)
    for value in CHAIN[1:]:
        sv.set_field(sim, app, "transparency", value)
        assert sv.get_field(sim, app, "transparency")["value"] == value
        sim.run(1)
        steps += 1
        ref = _sim(world(value, target), precision)
        ref.run(steps)
        refs[value] = readings(ref)
        assert same(readings(sim), refs[value]) == [], (target, value)
    # the three worlds are told apart by these sensors (else the comparison above proves nothing):
    # hidden, the shape is no longer seen by visual rays; translucent, it casts no shadow
    opaque, clear, hidden = refs[0.0], refs[0.5], refs[1.0]
    seen_by_visual_rays = {"cam", "rf", "lidar", "ir", "segmentation"} | (
        {"laser", "objects"} if target == "block" else set())     # (hidden, the block no longer hides the ball)
    assert seen_by_visual_rays <= set(same(opaque, hidden))      # (a laser skips its own robot, as Webots' rays)
    assert "cam" in same(opaque, clear) and "ir" in same(opaque, clear)      # shadow and blending; red·(1 − t)
    assert opaque["rf"].tolist() == clear["rf"].tolist()                      # seen as opaque by depth rays
    if target == "block":   # bounding rays (sonar, light occlusion) meet the block whatever its transparency
        assert opaque["sonar"] == hidden["sonar"] < 1000.0 and opaque["ls"] == hidden["ls"]


def test_a_reset_brings_the_loaded_transparency_back():
    sim = _sim(world(0.0, "block"), "exact")
    sim.run(1)
    first = readings(sim)
    sv.set_field(sim, _appearance(sim, "block"), "transparency", 1.0)
    sim.run(1)
    assert same(readings(sim), first)
    sim.reset()
    for d in DEVICES:
        sim.device(f"r/{d}").enable(16)
    sim.run(1)
    assert same(readings(sim), first) == []


def test_hiding_and_showing_again_and_again_keeps_the_tables_bounded():
    sim = _sim(world(0.0, "visor"), "fast")
    apps = [_appearance(sim, "block"), _appearance(sim, "visor")]
    engine = sim.scene.engine
    counts = []
    for _ in range(40):
        for value in (0.5, 1.0, 0.0):
            for app in apps:
                sv.set_field(sim, app, "transparency", value)
            sim.run(1)
        counts.append((engine.held_tiers, engine.shape_count, len(sim.scene.shapes), len(sim.scene.transparency)))
    assert counts[-1] == counts[1] and len(set(counts[1:])) == 1, counts[:3]
    assert engine.shape_count == 7 and engine.seen_version == 40 * 3 * 2


USE_WORLD = """#VRML_SIM R2023b utf8
WorldInfo {
  basicTimeStep 16
}
PointLight {
  location 0.3 0 0.05
  intensity 1
  ambientIntensity 0.2
  castShadows TRUE
}
Solid {
  translation 2 0 0
  name "wall"
  children [
    Shape {
      appearance PBRAppearance {
        baseColor 0.8 0.5 0.2
        metalness 0
      }
      geometry Box {
        size 0.1 20 20
      }
    }
  ]
}
Solid {
  translation 1 0.15 0
  name "left"
  children [
    Shape {
      appearance DEF BLOCK_APP PBRAppearance {
        baseColor 0.3 0.6 0.9
        metalness 0
        transparency T_PBR
      }
      geometry Box {
        size 0.1 0.2 0.4
      }
    }
    Shape {
      appearance Appearance {
        material DEF BLOCK_MAT Material {
          diffuseColor 0.9 0.2 0.1
          transparency T_MAT
        }
      }
      geometry Box {
        size 0.1 0.2 0.2
      }
    }
  ]
}
Solid {
  translation 1 -0.15 0
  name "right"
  children [
    Shape {
      appearance USE BLOCK_APP
      geometry Box {
        size 0.1 0.2 0.4
      }
    }
    Shape {
      appearance Appearance {
        material USE BLOCK_MAT
      }
      geometry Box {
        size 0.1 0.2 0.2
      }
    }
  ]
}
Robot {
  name "r"
  supervisor TRUE
  controller "<extern>"
  children [
    Camera {
      name "cam"
      width 21
      height 21
      fieldOfView 1
    }
    DistanceSensor {
      rotation 0 0 1 -0.15
      name "ir"
      type "infra-red"
      lookupTable [ 0 0 0, 10 1000 0 ]
    }
  ]
}
"""


def _use_world(tmp_path, t_pbr: float, t_mat: float) -> Simulation:
    from sensorium.server.world.loader import load_world

    path = tmp_path / f"use_{t_pbr}_{t_mat}.wbt"
    path.write_text(USE_WORLD.replace("T_PBR", repr(t_pbr)).replace("T_MAT", repr(t_mat)))
    sim = Simulation(load_world(path))
    for d in ("cam", "ir"):
        sim.device(f"r/{d}").enable(16)
    return sim


def _use_readings(sim: Simulation) -> tuple[np.ndarray, float]:
    sim.run(1)
    return sim.device("r/cam").image.copy(), float(sim.device("r/ir").value)


def test_a_defd_appearance_or_material_crosses_in_every_shape_that_uses_it(tmp_path):
    sim = _use_world(tmp_path, 0.0, 0.0)
    use_app = sv.node_by_id(sim, sv.get_field(sim, sv.node_by_id(sim, sv.get_field(
        sim, sv.find_node(sim, "right"), "children")["value"][0]), "appearance")["value"])
    assert use_app.def_name == "" and use_app.type == "PBRAppearance"     # the USE, a node of its own
    for t_pbr, t_mat, node in ((1.0, 0.0, "BLOCK_APP"), (1.0, 0.5, "BLOCK_MAT"), (0.5, 0.5, use_app),
                               (0.5, 1.0, "BLOCK_MAT"), (0.5, 0.0, "BLOCK_MAT"), (0.0, 0.0, "BLOCK_APP")):
        target = sv.find_node(sim, node) if isinstance(node, str) else node
        sv.set_field(sim, target, "transparency", t_mat if target.type == "Material" else t_pbr)
        got, ref = _use_readings(sim), _use_readings(_use_world(tmp_path, t_pbr, t_mat))
        assert np.array_equal(got[0], ref[0]) and got[1] == ref[1], (t_pbr, t_mat)
    hidden, shown = _use_readings(_use_world(tmp_path, 1.0, 1.0)), _use_readings(_use_world(tmp_path, 0.0, 0.0))
    assert not np.array_equal(hidden[0], shown[0]) and hidden[1] != shown[1]


def _textured(image: str, base_dir) -> Simulation:
    w = world(0.0, "block").model_dump()
    w["solids"][1]["appearance"] = {"texture": {"url": image}}
    sim = Simulation(wm.World.model_validate(w), base_dir=base_dir)
    for d in DEVICES:
        sim.device(f"r/{d}").enable(16)
    return sim


def test_a_url_whose_image_has_alpha_lets_the_light_through_as_the_world_file_naming_it(tmp_path):
    from PIL import Image

    Image.new("RGB", (2, 2), (200, 120, 40)).save(tmp_path / "rgb.png")
    Image.new("RGBA", (2, 2), (200, 120, 40, 255)).save(tmp_path / "rgba.png")   # the same colours, alpha 255
    sim = _textured("rgb.png", tmp_path)
    (shape,) = sv.get_field(sim, sv.find_node(sim, "block"), "children")["value"]
    app = sv.node_by_id(sim, sv.get_field(sim, sv.node_by_id(sim, shape), "appearance")["value"])
    tex = sv.node_by_id(sim, sv.get_field(sim, app, "baseColorMap")["value"])
    refs = {}
    for steps, image in enumerate(("rgba.png", "rgb.png", "rgba.png"), start=1):
        sv.change_item(sim, tex, "url", "set", 0, image)
        sim.run(1)
        ref = _textured(image, tmp_path)
        ref.run(steps)
        refs[image] = readings(ref)
        assert same(readings(sim), refs[image]) == [], image
    # the block's shadow on the wall is the only difference: an RGBA image makes it translucent (Webots)
    assert same(refs["rgb.png"], refs["rgba.png"]) == ["cam"]
