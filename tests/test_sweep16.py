"""Sweep 16: Webots' device samples not run before, each on a stand-in world of ours
(tests/data/sweep16/: the sample's poses and sizes, our own text) driven by the calls its sample
controller makes, checked against closed forms."""

from __future__ import annotations

import math
import subprocess
from pathlib import Path

import numpy as np
import pytest
from _serve import child_env, sensorium

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data" / "sweep16"

# sick_point_cloud: the Sick LD-MRS 800001S01's first lidar ('sick'): 85° over 170 columns, 8 layers
# over 7.2°, at (0.25, 0, 1.2), turned -7.5° about z and mounted upside down (Rz(-7.5°)·Rx(π)).
SICK_AT = np.array([0.25, 0.0, 1.2])
SICK_FOV, SICK_W, SICK_L, SICK_VFOV = math.radians(85), 170, 8, math.radians(7.2)
CAN_R, CAN_H = 0.03175, 0.1222
CANS = 11
# the controller's prints over 12 s (one 64 ms step each), as the closed form below counts them
SICK_PRINTS = [3, 4, 5, 6, 7, 8, 7, 6, 7, 6, 7, 6, 7, 6, 7, 6, 7, 6, 5, 4, 5, 4, 5, 4, 5, 4, 5, 4, 3, 2, 3, 2,
               3, 2, 3, 2, 3, 2, 1, 0]


def sick_rotation() -> np.ndarray:
    a = math.radians(-7.5)
    rz = np.array([[math.cos(a), -math.sin(a), 0.0], [math.sin(a), math.cos(a), 0.0], [0.0, 0.0, 1.0]])
    return rz @ np.diag([1.0, -1.0, -1.0])


def middle_layer_closed_form(cans: list[np.ndarray]) -> np.ndarray:
    """Layer L/2 = 4's points (170, 3) in the lidar's frame, +inf where the beam meets no can: each
    beam ``(cos e cos θ, cos e sin θ, sin e)``, e = 3.6° - 4·7.2°/7 (−0.514°: +0.514° in the world,
    upside down), θ_j = 42.5° - (j + ½)·0.5°, cast from the lidar's origin against each can's
    cylinder (vertical axis through its origin, radius 0.03175, ±0.0611 m about it). The arena's
    walls are the only other thing these beams meet, each more than 3 m ahead along the lidar's x."""
    rot = sick_rotation()
    e = SICK_VFOV / 2 - 4 * SICK_VFOV / (SICK_L - 1)
    out = np.full((SICK_W, 3), np.inf)
    for j in range(SICK_W):
        th = SICK_FOV / 2 - (j + 0.5) * SICK_FOV / SICK_W
        d = np.array([math.cos(e) * math.cos(th), math.cos(e) * math.sin(th), math.sin(e)])
        dw = rot @ d
        best = math.inf
        for c in cans:
            oc = SICK_AT[:2] - c[:2]
            a, b, cc = dw[0] ** 2 + dw[1] ** 2, 2 * (oc @ dw[:2]), oc @ oc - CAN_R ** 2
            disc = b * b - 4 * a * cc
            if disc < 0:
                continue
            t = (-b - math.sqrt(disc)) / (2 * a)
            if 0 < t < best and abs(SICK_AT[2] + t * dw[2] - c[2]) <= CAN_H / 2:
                best = t
        if best < math.inf:
            out[j] = best * d
    return out


def count_runs(x: np.ndarray) -> int:
    """sick_point_cloud's count: the runs of columns whose point's x is under 3 m."""
    near = x < 3.0
    return int(near[0]) + int(np.sum(near[1:] & ~near[:-1]))


