"""Sweep 31: Webots `projects/robots` worlds of wheeled robots with range sensors not run before, each on a
stand-in world of ours (tests/data/sweep31/: the PROTOs' device names, places, joints and bounding objects,
our own text, meshes left out) driven in process by the calls its controller makes and checked against
closed forms."""

from __future__ import annotations

import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from _serve import child_env, sensorium

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data" / "sweep31"
HALF = 7.5                      # the arena's walls' inner faces (floorSize 15)


def yaw_of(pose) -> float:
    r = np.asarray(pose.rotation)
    return math.atan2(r[1, 0], r[0, 0])


def ray_length(eye: np.ndarray, d: np.ndarray, boxes: list[tuple[np.ndarray, np.ndarray]]) -> float:
    """How far a horizontal ray from ``eye`` along unit ``d`` runs to the arena's walls (the inside of
    [−HALF, HALF]²) or the nearest axis-aligned box (centre, half sizes) in its way, in the plane."""
    t = min((math.copysign(HALF, d[k]) - eye[k]) / d[k] for k in (0, 1) if d[k] != 0.0)
    for c, h in boxes:
        lo, hi = c[:2] - h[:2], c[:2] + h[:2]
        near, far = -math.inf, math.inf
        for k in (0, 1):
            if d[k] == 0.0:
                if not lo[k] <= eye[k] <= hi[k]:
                    near, far = math.inf, -math.inf
                continue
            a, b = (lo[k] - eye[k]) / d[k], (hi[k] - eye[k]) / d[k]
            near, far = max(near, min(a, b)), min(far, max(a, b))
        if 0.0 < near <= far:
            t = min(t, near)
    return t


# ------------------------------------------------------------------------------------ TIAGo PMB-2 Base
# tiago_pmb2_base (pal_robotics/tiago_pmb2_base, R2023b): the TIAGo PMB-2 Base at (−4.416, 1.063, 0) facing +x,
# its Hokuyo URG-04LX-UG01 in the lidar slot at (0.202, 0, 0.091): 667 rays over 4.18879 rad, 0.2 to 5.6 m; drive
# wheels of radius 0.0985 m whose Solids are at y ±0.202; four free casters. The world's basicTimeStep is
# Webots' default 32 ms. Our wooden box (0.6 m cube) stands at (−0.6, 0.863).
PMB2 = DATA / "tiago_pmb2_base.wbt"
PMB2_NAME = "TIAGo PMB-2 Base"
HOKUYO = "Hokuyo URG-04LX-UG01"
HOKUYO_FOV, HOKUYO_RAYS, HOKUYO_MAX = 4.18879, 667, 5.6
LIDAR_AT = (0.202, 0.091)       # in the slot: ahead of the origin, height
WHEEL_R, AXLE = 0.0985, 0.404
PMB2_Z = 0.0035                 # 0.0985 − 0.095: wheels (and casters: 0.025 + 0.04 − 0.0615) 3.5 mm into the floor
CRATE = (np.array([-0.6, 0.863]), np.array([0.3, 0.3]))
PMB2_STEP = 32
UNUSED_POINT, N_SECTOR = 83, 5   # tiago_pmb2_base.c's
MAX_SPEED, CRUISING_SPEED = 6.4, 3.0
FAR_OBSTACLE_THRESHOLD, NEAR_OBSTACLE_THRESHOLD = 0.4, 0.7
FAST_DECREASE_FACTOR, SLOW_DECREASE_FACTOR = 0.9, 0.5


def hokuyo_closed_form(x: float, y: float, h: float, box=CRATE) -> np.ndarray:
    """The Hokuyo's ranges with the robot at (x, y) heading h: ray i at azimuth fov/2 − (i + 0.5)·fov/667 from
    the robot's x, from the lidar 0.202 m ahead of the origin to the walls or our box (inf past 5.6 m)."""
    eye = np.array([x + LIDAR_AT[0] * math.cos(h), y + LIDAR_AT[0] * math.sin(h)])
    out = np.full(HOKUYO_RAYS, math.inf)
    for i in range(HOKUYO_RAYS):
        a = h + HOKUYO_FOV / 2 - (i + 0.5) * HOKUYO_FOV / HOKUYO_RAYS
        t = ray_length(eye, np.array([math.cos(a), math.sin(a)]), [box])
        out[i] = t if t <= HOKUYO_MAX else math.inf
    return out


