"""In-process simulation: timing, closed-form readings through the whole pipeline, laziness counters."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world

WALL_X = 0.05  # the near face of the test wall, in front of the robot at the origin


def world(devices: list[dict], *, solids: list[dict] | None = None, lights: list[dict] | None = None,
          step: int = 32, seed: int = 3, offset: tuple[float, float, float] = (0.0, 0.0, 0.0),
          robots_extra: list[dict] | None = None, precision: str = "exact") -> Simulation:
    ox, oy, oz = offset
    if solids is None:
        # a wall whose near face is the plane x = WALL_X
        solids = [{"name": "wall", "pose": {"translation": [WALL_X + 0.05 + ox, oy, oz]},
                   "geometry": {"type": "box", "size": [0.1, 2.0, 2.0]},
                   "appearance": {"base_color": [0.5, 0.5, 0.5]}}]
    data = {
        "world_info": {"basic_time_step": step, "random_seed": seed},
        "solids": solids,
        "lights": lights or [],
        "robots": [{"name": "r", "pose": {"translation": [ox, oy, oz]}, "devices": devices}, *(robots_extra or [])],
    }
    return Simulation(parse_world(data), precision=precision)


# ------------------------------------------------------------------ timing (devices.md §1.1)

def test_enable_96_with_32_step_gives_nan_nan_value() -> None:
    sim = world([{"device": "DistanceSensor", "name": "d"}])
    d = sim.device("r/d")
    d.enable(96)
    seen = []
    for _ in range(4):
        sim.step()
        seen.append(d.value)
    assert math.isnan(seen[0]) and math.isnan(seen[1])
    assert seen[2] == pytest.approx(500.0, abs=1e-9)
    assert seen[3] == seen[2]
    assert d.measured_at_ms == 96


def test_pose_change_shows_at_next_refresh() -> None:
    sim = world([{"device": "DistanceSensor", "name": "slow"}, {"device": "DistanceSensor", "name": "fast"}])
    slow, fast = sim.device("r/slow"), sim.device("r/fast")
    slow.enable(96)
    fast.enable(32)
    values = []
    for k in range(1, 7):
        sim.step()
        if sim.time_ms == 96:
            sim.robot("r").set_pose([0.02, 0.0, 0.0])   # wall now 0.03 m away: 300
        values.append((k, slow.value, fast.value))
    assert values[2][1] == pytest.approx(500.0)          # t=96 measured before the move
    assert values[3][2] == pytest.approx(300.0)          # period 32: step 4 sees it
    assert values[4][1] == pytest.approx(500.0)          # period 96: not before t=192
    assert values[5][1] == pytest.approx(300.0)


def test_period_rounded_up_to_basic_step_multiple() -> None:
    sim = world([{"device": "DistanceSensor", "name": "d"}])
    d = sim.device("r/d")
    d.enable(40)   # effective 64
    times = []
    for _ in range(8):
        sim.step()
        if d.measured_at_ms == sim.time_ms:
            times.append(sim.time_ms)
    assert times == [64, 128, 192, 256]
    assert d.sampling_period == 40


def test_last_value_kept_after_disable_and_nothing_computed() -> None:
    sim = world([{"device": "DistanceSensor", "name": "d"}])
    d = sim.device("r/d")
    d.enable(32)
    sim.step()
    v = d.value
    d.disable()
    before = sim.counters["rays_distance"]
    sim.robot("r").set_pose([0.02, 0, 0])
    sim.run(5)
    assert d.value == v and d.sampling_period == 0
    assert sim.counters["rays_distance"] == before


def test_negative_or_non_integer_period_rejected() -> None:
    sim = world([{"device": "DistanceSensor", "name": "d"}])
    with pytest.raises(ValueError, match=">= 0"):
        sim.device("r/d").enable(-1)
    with pytest.raises(ValueError, match="integer"):
        sim.device("r/d").enable(3.5)


def test_million_steps_no_clock_drift() -> None:
    sim = Simulation(parse_world({"world_info": {"basic_time_step": 7}}))
    sim.run(1_000_000)
    assert sim.time_ms == 7_000_000 and isinstance(sim.time_ms, int)


def test_unknown_names_are_clear() -> None:
    sim = world([{"device": "DistanceSensor", "name": "d"}])
    with pytest.raises(KeyError, match="robot 'r' has no device 'x'"):
        sim.device("r/x")
    with pytest.raises(KeyError, match="no robot 'q'"):
        sim.device("q/d")


# ------------------------------------------------------------------ distance sensors, closed form

@pytest.mark.parametrize("precision", ["fast", "exact"])
@pytest.mark.parametrize("kind", ["generic", "sonar", "laser", "infra-red"])
def test_single_ray_in_front_of_wall(kind: str, precision: str) -> None:
    sim = world([{"device": "DistanceSensor", "name": "d", "type": kind, "red_color_sensitivity": 0}], precision=precision)
    d = sim.device("r/d")
    d.enable(32)
    sim.step()
    tol = 1e-9 if precision == "exact" else 1e-3
    assert d.value == pytest.approx(1000 * WALL_X / 0.1, abs=tol)


@pytest.mark.parametrize("n", [2, 3, 5, 8, 10, 20])
def test_generic_weighted_average_over_wall(n: int) -> None:
    """Every ray of the cone hits the plane x = 0.05 at 0.05/cos(theta_i)."""
    from sensorium.server.devices import distance as dm

    aperture = 0.6
    sim = world([{"device": "DistanceSensor", "name": "d", "number_of_rays": n, "aperture": aperture,
                  "lookup_table": [[0, 0, 0], [1, 1, 0]]}])
    d = sim.device("r/d")
    d.enable(32)
    sim.step()
    dirs = dm.ray_directions(n, aperture)
    w = dm.ray_weights(n, aperture, 1.0)
    expected = float(np.sum(w * WALL_X / dirs[:, 0]))
    assert d.value == pytest.approx(expected, abs=1e-12)


def test_no_hit_rays_count_as_table_max() -> None:
    sim = world([{"device": "DistanceSensor", "name": "d", "lookup_table": [[0, 0, 0], [0.04, 4, 0]]}])
    d = sim.device("r/d")
    d.enable(32)
    sim.step()
    assert d.value == 4.0


def test_empty_lookup_table_reads_zero() -> None:
    # devices.md §3.1: an empty table gives the value 0 whatever the rays hit
    sim = world([{"device": "DistanceSensor", "name": "d", "lookup_table": []},
                 {"device": "DistanceSensor", "name": "e", "type": "infra-red", "lookup_table": []}])
    for name in ("d", "e"):
        sim.device(f"r/{name}").enable(32)
    sim.step()
    assert sim.device("r/d").value == 0.0 and sim.device("r/e").value == 0.0


@pytest.mark.parametrize("tilt_deg,expect_echo", [(20.0, True), (24.0, False)])
def test_sonar_incidence_on_tilted_wall(tilt_deg: float, expect_echo: bool) -> None:
    tilt = math.radians(tilt_deg)
    wall = {"name": "wall", "pose": {"translation": [0.5, 0, 0], "rotation": [0, 0, 1, tilt]},
            "geometry": {"type": "box", "size": [0.02, 4.0, 4.0]}}
    sim = world([{"device": "DistanceSensor", "name": "s", "type": "sonar", "lookup_table": [[0, 0, 0], [2, 2, 0]]}],
                solids=[wall])
    s = sim.device("r/s")
    s.enable(32)
    sim.step()
    # the centre ray meets the rotated near face at 0.5 - 0.01/cos(tilt)
    assert s.value == (pytest.approx(0.5 - 0.01 / math.cos(tilt), abs=1e-9) if expect_echo else 2.0)


@pytest.mark.parametrize("red,roughness", [(1.0, 0.0), (0.5, 0.0), (0.0, 0.0), (0.8, 1.0)])
def test_infra_red_colour_factor(red: float, roughness: float) -> None:
    wall = {"name": "wall", "pose": {"translation": [WALL_X + 0.05, 0, 0]}, "geometry": {"type": "box", "size": [0.1, 2, 2]},
            "appearance": {"base_color": [red, 0.3, 0.3], "roughness": roughness}}
    sim = world([{"device": "DistanceSensor", "name": "ir", "type": "infra-red", "lookup_table": [[0, 0, 0], [1, 1, 0]]}],
                solids=[wall])
    ir = sim.device("r/ir")
    ir.enable(32)
    sim.step()
    f = 0.2 + 0.8 * red * (1 - 0.5 * roughness)
    assert ir.value == pytest.approx(WALL_X / f, abs=1e-12)


def test_infra_red_ignores_fully_transparent_visuals_laser_ignores_transparent_bounding() -> None:
    glass = {"name": "glass", "pose": {"translation": [0.02, 0, 0]}, "geometry": {"type": "box", "size": [0.002, 2, 2]},
             "appearance": {"transparency": 1.0}}
    wall = {"name": "wall", "pose": {"translation": [WALL_X + 0.05, 0, 0]}, "geometry": {"type": "box", "size": [0.1, 2, 2]}}
    sim = world([{"device": "DistanceSensor", "name": t, "type": t, "lookup_table": [[0, 0, 0], [1, 1, 0]],
                  "red_color_sensitivity": 0} for t in ("infra-red", "laser", "generic")], solids=[glass, wall])
    for t in ("infra-red", "laser", "generic"):
        sim.device(f"r/{t}").enable(32)
    sim.step()
    assert sim.device("r/infra-red").value == pytest.approx(WALL_X, abs=1e-12)
    assert sim.device("r/laser").value == pytest.approx(WALL_X, abs=1e-12)
    assert sim.device("r/generic").value == pytest.approx(0.019, abs=1e-12)   # generic sees it


def test_own_body_ignored_by_bounding_rays_unless_self_collision() -> None:
    for self_collision in (False, True):
        data = {"solids": [{"name": "wall", "pose": {"translation": [WALL_X + 0.05, 0, 0]},
                            "geometry": {"type": "box", "size": [0.1, 2, 2]}}],
                "robots": [{"name": "r", "self_collision": self_collision,
                            "body": {"geometry": {"type": "sphere", "radius": 0.03}},
                            "devices": [{"device": "DistanceSensor", "name": "d", "lookup_table": [[0, 0, 0], [1, 1, 0]],
                                         "pose": {"translation": [-0.1, 0, 0]}}]}]}
        sim = Simulation(parse_world(data))
        sim.device("r/d").enable(32)
        sim.step()
        # from x=-0.1 the own body's near surface is at x=-0.03 (distance 0.07); the wall at 0.15
        assert sim.device("r/d").value == pytest.approx(0.07 if self_collision else WALL_X + 0.1, abs=1e-9)


@pytest.mark.parametrize("offset", [1e5, 1e6])
def test_far_from_origin_exact(offset: float) -> None:
    sim = world([{"device": "DistanceSensor", "name": "d", "number_of_rays": 4, "aperture": 0.3,
                  "lookup_table": [[0, 0, 0], [1, 1, 0]]}], offset=(offset, -offset / 3, 0.5 * offset))
    ref = world([{"device": "DistanceSensor", "name": "d", "number_of_rays": 4, "aperture": 0.3,
                  "lookup_table": [[0, 0, 0], [1, 1, 0]]}])
    for s in (sim, ref):
        s.device("r/d").enable(32)
        s.step()
    assert sim.device("r/d").value == pytest.approx(ref.device("r/d").value, abs=1e-9)


# ------------------------------------------------------------------ light sensors, closed form

def test_point_light_irradiance_and_occlusion() -> None:
    lights = [{"type": "PointLight", "location": [2.0, 0, 0], "intensity": 3.0, "attenuation": [0, 0, 1]}]
    wall = {"name": "wall", "pose": {"translation": [1.0, 0, 0]}, "geometry": {"type": "box", "size": [0.1, 1, 1]}}
    sim = world([{"device": "LightSensor", "name": "open", "lookup_table": [[0, 0, 0], [100, 100, 0]]},
                 {"device": "LightSensor", "name": "shaded", "occlusion": True, "lookup_table": [[0, 0, 0], [100, 100, 0]]}],
                solids=[wall], lights=lights)
    for n in ("open", "shaded"):
        sim.device(f"r/{n}").enable(32)
    sim.step()
    assert sim.device("r/open").value == pytest.approx(3.0 / 4.0, abs=1e-12)   # I*c/d^2 * (1+1+1)/3
    assert sim.device("r/shaded").value == 0.0
    sim.set_solid_pose("wall", [1.0, 5.0, 0.0])                                 # move the wall away
    sim.step()
    assert sim.device("r/shaded").value == pytest.approx(0.75, abs=1e-12)


def test_light_sensor_with_an_empty_lookup_table_reads_the_irradiance() -> None:
    # devices.md §1.2: an empty table returns its input unchanged (the world used to pass validate
    # and then fail every step)
    lights = [{"type": "PointLight", "location": [2.0, 0, 0], "intensity": 3.0, "attenuation": [0, 0, 1]}]
    sim = world([{"device": "LightSensor", "name": "raw", "lookup_table": [], "resolution": 0.25}], solids=[],
                lights=lights)
    sim.device("r/raw").enable(32)
    sim.step()
    assert sim.device("r/raw").value == 0.75                                    # 3/2² = 0.75, a multiple of 0.25


def test_occlusion_rays_one_per_lit_light() -> None:
    lights = [{"type": "PointLight", "location": [2.0, y, 0.0]} for y in (-1.0, 0.0, 1.0)]
    lights.append({"type": "PointLight", "location": [-2.0, 0.0, 0.0]})          # behind: no direct term
    lights.append({"type": "PointLight", "location": [2.0, 0.0, 0.0], "on": False})
    sim = world([{"device": "LightSensor", "name": "a", "occlusion": True},
                 {"device": "LightSensor", "name": "b", "occlusion": False}], solids=[], lights=lights)
    sim.device("r/a").enable(32)
    sim.device("r/b").enable(32)
    sim.run(4)
    assert sim.counters["rays_light"] == 3 * 4


def test_lighting_world_occlusion_on_and_off() -> None:
    from pathlib import Path

    sim = Simulation.from_file(Path(__file__).resolve().parents[1] / "sensorium" / "worlds" / "lighting.yaml")
    for d in sim.all_devices():
        d.enable(32)
    sim.step()
    v = {d.name: d.value for d in sim.all_devices()}
    assert v["east_occluded"] < v["east_open"]        # the screen hides the bulb
    assert v["north_occluded"] < v["north_open"]      # the lamp shade hides the shaded bulb
    assert all(math.isfinite(x) for x in v.values())


# ------------------------------------------------------------------ lidar

ROOM = 2.0  # half-size of the square room


def room_world(lidar: dict, precision: str = "exact", step: int = 32) -> Simulation:
    walls = []
    for name, (x, y, sx, sy) in {"n": (0, ROOM + 0.05, 2 * ROOM + 0.2, 0.1), "s": (0, -ROOM - 0.05, 2 * ROOM + 0.2, 0.1),
                                 "e": (ROOM + 0.05, 0, 0.1, 2 * ROOM), "w": (-ROOM - 0.05, 0, 0.1, 2 * ROOM)}.items():
        walls.append({"name": name, "pose": {"translation": [x, y, 0]}, "geometry": {"type": "box", "size": [sx, sy, 4.0]}})
    data = {"world_info": {"basic_time_step": step}, "solids": walls,
            "robots": [{"name": "r", "devices": [{"device": "Lidar", "name": "l", **lidar}]}]}
    return Simulation(parse_world(data), precision=precision)


@pytest.mark.parametrize("layers", [1, 8])
def test_lidar_points_lie_on_walls(layers: int) -> None:
    sim = room_world({"horizontal_resolution": 180, "field_of_view": 2 * math.pi, "number_of_layers": layers,
                      "vertical_field_of_view": 0.4, "max_range": 10, "min_range": 0.1})
    lidar = sim.device("r/l")
    lidar.enable(32)
    lidar.enable_point_cloud()
    sim.step()
    assert lidar.range_image.shape == (layers, 180) and lidar.range_image.dtype == np.float32
    pts = lidar.point_cloud
    xyz = np.stack([pts["x"], pts["y"], pts["z"]], axis=1).astype(np.float64)
    on_wall = np.minimum(np.abs(np.abs(xyz[:, 0]) - ROOM), np.abs(np.abs(xyz[:, 1]) - ROOM))
    assert np.all(on_wall < 2e-6)   # float32 storage of coordinates ~2 m
    np.testing.assert_allclose(np.linalg.norm(xyz, axis=1), lidar.range_image.reshape(-1), rtol=1e-6)
    assert set(np.unique(pts["layer_id"])) == set(range(layers))


def test_lidar_laser_scan_angles_reproduce_points() -> None:
    W = 90
    fov = 3.0
    sim = room_world({"horizontal_resolution": W, "field_of_view": fov, "number_of_layers": 1, "max_range": 10})
    lidar = sim.device("r/l")
    lidar.enable(32)
    lidar.enable_point_cloud()
    sim.step()
    ranges = lidar.range_image[0].astype(np.float64)
    # LaserScan convention used on the wire: angle_min = first column, negative increment
    angle_min, inc = fov / 2 - 0.5 * fov / W, -fov / W
    ang = angle_min + inc * np.arange(W)
    pts = lidar.point_cloud
    np.testing.assert_allclose(ranges * np.cos(ang), pts["x"], atol=1e-5)
    np.testing.assert_allclose(ranges * np.sin(ang), pts["y"], atol=1e-5)


def test_lidar_range_limits_give_inf() -> None:
    sim = room_world({"horizontal_resolution": 64, "field_of_view": 2 * math.pi, "number_of_layers": 1,
                      "max_range": 2.2, "min_range": 0.1})
    lidar = sim.device("r/l")
    lidar.enable(32)
    sim.step()
    r = lidar.range_image[0]
    # walls are at 2.0 (axis-aligned) up to 2.83 (corners): beyond 2.2 is +inf
    assert np.isinf(r).any() and np.isfinite(r).any()
    assert np.all(r[np.isfinite(r)] < 2.2)


def test_lidar_zero_before_first_measurement_and_full_circle_no_duplicate() -> None:
    sim = room_world({"horizontal_resolution": 4, "field_of_view": 2 * math.pi, "number_of_layers": 1, "max_range": 10})
    lidar = sim.device("r/l")
    assert np.all(lidar.range_image == 0)
    lidar.enable(64)
    sim.step()
    assert np.all(lidar.range_image == 0)
    sim.step()
    # 4 columns of a full circle at azimuths 3pi/4, pi/4, -pi/4, -3pi/4: all corners, all distinct
    np.testing.assert_allclose(lidar.range_image[0], ROOM * math.sqrt(2), rtol=1e-6)


def test_disabled_lidar_adds_no_ray_and_point_cloud_only_when_enabled() -> None:
    sim = room_world({"horizontal_resolution": 32, "number_of_layers": 2, "max_range": 10})
    sim.run(3)
    assert sim.counters["rays_lidar"] == 0
    lidar = sim.device("r/l")
    lidar.enable(32)
    sim.run(2)
    assert sim.counters["rays_lidar"] == 2 * 64 and sim.counters["points_built"] == 0
    lidar.enable_point_cloud()
    sim.step()
    assert sim.counters["points_built"] == 64


def test_rotating_lidar_sweeps_sectors() -> None:
    # 10 Hz, 25 ms step: a quarter turn per step, a full panorama in 4 steps
    sim = room_world({"type": "rotating", "horizontal_resolution": 64, "field_of_view": 2 * math.pi, "number_of_layers": 1,
                      "max_range": 10, "default_frequency": 10}, step=25)
    lidar = sim.device("r/l")
    lidar.enable(25)
    lidar.enable_point_cloud()
    filled = []
    for _ in range(4):
        sim.step()
        filled.append(int(np.count_nonzero(lidar.range_image)))
    assert filled == [16, 32, 48, 64]
    assert sim.counters["rays_lidar"] == 64
    times = lidar.point_cloud["time"]
    assert times.min() >= 0.0 and times.max() < 0.1 + 1e-6
    # the panorama is that of a fixed full-circle lidar with the rotating column order
    assert np.all(np.isfinite(lidar.range_image))


def test_lidar_inside_closed_mesh_sees_it_everywhere(tmp_path) -> None:
    import trimesh

    trimesh.creation.icosphere(subdivisions=3, radius=1.0).export(tmp_path / "ball.stl")
    data = {"solids": [{"name": "ball", "geometry": {"type": "mesh", "url": "ball.stl"}}],
            "robots": [{"name": "r", "devices": [{"device": "Lidar", "name": "l", "horizontal_resolution": 720,
                                                  "field_of_view": 2 * math.pi, "number_of_layers": 16,
                                                  "vertical_field_of_view": 1.2, "max_range": 5}]}]}
    sim = Simulation(parse_world(data, base_dir=tmp_path))
    lidar = sim.device("r/l")
    lidar.enable(32)
    sim.step()
    r = lidar.range_image
    assert np.all(np.isfinite(r)) and r.min() > 0.98 and r.max() <= 1.0 + 1e-6


# ------------------------------------------------------------------ noise streams

def _noisy_world(extra: bool) -> Simulation:
    devices = [{"device": "DistanceSensor", "name": "d", "lookup_table": [[0, 0, 0.1], [0.1, 1000, 0.1]]}]
    if extra:
        devices.append({"device": "DistanceSensor", "name": "e", "lookup_table": [[0, 0, 0.2], [0.1, 1000, 0.2]]})
    sim = world(devices)
    sim.device("r/d").enable(32)
    if extra:
        sim.device("r/e").enable(32)
    return sim


def test_noise_reproducible_and_independent_of_other_devices() -> None:
    runs = []
    for extra in (False, False, True):
        sim = _noisy_world(extra)
        vals = []
        for _ in range(20):
            sim.step()
            vals.append(sim.device("r/d").value)
        runs.append(vals)
    assert runs[0] == runs[1] == runs[2]
    assert np.std(runs[0]) > 10   # noise is really there (σ = 10 % of 500)


# ------------------------------------------------------------------ moving things, batching

def test_moving_robot_changes_reading_without_bvh_rebuild() -> None:
    data = {"solids": [{"name": "wall", "pose": {"translation": [1.0, 0, 0]}, "geometry": {"type": "box", "size": [0.1, 4, 4]}}],
            "robots": [{"name": "r", "body": {"geometry": {"type": "box", "size": [0.1, 0.1, 0.1]}},
                        "devices": [{"device": "DistanceSensor", "name": "d", "lookup_table": [[0, 0, 0], [2, 2, 0]]}]},
                       {"name": "other", "pose": {"translation": [0.5, 0, 0]}, "body": {"geometry": {"type": "sphere", "radius": 0.1}}}]}
    sim = Simulation(parse_world(data))
    d = sim.device("r/d")
    d.enable(32)
    sim.step()
    assert d.value == pytest.approx(0.4, abs=1e-9)      # the other robot's body, 0.5 - 0.1
    builds = sim.counters["bvh_builds"]
    sim.robot("other").set_pose([0.5, 1.0, 0.0])
    sim.step()
    assert d.value == pytest.approx(0.95, abs=1e-9)     # the wall
    sim.robot("r").set_pose([0.3, 0.0, 0.0])
    sim.step()
    assert d.value == pytest.approx(0.65, abs=1e-9)
    assert sim.counters["bvh_builds"] == builds


def test_all_sensors_of_a_step_share_one_cast_per_ray_kind_and_outputs() -> None:
    from pathlib import Path

    sim = Simulation.from_file(Path(__file__).resolve().parents[1] / "sensorium" / "worlds" / "arena.yaml")
    for d in sim.all_devices():
        d.enable(32)
    sim.step()
    # casts: infra-red (visual, with normals and shapes), lidar (visual, distances only), sonar +
    # light occlusion (bounding); lidars share one distance-only cast whatever their number
    assert sim.counters["cast_calls"] == 3


# ------------------------------------------------------------------ probe command

def test_probe_json_lines() -> None:
    res = subprocess.run([sys.executable, "-m", "sensorium", "probe", "--steps", "3", "--json",
                          "--enable", "epuck/ps0:64", "--enable", "scout/lidar:32"],
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    rows = [json.loads(line) for line in res.stdout.splitlines()]
    assert [(r["step"], r["device"]) for r in rows] == [(1, "ps0"), (1, "lidar"), (2, "ps0"), (2, "lidar"), (3, "ps0"), (3, "lidar")]
    assert rows[0]["value"] is None and isinstance(rows[2]["value"], float)
    assert rows[1]["range_image"]["shape"] == [1, 360] and rows[1]["time_ms"] == 32


def test_probe_enables_all_devices_of_every_kind(tmp_path) -> None:
    """``probe --enable all:P`` on a world with an altimeter, an emitter and a receiver: it ended in
    a traceback (AttributeError: 'Altimeter' object has no attribute 'readings'); every device
    kind the simulation makes now says what it reads."""
    from sensorium.schemas.devices import KINDS
    from sensorium.server.sim.sensors import Device, device_class

    for name in KINDS:
        cls = device_class(name)
        if cls is not None and issubclass(cls, Device):     # (a motor is the drive's, never enabled)
            assert callable(getattr(cls, "readings", None)), name
    (tmp_path / "w.yaml").write_text(json.dumps({
        "world_info": {"basic_time_step": 32},
        "robots": [{"name": "a", "devices": [{"device": "Altimeter", "name": "alt"}, {"device": "Emitter", "name": "em"}]},
                   {"name": "b", "devices": [{"device": "Receiver", "name": "rx"}]}]}))
    res = subprocess.run([sys.executable, "-m", "sensorium", "probe", str(tmp_path / "w.yaml"), "--steps", "2",
                          "--json", "--enable", "all:32"], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    rows = [json.loads(line) for line in res.stdout.splitlines()]
    assert [(r["step"], r["device"]) for r in rows] == [(k, d) for k in (1, 2) for d in ("alt", "em", "rx")]
    assert rows[0]["value"] == 0.0 and rows[1]["range"] == -1.0 and rows[2]["queue_length"] == 0.0


def test_probe_rejects_bad_enable() -> None:
    res = subprocess.run([sys.executable, "-m", "sensorium", "probe", "--enable", "epuck/nope:32"],
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 2 and "no device 'nope'" in res.stderr


# ------------------------------------------------------------------ kinematic drive

def _driven(**drive) -> Simulation:
    data = {"world_info": {"basic_time_step": 16},
            "robots": [{"name": "r", "pose": {"translation": [1.0, 2.0, 0.0], "rotation": [0, 0, 1, 0.5]},
                        "differential_drive": {"wheel_radius": 0.02, "axle_length": 0.05, "max_wheel_speed": 10, **drive}}]}
    return Simulation(parse_world(data))


def test_drive_straight_and_turn_in_place() -> None:
    sim = _driven()
    r = sim.robot("r")
    left, right = r.motor("left wheel motor"), r.motor("right wheel motor")
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(5.0)
    sim.run(100)                                   # 1.6 s at 0.1 m/s
    np.testing.assert_allclose(r.pose.translation, [1 + 0.16 * math.cos(0.5), 2 + 0.16 * math.sin(0.5), 0], atol=1e-12)
    left.set_velocity(-5.0)
    sim.run(10)                                    # turn in place: w = 0.02*10/0.05 = 4 rad/s for 0.16 s
    fwd = r.pose.rotation[:, 0]
    assert math.atan2(fwd[1], fwd[0]) == pytest.approx(0.5 + 0.64, abs=1e-12)
    np.testing.assert_allclose(r.pose.translation[:2], [1 + 0.16 * math.cos(0.5), 2 + 0.16 * math.sin(0.5)], atol=1e-12)


def test_velocity_clamped_and_position_control_stops_at_target() -> None:
    sim = _driven()
    m = sim.robot("r").motor("left wheel motor")
    m.set_velocity(100.0)
    assert m.velocity == 10.0
    m.set_position(1.0)                            # position control at speed 10 rad/s
    sim.run(20)
    assert m.position == pytest.approx(1.0, abs=1e-12)
    with pytest.raises(ValueError, match="must be a number"):
        m.set_velocity(math.nan)
    with pytest.raises(KeyError, match="no motor 'x'"):
        sim.robot("r").motor("x")


def test_negative_velocity_in_position_control_is_ignored_with_webots_line_as_the_clients_do(capsys) -> None:
    """Webots' libController (and both clients) print one error line and ignore setVelocity(v < 0)
    while the motor is in position control; the in-process API took it and ran at |v|. The wheel
    keeps maxVelocity (10 rad/s) as its speed limit: one 16 ms step towards target 1 rad turns it
    0.16 rad (0.048 at 3 rad/s). In velocity control a negative velocity turns the wheel backwards."""
    sim = _driven()
    m = sim.robot("r").motor("left wheel motor")
    m.set_position(1.0)
    m.set_velocity(-3.0)
    err = capsys.readouterr().err.splitlines()
    assert err == ["Error: setVelocity() called with negative 'velocity' argument in position control mode (1): "
                   "motor 'left wheel motor' keeps 10."]
    assert m.velocity == 10.0
    sim.run(1)
    assert m.position == pytest.approx(0.16, abs=1e-12)
    m.set_position(math.inf)
    m.set_velocity(-3.0)
    assert m.velocity == -3.0 and capsys.readouterr().err == ""
    sim.run(1)
    assert m.position == pytest.approx(0.16 - 0.048, abs=1e-12)


def test_infinite_velocity_is_clamped_to_max_velocity_as_the_clients_do() -> None:
    """set_velocity(inf) raised ValueError in process where the Python and C clients clamp it to
    maxVelocity (Webots' WbMotor::setVelocity clamps any |v| > maxVelocity, inf included):
    velocity control at +inf/-inf turns the wheel at +/-maxVelocity, position control at inf moves
    toward the target at maxVelocity. tests/test_c_client.py runs the same commands through both
    clients and compares them with this simulation's lines."""
    sim = _driven()
    left, right = sim.robot("r").motor("left wheel motor"), sim.robot("r").motor("right wheel motor")
    left.set_position(math.inf)
    right.set_position(math.inf)
    left.set_velocity(math.inf)
    right.set_velocity(-math.inf)
    assert (left.velocity, right.velocity) == (10.0, -10.0)
    sim.run(5)
    assert (left.position, right.position) == (pytest.approx(10.0 * 0.08), pytest.approx(-10.0 * 0.08))
    left.set_position(0.0)
    left.set_velocity(float("inf"))            # position control: the speed limit is maxVelocity
    assert left.velocity == 10.0
    sim.run(5)
    assert left.position == pytest.approx(0.0, abs=1e-12)
    for bad in (math.nan, "fast", True):
        with pytest.raises(ValueError, match="must be a number"):
            left.set_velocity(bad)             # type: ignore[arg-type]


def test_encoder_resolution_is_webots_discretize() -> None:
    """A PositionSensor's resolution is Webots' discretize, (int)(v/res + 0.5)·res, as for the
    other sensors: a wheel turned back to -1.4 rad reads -1.0 with res 0.5, and 1.25 rad reads 1.5
    (they read -1.5 and 1.0: Python's round, which rounds halves to even and negatives
    symmetrically)."""
    data = {"world_info": {"basic_time_step": 16},
            "robots": [{"name": "r", "differential_drive": {"wheel_radius": 0.02, "axle_length": 0.05, "max_wheel_speed": 10},
                        "devices": [{"device": "PositionSensor", "name": "enc", "motor": "left wheel motor",
                                     "resolution": 0.5}]}]}
    sim = Simulation(parse_world(data))
    m, enc = sim.robot("r").motor("left wheel motor"), sim.device("r/enc")
    enc.enable(16)
    for target, webots in ((-1.4, -1.0), (1.25, 1.5), (-0.2, 0.0), (0.75, 1.0), (-2.75, -2.5)):
        m.set_position(target)
        sim.run(100)
        assert m.position == target and enc.value == webots, (target, enc.value)


def test_circle_stays_on_circle_for_a_million_steps() -> None:
    from sensorium.server.sim.motion import arc_step

    v, w, dt = 0.1, 0.7, 0.016            # radius v/w around the centre (0, v/w) from the origin
    x = y = yaw = 0.0
    for _ in range(1_000_000):
        x, y, yaw = arc_step(x, y, yaw, v, w, dt)
    assert math.hypot(x, y - v / w) == pytest.approx(v / w, abs=1e-9)
    # and it is where the closed form says after 16,000 s
    phase = w * 16_000.0
    assert x == pytest.approx((v / w) * math.sin(phase), abs=1e-6)


def test_driving_changes_sensor_readings() -> None:
    data = {"world_info": {"basic_time_step": 32},
            "solids": [{"name": "wall", "pose": {"translation": [1.0, 0, 0]}, "geometry": {"type": "box", "size": [0.1, 4, 1]}}],
            "robots": [{"name": "r", "differential_drive": {"wheel_radius": 0.05, "axle_length": 0.1},
                        "devices": [{"device": "DistanceSensor", "name": "d", "lookup_table": [[0, 0, 0], [2, 2, 0]]}]}]}
    sim = Simulation(parse_world(data))
    r = sim.robot("r")
    for m in r.motors.values():
        m.set_position(math.inf)
        m.set_velocity(2.0)                         # 0.1 m/s
    sim.device("r/d").enable(32)
    sim.run(10)
    assert sim.device("r/d").value == pytest.approx(0.95 - 0.1 * 0.32, abs=1e-12)
