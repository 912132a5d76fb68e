"""Sweep 24: Webots samples not run before, each on a stand-in world of ours (tests/data/sweep24/: the
sample's poses, sizes and devices, our own text, PROTO meshes stood in for by plain shapes) driven in
process by the calls its controller makes and checked against closed forms."""

from __future__ import annotations

import math
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from test_sweep19 import rot
from test_sweep20 import ray_to_boxes

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data" / "sweep24"

# ------------------------------------------------------------------------------------------------ koala
# koala (k-team/koala): the Koala, six wheels of radius 0.0425 m (the middle pair on motorised hinges 0.285 m
# apart), no Physics, named "koala", turned half a turn at (1, 0, 0) in a 4 m arena whose walls and blocks are
# boxes of a Solid turned (0.99965, 0.01878, 0.01878) 1.57115 rad (y-up geometry stood up, with 2.15° of yaw),
# a green cylinder of radius 0.3 m at the centre, running Webots' generic `braitenberg` controller: 32 ms
# steps, each wheel's speed 0.1 × Σ_j w_j (1 − ds_j/512), bounded to ±10 rad/s, from its sixteen infra-red
# sensors (table 0 → 1024, 0.5 m → 0, or 0.35 m for ds3, ds6, ds9, ds12).
KOALA_R = 0.0425
KOALA_AXLE = 2.0 * math.hypot(0.1425, 0.0425)     # Webots' rule without Physics: the wheels' 3-D distances
# the sensors in the robot's frame (x forward, y left): position, turn about z, range of the table
KOALA_DS = [((0.175, -0.015, 0.102), -0.0999963, 0.5), ((0.169, -0.04, 0.102), -0.1999963, 0.5),
            ((0.16, -0.07, 0.102), -0.2999963, 0.5), ((0.14, -0.12, 0.102), -0.8, 0.35),
            ((0.055, -0.14, 0.102), -1.5707963, 0.5), ((-0.05, -0.14, 0.102), -1.5707963, 0.5),
            ((-0.12, -0.125, 0.102), -2.4231963, 0.35), ((-0.13, -0.0475, 0.107), -3.1415963, 0.5),
            ((-0.13, 0.0475, 0.107), -3.1415963, 0.5), ((-0.12, 0.125, 0.102), -3.9307963, 0.35),
            ((-0.05, 0.14, 0.102), 1.5709937, 0.5), ((0.055, 0.14, 0.102), 1.5707937, 0.5),
            ((0.14, 0.125, 0.102), 0.8000037, 0.35), ((0.16, 0.07, 0.102), 0.3000037, 0.5),
            ((0.169, 0.04, 0.102), 0.2000037, 0.5), ((0.175, 0.015, 0.102), 0.1000037, 0.5)]
KOALA_WEIGHTS = [(17, -1), (8, -2), (4, -3), (9, -2), (5, -3), (-4, -2), (-4, -2), (-2, -2),
                 (-2, -2), (-2, -4), (-2, -4), (-4, 5), (-3, 8), (-3, 5), (-2, 10), (-1, 15)]
ARENA_TURN = rot((0.9996471590895996, 0.018782402989139663, 0.018782402989139663), 1.57115)
# the arena's boxes in the turned Solid's frame (y up there): centre, turn about its y, size
ARENA_BOXES = [((0, -0.02, 0), 0.0, (4, 0.04, 4)), ((2, 0.15, 0), 0.0, (0.02, 0.3, 4)),
               ((-2, 0.15, 0), 0.0, (0.02, 0.3, 4)), ((0, 0.15, 2), 1.57, (0.02, 0.3, 4)),
               ((0, 0.15, -2), 1.57, (0.02, 0.3, 4)), ((1.7, 0.15, 0), 0.0, (0.4, 0.3, 0.6)),
               ((1.77, 0.15, 0.455), 0.885, (0.1, 0.3, 0.6)), ((-1.77, 0.15, -0.455), 0.885, (0.1, 0.3, 0.6)),
               ((1.77, 0.15, -0.455), -0.885, (0.1, 0.3, 0.6)), ((-1.77, 0.15, 0.455), -0.885, (0.1, 0.3, 0.6)),
               ((-1.7, 0.15, 0), 0.0, (0.4, 0.3, 0.6)), ((0, 0.15, 1.7), 1.57, (0.4, 0.3, 0.6)),
               ((0, 0.15, -1.7), 1.57, (0.4, 0.3, 0.6)), ((-0.445, 0.15, 1.77), -0.685, (0.1, 0.3, 0.6)),
               ((0.445, 0.15, 1.77), 0.685, (0.1, 0.3, 0.6)), ((0.445, 0.15, -1.77), -0.685, (0.1, 0.3, 0.6)),
               ((-0.445, 0.15, -1.77), 0.685, (0.1, 0.3, 0.6))]