def braitenberg_pmb2(values, width: int, max_range: float) -> tuple[float, float, bool]:
    """tiago_pmb2_base.c's loop body: the wheel speeds it sets from one range image, and whether it makes its
    extra wb_robot_step(1) (the front-obstacle u-turn)."""
    sector_size = int((width - 2.0 * UNUSED_POINT - 1.0) / N_SECTOR)
    sector_range = [UNUSED_POINT + (i + 1) * sector_size for i in range(N_SECTOR)]
    threshold = max_range / 2.0
    left = front_left = front = front_right = right = 0.0
    for i in range(UNUSED_POINT, width - UNUSED_POINT - 1):
        v = float(values[i])
        if v < threshold:
            w = 1.0 - v / max_range
            if i < sector_range[0]:
                left += w
            if sector_range[0] <= i < sector_range[1]:
                front_left += w
            if sector_range[1] <= i < sector_range[2]:
                front += w
            if sector_range[2] <= i < sector_range[3]:
                front_right += w
            if sector_range[3] <= i < sector_range[4] + 1:
                right += w
    left, front_left, front, front_right, right = (s / sector_size for s in (left, front_left, front, front_right,
                                                                           right))

    def check(s: float) -> float:
        return min(s, MAX_SPEED)

    if left > right and left > NEAR_OBSTACLE_THRESHOLD:
        f = (1.0 - FAST_DECREASE_FACTOR * left) * MAX_SPEED / left
        return check(f * left), check(f * right), False
    if front_left > front_right and front_left > FAR_OBSTACLE_THRESHOLD:
        f = (1.0 - SLOW_DECREASE_FACTOR * front_left) * MAX_SPEED / front_left
        return check(f * front_left), check(f * front_right), False
    if front_right > front_left and front_right > FAR_OBSTACLE_THRESHOLD:
        f = (1.0 - SLOW_DECREASE_FACTOR * front_right) * MAX_SPEED / front_right
        return check(f * front_left), check(f * front_right), False
    if right > left and right > NEAR_OBSTACLE_THRESHOLD:
        f = (1.0 - FAST_DECREASE_FACTOR * right) * MAX_SPEED / right
        return check(f * left), check(f * right), False
    if front > NEAR_OBSTACLE_THRESHOLD:
        f = (1.0 - FAST_DECREASE_FACTOR * front) * MAX_SPEED / front
        if front_right > front_left or right > left:
            return -check(f * front), check(f * front), True
        return check(f * front), -check(f * front), True
    return CRUISING_SPEED, CRUISING_SPEED, False


def diff_arc(x: float, y: float, h: float, wl: float, wr: float, dt: float) -> tuple[float, float, float]:
    """A two-wheel drive's exact arc: wheel speeds wl, wr (rad/s) for dt s."""
    v, w = WHEEL_R * (wl + wr) / 2.0, WHEEL_R * (wr - wl) / AXLE
    if w == 0.0:
        return x + v * dt * math.cos(h), y + v * dt * math.sin(h), h
    return (x + v / w * (math.sin(h + w * dt) - math.sin(h)), y - v / w * (math.cos(h + w * dt) - math.cos(h)),
            h + w * dt)


