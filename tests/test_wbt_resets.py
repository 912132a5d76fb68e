"""A .wbt world with a value Webots would not use loads as in Webots: the field reset to the value
Webots uses, one warning naming file, line, column, node, field, what was wrong and the value used
(wbt/resets.py). The same value in a YAML world stays an error; values Webots refuses, or that
would break the sensors here, stay errors in a .wbt world too."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest
from _protos import proto_file, world_file
from _serve import serve, wait_until

from sensorium.cli import main as cli
from sensorium.server.world.loader import LoadedWorld, WorldError, load_world, parse_text, parse_world

HEADER = "#VRML_SIM R2023b utf8\n"
AS_WEBOTS = "(as Webots does)"


def load(tmp_path: Path, body: str) -> tuple[Path, LoadedWorld]:
    p = tmp_path / "w.wbt"
    p.write_text(HEADER + body)
    return p, load_world(p)


def shape(geometry: str, appearance: str = "") -> str:
    app = f"appearance {appearance} " if appearance else ""
    return f'Solid {{ name "s" children [ Shape {{ {app}geometry {geometry} }} ] }}\n'


def robot(device: str) -> str:
    return f'Robot {{ name "r" controller "<extern>" children [ {device} ] }}\n'


def first_shape(loaded: LoadedWorld) -> Any:
    return loaded.world.solids[0].shapes[0]


def device(loaded: LoadedWorld) -> Any:
    return loaded.world.robots[0].devices[0]


# (world body, the warning after "file:line:col: ", what reached the model); the warning's place is
# the field's, where the body writes it (_field_at)
CASES = [
    # geometry: a non-positive size is 1; a Box's or Plane's size with one non-positive component all ones
    (shape("Sphere { radius 0 }"), "Sphere.radius: 0 is not > 0; using 1",
     lambda w: first_shape(w).geometry.radius == 1.0),
    (shape("Box { size 1 -1 1 }"), "Box.size: 1 -1 1 has a component that is not > 0; using 1 1 1",
     lambda w: first_shape(w).geometry.size == (1.0, 1.0, 1.0)),
    (shape("Cylinder { radius -0.5 height 0.2 }"), "Cylinder.radius: -0.5 is not > 0; using 1",
     lambda w: (first_shape(w).geometry.radius, first_shape(w).geometry.height) == (1.0, 0.2)),
    (shape("Cylinder { radius 0.5 height -2 }"), "Cylinder.height: -2 is not > 0; using 1",
     lambda w: (first_shape(w).geometry.radius, first_shape(w).geometry.height) == (0.5, 1.0)),
    (shape("Capsule { radius 0 }"), "Capsule.radius: 0 is not > 0; using 1",
     lambda w: first_shape(w).geometry.radius == 1.0),
    (shape("Capsule { height 0 }"), "Capsule.height: 0 is not > 0; using 1",
     lambda w: first_shape(w).geometry.height == 1.0),
    (shape("Cone { bottomRadius -1 }"), "Cone.bottomRadius: -1 is not > 0; using 1",
     lambda w: first_shape(w).geometry.bottom_radius == 1.0),
    (shape("Cone { height 0 }"), "Cone.height: 0 is not > 0; using 1",
     lambda w: first_shape(w).geometry.height == 1.0),
    (shape("Plane { size 0 2 }"), "Plane.size: 0 2 has a component that is not > 0; using 1 1",
     lambda w: first_shape(w).geometry.size == (1.0, 1.0)),
    # appearance: colours clamped (an SFColor as read), transparency and roughness reset
    (shape("Box { }", "PBRAppearance { baseColor 1.5 -0.5 0.5 }"),
     "PBRAppearance.baseColor: 1.5 -0.5 0.5 is outside [0, 1]; using 1 0 0.5",
     lambda w: first_shape(w).appearance.base_color == (1.0, 0.0, 0.5)),
    (shape("Box { }", "PBRAppearance { transparency 2 }"),
     "PBRAppearance.transparency: 2 is outside [0, 1]; using 0", lambda w: first_shape(w).appearance.transparency == 0.0),
    (shape("Box { }", "PBRAppearance { roughness -1 }"),
     "PBRAppearance.roughness: -1 is outside [0, 1]; using 0", lambda w: first_shape(w).appearance.roughness == 0.0),
    (shape("Box { }", "Appearance { material Material { diffuseColor 0 2 0 } }"),
     "Material.diffuseColor: 0 2 0 is outside [0, 1]; using 0 1 0",
     lambda w: first_shape(w).appearance.base_color == (0.0, 1.0, 0.0)),
    (shape("Box { }", "Appearance { material Material { transparency -1 } }"),
     "Material.transparency: -1 is outside [0, 1]; using 0.5", lambda w: first_shape(w).appearance.transparency == 0.5),
    # colours elsewhere (MFColor items clamped as read)
    ('Solid { name "s" recognitionColors [ 1 2 0 ] }\n',
     "Solid.recognitionColors: 1 2 0 has components outside [0, 1]; using 1 1 0",
     lambda w: w.world.solids[0].recognition_colors == [(1.0, 1.0, 0.0)]),
    ("Background { skyColor [ 0 0 -1 ] }\n",
     "Background.skyColor: 0 0 -1 has components outside [0, 1]; using 0 0 0",
     lambda w: w.world.background.sky_color == (0.0, 0.0, 0.0)),
    # lights
    ("PointLight { radius -1 }\n", "PointLight.radius: -1 is negative; using 0",
     lambda w: w.world.lights[0].radius == 0.0),
    # devices
    (robot("LightSensor { colorFilter 1 1 3 }"),
     "LightSensor.colorFilter: 1 1 3 is outside [0, 1]; using 1 1 1", lambda w: device(w).color_filter == (1.0, 1.0, 1.0)),
    (robot("LED { color [ 2 0 0 ] }"), "LED.color: 2 0 0 has components outside [0, 1]; using 1 0 0",
     lambda w: device(w).color == [(1.0, 0.0, 0.0)]),
    (robot("Lidar { horizontalResolution 0 }"), "Lidar.horizontalResolution: 0 is not > 0; using 1",
     lambda w: device(w).horizontal_resolution == 1),
    (robot("Lidar { numberOfLayers -2 horizontalResolution 64 }"),
     "Lidar.numberOfLayers: -2 is not > 0; using 1", lambda w: device(w).number_of_layers == 1),
    (robot("Lidar { fieldOfView 0 }"), "Lidar.fieldOfView: 0 is not > 0; using 0.7854",
     lambda w: device(w).field_of_view == 0.7854),
    (robot("Lidar { verticalFieldOfView -1 }"), "Lidar.verticalFieldOfView: -1 is not > 0; using 0.1",
     lambda w: device(w).vertical_field_of_view == 0.1),
    (robot("Lidar { near 0 }"), "Lidar.near: 0 is not > 0; using 0.01", lambda w: device(w).near == 0.01),
    (robot("Lidar { minRange -1 }"), "Lidar.minRange: -1 is not > 0; using 0.01",
     lambda w: device(w).min_range == 0.01),
    (robot("Lidar { maxRange -3 }"), "Lidar.maxRange: -3 is not > minRange 0.01; using 1.01",
     lambda w: device(w).max_range == 1.01),
    (robot("Lidar { noise -0.1 }"), "Lidar.noise: -0.1 is negative; using 0", lambda w: device(w).noise == 0.0),
    (robot('Lidar { type "spinning" }'), 'Lidar.type: "spinning" is neither fixed nor rotating; using "fixed"',
     lambda w: device(w).type == "fixed"),
    (robot("Lidar { minFrequency 0 defaultFrequency 1 }"), "Lidar.minFrequency: 0 is not > 0; using 0.01",
     lambda w: device(w).min_frequency == 0.01),
    (robot("Camera { fieldOfView 4 }"), "Camera.fieldOfView: 4 is > pi with a planar projection; using 0.7854",
     lambda w: device(w).field_of_view == 0.7854),
    (robot("Camera { width 0 }"), "Camera.width: 0 is not > 0; using 1", lambda w: device(w).width == 1),
    (robot("Camera { height -1 }"), "Camera.height: -1 is not > 0; using 1", lambda w: device(w).height == 1),
    (robot("Camera { near 0 }"), "Camera.near: 0 is not > 0; using 0.01", lambda w: device(w).near == 0.01),
    (robot("Camera { far -1 }"), "Camera.far: -1 is negative; using 0", lambda w: device(w).far == 0.0),
    (robot("Camera { exposure -1 }"), "Camera.exposure: -1 is negative; using 1",
     lambda w: device(w).exposure == 1.0),
    (robot("Camera { noise -1 }"), "Camera.noise: -1 is negative; using 0", lambda w: device(w).noise == 0.0),
    (robot('Camera { projection "fisheye" }'),
     'Camera.projection: "fisheye" is not planar, spherical or cylindrical; using "planar"',
     lambda w: device(w).projection == "planar"),
    (robot("Camera { recognition Recognition { frameColor 0 0 9 } }"),
     "Recognition.frameColor: 0 0 9 is outside [0, 1]; using 0 0 1",
     lambda w: device(w).recognition.frame_color == (0.0, 0.0, 1.0)),
    (robot("RangeFinder { fieldOfView -1 }"), "RangeFinder.fieldOfView: -1 is not > 0; using 0.7854",
     lambda w: device(w).field_of_view == 0.7854),
    (robot("RangeFinder { minRange 0 }"), "RangeFinder.minRange: 0 is not > 0; using 0.01",
     lambda w: device(w).min_range == 0.01),
    (robot("RangeFinder { noise -1 }"), "RangeFinder.noise: -1 is negative; using 0",
     lambda w: device(w).noise == 0.0),
    (robot("Pen { inkColor 2 0 0 }"), "Pen.inkColor: 2 0 0 is outside [0, 1]; using 1 0 0",
     lambda w: device(w).ink_color == (1.0, 0.0, 0.0)),
]


def _field_at(body: str, node: str, field: str) -> tuple[int, int]:
    """(line, column) of HEADER + body where ``node``'s ``field`` is written (bodies are one line)."""
    line = (HEADER + body).splitlines()[1]
    return 2, line.index(f" {field} ", line.index(f"{node} {{")) + 2