# Webots' infra-red factor 0.2 + 0.8 · red · (1 − 0.5 · roughness), both PBRAppearances of roughness 1
WALL_FACTOR = 0.2 + 0.4 * 0.103335
CYLINDER_FACTOR = 0.2 + 0.4 * 0.16452
CYLINDER_RADIUS = 0.3


def koala_boxes() -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    return [(ARENA_TURN @ np.array(c, dtype=float), ARENA_TURN @ rot((0, 1, 0), a), np.array(s) / 2)
            for c, a, s in ARENA_BOXES]


def ray_to_cylinder(origin: np.ndarray, u: np.ndarray) -> float:
    """The distance along a horizontal unit ray (from outside, below its 0.3 m top) to the central
    cylinder's side; inf when it misses."""
    b = origin[0] * u[0] + origin[1] * u[1]
    a = u[0] ** 2 + u[1] ** 2
    c = origin[0] ** 2 + origin[1] ** 2 - CYLINDER_RADIUS ** 2
    disc = b * b - a * c
    if a == 0.0 or disc < 0.0:
        return math.inf
    t = (-b - math.sqrt(disc)) / a
    return t if t >= 0.0 else math.inf


def koala_mid_heading(x: float, y: float, yaw: float, wl: float, wr: float, t: float) -> tuple[float, float, float]:
    """One basic step of Webots' kinematic rule (a robot without Physics): d = (ωr − ωl)·t·r/(2·axle), a
    straight segment of (ωl + ωr)·r·t/2 along yaw + d, the heading then yaw + 2d."""
    d = (wr - wl) * t * KOALA_R / (2.0 * KOALA_AXLE)
    v = 0.5 * (wl + wr) * KOALA_R * t
    return x + v * math.cos(yaw + d), y + v * math.sin(yaw + d), yaw + 2.0 * d


def noiseless_koala(tmp_path: Path) -> Path:
    """A copy of the koala stand-in whose sensors' tables have no noise (their third column 0.01 at 0.5 m)."""
    shutil.copytree(DATA / "protos", tmp_path / "protos")
    proto = tmp_path / "protos" / "Koala.proto"
    proto.write_text(re.sub(r"(lookupTable \[ 0 1024 0, \S+ 0) 0\.01 \]", r"\1 0 ]", proto.read_text()))
    shutil.copy(DATA / "koala.wbt", tmp_path / "koala.wbt")
    return tmp_path / "koala.wbt"