def test_the_pmb2_base_loads_as_a_two_wheel_drive_with_its_lidar_sonars_and_bumper() -> None:
    """The PMB-2 stand-in loads with the arena's stand-in line only: its two motorised wheels (radius 0.0985 m,
    Solids 0.404 m apart) are its drive, its four casters' free hinges no wheel and no line, and every device
    the PROTO has is there with the Hokuyo from the slot (667 rays, 4.18879 rad, 0.2 to 5.6 m). It settles 3.5
    mm up, where its wheels and casters (all reaching 3.5 mm below its origin) touch the floor; its rear sonars
    read 1000 (nothing within their table's 0.1 m) and its bumper 0."""
    w = load_world(PMB2)
    assert len(w.warnings) == 1 and "built-in stand-ins used for RectangleArena" in w.warnings[0], w.warnings
    (robot,) = w.world.robots
    assert [d.name for d in robot.devices] == [
        HOKUYO, "accelerometer", "inertial unit", "gyro", "base_cover_link", "base_sonar_03_link",
        "base_sonar_02_link", "base_sonar_01_link", "wheel_right_joint", "wheel_right_joint_sensor",
        "wheel_left_joint", "wheel_left_joint_sensor"]
    dd = robot.differential_drive
    assert (dd.wheel_radius, dd.axle_length, dd.left_motor, dd.right_motor) == (WHEEL_R, AXLE, "wheel_left_joint",
                                                                                "wheel_right_joint")
    sim = Simulation(w, "exact")
    assert "its origin's z from 0.0000 to 0.0035 m" in w.warnings[-1]
    pose = sim.robot(PMB2_NAME).pose
    assert list(pose.translation) == pytest.approx([-4.416, 1.063, PMB2_Z], abs=1e-12)
    lidar = sim.device(f"{PMB2_NAME}/{HOKUYO}")
    info = lidar.info()
    assert (info["horizontalResolution"], info["fov"], info["minRange"], info["maxRange"]) == (
        HOKUYO_RAYS, HOKUYO_FOV, 0.2, HOKUYO_MAX)
    # the rear sonars (DistanceSensors with Webots' default table, 0 m -> 0, 0.1 m -> 1000) see nothing within
    # 0.1 m: the table's last value; the bumper touches nothing
    sensors = [sim.device(f"{PMB2_NAME}/base_sonar_0{k}_link") for k in (1, 2, 3)] + [
        sim.device(f"{PMB2_NAME}/base_cover_link")]
    for d in sensors:
        d.enable(PMB2_STEP)
    sim.step()
    assert [float(d.value) for d in sensors] == [1000.0, 1000.0, 1000.0, 0.0]


def test_the_hokuyo_reads_the_box_and_the_walls_by_their_closed_forms() -> None:
    """At the start every ray the controller uses (83 to 583, ±90° about the robot's x) reads the distance from
    the lidar to our box's west face or the arena's walls along its azimuth (float32, 1e-5), inf past 5.6 m:
    our box on 28 rays (329 to 356) from 3.314 m (ray 333, nearly straight ahead) to 3.3489 m, every wall beyond
    5.6 m (the nearest, north, 6.437 m off) so inf on every other ray; the rays
    outside ±90° see the robot's own wheels (0.2098 m on the first: as Webots' lidar sees its robot, which is why
    the controller skips 83 rays each side)."""
    sim = Simulation(load_world(PMB2), "exact")
    lidar = sim.device(f"{PMB2_NAME}/{HOKUYO}")
    lidar.enable(PMB2_STEP)
    sim.step()
    got = np.asarray(lidar.range_image, dtype=float).reshape(-1)
    want = hokuyo_closed_form(-4.416, 1.063, 0.0)
    used = slice(UNUSED_POINT, HOKUYO_RAYS - UNUSED_POINT)
    assert np.array_equal(np.isinf(got[used]), np.isinf(want[used]))
    hit = np.isfinite(want[used])
    assert got[used][hit] == pytest.approx(want[used][hit], abs=1e-5)
    assert list(np.nonzero(np.isfinite(got[used]))[0] + UNUSED_POINT) == list(range(329, 357))
    assert (got[333], got[356]) == pytest.approx((3.314, 3.348873), abs=1e-5)
    # the first ray (120° left) meets the left wheel's inner face (y 0.182) within its radius
    assert got[0] == pytest.approx(0.182 / math.sin(HOKUYO_FOV / 2 - 0.5 * HOKUYO_FOV / HOKUYO_RAYS), abs=1e-5)