@pytest.mark.parametrize("body, message, reached", CASES, ids=[c[1].split(":")[0] for c in CASES])
def test_a_value_webots_resets_is_reset_with_one_warning_at_its_field(tmp_path: Path, body: str, message: str,
                                                                      reached) -> None:
    p, loaded = load(tmp_path, body)
    line, col = _field_at(body, *message.split(":")[0].split("."))
    said = [w for w in loaded.warnings if AS_WEBOTS in w]
    assert said == [f"{p}:{line}:{col}: {message} {AS_WEBOTS}"]
    assert reached(loaded)


def test_each_bad_field_of_a_node_is_reset_and_said(tmp_path: Path) -> None:
    p, loaded = load(tmp_path, shape("Cylinder { radius 0 height -1 }"))
    geometry = first_shape(loaded).geometry
    assert (geometry.radius, geometry.height) == (1.0, 1.0)
    assert [w.split(": ", 1)[1] for w in loaded.warnings if AS_WEBOTS in w] == [
        f"Cylinder.radius: 0 is not > 0; using 1 {AS_WEBOTS}", f"Cylinder.height: -1 is not > 0; using 1 {AS_WEBOTS}"]


def test_a_node_used_twice_is_said_once(tmp_path: Path) -> None:
    """A DEF geometry that is both the visual shape and the boundingObject: one warning."""
    body = 'Solid { name "s" children [ Shape { geometry DEF B Box { size 0 1 1 } } ] boundingObject USE B }\n'
    p, loaded = load(tmp_path, body)
    assert [w for w in loaded.warnings if AS_WEBOTS in w] == [
        f"{p}:2:58: Box.size: 0 1 1 has a component that is not > 0; using 1 1 1 {AS_WEBOTS}"]
    (part,) = loaded.world.solids[0].shapes
    assert part.geometry.size == (1.0, 1.0, 1.0) and part.seen_by == "both"


