"""World files: loading, round trips, sanitising and every rejection with its exact message."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from sensorium.schemas import world as wm
from sensorium.server.world.loader import WorldError, default_world_path, load_world, parse_world

WORLDS = Path(__file__).resolve().parents[1] / "sensorium" / "worlds"


def _robot(devices: list[dict], **extra) -> dict:
    return {"name": "r", **extra, "devices": devices}


def _problems(data: dict, tmp_path: Path | None = None) -> list[tuple[str, str]]:
    with pytest.raises(WorldError) as info:
        parse_world(data, source="w.yaml", base_dir=tmp_path or Path.cwd())
    return [(p.path, p.message) for p in info.value.problems]


@pytest.mark.parametrize("name", ["arena.yaml", "warehouse.yaml", "lighting.yaml"])
def test_shipped_worlds_load(name: str) -> None:
    loaded = load_world(WORLDS / name)
    assert loaded.world.robots, "every shipped world has robots"
    assert loaded.warnings == []


def test_default_world_is_arena() -> None:
    assert default_world_path().name == "arena.yaml"
    w = load_world(default_world_path()).world
    kinds = {s.geometry.type for s in w.solids}
    assert kinds >= {"box", "sphere", "cylinder", "capsule", "plane", "mesh"}
    assert {lt.type for lt in w.lights} == {"PointLight", "SpotLight", "DirectionalLight"}
    epuck = next(r for r in w.robots if r.name == "epuck")
    assert sum(d.device == "DistanceSensor" and d.type == "infra-red" for d in epuck.devices) == 8
    assert sum(d.device == "LightSensor" for d in epuck.devices) == 2
    scout = next(r for r in w.robots if r.name == "scout")
    lidars = [d for d in scout.devices if d.device == "Lidar"]
    assert len(lidars) == 1 and lidars[0].number_of_layers == 1
    assert any(d.device == "DistanceSensor" and d.type == "sonar" for d in scout.devices)


def test_warehouse_is_lidar_heavy() -> None:
    from sensorium.server.sim.summary import world_summary

    s = world_summary(WORLDS / "warehouse.yaml")
    assert s["triangles"] >= 100_000
    w = load_world(WORLDS / "warehouse.yaml").world
    lidar = [d for r in w.robots for d in r.devices if d.device == "Lidar"]
    assert any(d.type == "rotating" and d.number_of_layers == 16 for d in lidar)


def test_yaml_json_round_trip(tmp_path: Path) -> None:
    original = load_world(default_world_path()).world
    dumped = original.model_dump(mode="json")
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "rock.stl").write_bytes((WORLDS / "meshes" / "rock.stl").read_bytes())
    (tmp_path / "w.json").write_text(json.dumps(dumped))
    (tmp_path / "w.yaml").write_text(yaml.safe_dump(dumped))
    assert load_world(tmp_path / "w.json").world == original
    assert load_world(tmp_path / "w.yaml").world == original


def test_defaults_are_webots_defaults() -> None:
    w = parse_world({"robots": [_robot([
        {"device": "LightSensor", "name": "ls"},
        {"device": "DistanceSensor", "name": "ds"},
        {"device": "Lidar", "name": "li"},
    ])], "lights": [{"type": "SpotLight"}]}).world
    ls, ds, li = w.robots[0].devices
    assert ls.lookup_table == [(0, 0, 0), (1, 1000, 0)] and ls.color_filter == (1, 1, 1) and not ls.occlusion
    assert ds.lookup_table == [(0, 0, 0), (0.1, 1000, 0)] and ds.type == "generic"
    assert (ds.number_of_rays, ds.aperture, ds.gaussian_width, ds.resolution, ds.red_color_sensitivity) == (1, 1.5708, 1, -1, 1)
    assert (li.horizontal_resolution, li.field_of_view, li.vertical_field_of_view, li.number_of_layers) == (512, 1.5708, 0.2, 4)
    assert (li.near, li.min_range, li.max_range, li.type, li.projection) == (0.01, 0.01, 1.0, "fixed", "cylindrical")
    assert (li.default_frequency, li.min_frequency, li.max_frequency) == (10, 1, 25)
    spot = w.lights[0]
    # Webots: default beam_width 1.5708 > cut_off_angle 0.785398 is clamped to the cut-off
    assert spot.beam_width == spot.cut_off_angle == 0.785398
    assert w.world_info.basic_time_step == 32


def test_a_spotlight_with_webots_defaults_loads_without_a_warning(tmp_path: Path) -> None:
    # WbSpotLight clamps its default beamWidth (pi/2) to the default cutOffAngle (pi/4) silently; a
    # beam width written above the cut-off is still reported
    loaded = parse_world({"lights": [{"type": "SpotLight"}, {"type": "SpotLight", "cut_off_angle": 0.5, "beam_width": 0.7}]})
    assert [x.beam_width for x in loaded.world.lights] == [0.785398, 0.5]
    assert loaded.warnings == ["lights[1].beam_width: 0.7 > cut_off_angle, set to 0.5"]
    wbt = tmp_path / "spot.wbt"
    wbt.write_text("#VRML_SIM R2023b utf8\nWorldInfo { }\nSpotLight { }\n")
    from_wbt = load_world(wbt)
    assert from_wbt.world.lights[0].beam_width == 0.785398 and from_wbt.warnings == []


def test_sanitising_warns() -> None:
    loaded = parse_world({"lights": [
        {"type": "PointLight", "ambient_intensity": 1.5},
        {"type": "PointLight", "ambient_intensity": 0.5, "attenuation": [0, 0, 1]},
        {"type": "SpotLight", "cut_off_angle": 3.0},
    ], "robots": [_robot([
        {"device": "DistanceSensor", "name": "d", "aperture": -0.5, "number_of_rays": 0, "gaussian_width": -2,
         "resolution": -3, "red_color_sensitivity": -2},
        {"device": "DistanceSensor", "name": "laser", "type": "laser", "number_of_rays": 4},
        {"device": "Lidar", "name": "li", "near": 0.5, "min_range": 0.1, "max_range": 0.05},
    ])]})
    w = loaded.world
    assert w.lights[0].ambient_intensity == 1.0
    assert w.lights[1].ambient_intensity == 0.0
    assert w.lights[2].cut_off_angle == pytest.approx(math.pi / 2)
    d, laser, li = w.robots[0].devices
    assert (d.aperture, d.number_of_rays, d.gaussian_width, d.resolution, d.red_color_sensitivity) == (0.5, 1, 1.0, -1.0, 2)
    assert laser.number_of_rays == 1
    assert li.near == 0.1 and li.max_range == pytest.approx(1.1)
    assert len(loaded.warnings) == 11
    assert any("lights[1].ambient_intensity" in x for x in loaded.warnings)


def test_light_values_outside_webots_ranges_are_reset_with_one_warning_naming_the_light() -> None:
    loaded = parse_world({"lights": [
        {"type": "PointLight", "name": "lamp", "intensity": -2, "ambient_intensity": -0.5},
        {"type": "SpotLight", "name": "spot", "cut_off_angle": 2.5, "beam_width": -1},
        {"type": "DirectionalLight", "ambient_intensity": 3},
    ]})
    lamp, spot, sun = loaded.world.lights
    assert (lamp.intensity, lamp.ambient_intensity) == (1.0, 0.0)        # WbLight's reset values
    assert (spot.cut_off_angle, spot.beam_width) == (math.pi / 2, 0.0)   # WbSpotLight's
    assert sun.ambient_intensity == 1.0
    assert loaded.warnings == [
        "lights[0] (lamp).ambient_intensity: must be within [0, 1], got -0.5, reset to 0",
        "lights[0] (lamp).intensity: must be >= 0, got -2.0, reset to 1",
        "lights[1] (spot).cut_off_angle: must be within [0, pi/2], got 2.5, reset to pi/2",
        "lights[1] (spot).beam_width: must be within [0, pi/2], got -1.0, reset to 0",
        "lights[2].ambient_intensity: must be within [0, 1], got 3.0, reset to 1",
    ]
    # the bounds themselves pass untouched
    edge = parse_world({"lights": [{"type": "SpotLight", "ambient_intensity": 1.0, "intensity": 0.0,
                                    "cut_off_angle": math.pi / 2, "beam_width": math.pi / 2}]})
    assert edge.warnings == [] and edge.world.lights[0].cut_off_angle == math.pi / 2


@pytest.mark.parametrize("where", ["lights", "solid", "robot"])
def test_light_colour_outside_unit_range_is_an_error_naming_the_light(where: str) -> None:
    light = {"type": "SpotLight", "name": "spot", "color": [1, 0.5, 1.5]}
    data = {"lights": {"lights": [light]},
            "solid": {"solids": [{"name": "post", "lights": [light]}]},
            "robot": {"robots": [_robot([], lights=[light])]}}[where]
    path = {"lights": "lights[0]", "solid": "solids[0] (post).lights[0]", "robot": "robots[0] (r).lights[0]"}[where]
    with pytest.raises(WorldError) as info:
        parse_world(data, source="w.yaml")
    assert str(info.value) == f"w.yaml: {path} (spot).color: colour components must be within [0, 1], got [1.0, 0.5, 1.5]"


def test_infrared_spelling_normalised() -> None:
    w = parse_world({"robots": [_robot([{"device": "DistanceSensor", "name": "d", "type": "InfraRed"}])]}).world
    assert w.robots[0].devices[0].type == "infra-red"


# ------------------------------------------------------------------ rejections

def test_unsorted_lookup_table_names_the_row() -> None:
    probs = _problems({"robots": [_robot([
        {"device": "LightSensor", "name": "a"},
        {"device": "LightSensor", "name": "b"},
        {"device": "DistanceSensor", "name": "c", "lookup_table": [[0, 0, 0], [0.2, 5, 0], [0.1, 9, 0]]},
    ])]})
    assert probs == [("robots[0].devices[2].lookup_table[2]",
                      "lookup table inputs must be strictly increasing: input 0.1 follows 0.2")]


def test_equal_lookup_inputs_rejected() -> None:
    probs = _problems({"robots": [_robot([{"device": "LightSensor", "name": "a", "lookup_table": [[1, 0, 0], [1, 5, 0]]}])]})
    assert probs[0][0] == "robots[0].devices[0].lookup_table[1]"


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -float("inf")])
def test_non_finite_numbers_rejected(bad: float) -> None:
    probs = _problems({"solids": [{"name": "s", "pose": {"translation": [0, bad, 0]}, "geometry": {"type": "sphere"}}]})
    assert probs == [("solids[0].pose.translation[1]", f"expected a finite number, got {bad!r}")]


def test_nan_in_yaml_file_rejected(tmp_path: Path) -> None:
    (tmp_path / "w.yaml").write_text("lights:\n  - {type: PointLight, intensity: .nan}\n")
    with pytest.raises(WorldError) as info:
        load_world(tmp_path / "w.yaml")
    assert str(info.value) == f"{tmp_path / 'w.yaml'}: lights[0].intensity: expected a finite number, got nan"


def test_unknown_keys_rejected() -> None:
    probs = _problems({"robots": [_robot([{"device": "Lidar", "name": "l", "horizontal_resolutoin": 5}])], "colour": 1})
    assert ("robots[0].devices[0].horizontal_resolutoin", "unknown key (check spelling; field names are Webots' names in snake_case)") in probs
    assert ("colour", "unknown key (check spelling; field names are Webots' names in snake_case)") in probs


def test_a_missing_or_unknown_kind_names_the_key_and_the_kinds() -> None:
    # pydantic's "Unable to extract tag using discriminator 'device'" did not say what to write
    from sensorium.schemas import world as wm

    probs = _problems({"solids": [{"name": "s", "geometry": {"radius": 1}}, {"name": "t", "geometry": {"type": "ball"}}],
                       "lights": [{"location": [0, 0, 1]}],
                       "robots": [_robot([{"name": "x"}, {"device": "Sonar", "name": "y"}])]})
    geometries = "box, sphere, cylinder, capsule, cone, plane, triangles, mesh, elevation_grid"
    devices = ", ".join(wm.DEVICE_TYPES)
    assert sorted(probs) == sorted([
        ("solids[0].geometry", f"no 'type' key: it says what this is (one of: {geometries})"),
        ("solids[1].geometry", f"type 'ball' is not one of: {geometries}"),
        ("lights[0]", "no 'type' key: it says what this is (one of: PointLight, SpotLight, DirectionalLight)"),
        ("robots[0].devices[0]", f"no 'device' key: it says what this is (one of: {devices})"),
        ("robots[0].devices[1]", f"device 'Sonar' is not one of: {devices}")])


def test_attenuation_zero_rejected() -> None:
    probs = _problems({"lights": [{"type": "PointLight", "attenuation": [0, 0, 0]}]})
    assert probs == [("lights[0].attenuation", "attenuation 0 0 0 would give infinite irradiance; use 1 0 0 for none")]


def test_negative_attenuation_rejected() -> None:
    probs = _problems({"lights": [{"type": "SpotLight", "attenuation": [1, -1, 0]}]})
    assert probs == [("lights[0].attenuation", "attenuation components must be >= 0")]


def test_unknown_device_and_sensor_type_rejected() -> None:
    probs = _problems({"robots": [_robot([{"device": "Kamera", "name": "c"},
                                          {"device": "DistanceSensor", "name": "d", "type": "radar"}])]})
    assert probs[0][0] == "robots[0].devices[0]"
    assert "'Kamera'" in probs[0][1] and "LightSensor" in probs[0][1] and "Camera" in probs[0][1]
    assert probs[1][0] == "robots[0].devices[1].type"
    assert "'radar'" in probs[1][1] and "sonar" in probs[1][1]


def test_missing_mesh_file_rejected(tmp_path: Path) -> None:
    probs = _problems({"solids": [{"name": "m", "geometry": {"type": "mesh", "url": "nope.stl"}}]}, tmp_path)
    # the url as written, never a resolved path (issue 16)
    assert probs == [("solids[0].geometry.url", "mesh file 'nope.stl' not found (urls are relative to the world file)")]


def test_corrupt_mesh_file_rejected(tmp_path: Path) -> None:
    (tmp_path / "bad.stl").write_bytes(b"solid nothing\nendsolid\n")
    probs = _problems({"robots": [{"name": "r", "body": {"geometry": {"type": "mesh", "url": "bad.stl"}}}]}, tmp_path)
    assert probs[0][0] == "robots[0].body.geometry.url"


def test_duplicate_names_rejected() -> None:
    probs = _problems({
        "solids": [{"name": "a", "geometry": {"type": "sphere"}}, {"name": "a", "geometry": {"type": "sphere"}}],
        "robots": [_robot([{"device": "LightSensor", "name": "x"}, {"device": "Lidar", "name": "x"}]),
                   {"name": "r"}],
    })
    assert probs == [
        ("solids[1].name", "duplicate solid name 'a' (first used at solids[0].name)"),
        ("robots[1].name", "duplicate robot name 'r' (first used at robots[0].name)"),
        ("robots[0].devices[1].name", "duplicate device name 'x' (first used at robots[0].devices[0].name)"),
    ]


def test_every_problem_reported_at_once() -> None:
    probs = _problems({"solids": [{"name": "s", "geometry": {"type": "box", "size": [1, 0, 1]}},
                                  {"name": "t", "geometry": {"type": "sphere", "radius": -1}}],
                       "world_info": {"basic_time_step": 0}})
    paths = [p for p, _ in probs]
    assert paths == ["world_info.basic_time_step", "solids[0].geometry.size", "solids[1].geometry.radius"] or \
        sorted(paths) == sorted(["world_info.basic_time_step", "solids[0].geometry.size", "solids[1].geometry.radius"])


def test_rotation_and_quaternion_exclusive() -> None:
    probs = _problems({"solids": [{"name": "s", "geometry": {"type": "sphere"},
                                   "pose": {"rotation": [0, 0, 1, 1], "quaternion": [0, 0, 0, 1]}}]})
    assert probs == [("solids[0].pose", "give either 'rotation' (axis-angle) or 'quaternion', not both")]


def test_not_a_mapping_and_bad_yaml(tmp_path: Path) -> None:
    (tmp_path / "a.yaml").write_text("- 1\n- 2\n")
    (tmp_path / "b.yaml").write_text("robots: [unclosed\n")
    with pytest.raises(WorldError, match="a world must be a mapping, got list"):
        load_world(tmp_path / "a.yaml")
    with pytest.raises(WorldError, match="line 2, column 1: not valid YAML"):
        load_world(tmp_path / "b.yaml")
    with pytest.raises(WorldError, match="cannot read world file"):
        load_world(tmp_path / "missing.yaml")


def test_quaternion_pose_equals_axis_angle() -> None:
    import numpy as np

    from sensorium.server.world.poses import pose_from_model

    a = wm.Pose(rotation=(0, 0, 1, math.pi / 3))
    q = wm.Pose(quaternion=(0, 0, math.sin(math.pi / 6), math.cos(math.pi / 6)))
    np.testing.assert_allclose(pose_from_model(a).rotation, pose_from_model(q).rotation, atol=1e-15)


# ------------------------------------------------------------------ command line

def _cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "sensorium", *args], capture_output=True, text=True, timeout=60)


def test_cli_validate_ok_and_failure(tmp_path: Path) -> None:
    ok = _cli("validate", str(WORLDS / "arena.yaml"))
    assert ok.returncode == 0 and ok.stdout.strip().endswith("OK")
    bad = tmp_path / "bad.yaml"
    bad.write_text("lights:\n  - {type: PointLight, attenuation: [0, 0, 0]}\nrobots:\n  - {name: r, devices: [{device: Sonar, name: s}]}\n")
    res = _cli("validate", str(bad))
    assert res.returncode == 1
    assert f"{bad}: lights[0].attenuation: attenuation 0 0 0" in res.stderr
    assert f"{bad}: robots[0] (r).devices[0] (s):" in res.stderr
    assert "INVALID (2 problems)" in res.stderr


def test_cli_validate_light_colour_out_of_range_yaml_error_wbt_clamped_as_webots(tmp_path: Path) -> None:
    yml = tmp_path / "bad.yaml"
    yml.write_text("lights:\n  - {type: PointLight, name: lamp, color: [2, 0, 0]}\n")
    res = _cli("validate", str(yml))
    assert res.returncode == 1 and "Traceback" not in res.stderr
    assert [line for line in res.stderr.splitlines() if "INVALID" not in line] == [
        f"{yml}: lights[0] (lamp).color: colour components must be within [0, 1], got [2.0, 0.0, 0.0]"]
    # a Webots world loads as in Webots: its light's colour clamped, its negative intensity reset to 1,
    # each with a warning at the light's line
    wbt = tmp_path / "lamp.wbt"
    wbt.write_text("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 32 }\n"
                   "DEF LAMP PointLight {\n  color 1 0.5 -0.1\n  intensity -3\n}\n")
    res = _cli("validate", str(wbt))
    assert res.returncode == 0 and "Traceback" not in res.stderr
    assert f"{wbt}:3:10: PointLight color 1 0.5 -0.1 clamped to [0, 1] (Webots resets it)" in res.stdout + res.stderr
    assert f"{wbt}:3:10: PointLight (lights[0].intensity): must be >= 0, got -3.0, reset to 1" in res.stdout + res.stderr
    lamp = load_world(wbt).world.lights[0]
    assert (lamp.color, lamp.intensity) == ((1.0, 0.5, 0.0), 1.0)


def test_cli_info_default_world() -> None:
    res = _cli("info")
    assert res.returncode == 0, res.stderr
    assert "world     arena" in res.stdout
    assert "epuck" in res.stdout and "scout" in res.stdout
    data = json.loads(_cli("info", "--json").stdout)
    assert data["triangles"] > 0 and len(data["lights"]) == 3


def test_names_that_would_break_topic_paths_rejected() -> None:
    probs = _problems({"robots": [{"name": "a/b"}, {"name": "c", "devices": [{"device": "LightSensor", "name": "robot"},
                                                                           {"device": "LightSensor", "name": "x\0y"}]}]})
    assert probs == [
        ("robots[0].name", "name 'a/b' must not contain '/' or NUL (names are used in topic paths)"),
        ("robots[1].devices[0].name", "name 'robot' is reserved (robot-level services live under /<robot>/robot/)"),
        ("robots[1].devices[1].name", "name 'x\\x00y' must not contain NUL (names are used in topic paths)"),
    ]


def test_unsimulated_devices_are_accepted_with_their_model_and_nothing_else() -> None:
    devices = [{"device": "Display", "name": "display", "model": "Logitech", "pose": {"translation": [0.1, 0, 0]}},
               {"device": "RotationalMotor", "name": "left wheel motor"},
               {"device": "GPS", "name": "gps"}]
    loaded = parse_world({"robots": [_robot(devices, differential_drive={})]}, source="w.yaml", base_dir=Path.cwd())
    assert [(d.device, d.name, d.model) for d in loaded.world.robots[0].devices] == [
        ("Display", "display", "Logitech"), ("RotationalMotor", "left wheel motor", ""), ("GPS", "gps", "")]
    probs = _problems({"robots": [_robot([{"device": "Speaker", "name": "speaker", "width": 64}])]})
    assert probs and probs[0][0].startswith("robots[0].devices[0]") and "width" in probs[0][0] + probs[0][1]
    # a Display keeps its size (wb_display_get_width/height), Webots' 64 x 64 by default, at least 1
    ok = parse_world({"robots": [_robot([{"device": "Display", "name": "d", "width": 320}])]}, source="w.yaml",
                     base_dir=Path.cwd())
    assert (ok.world.robots[0].devices[0].width, ok.world.robots[0].devices[0].height) == (320, 64)
    assert _problems({"robots": [_robot([{"device": "Display", "name": "d", "width": 0}])]})


def test_a_validators_message_that_states_the_value_does_not_state_it_twice() -> None:
    probs = _problems({"robots": [_robot([{"device": "Emitter", "name": "e", "range": 0},
                                          {"device": "Emitter", "name": "f", "aperture": 7}])]})
    assert probs == [("robots[0].devices[0].range", "range must be -1 (unlimited) or > 0, got 0.0"),
                     ("robots[0].devices[1].aperture", "aperture must be -1 or within [0, 2*pi], got 7.0")]


def test_pydantics_own_message_that_says_got_still_shows_the_value() -> None:
    probs = _problems({"world_info": {"basic_time_step": 32.5}})
    assert probs == [("world_info.basic_time_step",
                      "Input should be a valid integer, got a number with a fractional part (got 32.5)")]


def test_cli_info_names_each_robots_controller_and_its_arguments(tmp_path: Path) -> None:
    """`sensorium info` listed a robot's devices but not which controller `run` would start for it."""
    wbt = tmp_path / "w.wbt"
    wbt.write_text('#VRML_SIM R2023b utf8\nWorldInfo { }\nRobot { name "a" controller "avoid" '
                   'controllerArgs [ "0.5" "two words" ] }\nRobot { name "bare" }\n'
                   'Robot { name "ext" controller "<extern>" synchronization FALSE }\n')
    res = _cli("info", str(wbt))
    assert res.returncode == 0, res.stderr
    assert [line for line in res.stdout.splitlines() if line.startswith("  ") and line[2] != " "] == [
        "  a: 0 devices, controller 'avoid' (controllerArgs '0.5' 'two words')",
        "  bare: 0 devices, controller '<extern>' (no controller field: `run` gives it Webots' default '<generic>')",
        "  ext (asynchronous): 0 devices, controller '<extern>'"]
    robots = json.loads(_cli("info", "--json", str(wbt)).stdout)["robots"]
    assert [(r["controller"], r["controller_args"], r["controller_given"]) for r in robots] == [
        ("avoid", ["0.5", "two words"], True), ("<extern>", [], False), ("<extern>", [], True)]