def run_pmb2(world: Path, box, until_ms: int) -> tuple[tuple[float, float, float], list]:
    """tiago_pmb2_base.c's calls in process until ``until_ms``, every step checking the range image against
    the closed form at the robot's pose (1e-5) and the pose against the two-wheel arcs of the speeds set
    (1e-9); the final (x, y, heading) and each control step's (time, left, right, extra step)."""
    sim = Simulation(load_world(world), "exact")
    robot = sim.robot(PMB2_NAME)
    lidar = sim.device(f"{PMB2_NAME}/{HOKUYO}")
    lidar.enable(PMB2_STEP)
    left, right = robot.motor("wheel_left_joint"), robot.motor("wheel_right_joint")
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(0.0)
    x, y, h = -4.416, 1.063, 0.0
    wl = wr = 0.0
    dt = PMB2_STEP / 1000.0
    branches = []
    t = 0
    used = slice(UNUSED_POINT, HOKUYO_RAYS - UNUSED_POINT)
    while t < until_ms:
        sim.step()
        t += PMB2_STEP
        x, y, h = diff_arc(x, y, h, wl, wr, dt)
        pose = robot.pose
        assert [*pose.translation[:2], yaw_of(pose)] == pytest.approx([x, y, h], abs=1e-9), t
        got = np.asarray(lidar.range_image, dtype=float).reshape(-1)
        want = hokuyo_closed_form(x, y, h, box)
        assert np.array_equal(np.isinf(got[used]), np.isinf(want[used])), t
        hit = np.isfinite(want[used])
        assert got[used][hit] == pytest.approx(want[used][hit], abs=1e-5), t
        new_wl, new_wr, extra = braitenberg_pmb2(got, HOKUYO_RAYS, HOKUYO_MAX)
        if extra:                   # wb_robot_step(1): one basic step on the speeds set before
            sim.step()
            t += PMB2_STEP
            x, y, h = diff_arc(x, y, h, wl, wr, dt)
        wl, wr = new_wl, new_wr
        branches.append((t, wl, wr, extra))
        left.set_velocity(wl)
        right.set_velocity(wr)
    return (x, y, h), branches


def test_tiago_pmb2_base_calls_drive_to_the_box_and_turn_away_on_closed_form_arcs() -> None:
    """tiago_pmb2_base.c's calls for 12 s: each step the range image is the closed form's at the robot's pose
    (1e-5) and the wheel speeds its Braitenberg rule sets from it carry the robot on the two-wheel arc of those
    speeds (1e-9). It cruises at 3 rad/s (0.2955 m/s) for 8.8 s, when the box, on its right, passes 0.4 in its
    front-right sector: on 43 steps to 10.208 s (two runs, three cruising steps between at 9.4 s) the rule
    stops the left wheel and turns the right one between 1.379 and 5.1137 rad/s, pivoting the robot left about
    its left wheel, then it cruises on past the box, at (−1.3394, 1.5763) heading 0.9385 rad at 12 s. The
    u-turn branch (and its wb_robot_step(1)) is not reached: the next test reaches it."""
    (x, y, h), branches = run_pmb2(PMB2, CRATE, 12000)
    turning = [b for b in branches if b[1:3] != (CRUISING_SPEED, CRUISING_SPEED)]
    assert (len(turning), turning[0][0], turning[-1][0]) == (43, 8800, 10208)
    assert all(b[1] == 0.0 and 1.37 < b[2] < 5.12 for b in turning) and not any(b[3] for b in branches)
    assert turning[0][2] == pytest.approx(5.113733, abs=1e-6)
    assert (x, y, h) == pytest.approx((-1.339437, 1.576264, 0.938508), abs=1e-6)


POST = (np.array([-2.5, 1.063]), np.array([0.15, 0.15]))


def test_tiago_pmb2_base_calls_u_turn_before_a_post_dead_ahead(tmp_path: Path) -> None:
    """With a 0.3 m post of ours dead ahead instead of the box (at (−2.5, 1.063): mirror-symmetric, the side
    sectors empty) only the front sector fills: at 3.296 s (the post's face 0.5995 m ahead of the lidar) it passes
    0.7 and the rule takes its u-turn branch, right wheel back and left ahead at 2.3418 rad/s (neither side
    fuller: it turns right), after its wb_robot_step(1), one basic step of 32 ms on the speeds set before (a
    step shorter than the basic step ends at the next basic step, as in Webots); three times (3.328, 3.392 and
    4.16 s, counting the extra steps), cruising between as the post leaves the front sector, then the post
    fills the front-left sector and the rule pivots the robot right about its right wheel (left wheel at
    4.8549 rad/s and falling) until it is clear; at 10 s it is at (−2.2964, −0.0956) heading −0.9242 rad,
    every step the closed forms' (the image 1e-5, the pose 1e-9)."""
    world = tmp_path / "post.wbt"
    world.write_text(PMB2.read_text().replace("protos/", f"{DATA}/protos/")
                     .replace("translation -0.6 0.863 0.3", "translation -2.5 1.063 0.3")
                     .replace("size 0.6 0.6 0.6", "size 0.3 0.3 0.6"))
    (x, y, h), branches = run_pmb2(world, POST, 10000)
    u_turns = [b for b in branches if b[3]]
    assert [b[0] for b in u_turns] == [3328, 3392, 4160]
    assert all(b[1] == -b[2] > 2.3 for b in u_turns) and u_turns[0][1] == pytest.approx(2.341800, abs=1e-6)
    after = next(b for b in branches if b[0] > 4160)
    assert after[0] == 4192 and after[2] == 0.0 and after[1] == pytest.approx(4.854942, abs=1e-6)
    assert (x, y, h) == pytest.approx((-2.296422, -0.095565, -0.924233), abs=1e-6)