def test_a_reset_inside_a_proto_names_the_instance(tmp_path: Path) -> None:
    """A PROTO instantiated with a bad value: corrected where the PROTO writes the field, the
    instance in the world file named."""
    proto_file(tmp_path / "protos", "Ball", "[ field SFFloat size 0.1 ] { Solid { name \"ball\" children [ "
                                            "Shape { geometry Sphere { radius IS size } } ] } }")
    world = world_file(tmp_path, "Ball { size -2 }\n", ["protos/Ball.proto"])
    loaded = load_world(world)
    assert first_shape(loaded).geometry.radius == 1.0
    (said,) = [w for w in loaded.warnings if AS_WEBOTS in w]
    assert said.endswith(f"(in PROTO Ball at {world}:3:1): Sphere.radius: -2 is not > 0; using 1 {AS_WEBOTS}")
    assert said.startswith(str(tmp_path / "protos" / "Ball.proto") + ":")


def test_validate_lists_the_reset_and_passes(tmp_path: Path, capsys) -> None:
    p, _ = load(tmp_path, shape("Sphere { radius 0 }"))
    assert cli(["validate", str(p)]) == 0
    out = capsys.readouterr()
    assert f"warning: {p}:2:55: Sphere.radius: 0 is not > 0; using 1 {AS_WEBOTS}" in out.err
    assert out.out.strip().endswith(f"{p}: OK")