def run_koala(world: Path, duration_ms: int) -> tuple[list[tuple[int, int]], list[tuple[int, float]], list[float]]:
    """braitenberg.c's calls in process for the robot "koala" for ``duration_ms``, each step checked against
    the closed forms: each infra-red sensor reads the table at its ray's distance to the nearest green wall or
    block face divided by 0.24133, or to the cylinder divided by 0.26581 (Webots' reflection factors), and
    the pose is Webots' kinematic rule on the wheel speeds set from the readings (1e-9), flat (no tilt: a
    robot without Physics rides nothing) — but where kinematic contact pushes the body off the cylinder or
    a wall, from where it is pushed. Returns when each sensor first read something, each step contact
    pushed the robot and by how much, and the final x, y, yaw."""
    sim = Simulation(load_world(world), "exact")
    robot = sim.robot("koala")
    step = sim.basic_time_step
    assert step == 32
    ds = [sim.device(f"koala/ds{i}") for i in range(16)]
    for s in ds:
        s.enable(step)
    left, right = robot.motor("left wheel motor"), robot.motor("right wheel motor")
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(0.0)
    boxes = koala_boxes()
    x, y, yaw, wl, wr = 1.0, 0.0, 3.14159, 0.0, 0.0
    seen: dict[int, int] = {}
    pushes: list[tuple[int, float]] = []
    for k in range(1, duration_ms // step + 1):
        sim.step()
        x, y, yaw = koala_mid_heading(x, y, yaw, wl, wr, step / 1000)
        body = rot((0, 0, 1), yaw)
        at = np.asarray(robot.pose.translation)
        if abs(at[0] - x) + abs(at[1] - y) > 1e-9:
            pushes.append((k, float(np.hypot(at[0] - x, at[1] - y))))
            x, y = float(at[0]), float(at[1])
        assert list(robot.pose.translation) == pytest.approx([x, y, 0.0], abs=1e-9), k
        assert np.asarray(robot.pose.rotation) == pytest.approx(body, abs=1e-9), k
        values = []
        for i, (at, turn, reach) in enumerate(KOALA_DS):
            origin = np.array([x, y, 0.0]) + body @ np.array(at)
            u = body @ rot((0, 0, 1), turn) @ np.array([1.0, 0.0, 0.0])
            seen_at = min(ray_to_boxes(origin, u, boxes) / WALL_FACTOR, ray_to_cylinder(origin, u) / CYLINDER_FACTOR)
            values.append(1024.0 * (1.0 - seen_at / reach) if seen_at < reach else 0.0)
            if values[-1] > 0.0:
                seen.setdefault(i, k * step)
            assert float(ds[i].value) == pytest.approx(values[-1], abs=1e-6), (k, i, seen_at)
        wl, wr = (max(-10.0, min(10.0, sum(0.1 * w[side] * (1.0 - v / 512) for w, v in zip(KOALA_WEIGHTS, values,
                                                                                            strict=True))))
                  for side in (0, 1))
        left.set_velocity(wl)
        right.set_velocity(wr)
    return sorted((t, i) for i, t in seen.items()), pushes, [x, y, math.remainder(yaw, 2 * math.pi)]


def test_the_koala_stand_in_loads_the_devices_braitenberg_asks_for_and_webots_kinematic_rule() -> None:
    """The Koala loads without a line with its 20 devices (ds0…ds15, both wheel motors and sensors) and, having
    no Physics, Webots' kinematic rule: radius 0.0425 m, axle 2·√(0.1425² + 0.0425²) = 0.29741 m (its middle
    wheels' 3-D distances from its origin; the four wheels on no hinge play no part). The arena's floor box,
    stood up by a rotation written to six digits, leans 7.7e-7 rad: a ramp, so the world has a ground; the
    Koala, which Webots gives no contact with it, is not said to start over no ground (it rides none)."""
    import warnings

    w = load_world(DATA / "koala.wbt")
    assert w.warnings == []
    (robot,) = w.world.robots
    names = {d.name for d in robot.devices}
    assert len(names) == 20 and {*(f"ds{i}" for i in range(16)), "left wheel motor", "right wheel motor",
                                 "left wheel sensor", "right wheel sensor"} <= names
    drive = robot.differential_drive
    assert robot.mass is None and drive.step_rule == "mid_heading"
    assert (drive.wheel_radius, drive.axle_length) == pytest.approx((KOALA_R, KOALA_AXLE), abs=1e-15)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sim = Simulation(w, "exact")
    assert sim.ground is not None
    lean = math.acos(min(1.0, float((ARENA_TURN @ np.array([0.0, 1.0, 0.0]))[2])))
    assert 7e-7 < lean < 8e-7


def test_braitenbergs_calls_drive_the_koala_by_webots_kinematic_rule_flat_on_the_leaning_floor(tmp_path: Path) -> None:
    """koala: for 12 s (375 steps of 32 ms) every reading and pose meets run_koala's closed forms. In open
    space every sensor reads 0, so the wheels turn at 0.1·Σ w = 1.4 and 1.6 rad/s: 0.06375 m/s, curving left
    at 0.2·0.0425/0.29741 = 0.02858 rad/s towards the cylinder, which ds1 first sees at 6.272 s (the green
    cylinder reflects as a white one 0.26581 times as near: ds1's 0.5 m reach is 0.133 m of it), then ds0
    and ds2 at 6.336 s, the robot turning right round it; its body touches the cylinder at 8.672 s, contact
    pushing it off by at most 0.66 mm for 12 steps (Sensorium's kinematic contact); at 12 s it is at (0.4185, −0.2796), heading −1.8351. It stays flat: the floor's 7.7e-7 rad lean
    tilted it by as much (it rode the floor as a ramp, where Webots gives a robot without Physics no contact
    with the ground)."""
    seen, pushes, end = run_koala(noiseless_koala(tmp_path), 12000)
    assert seen == [(6272, 1), (6336, 0), (6336, 2), (7328, 3), (8544, 4), (9408, 5), (11616, 6)]
    assert [k for k, _ in pushes] == list(range(271, 283)) and max(p for _, p in pushes) < 6.6e-4
    assert end == pytest.approx([0.4185, -0.2796, -1.8351], abs=1e-4)


@pytest.mark.slow
def test_braitenbergs_calls_drive_the_koala_for_a_minute(tmp_path: Path) -> None:
    """The same closed forms for 60 s (1875 steps): after the cylinder the Koala meets the arena's walls and
    blocks (pushed off them at most 1.8 mm from 28.35 s and 55.23 s), its front-left sensors ds15 and ds14 first read at
    51.808 and 52.032 s, and it ends at (1.8235, −1.2926), heading 1.8576."""
    seen, pushes, end = run_koala(noiseless_koala(tmp_path), 60000)
    assert seen[-2:] == [(51808, 15), (52032, 14)] and len(seen) == 9
    assert max(p for _, p in pushes) < 1.8e-3 and {k for k, _ in pushes} >= {886, 1726}
    assert end == pytest.approx([1.8235, -1.2926, 1.8576], abs=1e-4)


# ------------------------------------------------------------------------------------------------ khepera2
# khepera2 (k-team/khepera2): the Khepera II, no Physics, two wheels of radius 0.0075 m whose hinges run
# along y through (0, 0, 0.0075) and whose end points sit at y ±0.026, named "khepera2" at the centre of a 2 m
# RectangleArena with five 0.1 m boxes, running Webots' generic `braitenberg` controller: the name starts
# with "khepera", so eight sensors ds0…ds7 (table 0 → 1023, 0.05 m → 0), each wheel 1.0 × Σ_j w_j (1 − ds_j/512)
# bounded to ±1 rad/s; its wheels' sensors have a resolution of 0.0314 rad.
K2_R, K2_RES = 0.0075, 0.0314
K2_AXLE = 2.0 * math.hypot(0.026, 0.0075)     # Webots' rule without Physics: the wheels' 3-D distances
K2_DS = [((0.015, 0.027, 0.017), (-0.754266, -0.464264, -0.464264), -1.849141),
         ((0.022, 0.021, 0.017), (0.917492, 0.281254, 0.281254), 1.656801),
         ((0.029, 0.007, 0.017), (1, -0.000398, -0.000398), 1.570796),
         ((0.029, -0.007, 0.017), (1, -0.000398, -0.000398), 1.570796),
         ((0.022, -0.021, 0.017), (0.909527, -0.293906, -0.293906), 1.665485),
         ((0.015, -0.027, 0.017), (-0.72051, 0.490339, 0.490339), -1.892875),
         ((-0.029, -0.007, 0.017), (-0.000282, 0.707107, 0.707107), -3.14103),
         ((-0.029, 0.007, 0.017), (-0.000282, 0.707107, 0.707107), -3.14103)]
K2_WEIGHTS = [(-2, 4), (-3, 5), (-7, 7), (7, -6), (5, -4), (4, -2), (-0.5, -0.5), (-0.5, -0.5)]
K2_BOXES = [((-0.2, -0.683174), (-0.45445591677276886, -0.7661198596958863, 0.45445591677276886), -1.8341153071795864),
            ((-0.75, 0.35), (-0.12634796090434602, 0.9839066955512742, -0.12634796090434602), -1.5870153071795858),
            ((0.5, -0.35471), (-1.46018e-08, 7.19235e-09, -1), 0.915365),
            ((-0.3, 0.36), (-0.3063990552359414, 0.9012431624711751, -0.3063990552359414), -1.6745853071795862),
            ((-0.65, -0.66), (-0.3063990552359414, 0.9012431624711751, -0.3063990552359414), -1.6745853071795862)]


def khepera_arena(boxes: list) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """A Khepera world's obstacles: the 2 m arena's four walls (0.01 m thick, 0.1 m high, outside the floor)
    and its 0.1 m boxes, each ((x, y), rotation axis, angle)."""
    walls = [((1.005, 0.0), (0.005, 1.0)), ((-1.005, 0.0), (0.005, 1.0)),
             ((0.0, 1.005), (1.01, 0.005)), ((0.0, -1.005), (1.01, 0.005))]
    out = [(np.array([x, y, 0.05]), np.eye(3), np.array([hx, hy, 0.05])) for (x, y), (hx, hy) in walls]
    out += [(np.array([x, y, 0.05]), rot(axis, a), np.full(3, 0.05)) for (x, y), axis, a in boxes]
    return out


def k2_obstacles() -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """khepera2's arena and its five boxes."""
    return khepera_arena(K2_BOXES)


def noiseless_khepera2(tmp_path: Path) -> Path:
    """A copy of the khepera2 stand-in whose infra-red tables have no noise (0.01 at 0.05 m)."""
    shutil.copytree(DATA / "protos", tmp_path / "protos")
    proto = tmp_path / "protos" / "Khepera2.proto"
    proto.write_text(proto.read_text().replace("lookupTable [ 0 1023 0, 0.05 0 0.01 ]", "lookupTable [ 0 1023 0, 0.05 0 0 ]"))
    shutil.copy(DATA / "khepera2.wbt", tmp_path / "khepera2.wbt")
    return tmp_path / "khepera2.wbt"


def run_braitenberg_khepera(world: Path, robot_name: str, duration_ms: int, sensors: list, obstacles: list,
                            radius: float, axle: float, resolution: float, rule: str
                            ) -> tuple[list[tuple[int, int]], list[tuple[int, float]], list[float]]:
    """braitenberg.c's calls in process for a Khepera ``robot_name`` (eight infra-red sensors ds0…ds7 at
    ``sensors``' places and turns, tables 0 → 1023 at 0.05 m, two wheels), each 32 ms step checked against the
    closed forms: each sensor reads the table at its ray's distance to the nearest (white) wall or box face of
    ``obstacles``, the wheels' sensors their angles rounded to ``resolution``, and the pose (1e-9, flat) the
    drive's ``rule`` on the wheel speeds set from the readings: ``mid_heading`` (Webots' kinematic rule without
    Physics: a straight segment along the mid-step heading, axle the wheels' 3-D distances) or ``arc`` (the
    exact arc of v = (ωl + ωr)·r/2, ω = (ωr − ωl)·r/axle) — but where kinematic contact pushes it, from where it
    is pushed. Returns when each sensor first read something, the pushes, and the final x, y, yaw."""
    sim = Simulation(load_world(world), "exact")
    robot = sim.robot(robot_name)
    step = sim.basic_time_step
    assert step == 32
    ds = [sim.device(f"{robot_name}/ds{i}") for i in range(8)]
    for s in ds:
        s.enable(step)
    wheel_sensors = [sim.device(f"{robot_name}/left wheel sensor"), sim.device(f"{robot_name}/right wheel sensor")]
    for s in wheel_sensors:
        s.enable(step)
    left, right = robot.motor("left wheel motor"), robot.motor("right wheel motor")
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(0.0)
    rays = [(np.array(at), rot(axis, a) @ np.array([1.0, 0.0, 0.0])) for at, axis, a in sensors]
    x, y, yaw, wl, wr = 0.0, 0.0, 0.0, 0.0, 0.0
    angles = [0.0, 0.0]
    seen: dict[int, int] = {}
    pushes: list[tuple[int, float]] = []
    dt = step / 1000
    for k in range(1, duration_ms // step + 1):
        sim.step()
        if rule == "mid_heading":
            d = (wr - wl) * dt * radius / (2.0 * axle)
            v = 0.5 * (wl + wr) * radius * dt
            x, y, yaw = x + v * math.cos(yaw + d), y + v * math.sin(yaw + d), yaw + 2.0 * d
        else:
            v, w = 0.5 * (wl + wr) * radius, (wr - wl) * radius / axle
            if w == 0.0:
                x, y = x + v * dt * math.cos(yaw), y + v * dt * math.sin(yaw)
            else:
                x, y = (x + v / w * (math.sin(yaw + w * dt) - math.sin(yaw)),
                        y - v / w * (math.cos(yaw + w * dt) - math.cos(yaw)))
            yaw += w * dt
        angles = [angles[0] + wl * dt, angles[1] + wr * dt]
        at = np.asarray(robot.pose.translation)
        if abs(at[0] - x) + abs(at[1] - y) > 1e-9:
            pushes.append((k, float(np.hypot(at[0] - x, at[1] - y))))
            x, y = float(at[0]), float(at[1])
        body = rot((0, 0, 1), yaw)
        assert list(robot.pose.translation) == pytest.approx([x, y, 0.0], abs=1e-9), k
        assert np.asarray(robot.pose.rotation) == pytest.approx(body, abs=1e-9), k
        values = []
        for i, (p, u) in enumerate(rays):
            distance = ray_to_boxes(np.array([x, y, 0.0]) + body @ p, body @ u, obstacles)
            values.append(1023.0 * (1.0 - distance / 0.05) if distance < 0.05 else 0.0)
            if values[-1] > 0.0:
                seen.setdefault(i, k * step)
            assert float(ds[i].value) == pytest.approx(values[-1], abs=1e-6), (k, i, distance)
        for s, a in zip(wheel_sensors, angles, strict=True):
            assert float(s.value) == pytest.approx(round(a / resolution) * resolution, abs=1e-12), k
        wl, wr = (max(-1.0, min(1.0, sum(w[side] * (1.0 - v / 512) for w, v in zip(K2_WEIGHTS, values, strict=True))))
                  for side in (0, 1))
        left.set_velocity(wl)
        right.set_velocity(wr)
    return sorted((t, i) for i, t in seen.items()), pushes, [x, y, math.remainder(yaw, 2 * math.pi)]


def run_khepera2(world: Path, duration_ms: int) -> tuple[list[tuple[int, int]], list[tuple[int, float]], list[float]]:
    """braitenberg.c's calls for the robot "khepera2" (no Physics: Webots' kinematic rule), checked step by step
    against the closed forms (:func:`run_braitenberg_khepera`)."""
    return run_braitenberg_khepera(world, "khepera2", duration_ms, K2_DS, k2_obstacles(), K2_R, K2_AXLE, K2_RES,
                                   "mid_heading")


def test_the_khepera2_stand_in_loads_the_devices_braitenberg_asks_for_and_webots_kinematic_rule() -> None:
    """The Khepera II loads without a line with its 24 devices (ds0…ds7, ls0…ls7, two LEDs, the serial
    emitter and receiver, both wheel motors and sensors) and, having no Physics, Webots' kinematic rule:
    radius 0.0075 m (the wheels' cylinders, turned onto −y by their end points' and Poses' rotations, within
    1e-4), axle 2·√(0.026² + 0.0075²) = 0.054120 m where the wheels are 0.052 m apart."""
    w = load_world(DATA / "khepera2.wbt")
    assert w.warnings == []
    (robot,) = w.world.robots
    names = {d.name for d in robot.devices}
    assert len(names) == 24 and {*(f"ds{i}" for i in range(8)), *(f"ls{i}" for i in range(8)), "led0", "led1",
                                 "rs232_out", "rs232_in", "left wheel sensor", "right wheel sensor"} <= names
    drive = robot.differential_drive
    assert robot.mass is None and drive.step_rule == "mid_heading"
    assert (drive.wheel_radius, drive.axle_length) == pytest.approx((K2_R, K2_AXLE), abs=1e-15)


def test_braitenbergs_calls_drive_the_khepera2_straight_at_its_bounded_speed(tmp_path: Path) -> None:
    """khepera2: in open space the Braitenberg sums are 3 on both wheels, bounded to 1 rad/s: 0.0075 m/s
    along +x; for 24 s (750 steps) every reading (0) and wheel sensor (t rad, rounded to 0.0314) and the
    pose meet run_khepera2's closed forms: 0.0075 × 23.968 = 0.17976 m along x (the speeds are set after
    the first step's readings)."""
    seen, pushes, end = run_khepera2(noiseless_khepera2(tmp_path), 24000)
    assert seen == [] and pushes == []
    assert end == pytest.approx([0.0075 * 23.968, 0.0, 0.0], abs=1e-12)


@pytest.mark.slow
def test_braitenbergs_calls_drive_the_khepera2_to_the_wall_and_round(tmp_path: Path) -> None:
    """The same closed forms for 200 s (6250 steps): ds2 and ds3 meet the wall at x 1 at 122.848 s (the
    robot at 0.9214 = 1 − 0.029 − 0.05 + a step), then ds1, ds4 and ds0; it turns right along the wall,
    never touching it, to (0.7914, −0.4642), heading −1.9113."""
    seen, pushes, end = run_khepera2(noiseless_khepera2(tmp_path), 200000)
    assert seen == [(122848, 2), (122848, 3), (124928, 1), (125056, 4), (127808, 0)] and pushes == []
    assert end == pytest.approx([0.7914, -0.4642, -1.9113], abs=1e-4)


# ------------------------------------------------------------------------------------------------ khepera_kinematic
# khepera_kinematic (k-team/khepera1): two Khepera I robots with `kinematic TRUE` (the template leaves out
# their Physics), "khepera" and "khepera(1)", facing each other across a 1 m RectangleArena with a light blue
# box (0.1 × 0.3 m seen from above, a quarter turn about x) between them and a cylinder of radius 0.1 m at the
# centre turned 4.7e-6 rad about x; each runs `braitenberg` with the Khepera weights, as the Khepera II.
K1_DS = [((0.012, 0.0245, 0.0145), (0.610934, 0.559803, 0.559803), 2.044752),
         ((0.021, 0.0185, 0.0145), (0.862854, 0.357409, 0.357409), 1.717773),
         ((0.027, 0.0075, 0.0145), (-1, 0, 0), -1.570796),
         ((0.027, -0.0075, 0.0145), (-1, 0, 0), -1.570796),
         ((0.021, -0.0185, 0.0145), (0.862857, -0.357406, -0.357406), 1.717771),
         ((0.012, -0.0245, 0.0145), (0.610937, -0.559802, -0.559802), 2.044747),
         ((-0.026, -0.009, 0.0145), (0, -0.707107, -0.707107), -3.14159),
         ((-0.026, 0.009, 0.0145), (0, -0.707107, -0.707107), -3.14159)]
K1_ROBOTS = {"khepera": ((0.425571, 0.341915), (6.42555e-10, -7.19234e-09, 1), -2.9633853071795864),
             "khepera(1)": ((-0.441747, 0.329789), (4.3816e-07, -7.19235e-09, 1), -0.03282530717958654)}
OBSTACLE_FACTOR = 0.2 + 0.4 * 0.678431      # the light blue PBRAppearance, roughness 1
K1_CYLINDER_TURN = rot((1, 0, 0), 4.692820414042842e-06)


def k1_walls_and_box() -> tuple[list, list]:
    """The 1 m arena's four white walls (0.01 m thick, 0.1 m high), and the light blue box."""
    walls = [((0.505, 0.0), (0.005, 0.5)), ((-0.505, 0.0), (0.005, 0.5)),
             ((0.0, 0.505), (0.51, 0.005)), ((0.0, -0.505), (0.51, 0.005))]
    white = [(np.array([x, y, 0.05]), np.eye(3), np.array([hx, hy, 0.05])) for (x, y), (hx, hy) in walls]
    blue = [(np.array([0.0, 0.35, 0.0]), rot((1, 0, 0), 1.5707963267948966), np.array([0.05, 0.05, 0.15]))]
    return white, blue


def ray_to_tilted_cylinder(origin: np.ndarray, u: np.ndarray) -> float:
    """The distance along the unit ray to the side of the centre cylinder (radius 0.1 m, 0.1 m high, its axis
    turned 4.7e-6 rad about x), in its own frame; inf when the ray misses it or passes above it."""
    p, d = K1_CYLINDER_TURN.T @ origin, K1_CYLINDER_TURN.T @ u
    a, b, c = d[0] ** 2 + d[1] ** 2, p[0] * d[0] + p[1] * d[1], p[0] ** 2 + p[1] ** 2 - 0.01
    disc = b * b - a * c
    if a == 0.0 or disc < 0.0:
        return math.inf
    t = (-b - math.sqrt(disc)) / a
    return t if t >= 0.0 and abs(p[2] + t * d[2]) <= 0.05 else math.inf


def run_khepera_kinematic(world: Path, duration_ms: int) -> dict[str, tuple[list[tuple[int, int]], list[float]]]:
    """braitenberg.c's calls for both robots in process, each 32 ms step checked against the closed forms:
    each infra-red sensor reads the table at its ray's distance to the nearest wall face (white), or to the
    box or the cylinder over 0.47137 (their light blue, roughness 1), and each robot moves by Webots'
    kinematic rule on the speeds set from its readings (1e-9; the robots stay over 0.12 m apart, beyond each
    other's rays). Returns, per robot, when each sensor first read something and the final x, y, yaw."""
    sim = Simulation(load_world(world), "exact")
    step = sim.basic_time_step
    white, blue = k1_walls_and_box()
    rays = [(np.array(at), rot(axis, a) @ np.array([1.0, 0.0, 0.0])) for at, axis, a in K1_DS]
    state = {}
    for name, ((x, y), axis, angle) in K1_ROBOTS.items():
        robot = sim.robot(name)
        ds = [sim.device(f"{name}/ds{i}") for i in range(8)]
        for s in ds:
            s.enable(step)
        motors = robot.motor("left wheel motor"), robot.motor("right wheel motor")
        for m in motors:
            m.set_position(math.inf)
            m.set_velocity(0.0)
        state[name] = {"robot": robot, "ds": ds, "motors": motors, "pose": [x, y, angle], "turn0": rot(axis, angle),
                       "yaw0": angle, "speeds": (0.0, 0.0), "seen": {}}
    for k in range(1, duration_ms // step + 1):
        sim.step()
        for name, st in state.items():
            x, y, yaw = st["pose"]
            wl, wr = st["speeds"]
            d = (wr - wl) * step / 1000 * K2_R / (2.0 * K2_AXLE)
            v = 0.5 * (wl + wr) * K2_R * step / 1000
            x, y, yaw = x + v * math.cos(yaw + d), y + v * math.sin(yaw + d), yaw + 2.0 * d
            st["pose"] = [x, y, yaw]
            body = rot((0, 0, 1), yaw - st["yaw0"]) @ st["turn0"]
            assert list(st["robot"].pose.translation) == pytest.approx([x, y, 0.0], abs=1e-9), (k, name)
            assert np.asarray(st["robot"].pose.rotation) == pytest.approx(body, abs=1e-9), (k, name)
            values = []
            for i, (p, u) in enumerate(rays):
                o, w = np.array([x, y, 0.0]) + body @ p, body @ u
                seen_at = min(ray_to_boxes(o, w, white),
                              min(ray_to_boxes(o, w, blue), ray_to_tilted_cylinder(o, w)) / OBSTACLE_FACTOR)
                values.append(1023.0 * (1.0 - seen_at / 0.05) if seen_at < 0.05 else 0.0)
                if values[-1] > 0.0:
                    st["seen"].setdefault(i, k * step)
                assert float(st["ds"][i].value) == pytest.approx(values[-1], abs=1e-6), (k, name, i, seen_at)
            st["speeds"] = tuple(max(-1.0, min(1.0, sum(w[side] * (1.0 - r / 512) for w, r in zip(K2_WEIGHTS, values,
                                                                                                   strict=True))))
                                 for side in (0, 1))
            for m, s in zip(st["motors"], st["speeds"], strict=True):
                m.set_velocity(s)
        (ax, ay, _), (bx, by, _) = (st["pose"] for st in state.values())
        assert math.hypot(ax - bx, ay - by) > 0.12, k
    return {name: (sorted((t, i) for i, t in st["seen"].items()), [*st["pose"][:2], math.remainder(st["pose"][2], 2 * math.pi)])
            for name, st in state.items()}


def noiseless_khepera1(tmp_path: Path) -> Path:
    shutil.copytree(DATA / "protos", tmp_path / "protos")
    proto = tmp_path / "protos" / "Khepera1.proto"
    proto.write_text(proto.read_text().replace("lookupTable [ 0 1023 0, 0.05 0 0.01 ]", "lookupTable [ 0 1023 0, 0.05 0 0 ]"))
    shutil.copy(DATA / "khepera_kinematic.wbt", tmp_path / "khepera_kinematic.wbt")
    return tmp_path / "khepera_kinematic.wbt"


def test_the_kinematic_khepera_template_leaves_out_physics_and_gives_webots_kinematic_rule() -> None:
    """Both Khepera I robots load without a line with their 24 devices; `kinematic TRUE` leaves out their
    Physics (no mass), so each moves by Webots' kinematic rule (radius 0.0075 m, axle 0.054120 m, as the
    Khepera II's); the box and the cylinder, half sunk in the floor, make no ground to ride."""
    w = load_world(DATA / "khepera_kinematic.wbt")
    assert w.warnings == []
    assert [r.name for r in w.world.robots] == ["khepera", "khepera(1)"]
    for robot in w.world.robots:
        assert len({d.name for d in robot.devices}) == 24 and robot.mass is None
        drive = robot.differential_drive
        assert drive.step_rule == "mid_heading"
        assert (drive.wheel_radius, drive.axle_length) == pytest.approx((K2_R, K2_AXLE), abs=1e-15)
    assert Simulation(w, "exact").ground is None


def test_braitenbergs_calls_drive_both_kinematic_kheperas_by_the_closed_forms(tmp_path: Path) -> None:
    """khepera_kinematic: for 16 s (500 steps) every reading and pose of both robots meets
    run_khepera_kinematic's closed forms; each starts 7 cm from the wall behind it, which its rear sensors
    read from the first step (ds7 for "khepera", ds6 and ds7 for "khepera(1)"), too little to lower the
    bounded speed: both drive straight at 0.0075 m/s, 0.11976 m in 15.968 s, towards the box."""
    out = run_khepera_kinematic(noiseless_khepera1(tmp_path), 16000)
    assert out["khepera"][0] == [(32, 7)] and out["khepera(1)"][0] == [(32, 6), (32, 7)]
    for name, ((x, y), _, yaw) in K1_ROBOTS.items():
        travel = 0.0075 * 15.968
        assert out[name][1] == pytest.approx([x + travel * math.cos(yaw), y + travel * math.sin(yaw), yaw], abs=1e-9)


@pytest.mark.slow
def test_braitenbergs_calls_drive_both_kinematic_kheperas_round_the_box_and_cylinder(tmp_path: Path) -> None:
    """The same closed forms for 120 s (3750 steps): "khepera" meets the box at 44.0 s (ds3 first) and
    "khepera(1)" at 45.536 s (ds2), the light blue faces seen 0.47137 times as near as white ones; each
    turns away, never within 0.12 m of the other (beyond its rays), to (0.2990, −0.1552), heading −0.9094,
    and (−0.2023, −0.1642), heading −1.8075."""
    out = run_khepera_kinematic(noiseless_khepera1(tmp_path), 120000)
    assert out["khepera"][0] == [(32, 7), (44000, 3), (44352, 2), (45056, 4), (47168, 5)]
    assert out["khepera(1)"][0] == [(32, 6), (32, 7), (45536, 2), (45600, 3), (47136, 1), (49248, 0)]
    assert out["khepera"][1] == pytest.approx([0.2990, -0.1552, -0.9094], abs=1e-4)
    assert out["khepera(1)"][1] == pytest.approx([-0.2023, -0.1642, -1.8075], abs=1e-4)


@pytest.mark.parametrize("helper", [True, False])
def test_the_batched_simulation_keeps_the_koala_flat_as_simulation_does_bit_for_bit(tmp_path: Path, helper: bool) -> None:
    """The Koala without Physics in the batched simulation rides no ground either: on the arena floor leaning
    7.7e-7 rad, each copy's pose is the single Simulation's bit for bit at every step (C drive pass and numpy),
    its rotation a turn about the world's z only (third row and column exactly (0, 0, 1)) and its height the one
    it was placed at. Before, the batched copies rode the floor as a ramp: tilted by the lean, 1.3e-10 m up."""
    from sensorium.gym.views import CopySim
    from sensorium.server.raycast import packets
    from sensorium.server.sim.batched import BatchedSimulation

    if helper and packets.library() is None:
        pytest.skip(f"no C helper: {packets.status()}")
    lw = load_world(noiseless_koala(tmp_path))
    batched = BatchedSimulation(lw, 2)
    if not helper:
        batched._drive_step = None
    batched.reset(np.arange(2), [1, 2])
    singles = [Simulation(lw, "exact") for _ in range(2)]
    slot = batched.slot("koala")
    z0 = float(batched.pos[0, slot, 2])
    speeds = [(1.4, 1.6), (-3.0, 5.0)]
    for c, single in enumerate(singles):
        for sim in (single, CopySim(batched, c)):
            for m, v in zip(("left wheel motor", "right wheel motor"), speeds[c]):
                motor = sim.robot("koala").motors[m]
                motor.set_position(math.inf)
                motor.set_velocity(v)
    for t in range(60):
        batched.step()
        for c, single in enumerate(singles):
            single.step()
            p = single.robot("koala").pose
            assert batched.pos[c, slot].tobytes() == p.translation.tobytes(), (t, c)
            assert batched.rot[c, slot].tobytes() == p.rotation.tobytes(), (t, c)
            assert batched.pos[c, slot, 2] == z0, (t, c)
            assert batched.rot[c, slot, 2].tolist() == [0.0, 0.0, 1.0], (t, c)
            assert batched.rot[c, slot, :, 2].tolist() == [0.0, 0.0, 1.0], (t, c)
    assert float(np.hypot(*(batched.pos[1, slot, :2] - batched.pos[0, slot, :2]))) > 0.01   # the copies differ