# our Python controller making tiago_pmb2_base.c's calls in its order (only the prints are the test's)
PMB2_CONTROLLER = '''"""Sensorium's stand-in for tiago_pmb2_base.c (sweep 31): our own Python making its calls in its order (the
Hokuyo enabled at the basic step, both wheels in velocity control, each step the Braitenberg rule on the range
image, its u-turn branch with robot.step(1)); each control step prints the time and the speeds it set."""
from controller import Robot

MAX_SPEED, CRUISING_SPEED = 6.4, 3.0
FAR, NEAR, FAST, SLOW = 0.4, 0.7, 0.9, 0.5
UNUSED_POINT, N_SECTOR = 83, 5

robot = Robot()
time_step = int(robot.getBasicTimeStep())
lidar = robot.getDevice("Hokuyo URG-04LX-UG01")
left_wheel, right_wheel = robot.getDevice("wheel_left_joint"), robot.getDevice("wheel_right_joint")
lidar.enable(time_step)
width = lidar.getHorizontalResolution()
sector_size = int((width - 2.0 * UNUSED_POINT - 1.0) / N_SECTOR)
sector_range = [UNUSED_POINT + (i + 1) * sector_size for i in range(N_SECTOR)]
max_range = lidar.getMaxRange()
threshold = max_range / 2.0
for wheel in (left_wheel, right_wheel):
    wheel.setPosition(float("inf"))
    wheel.setVelocity(0.0)


def check(speed):
    return min(speed, MAX_SPEED)


while robot.step(time_step) != -1:
    values = lidar.getRangeImage()
    left = front_left = front = front_right = right = 0.0
    for i in range(UNUSED_POINT, width - UNUSED_POINT - 1):
        if values[i] < threshold:
            w = 1.0 - values[i] / max_range
            if i < sector_range[0]:
                left += w
            if sector_range[0] <= i < sector_range[1]:
                front_left += w
            if sector_range[1] <= i < sector_range[2]:
                front += w
            if sector_range[2] <= i < sector_range[3]:
                front_right += w
            if sector_range[3] <= i < sector_range[4] + 1:
                right += w
    left, front_left, front, front_right, right = (v / sector_size for v in (left, front_left, front, front_right,
                                                                           right))
    extra = 0
    if left > right and left > NEAR:
        f = (1.0 - FAST * left) * MAX_SPEED / left
        ls, rs = check(f * left), check(f * right)
    elif front_left > front_right and front_left > FAR:
        f = (1.0 - SLOW * front_left) * MAX_SPEED / front_left
        ls, rs = check(f * front_left), check(f * front_right)
    elif front_right > front_left and front_right > FAR:
        f = (1.0 - SLOW * front_right) * MAX_SPEED / front_right
        ls, rs = check(f * front_left), check(f * front_right)
    elif right > left and right > NEAR:
        f = (1.0 - FAST * right) * MAX_SPEED / right
        ls, rs = check(f * left), check(f * right)
    elif front > NEAR:
        f = (1.0 - FAST * front) * MAX_SPEED / front
        if front_right > front_left or right > left:
            ls, rs = -check(f * front), check(f * front)
        else:
            ls, rs = check(f * front), -check(f * front)
        robot.step(1)
        extra = 1
    else:
        ls, rs = CRUISING_SPEED, CRUISING_SPEED
    left_wheel.setVelocity(ls)
    right_wheel.setVelocity(rs)
    print(round(robot.getTime() * 1000), repr(ls), repr(rs), extra, flush=True)
'''