def test_the_ld_mrs_middle_layer_counts_the_cans_the_closed_form_counts() -> None:
    """sick_point_cloud's calls (its 64 ms step, the point cloud of layer getNumberOfLayers()/2, its
    count of the runs of points nearer than 3 m) on our stand-in, the belt at its 0.5 m/s: every
    64 ms for 12 s each point of the middle layer is where the closed form's beam meets the cans
    where they are (1e-6 m, the float32 of the point; EXACT precision:
    FAST's 36-sided circumscribed prisms put them up to 0.15 mm nearer, the counts unchanged), the runs counted are its runs, and the counts change as the prints of
    Webots' controller under `sensorium run` did (3 cans, then 4 … 8 as the belt brings them into
    the field of view, one too many or too few while two cans 0.1 m apart merge at the field's
    edge, 0 once all have fallen off the belt's end). The cans, placed 8.9 mm above the belt as in
    Webots' world, settle on it at load (their origins' z 1.22 to 1.2111; `sensorium run` warns of it)."""
    w = load_world(DATA / "sick_point_cloud.wbt")
    assert any("its belt carries the solids" in x for x in w.warnings), w.warnings
    sim = Simulation(w, "exact")
    assert sim.scene.solid_poses["can(0)"].translation[2] == pytest.approx(1.15 + CAN_H / 2, abs=1e-12)
    belt = sim.robot("conveyor belt").motor("belt_motor")
    belt.set_position(math.inf)
    belt.set_velocity(0.5)
    sick = sim.device("robot/sick")
    assert (int(sick.params.horizontal_resolution), int(sick.params.number_of_layers)) == (SICK_W, SICK_L)
    sick.enable(64)
    sick.enable_point_cloud()
    prints, previous, near_seen = [], 0, 0
    for _ in range(12000 // 64):
        sim.run(4)
        layer = sick.layer_point_cloud(SICK_L // 2)
        cans = [np.asarray(sim.scene.solid_poses[f"can({i})"].translation, dtype=float) for i in range(CANS)]
        want = middle_layer_closed_form(cans)
        got = np.stack([layer["x"], layer["y"], layer["z"]], axis=1).astype(float)
        hit = np.isfinite(want[:, 0])
        assert list(got[:, 0] < 3.0) == list(hit), sim.time_ms
        assert got[hit] == pytest.approx(want[hit], abs=1e-6), sim.time_ms
        near_seen = max(near_seen, int(hit.sum()))
        n = count_runs(got[:, 0])
        assert n == count_runs(want[:, 0])
        if n != previous:
            prints.append(n)
            previous = n
    assert prints == SICK_PRINTS
    assert near_seen > 0


SICK_CONTROLLER = '''\
from controller import Robot

robot = Robot()
sick = robot.getDevice("sick")
sick.enable(64)
sick.enablePointCloud()
resolution, layers = sick.getHorizontalResolution(), sick.getNumberOfLayers()
print(f"resolution {resolution} layers {layers}", flush=True)
previous = 0
while robot.step(64) != -1:
    layer = sick.getLayerPointCloud(layers // 2)
    count, before = 0, False
    for p in range(resolution):
        near = layer[p].x < 3.0
        count += near and not before
        before = near
    if count != previous:
        print(f"I see {count}", flush=True)
        previous = count
'''

BELT_CONTROLLER = '''\
import math
import sys

from controller import Robot

robot = Robot()
motor = robot.getDevice("belt_motor")
motor.setPosition(math.inf)
motor.setVelocity(float(sys.argv[1]))
while robot.step(int(robot.getBasicTimeStep())) != -1:
    pass
'''


@pytest.mark.slow
def test_the_sick_point_cloud_controller_counts_the_cans_under_sensorium_run(tmp_path: Path) -> None:
    """Python controllers of ours making sick_point_cloud's calls and the ConveyorBelt's controller's
    (its speed from controllerArgs), started by ``sensorium run``: the 170 columns and 8 layers,
    then the same counts as in process, 3 … 8 … 0 over 12 s."""
    (tmp_path / "worlds").mkdir()
    (tmp_path / "worlds" / "sick_point_cloud.wbt").write_text((DATA / "sick_point_cloud.wbt").read_text())
    for name, text in (("sick_point_cloud", SICK_CONTROLLER), ("conveyor_belt", BELT_CONTROLLER)):
        folder = tmp_path / "controllers" / name
        folder.mkdir(parents=True)
        (folder / f"{name}.py").write_text(text)
    done = subprocess.run(sensorium("run", str(tmp_path / "worlds" / "sick_point_cloud.wbt"), "--until", "12000",
                                    "--rpc", "tcp://127.0.0.1:0", "--pub", "tcp://127.0.0.1:0"),
                          env=child_env(), cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "resolution 170 layers 8" in done.stdout, (done.stdout, done.stderr)
    seen = [int(x.rsplit(" ", 1)[1]) for x in done.stdout.splitlines() if "I see " in x]
    assert seen == SICK_PRINTS, (done.stdout, done.stderr)


# sick: the tricycle's Sick LMS 291 (180 columns over 3.14159 rad, one layer, maxRange 80) at z 0.57,
# the 46 obstacles (cylinders of radius 0.5 m) and the arena's walls (inner faces at ±50 m) around it
def sick_obstacles() -> list[tuple[float, float]]:
    text = (DATA / "sick.wbt").read_text()
    out = []
    for line in text.splitlines():
        if line.startswith("Solid { translation ") and 'name "obstacle ' in line:
            x, y = line.split()[3:5]
            out.append((float(x), float(y)))
    return out


def lms291_closed_form(obstacles: list[tuple[float, float]]) -> np.ndarray:
    """The 180 ranges from the origin: column j's beam at θ_j = Φ/2 - (j + ½)·Φ/180 (Φ = 3.14159) to
    the nearest obstacle's circle or the wall it meets first."""
    fov, w = 3.14159, 180
    out = np.empty(w)
    for j in range(w):
        th = fov / 2 - (j + 0.5) * fov / w
        d = np.array([math.cos(th), math.sin(th)])
        best = min(50.0 / abs(d[0]) if abs(d[0]) > 1e-12 else math.inf,
                   50.0 / abs(d[1]) if abs(d[1]) > 1e-12 else math.inf)
        for cx, cy in obstacles:
            c = np.array([cx, cy])
            b = float(c @ d)
            disc = b * b - (float(c @ c) - 0.25)
            if disc >= 0 and b - math.sqrt(disc) > 0:
                best = min(best, b - math.sqrt(disc))
        out[j] = best
    return out


def braitenberg_obstacle(ranges: np.ndarray, max_range: float = 80.0) -> float:
    """The sick controller's sum: Gaussian weights (mean 90, sigma 5, its integer divisions) times
    1 - range / maxRange (an infinite range counted as maxRange)."""
    i = np.arange(len(ranges), dtype=float)
    g = np.exp(-((i - 90) ** 2) / 50.0) / (5 * math.sqrt(2 * math.pi))
    v = np.where(np.isinf(ranges), max_range, ranges)
    return float(np.sum(g * (1.0 - v / max_range)))


def test_the_sick_tricycle_loads_as_a_tricycle_and_its_lms_291_reads_the_closed_form() -> None:
    """sick (Webots' LMS 291 on a tricycle): its back wheels are driven, its front wheel turns freely
    on a steering hinge ('direction'): a steered drive with that free wheel, no load line. Its lidar's
    180 ranges are the closed form's to the 46 obstacles and the
    walls (1e-5 m relative, float32), and the controller's Braitenberg sum over them is 0.413814
    (as Webots' controller printed it under `sensorium run`: speed 100·(0.99 - 0.413814) = 57.62 rad/s,
    direction 0.007182 rad)."""
    w = load_world(DATA / "sick.wbt")
    assert w.warnings == []
    wheels = w.world.robots[0].steered_drive.wheels
    assert [(x.motor, x.steer, x.position, x.radius) for x in wheels] == [
        ("back_right_wheel", None, (-0.4, -0.2), 0.17), ("back_left_wheel", None, (-0.4, 0.2), 0.17),
        (None, "direction", (0.4, 0.0), 0.17)]
    sim = Simulation(w, "exact")
    sick = sim.device("robot/Sick LMS 291")
    sick.enable(32)
    sim.run(2)
    got = np.asarray(sick.range_image, dtype=float).reshape(-1)
    obstacles = sick_obstacles()
    assert len(obstacles) == 46
    want = lms291_closed_form(obstacles)
    assert got == pytest.approx(want, rel=1e-6)
    obstacle = braitenberg_obstacle(got)
    assert obstacle == pytest.approx(0.413814, abs=5e-7)
    speed = 100.0 * (0.99 - obstacle)
    assert (speed, obstacle / speed) == pytest.approx((57.618592, 0.007182), abs=5e-6)


def test_the_sick_controller_s_calls_drive_the_tricycle_on_the_bicycle_model() -> None:
    """The sick controller's calls in process (32 ms steps: back wheels at 100·(0.99 - obstacle) rad/s,
    'direction' at obstacle / speed) for 3 s: the rear axle's centre (0.4 m behind the origin) follows
    the bicycle model step by step, v = 0.17·ω and ωz = v·tan δ / 0.8 with δ the steering joint's
    position that step plus the front wheel's heading as loaded (-5.9e-8 rad: the sample's rounded
    rotations), 1e-9 m and rad; the rear axle has gone 22.8 m (its speed falls as the obstacles near)."""
    loaded = load_world(DATA / "sick.wbt")
    h0 = loaded.world.robots[0].steered_drive.wheels[2].heading
    assert abs(h0) < 1e-7
    sim = Simulation(loaded, "exact")
    robot = sim.robot("robot")
    lms = sim.device("robot/Sick LMS 291")
    lms.enable(32)
    left, right, direction = robot.motor("back_left_wheel"), robot.motor("back_right_wheel"), robot.motor("direction")
    left.set_position(math.inf)
    right.set_position(math.inf)

    def axle() -> tuple[float, float, float]:
        p = robot.pose
        yaw = math.atan2(p.rotation[1, 0], p.rotation[0, 0])
        return float(p.translation[0]) - 0.4 * math.cos(yaw), float(p.translation[1]) - 0.4 * math.sin(yaw), yaw

    x, y, yaw = axle()
    speed = 100.0                 # Webots' motor after setPosition(inf): its maxVelocity until set
    dt = 0.032
    for _ in range(94):
        sim.run(1)
        delta = direction.position + h0
        v = 0.17 * speed
        w = v * math.tan(delta) / 0.8
        if w == 0.0:
            x, y = x + v * dt * math.cos(yaw), y + v * dt * math.sin(yaw)
        else:
            x, y = (x + v / w * (math.sin(yaw + w * dt) - math.sin(yaw)),
                    y - v / w * (math.cos(yaw + w * dt) - math.cos(yaw)))
            yaw = math.remainder(yaw + w * dt, 2 * math.pi)
        gx, gy, gyaw = axle()
        assert (gx, gy, gyaw) == pytest.approx((x, y, yaw), abs=1e-9)
        obstacle = braitenberg_obstacle(np.asarray(lms.range_image, dtype=float).reshape(-1))
        speed = 100.0 * (0.99 - obstacle)
        direction.set_position(obstacle / speed)
        left.set_velocity(speed)
        right.set_velocity(speed)
    assert math.hypot(gx, gy) == pytest.approx(22.8167, abs=1e-3)
    assert abs(gyaw) > 1e-3                  # it steered