@pytest.mark.slow
def test_serve_prints_the_reset_before_serving(tmp_path: Path) -> None:
    p, _ = load(tmp_path, shape("Sphere { radius 0 }") + robot(""))
    line = f"warning: {p}:2:55: Sphere.radius: 0 is not > 0; using 1 {AS_WEBOTS}"
    with serve(p, "--precision", "fast") as s:                      # free ports (fixed ones can be taken)
        # printed before the ready line, but read from stderr by its own thread: wait for it
        wait_until(lambda: line in s.stderr(), timeout=60.0, what="the reset line on stderr")


# ---------------------------------------------------------------- what stays an error

@pytest.mark.parametrize("yaml_text, problem", [
    ("solids:\n  - {name: s, geometry: {type: sphere, radius: 0}}\n", "solids[0] (s).geometry.radius: Input should be greater than 0"),
    ("solids:\n  - {name: s, geometry: {type: box, size: [1, -1, 1]}}\n", "every box size component must be > 0"),
    ("solids:\n  - {name: s, geometry: {type: sphere}, appearance: {base_color: [1.5, 0, 0]}}\n",
     "colour components must be within [0, 1]"),
    ("solids:\n  - {name: s, geometry: {type: sphere}, appearance: {roughness: 2}}\n", "less than or equal to 1"),
    ("robots:\n  - {name: r, devices: [{device: Camera, name: c, width: 0}]}\n", "greater than or equal to 1"),
])
def test_the_yaml_format_still_refuses_the_value(yaml_text: str, problem: str) -> None:
    with pytest.raises(WorldError) as exc:
        parse_world(parse_text(yaml_text.encode(), "w.yaml"), "w.yaml")
    assert problem in str(exc.value)


def test_a_negative_attenuation_stays_an_error(tmp_path: Path) -> None:
    """Webots resets it to 0 0 0: an infinite irradiance sensors here cannot read."""
    with pytest.raises(WorldError) as exc:
        load(tmp_path, "PointLight { attenuation 0 -1 1 }\n")
    assert str(exc.value) == (f"{tmp_path / 'w.wbt'}: line 2, column 14: PointLight.attenuation: 0 -1 1 has a negative "
                              "component: Webots resets it to 0 0 0, an infinite irradiance, which is refused here "
                              "(1 0 0 is no attenuation)")


def test_a_value_webots_keeps_but_sensors_cannot_use_stays_an_error(tmp_path: Path) -> None:
    """A camera noise above 1 Webots keeps (there is no reset for it); the model refuses it, at its line."""
    with pytest.raises(WorldError) as exc:
        load(tmp_path, robot("Camera { noise 2 }"))
    assert "line 2, column 51 (Camera, converted as robots[0].devices[0].noise)" in str(exc.value)


def test_a_good_world_says_nothing(tmp_path: Path) -> None:
    _, loaded = load(tmp_path, shape("Sphere { radius 0.1 }", "PBRAppearance { baseColor 1 0 0 roughness 1 }")
                     + robot("Lidar { fieldOfView 3.14159 }"))
    assert not [w for w in loaded.warnings if AS_WEBOTS in w]
    assert math.isclose(loaded.world.robots[0].devices[0].field_of_view, 3.14159)