@pytest.mark.slow
def test_tiago_pmb2_base_calls_under_sensorium_run_set_the_in_process_speeds(tmp_path: Path) -> None:
    """Our Python controller making tiago_pmb2_base.c's calls under ``sensorium run`` before the post for 10 s:
    every control step sets exactly the speeds the in-process run's closed-form-checked steps set, at the same
    times; its robot.step(1) ends at the next basic step (the three u-turns at 3.328, 3.392 and 4.16 s) and
    says once that the step duration of 1 ms is rounded up."""
    (tmp_path / "worlds").mkdir()
    shutil.copytree(DATA / "protos", tmp_path / "worlds" / "protos")
    world = tmp_path / "worlds" / "tiago_pmb2_base.wbt"
    world.write_text(PMB2.read_text().replace("translation -0.6 0.863 0.3", "translation -2.5 1.063 0.3")
                     .replace("size 0.6 0.6 0.6", "size 0.3 0.3 0.6"))
    folder = tmp_path / "controllers" / "tiago_pmb2_base"
    folder.mkdir(parents=True)
    (folder / "tiago_pmb2_base.py").write_text(PMB2_CONTROLLER)
    done = subprocess.run(sensorium("run", str(world), "--until", "10000", "--rpc", "tcp://127.0.0.1:0",
                                    "--pub", "tcp://127.0.0.1:0"),
                          env=child_env(), cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert done.stderr.count("the step duration 1 ms of robot 'TIAGo PMB-2 Base' is not a multiple of the basic "
                             "time step (32 ms)") == 1, done.stderr
    rows = [line.split("] ", 1)[1].split() for line in done.stdout.splitlines()
            if line.startswith(f"[{PMB2_NAME}] ")]
    _, want = run_pmb2(world, POST, 10000)
    got = [(int(r[0]), float(r[1]), float(r[2]), r[3] == "1") for r in rows]
    assert got[:len(want)] == want
    assert [b[0] for b in got if b[3]] == [3328, 3392, 4160]


# ------------------------------------------------------------------------------------ TIAGo OMNI Base
# tiago_omni_base (pal_robotics/tiago_omni_base, R2023b): the TIAGo OMNI Base at (−4.416, 1.063, 0) facing +x on
# four mecanum wheels (radius 0.0762 m at (±0.244, ±0.1725)), the world's ContactProperties turning the left
# wheels' friction by −0.785398 rad and the right ones' by 0.785398; its two SICK lidars (818 rays over 4.71 rad
# in front, 4.712389 at the rear, 0.05 to 25 m, 1 mm resolution) each upside down in a Pose turned π about a
# horizontal axis, the front one at (0.27512, −0.18297, 0.20864) facing 45° right, the rear one at
# (−0.27512, 0.18297, 0.20864) facing 135° left.
OMNI = DATA / "tiago_omni_base.wbt"
OMNI_NAME = "TIAGo OMNI Base"
OMNI_LIDARS = {  # name: (place in the robot, Pose's axis, fov)
    "base_front_laser": ((0.27512, -0.18297, 0.20864), (-0.9238797538373538, 0.38268289803626016, 0.0), 4.71),
    "base_rear_laser": ((-0.27512, 0.18297, 0.20864), (-0.382683, -0.92388, 0.0), 4.712389),
}
OMNI_RAYS = 818


def axis_angle(axis, angle: float) -> np.ndarray:
    a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    k = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)


def omni_world(tmp_path: Path) -> Path:
    """The stand-in with both lidars' noise (0.0024 m) taken out."""
    out = tmp_path / "sweep31"
    (out / "protos").mkdir(parents=True)
    for src in [OMNI, *(DATA / "protos").glob("TiagoOmniBase*.proto")]:
        dst = out / src.relative_to(DATA)
        dst.write_text(src.read_text().replace("noise 0.0024", "noise 0"))
    return out / OMNI.name


