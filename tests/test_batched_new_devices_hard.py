"""Hard cases for the batched simulation's newest devices (sensorium/server/sim/batched_lidar.py,
batched_kinematic.py): rotating lidars far from the origin, turning more than a turn or a tiny
fraction of a column per step, one column or one layer, tiny and huge ranges, 256 copies reset on the
step their sector wraps, a 10^4-step run; WGS84 GPS near the poles, on a zone boundary, at the
antimeridian, just south of the equator, 100 km from the reference, with noise and resolution; bumpers
touching a wall at rest, sliding along it at a grazing angle, copies at the same pose not seeing one
another, a 60 s basic step; altimeters far away, quantised, on a tilted mount; the vector env's
autoreset on the step a bumper reads 1. Each against the single Simulation bit for bit and, where
there is one, a closed form. All worlds are written here."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sensorium.schemas import world as wm
from sensorium.server.devices import lidar as lmath
from sensorium.server.devices.gps import Utm
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import from_model

BOTH = ["fast", "exact"]


def _rounded(lo: float, hi: float):
    """Floats in [lo, hi] to 9 decimals (a world file refuses magnitudes below 1e-30 other than 0)."""
    return st.floats(lo, hi).map(lambda v: min(max(round(v, 9), lo), hi))


# ---------------------------------------------------------------------------------- rotating lidars

def _room(origin=(0.0, 0.0), heading: float = 0.0, W: int = 36, L: int = 3, f: float = 7.0, f_max: float = 20.0,
          max_range: float = 10.0, dt: int = 16, noise: float = 0.0, half: float = 1.5) -> wm.World:
    """A robot at the centre of a square room (walls ``half`` m from it, 2 m tall) at ``origin``,
    heading ``heading``, carrying a rotating lidar 1 m up: W columns over 2π, L layers over 0.3 rad
    (one layer: flat), turning at ``f`` Hz."""
    ox, oy = origin
    walls = [{"name": f"wall{k}", "pose": {"translation": [ox + x, oy + y, 1.0]},
              "geometry": {"type": "box", "size": [sx, sy, 2.0]}}
             for k, (x, y, sx, sy) in enumerate([(half + 0.05, 0, 0.1, 2 * half + 0.2), (-half - 0.05, 0, 0.1, 2 * half + 0.2),
                                                 (0, half + 0.05, 2 * half + 0.2, 0.1), (0, -half - 0.05, 2 * half + 0.2, 0.1)])]
    lidar = {"device": "Lidar", "name": "head", "pose": {"translation": [0, 0, 1.0]}, "type": "rotating",
             "horizontal_resolution": W, "field_of_view": 2 * math.pi, "number_of_layers": L,
             "vertical_field_of_view": 0.3 if L > 1 else 0.0, "near": 0.01, "min_range": 0.01, "max_range": max_range,
             "noise": noise, "default_frequency": f, "min_frequency": min(f, 1.0), "max_frequency": f_max}
    return wm.World.model_validate({
        "world_info": {"basic_time_step": dt, "random_seed": 1},
        "solids": walls,
        "robots": [{"name": "bot", "pose": {"translation": [ox, oy, 0], "rotation": [0, 0, 1, heading]},
                    "devices": [lidar]}]})


def _lidar_pair(headings: list[float], precision: str, **kw):
    """A batched simulation of the room with one copy per heading and a Simulation per copy, the
    lidar enabled every step in all."""
    bs = BatchedSimulation(from_model(_room(**kw)), len(headings), precision=precision)
    for c, yaw in enumerate(headings):
        bs.set_pose(c, 0, rotation=[0, 0, 1, yaw])
    dt = kw.get("dt", 16)
    bs.enable(bs.device("bot", "head"), dt)
    sims = [Simulation(from_model(_room(heading=yaw, **kw)), precision=precision) for yaw in headings]
    for s in sims:
        s.robot("bot").device("head").enable(dt)
    return bs, sims


def _same_lidar(bs: BatchedSimulation, sims: list[Simulation], copies, where) -> None:
    """Every listed copy's range image and head angle equal its Simulation's, bit for bit."""
    ref = bs.device("bot", "head")
    images = bs.range_image(ref)
    for c in copies:
        dev = sims[c].robot("bot").device("head")
        assert images[c].tobytes() == dev.range_image.tobytes(), (where, c)
        assert bs.rotating_lidars.head[c, 0] == dev.head_angle, (where, c)


def _wall_distances(yaw: float, W: int, L: int, half: float = 1.5) -> np.ndarray:
    """(L, W) closed form: column j of layer i leaves at azimuth ``yaw + π - j·2π/W`` and elevation
    ``0.15 - i·0.3/(L-1)`` (0 for one layer) and meets the nearer wall of the square room."""
    a = yaw + math.pi - np.arange(W) * (2 * math.pi / W)
    elev = 0.15 - np.arange(L) * (0.3 / (L - 1)) if L > 1 else np.zeros(1)
    return half / np.maximum(np.abs(np.cos(a)), np.abs(np.sin(a)))[None, :] / np.cos(elev)[:, None]


# name: (room arguments, steps); every case compared with Simulation and the closed form
LIDAR_CASES = {
    "far from the origin (1e5 m)": ({"origin": (1e5, -1e5)}, 12),
    "1.6 turns per step": ({"f": 100.0, "f_max": 100.0}, 6),
    "1.28 turns per 64 ms step": ({"f": 20.0, "dt": 64}, 6),
    "0.00128 columns per step": ({"f": 0.01, "W": 8}, 30),
    "one column": ({"W": 1}, 30),
    "one layer": ({"L": 1, "W": 40}, 12),
    "one column, one layer": ({"W": 1, "L": 1, "f": 11.0}, 30),
    "max range below the walls": ({"max_range": 0.05}, 12),
    "max range 1e6 m": ({"max_range": 1e6}, 12),
}


@pytest.mark.parametrize("precision", BOTH)
@pytest.mark.parametrize("case", list(LIDAR_CASES))
def test_rotating_lidar_hard_cases_equal_the_single_simulation_and_the_closed_form(case: str, precision: str):
    """Each case (two copies heading 0 and 0.4 rad): after every step both images and head angles
    equal the single simulation's bit for bit; the columns swept so far are ``ceil(W/2) ...
    ceil(W/2 + a·k) - 1`` (mod W, a = f·dt·W columns a step, all of them once a >= W), each reading
    the closed-form wall distance (+inf when the walls are beyond max range), the others still 0."""
    kw, steps = LIDAR_CASES[case]
    headings = [0.0, 0.4]
    bs, sims = _lidar_pair(headings, precision, **kw)
    W, L = kw.get("W", 36), kw.get("L", 3)
    advance = kw.get("f", 7.0) * kw.get("dt", 16) / 1000.0 * W
    seen_swept = 0
    for k in range(1, steps + 1):
        bs.step()
        for s in sims:
            s.step()
        _same_lidar(bs, sims, range(len(headings)), k)
        start, end = math.ceil(W / 2), math.ceil(W / 2 + advance * k)
        swept = np.unique(np.arange(max(start, end - W), end) % W)
        for c, yaw in enumerate(headings):
            img = bs.range_image(bs.device("bot", "head"))[c]
            want = _wall_distances(yaw, W, L)
            got = img[:, swept].astype(np.float64)
            if kw.get("max_range", 10.0) < 1.4:
                assert np.isinf(got).all(), (k, c)
            else:
                assert np.allclose(got, want[:, swept], rtol=0, atol=2e-5), (k, c)
            assert (np.delete(img, swept, axis=1) == 0.0).all(), (k, c)
        seen_swept = max(seen_swept, len(swept))
    assert seen_swept >= 1


@settings(max_examples=12, deadline=None, suppress_health_check=list(HealthCheck), database=None)
@given(W=st.integers(1, 64), L=st.integers(1, 4), f=st.floats(0.05, 60.0), dt=st.sampled_from([8, 16, 32, 64]),
       yaw=_rounded(-math.pi, math.pi), x=_rounded(-1e5 + 2.0, 1e5 - 2.0), y=_rounded(-1e5 + 2.0, 1e5 - 2.0))
def test_any_rotating_lidar_anywhere_sweeps_as_the_single_simulation(W, L, f, dt, yaw, x, y):
    """Property: a rotating lidar of any width and layer count turning at any frequency (a sliver of a
    column to several turns a step) on any basic step, anywhere in the world bounds, heading anywhere:
    after every one of 5 steps both copies' images and head angles equal the single simulation's."""
    bs, sims = _lidar_pair([yaw, -yaw], "fast", W=W, L=L, f=f, f_max=60.0, dt=dt, origin=(x, y))
    for k in range(5):
        bs.step()
        for s in sims:
            s.step()
        _same_lidar(bs, sims, [0, 1], k)


def _fresh_simulation(sims: list[Simulation], copies: list[int], kw: dict) -> None:
    """The listed copies, reset together, become one new Simulation of the room (heading 0): fresh
    simulations of one world step alike, so one stands for them all (stepped once a step)."""
    fresh = Simulation(from_model(_room(**kw)), precision="fast")
    fresh.robot("bot").device("head").enable(16)
    for c in copies:
        sims[c] = fresh


def test_256_copies_reset_on_the_step_their_sector_wraps_read_as_fresh_simulations():
    """256 copies at random headings, each copy's head starting at 0 (40 columns, 9.3 Hz: 5.95
    columns a step). A copy is reset (a new world, its Simulation rebuilt: one for the copies reset
    together) right after the step whose sweep wrapped past 2π, another right before such a step
    (from the single model's next sweep):
    after every step every copy's image and head angle equal its Simulation's bit for bit, and the
    resets did happen on wrapping steps."""
    C, kw = 256, {"W": 40, "L": 2, "f": 9.3}
    rng = np.random.default_rng(3)
    headings = rng.uniform(-math.pi, math.pi, C).tolist()
    bs, sims = _lidar_pair(headings, "fast", **kw)
    ref = bs.device("bot", "head")
    dev0 = sims[0].robot("bot").device("head")
    params, freq = dev0.params, dev0.frequency
    resets = {"after": 0, "before": 0}
    for step in range(20):
        before = [s.robot("bot").device("head").head_angle for s in sims]
        # copies whose next sweep wraps, reset first (every 3rd copy): they start over at head 0
        wrap_next = [c for c in range(0, C, 3)
                     if lmath.rotating_sweep(params, before[c], freq, 16).head_angle_after > before[c]]
        if wrap_next:
            bs.reset(wrap_next, [1] * len(wrap_next))
            bs.enable(ref, 16, copies=wrap_next)
            _fresh_simulation(sims, wrap_next, kw)
            resets["before"] += len(wrap_next)
            before = [s.robot("bot").device("head").head_angle for s in sims]
        bs.step()
        for s in {id(s): s for s in sims}.values():
            s.step()
        _same_lidar(bs, sims, range(C), step)
        wrapped = [c for c in range(1, C, 3) if sims[c].robot("bot").device("head").head_angle > before[c]]
        if wrapped:     # the sector just swept past 2π: reset right after
            bs.reset(wrapped, [1] * len(wrapped))
            bs.enable(ref, 16, copies=wrapped)
            _fresh_simulation(sims, wrapped, kw)
            resets["after"] += len(wrapped)
            assert (bs.range_image(ref)[wrapped] == 0.0).all()
    assert resets["after"] > 50 and resets["before"] > 50


@pytest.mark.slow
def test_ten_thousand_steps_keep_the_head_angle_of_the_single_model():
    """10^4 steps of a noisy rotating lidar (37 columns, 7.3 Hz): the batched head angle equals the
    single device's after every step (no separate drift) and stays within 1e-9 rad of the closed form
    ``wrap(-2π·f·dt·k)``; the images are equal every 100 steps."""
    kw = {"W": 37, "L": 2, "f": 7.3, "noise": 0.02}
    bs, sims = _lidar_pair([0.0], "fast", **kw)
    dev = sims[0].robot("bot").device("head")
    worst = 0.0
    for k in range(1, 10_001):
        bs.step()
        sims[0].step()
        assert bs.rotating_lidars.head[0, 0] == dev.head_angle, k
        if k % 100 == 0:
            _same_lidar(bs, sims, [0], k)
        exact = -2.0 * math.pi * 7.3 * 0.016 * k
        worst = max(worst, abs(math.remainder(dev.head_angle - exact, 2.0 * math.pi)))
    assert worst < 1e-9


# ---------------------------------------------------------------------------------- WGS84 GPS

def _gps_world(reference, accuracy: float = 0.0, resolution: float = -1.0) -> wm.World:
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 16, "gps_coordinate_system": "WGS84", "gps_reference": list(reference),
                       "random_seed": 4},
        "robots": [{"name": "bot", "pose": {"translation": [0.0, 0.0, 0.0]},
                    "differential_drive": {"wheel_radius": 0.05, "axle_length": 0.2, "max_wheel_speed": 10.0},
                    "devices": [{"device": "GPS", "name": "gps", "accuracy": accuracy, "resolution": resolution,
                                 "noise_correlation": 0.5, "speed_noise": 0.1 if accuracy else 0.0},
                                {"device": "Altimeter", "name": "alt", "accuracy": accuracy, "resolution": resolution}]}]})


# east, north of the reference (m): at it, 1 km and 100 km away
OFFSETS = [(0.0, 0.0), (1e3, 0.0), (0.0, -1e3), (1e5, 0.0), (-1e5, 0.0), (0.0, 1e5), (0.0, -1e5), (7e4, -7e4)]
REFERENCES = {
    "north of 84°": (84.5, 10.0, 0.0),
    "south of -84°": (-84.5, -60.0, 12.0),
    "on a zone boundary (6°E)": (0.0, 6.0, 0.0),
    "antimeridian, west side": (10.0, -180.0, 0.0),
    "antimeridian, east side": (-0.0001, 179.999, 0.0),
    "just south of the equator, on a central meridian": (-1e-9, 3.0, -30.0),
}


def _gps_pair(reference, accuracy: float, resolution: float, seeds: list[int]):
    loaded = from_model(_gps_world(reference, accuracy, resolution))
    bs = BatchedSimulation(loaded, len(OFFSETS))
    bs.reset(np.arange(len(OFFSETS)), seeds)
    sims = []
    for c, (e, n) in enumerate(OFFSETS):
        bs.set_pose(c, 0, [e, n, 0.0])
        w = _gps_world(reference, accuracy, resolution)
        w = w.model_copy(update={"world_info": w.world_info.model_copy(update={"random_seed": seeds[c]})})
        s = Simulation(from_model(w))
        s.robot("bot").set_pose([e, n, 0.0])
        sims.append(s)
    for name in ("gps", "alt"):
        bs.enable(bs.device("bot", name), 16)
        for s in sims:
            s.robot("bot").device(name).enable(16)
    return bs, sims


@pytest.mark.parametrize("noisy", [False, True])
@pytest.mark.parametrize("where", list(REFERENCES))
def test_wgs84_gps_hard_references_equal_the_single_simulation(where: str, noisy: bool):
    """GPS (and altimeter) 0, 1 km and 100 km from references near the poles, on a zone boundary,
    either side of the antimeridian and just south of the equator, plain or with noise (0.5 m,
    correlated, speed noise) and a 1 cm resolution: every value, speed and speed vector equals the
    single simulation's bit for bit over 4 steps. Noise-free, the single model's forward projection of
    each reading is the reference's UTM east / north plus the offset (1 mm within 1 km; within 2 m
    at 100 km, the series' own error beyond 84°), and the altimeter reads the reference altitude."""
    reference = REFERENCES[where]
    accuracy, resolution = (0.5, 0.01) if noisy else (0.0, -1.0)
    bs, sims = _gps_pair(reference, accuracy, resolution, list(range(20, 20 + len(OFFSETS))))
    gps, alt = bs.device("bot", "gps"), bs.device("bot", "alt")
    for step in range(4):
        bs.step()
        for c, s in enumerate(sims):
            s.step()
            dev = s.robot("bot").device("gps")
            for what in ("values", "speed", "speed_vector"):
                want = np.asarray(getattr(dev, what), dtype=np.float64)
                assert want.tobytes() == bs.reading(gps, what)[c].tobytes(), (step, c, what)
            assert np.float64(s.robot("bot").device("alt").value).tobytes() == bs.value(alt)[c].tobytes()
    if noisy:
        assert len({v.tobytes() for v in bs.value(gps)[:2]}) == 2
        return
    utm = Utm(reference[0], reference[1])
    north0, east0 = utm.north_east(reference[0], reference[1])
    for c, (e, n) in enumerate(OFFSETS):
        lat, lon, up = bs.value(gps)[c].tolist()
        north, east = utm.north_east(lat, lon)
        tol = 1e-3 if max(abs(e), abs(n)) <= 1e3 else 2.0
        assert abs(east - east0 - e) < tol and abs(north - north0 - n) < tol, (c, east - east0, north - north0)
        assert up == reference[2] and bs.value(alt)[c] == reference[2]


@settings(max_examples=25, deadline=None, suppress_health_check=list(HealthCheck), database=None)
@given(lat=_rounded(-89.0, 89.0), lon=_rounded(-180.0, 180.0), alt=_rounded(-500.0, 9000.0),
       east=_rounded(-1e5, 1e5), north=_rounded(-1e5, 1e5))
def test_a_wgs84_gps_anywhere_reads_as_the_single_simulation(lat, lon, alt, east, north):
    """Property: any reference on Earth (short of the poles), the GPS at it and anywhere within 100 km
    of it, noisy (0.5 m, correlated, speed noise) and quantised (1 cm): latitude, longitude, altitude, speed and speed vector equal the
    single simulation's bit for bit (whatever the series gives so far from its zone)."""
    reference = (lat, lon, alt)
    bs, sims = _gps_pair(reference, 0.5, 0.01, [1, 2] + [3] * (len(OFFSETS) - 2))
    bs.set_pose(1, 0, [east, north, 0.0])
    sims[1].robot("bot").set_pose([east, north, 0.0])
    gps = bs.device("bot", "gps")
    for _ in range(2):
        bs.step()
        for c in (0, 1):
            sims[c].step()
            dev = sims[c].robot("bot").device("gps")
            for what in ("values", "speed", "speed_vector"):
                assert np.asarray(getattr(dev, what), dtype=np.float64).tobytes() == bs.reading(gps, what)[c].tobytes()


def test_wgs84_gps_across_the_equator_and_the_antimeridian():
    """Closed forms at the awkward places: with a reference 1e-9° south of the equator (false northing
    10,000 km) on zone 31's central meridian (3°E, scale 0.9996), a GPS 100 m north reads latitude
    -1e-9° + 100 / (0.9996 · 110,574.27 m/°) (9.0473e-4°: the same false northing going back), 100 m
    south -1e-9° minus that; 100 km east of a reference at 179.999°
    the longitude is past 180° (Webots' series, which does not wrap it: 180.896°), bit for bit the single
    model's."""
    bs, sims = _gps_pair(REFERENCES["just south of the equator, on a central meridian"], 0.0, -1.0, [1] * len(OFFSETS))
    bs.set_pose(1, 0, [0.0, 100.0, 0.0])
    bs.set_pose(2, 0, [0.0, -100.0, 0.0])
    bs.step()
    lat = bs.value(bs.device("bot", "gps"))[:, 0]
    north = 100.0 / (0.9996 * 110_574.27)
    assert lat[1] == pytest.approx(-1e-9 + north, abs=1e-10) and lat[2] == pytest.approx(-1e-9 - north, abs=1e-10)
    bs, sims = _gps_pair(REFERENCES["antimeridian, east side"], 0.0, -1.0, [1] * len(OFFSETS))
    bs.step()
    sims[3].step()
    lon = bs.value(bs.device("bot", "gps"))[3, 1]
    assert lon == sims[3].robot("bot").device("gps").values[1] and 180.8 < lon < 181.0


# ---------------------------------------------------------------------------------- bumpers

R, FACE = 0.05, 0.55          # the robot's radius; the wall's face (x)


def _walled(dt: int = 16, pose=(0.0, 0.0, 0.0), other=(0.0, -0.5)) -> wm.World:
    """A robot of radius 5 cm (a bumper, an altimeter on a tilted mount) left of a 20 m wall whose
    face is at x = 0.55, and a second robot at ``other``."""
    def robot(name, x, y, yaw, devices):
        return {"name": name, "pose": {"translation": [x, y, 0.05], "rotation": [0, 0, 1, yaw]},
                "body": {"geometry": {"type": "cylinder", "radius": R, "height": 0.05}},
                "differential_drive": {"wheel_radius": 0.05, "axle_length": 0.2, "max_wheel_speed": 10.0},
                "devices": devices}
    devices = [{"device": "TouchSensor", "name": "bumper"},
               {"device": "Altimeter", "name": "alt", "pose": {"translation": [0.03, -0.02, 0.04],
                                                               "rotation": [1, 0, 0, 0.4]}}]
    return wm.World.model_validate({
        "world_info": {"basic_time_step": dt},
        "solids": [{"name": "wall", "pose": {"translation": [FACE + 0.05, 0.0, 0.25]},
                    "geometry": {"type": "box", "size": [0.1, 20.0, 0.5]}}],
        "robots": [robot("bot", *pose, devices), robot("other", *other, 0.0, [{"device": "TouchSensor", "name": "bumper"}])]})


def _bumper_run(poses, wheels, steps: int, dt: int = 16, others=None):
    """Copies with the robot at ``poses`` (x, y, yaw), the other robot at ``others`` (default
    (0, -0.5)), wheels (left, right) rad/s: after every step each copy's bumper and pose equal a
    Simulation's bit for bit. Returns the batched simulation and the bumper values (steps, copies)."""
    others = others or [(0.0, -0.5)] * len(poses)
    bs = BatchedSimulation(from_model(_walled(dt)), len(poses))
    sims = []
    for c, ((x, y, yaw), o) in enumerate(zip(poses, others)):
        bs.set_pose(c, 0, [x, y, 0.05], [0, 0, 1, yaw])
        bs.set_pose(c, 1, [o[0], o[1], 0.05])
        sims.append(Simulation(from_model(_walled(dt, (x, y, yaw), o))))
    bump = bs.device("bot", "bumper")
    bs.enable(bump, dt)
    bs.set_wheels(0, np.array([w[0] for w in wheels], dtype=float), np.array([w[1] for w in wheels], dtype=float))
    for s, (left, right) in zip(sims, wheels):
        s.robot("bot").device("bumper").enable(dt)
        drive = s.robot("bot").drive
        for m, v in ((drive.lefts[0], left), (drive.rights[0], right)):
            m.set_position(math.inf)
            m.set_velocity(float(v))
    values = []
    for k in range(steps):
        bs.step()
        for c, s in enumerate(sims):
            s.step()
            assert np.float64(s.robot("bot").device("bumper").value).tobytes() == bs.value(bump)[c].tobytes(), (k, c)
            assert s.robot("bot").pose.translation.tobytes() == bs.pos[c, 0].tobytes(), (k, c)
        values.append(bs.value(bump).copy())
    return bs, np.array(values)


def test_a_robot_touching_a_wall_reads_0_at_rest_and_1_pushing_without_moving():
    """A robot exactly touching the wall (x = 0.5): stopped, it reads 0 every step; driven into the
    wall, 1 every step with its position unchanged (x = 0.5 bit for bit); backing off, 0."""
    bs, v = _bumper_run([(FACE - R, 0.0, 0.0)] * 3, [(0.0, 0.0), (10.0, 10.0), (-10.0, -10.0)], 6)
    assert (v[:, 0] == 0.0).all() and (v[:, 1] == 1.0).all() and (v[:, 2] == 0.0).all()
    assert bs.pos[1, 0, 0] == FACE - R and bs.pos[0, 0, 0] == FACE - R
    assert bs.pos[2, 0, 0] == pytest.approx(FACE - R - 6 * 0.008, abs=1e-12)


def test_a_robot_meeting_a_wall_at_a_grazing_angle_slides_along_it_pressing():
    """Heading 0.02 rad into the wall from 5 cm away at 8 mm a step: the bumper reads 0 until the
    robot reaches the wall (after 0.05 / (0.008 sin 0.02) = 312.5 steps), then 1 on every step while it
    slides along the face at x = 0.5 (to 1e-9), advancing 0.008 cos 0.02 along it per step."""
    a = 0.02
    bs, v = _bumper_run([(FACE - R - 0.05, 0.0, math.pi / 2 - a)], [(10.0, 10.0)], 400)
    first = int(np.argmax(v[:, 0] == 1.0))
    reach = 0.05 / (0.008 * math.sin(a))
    assert (v[:first, 0] == 0.0).all() and (v[first:, 0] == 1.0).all()
    assert first == math.ceil(reach) - 1
    assert bs.pos[0, 0, 0] == pytest.approx(FACE - R, abs=1e-9)
    assert bs.pos[0, 0, 1] == pytest.approx(400 * 0.008 * math.cos(a), abs=1e-9)


@settings(max_examples=15, deadline=None, suppress_health_check=list(HealthCheck), database=None)
@given(a=st.floats(1e-6, 1.5), before=st.floats(0.2, 5.0))
def test_any_grazing_angle_presses_from_contact_on_and_slides(a: float, before: float):
    """Property: heading ``a`` rad into the wall, ``before`` steps of travel away from it (8 mm a step,
    so 0.008·sin a·before m): the bumper reads 0 before the step that reaches the wall and 1 on every
    step from it on, the robot slides along the face (x = 0.5 to 1e-9, never through) and keeps the
    along-wall part of every move (y = 20·0.008·cos a after 20 steps, to 1e-9)."""
    gap = 0.008 * math.sin(a) * before
    bs, v = _bumper_run([(FACE - R - gap, 0.0, math.pi / 2 - a)], [(10.0, 10.0)], 20)
    first = int(np.argmax(v[:, 0] == 1.0))
    assert v[first, 0] == 1.0 and (v[:first, 0] == 0.0).all() and (v[first:, 0] == 1.0).all()
    assert abs(first - before) <= 1.0
    assert bs.pos[0, 0, 0] == pytest.approx(FACE - R, abs=1e-9) and bs.pos[0, 0, 0] <= FACE - R + 1e-9
    assert bs.pos[0, 0, 1] == pytest.approx(20 * 0.008 * math.cos(a), abs=1e-9)


def test_a_robot_driving_along_a_wall_it_touches_keeps_going_without_pressing():
    """A robot touching the wall and heading exactly along it (yaw π/2: cos gives 6e-17, 5e-19 m into
    the wall a step) is not pushing: it advances 8 mm every step and reads 0. (It used to stall for
    good from step 14, reading 1: the leftover of a slide's projection was taken for an impact.)"""
    bs, v = _bumper_run([(FACE - R, 0.0, math.pi / 2)], [(10.0, 10.0)], 40)
    assert bs.pos[0, 0, 1] == pytest.approx(40 * 0.008, abs=1e-9) and (v == 0.0).all()
    assert bs.pos[0, 0, 0] == FACE - R


def test_copies_at_the_same_pose_do_not_feel_each_others_robots():
    """The other robot stands in the driving robot's path (x = 0.3) in copy 1 only; copies 0 and 2
    have it 0.5 m aside and copy 2 duplicates copy 0's pose: copy 1's robot stops at x = 0.3 - 0.1 and
    presses from the step it reaches it; copies 0 and 2 read the same and stop at the wall (0.5)."""
    poses = [(0.0, 0.0, 0.0)] * 3
    others = [(0.0, -0.5), (0.3, 0.0), (0.0, -0.5)]
    bs, v = _bumper_run(poses, [(10.0, 10.0)] * 3, 70, others=others)
    assert v[:, 0].tobytes() == v[:, 2].tobytes()
    assert int(np.argmax(v[:, 1] == 1.0)) == 24 and int(np.argmax(v[:, 0] == 1.0)) == 62   # 0.2 m, 0.5 m at 8 mm
    assert bs.pos[1, 0, 0] == pytest.approx(0.2, abs=1e-9) and bs.pos[0, 0, 0] == pytest.approx(0.5, abs=1e-9)
    assert (bs.pos[[0, 2], 1] == bs.pos[0, 1]).all() and bs.pos[1, 1, 0] == 0.3      # the other robot never moved


def test_a_60_s_basic_step_stops_at_the_wall_not_through_it():
    """With a 60 s basic step a robot at 0.5 m/s moves 30 m a step: toward the wall it stops at x = 0.5
    in the first step and presses every step; backward it reaches -30, -60, -90 m without pressing;
    turning (arcs over 60 s) the same as the single simulation."""
    bs, v = _bumper_run([(0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.3)],
                        [(10.0, 10.0), (-10.0, -10.0), (3.0, 10.0)], 3, dt=60_000)
    assert (v[:, 0] == 1.0).all() and (v[:, 1] == 0.0).all()
    assert bs.pos[0, 0, 0] == pytest.approx(0.5, abs=1e-9) and bs.pos[1, 0, 0] == pytest.approx(-90.0, abs=1e-9)
    assert bs.pos[2, 0, 0] < FACE - R + 1e-9


# ---------------------------------------------------------------------------------- altimeters

@pytest.mark.parametrize("resolution", [-1.0, 0.01])
def test_altimeters_far_away_on_a_tilted_mount_read_their_height(resolution: float):
    """An altimeter 4 cm above the robot's origin on a mount tilted 0.4 rad about x (the tilt and the
    robot's heading do not change its height): at (0, 0), (1e5, -1e5) and (-1e5, 99,999.9) (the world bounds), headings 0, 1
    and -2.5, it reads 0.05 + 0.04 (to an ulp; with a 1 cm resolution: 0.09), bit for bit the single
    simulation's."""
    poses = [(0.0, 0.0, 0.0), (1e5, -1e5, 1.0), (-1e5, 99_999.9, -2.5)]
    w = _walled()
    dev = w.robots[0].devices[1].model_copy(update={"resolution": resolution})
    robot = w.robots[0].model_copy(update={"devices": [dev]})
    w = w.model_copy(update={"robots": [robot]})
    bs = BatchedSimulation(from_model(w), len(poses))
    ref = bs.device("bot", "alt")
    bs.enable(ref, 16)
    for c, (x, y, yaw) in enumerate(poses):
        bs.set_pose(c, 0, [x, y, 0.05], [0, 0, 1, yaw])
    bs.step()
    for c, (x, y, yaw) in enumerate(poses):
        s = Simulation(from_model(w))
        s.robot("bot").set_pose([x, y, 0.05], [0, 0, 1, yaw])
        s.robot("bot").device("alt").enable(16)
        s.step()
        assert np.float64(s.robot("bot").device("alt").value).tobytes() == bs.value(ref)[c].tobytes(), c
    want = 0.05 + 0.04
    assert np.allclose(bs.value(ref), want, rtol=0, atol=2e-17 if resolution < 0 else 0.0)


# ---------------------------------------------------------------------------------- the vector env

gym = pytest.importorskip("gymnasium")

from gymnasium.utils.env_checker import check_env  # noqa: E402

from sensorium.gym import SensoriumEnv, Task  # noqa: E402
from sensorium.gym.vector import SensoriumVectorEnv  # noqa: E402
from tests.test_gym_vector import _reset_both, _step_both  # noqa: E402

BUMPERS = Path(__file__).parent / "worlds" / "bumpers.yaml"


def _bumped(sim, robot, obs) -> bool:
    """The episode ends on the step the robot's bumper reads 1."""
    return bool(obs["bumper"][0] == 1.0)


def _bump_task() -> Task:
    return Task(robot="a", observations={"bumper": 16, "altimeter": 16}, control_period_ms=16, max_steps=200,
                terminated=_bumped)


def test_the_vector_env_autoresets_on_the_step_a_bumper_reads_1():
    """Episodes that end when the bumper reads 1 (full speed into the walls): every sub-env equals the
    single env with its seed bit for bit through the autoresets; an episode is terminated exactly on a
    step whose bumper reads 1, the sub-env's next observation is a fresh episode's (bumper 0, clock
    0); a sub-env passes Gymnasium's checker."""
    n = 3
    venv = SensoriumVectorEnv(BUMPERS, _bump_task(), n)
    singles = [SensoriumEnv(BUMPERS, _bump_task(), engine="simulation") for _ in range(n)]
    _reset_both(venv, singles, 11)
    rng = np.random.default_rng(4)
    done = np.zeros(n, dtype=bool)
    ends = 0
    for t in range(150):
        a = np.ones((n, 2), dtype=np.float32)
        a[:, 1] -= rng.uniform(0.0, 0.6, n).astype(np.float32)        # veering: the walls at different times
        was_done = done.copy()
        _, vobs = _step_both(venv, singles, a, done, t)
        for i in range(n):
            if was_done[i]:                                        # this step was the autoreset
                assert vobs["bumper"][i, 0] == 0.0
            elif done[i]:
                assert vobs["bumper"][i, 0] == 1.0
                ends += 1
    assert ends >= n
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(venv.sub_env(0), skip_render_check=True)
    venv.close()