def omni_lidar_closed_form(name: str, x: float, y: float) -> np.ndarray:
    """A lidar's ranges with the robot at (x, y) facing +x: ray i at azimuth fov/2 − (i + 0.5)·fov/818 in the
    lidar's own xy plane, turned by its Pose (π about its axis: upside down) into the robot's, to the walls,
    rounded to the 1 mm resolution."""
    place, axis, fov = OMNI_LIDARS[name]
    turn = axis_angle(axis, 3.141593)
    eye = np.array([x + place[0], y + place[1]])
    out = np.empty(OMNI_RAYS)
    for i in range(OMNI_RAYS):
        a = fov / 2 - (i + 0.5) * fov / OMNI_RAYS
        d = turn @ np.array([math.cos(a), math.sin(a), 0.0])
        out[i] = round(ray_length(eye, d[:2] / np.linalg.norm(d[:2]), []) / 0.001) * 0.001
    return out


def test_the_omni_base_loads_with_its_lidars_and_wheels_but_no_drive_for_its_side_wise_rollers() -> None:
    """The OMNI stand-in loads every device the PROTO has (the two lidars, the four wheel motors and their
    sensors, the accelerometer, inertial unit, gyro, GPS) and one line besides the arena's: no mecanum drive,
    as its rollers (the friction turned alike on each side's front and rear wheels, whose frames are alike)
    are not the youBot's pattern (alike on diagonal wheels), judged in the drive's frame, which its wheels
    turning about −y turn half round (its names' front and rear, left and right swapped: a positive speed
    would drive the robot backward; its direction written without a −0.0); the robot does not move."""
    w = load_world(OMNI)
    assert len(w.warnings) == 2 and "built-in stand-ins used for RectangleArena" in w.warnings[0], w.warnings
    assert ("robot 'TIAGo OMNI Base': no mecanum drive (the rollers (friction turned by 0.785398, -0.785398, "
            "0.785398, -0.785398 on the front left, front right, rear left and rear right wheels) are not alike on "
            "diagonal wheels and opposite on the front two; in the drive's frame: x forward along [-1.0, 0.0] in the "
            "robot's, y its left); the robot will not move") in w.warnings[1]
    (robot,) = w.world.robots
    assert [d.name for d in robot.devices] == [
        "accelerometer", "inertial unit", "gyro", "gps", "base_rear_laser", "base_front_laser",
        *(f"wheel_{k}_joint{s}" for k in ("front_right", "front_left", "rear_right", "rear_left")
          for s in ("", "_sensor"))]
    assert robot.differential_drive is None and getattr(robot, "mecanum_drive", None) is None


def test_the_omni_bases_upside_down_lidars_read_the_walls_by_their_closed_forms(tmp_path: Path) -> None:
    """Both lidars, upside down (so their rays sweep right to left in the robot's frame) and facing 45° right
    (front) and 135° left (rear), read the arena's walls along each ray's turned azimuth, rounded to their
    1 mm resolution (float32, 1e-6): mirrored, ray i points (i + 0.5)·fov/818 − fov/2 from its facing, counted
    anticlockwise seen from above, so the front one sweeps from due west (3.359 m) round by south and east to due north (6.62 m), the rear
    one from due east (12.191 m) round by north and west (2.809 m, ray 542) to due south (8.746 m)."""
    sim = Simulation(load_world(omni_world(tmp_path)), "exact")
    for name in OMNI_LIDARS:
        sim.device(f"{OMNI_NAME}/{name}").enable(32)
    sim.step()
    ends = {}
    for name in OMNI_LIDARS:
        got = np.asarray(sim.device(f"{OMNI_NAME}/{name}").range_image, dtype=float).reshape(-1)
        want = omni_lidar_closed_form(name, -4.416, 1.063)
        assert got == pytest.approx(want, abs=1e-6), name
        ends[name] = (got[0], got[-1], int(np.argmin(got)), got.min())
    # upside down, ray 0 (135° left in its own frame) points 135° right of where the lidar faces: the front
    # one's west (3.359 m to the wall at x −7.5), its last north (6.62 m); the rear one's east and south
    assert ends["base_front_laser"] == pytest.approx((3.359, 6.62, 0, 3.359), abs=1e-6)
    assert ends["base_rear_laser"] == pytest.approx((12.191, 8.746, 542, 2.809), abs=1e-6)
