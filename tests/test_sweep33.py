"""Sweep 33: Webots `projects/robots` worlds not run before, each on a stand-in world of ours
(tests/data/sweep33/: the PROTOs' device names, places, joints and bounding objects, our own text, meshes left
out) driven in process by the calls its controller makes and checked against closed forms, and under
``sensorium run`` by a controller of ours compiled against Sensorium's libController."""

from __future__ import annotations

import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from _serve import REPO, child_env, sensorium
from test_sweep31 import (
    CRATE,
    CRUISING_SPEED,
    FAR_OBSTACLE_THRESHOLD,
    FAST_DECREASE_FACTOR,
    HOKUYO,
    HOKUYO_RAYS,
    MAX_SPEED,
    N_SECTOR,
    NEAR_OBSTACLE_THRESHOLD,
    SLOW_DECREASE_FACTOR,
    UNUSED_POINT,
    diff_arc,
    hokuyo_closed_form,
    yaw_of,
)

from sensorium.server.sim import viewshot
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data" / "sweep33"
CLIB = REPO / "sensorium" / "client" / "c"

# ------------------------------------------------------------------------------------ TIAGo LITE
# tiago_lite (pal_robotics/tiago_lite, R2023b): the TIAGo LITE (TiagoBase with the TiagoBody, the Hokuyo in the
# lidar slot, the camera slot empty) at (−4.416, 1.063, 0.095) facing +x; TiagoBase's origin is 0.095 m above the
# floor, its lidar slot at (0.202, 0, −0.004): the lidar 0.091 m above the wheels' bottom, as the PMB-2 base's
# of sweep 31, and the same wheels and drive. The world's basicTimeStep is Webots' default 32 ms.
LITE = DATA / "tiago_lite.wbt"
LITE_NAME = "TIAGo LITE"
LITE_Z = 0.0985                 # the origin on the wheels' axle, 0.0985 m up: 3.5 mm above the world's 0.095
LITE_STEP = 32
USED = slice(UNUSED_POINT, HOKUYO_RAYS - UNUSED_POINT)


def test_the_tiago_lite_loads_with_the_bases_devices_and_no_astra_camera() -> None:
    """The stand-in loads with the arena's stand-in line only, its model PAL's, a two-wheel drive on the base's
    wheels (radius 0.0985 m, Solids 0.404 m apart), and the base's devices with the Hokuyo of the lidar slot's
    default: no "Astra rgb" or "Astra depth" (the camera slot is empty in the sample, which the controller's
    look-ups find out). It settles 3.5 mm up onto its wheels, its origin 0.0985 m above the floor."""
    w = load_world(LITE)
    assert len(w.warnings) == 1 and "built-in stand-ins used for RectangleArena" in w.warnings[0], w.warnings
    (robot,) = w.world.robots
    assert (robot.name, robot.model, robot.controller) == (LITE_NAME, "PAL Robotics - TIAGo LITE", "tiago_lite")
    names = [d.name for d in robot.devices]
    assert names[0] == HOKUYO and "Astra rgb" not in names and "Astra depth" not in names
    dd = robot.differential_drive
    assert (dd.wheel_radius, dd.axle_length, dd.left_motor, dd.right_motor) == (0.0985, 0.404, "wheel_left_joint",
                                                                                "wheel_right_joint")
    sim = Simulation(w, "exact")
    assert "its origin's z from 0.0950 to 0.0985 m" in w.warnings[-1]
    assert list(sim.robot(LITE_NAME).pose.translation) == pytest.approx([-4.416, 1.063, LITE_Z], abs=1e-12)


def braitenberg_in_c(values, width: int, max_range: float) -> tuple[float, float, bool]:
    """tiago_lite.c's loop body with its C arithmetic (tiago_pmb2_base.c's rule, sweep 31's
    ``braitenberg_pmb2`` in double): the range image and the max range are floats, so a ray counts below the
    float max range halved (2.7999999523) and weighs ``1.0 - values[i] / max_range`` with the division in
    float32; the wheel speeds it sets and whether it makes its extra wb_robot_step(1)."""
    f32 = np.float32
    rng = f32(max_range)
    size = int((width - 2.0 * UNUSED_POINT - 1.0) / N_SECTOR)
    bound = [UNUSED_POINT + (k + 1) * size for k in range(N_SECTOR)]
    s = [0.0] * N_SECTOR                           # left, front left, front, front right, right
    for i in range(UNUSED_POINT, width - UNUSED_POINT - 1):
        v = f32(values[i])
        if float(v) < float(rng) / 2.0:
            w = 1.0 - float(v / rng)
            k = next(k for k in range(N_SECTOR) if i < bound[k] + (k == N_SECTOR - 1))
            s[k] += w
    left, front_left, front, front_right, right = (x / size for x in s)
    if left > right and left > NEAR_OBSTACLE_THRESHOLD:
        f = (1.0 - FAST_DECREASE_FACTOR * left) * MAX_SPEED / left
        return min(f * left, MAX_SPEED), min(f * right, MAX_SPEED), False
    if front_left > front_right and front_left > FAR_OBSTACLE_THRESHOLD:
        f = (1.0 - SLOW_DECREASE_FACTOR * front_left) * MAX_SPEED / front_left
        return min(f * front_left, MAX_SPEED), min(f * front_right, MAX_SPEED), False
    if front_right > front_left and front_right > FAR_OBSTACLE_THRESHOLD:
        f = (1.0 - SLOW_DECREASE_FACTOR * front_right) * MAX_SPEED / front_right
        return min(f * front_left, MAX_SPEED), min(f * front_right, MAX_SPEED), False
    if right > left and right > NEAR_OBSTACLE_THRESHOLD:
        f = (1.0 - FAST_DECREASE_FACTOR * right) * MAX_SPEED / right
        return min(f * left, MAX_SPEED), min(f * right, MAX_SPEED), False
    if front > NEAR_OBSTACLE_THRESHOLD:
        f = (1.0 - FAST_DECREASE_FACTOR * front) * MAX_SPEED / front
        if front_right > front_left or right > left:
            return -min(f * front, MAX_SPEED), min(f * front, MAX_SPEED), True
        return min(f * front, MAX_SPEED), -min(f * front, MAX_SPEED), True
    return CRUISING_SPEED, CRUISING_SPEED, False


def run_lite(until_ms: int) -> tuple[tuple[float, float, float], list]:
    """tiago_lite.c's calls in process until ``until_ms`` (its loop is tiago_pmb2_base.c's: the Hokuyo's five
    sectors, the Braitenberg rule), every step checking the range image against the closed form at the robot's
    pose (1e-5) and the pose against the two-wheel arcs of the speeds set (1e-9); the final (x, y, heading) and
    each control step's (time, left, right, extra step)."""
    sim = Simulation(load_world(LITE), "exact")
    robot = sim.robot(LITE_NAME)
    lidar = sim.device(f"{LITE_NAME}/{HOKUYO}")
    lidar.enable(LITE_STEP)
    left, right = robot.motor("wheel_left_joint"), robot.motor("wheel_right_joint")
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(0.0)
    x, y, h = -4.416, 1.063, 0.0
    wl = wr = 0.0
    dt = LITE_STEP / 1000.0
    rows = []
    t = 0
    while t < until_ms:
        sim.step()
        t += LITE_STEP
        x, y, h = diff_arc(x, y, h, wl, wr, dt)
        pose = robot.pose
        assert [*pose.translation, yaw_of(pose)] == pytest.approx([x, y, LITE_Z, h], abs=1e-9), t
        got = np.asarray(lidar.range_image, dtype=float).reshape(-1)
        want = hokuyo_closed_form(x, y, h, CRATE)
        assert np.array_equal(np.isinf(got[USED]), np.isinf(want[USED])), t
        hit = np.isfinite(want[USED])
        assert got[USED][hit] == pytest.approx(want[USED][hit], abs=1e-5), t
        new_wl, new_wr, extra = braitenberg_in_c(got, HOKUYO_RAYS, lidar.info()["maxRange"])
        if extra:
            sim.step()
            t += LITE_STEP
            x, y, h = diff_arc(x, y, h, wl, wr, dt)
        wl, wr = new_wl, new_wr
        rows.append((t, wl, wr, extra))
        left.set_velocity(wl)
        right.set_velocity(wr)
    return (x, y, h), rows


def test_tiago_lite_calls_drive_to_the_box_and_turn_away_on_closed_form_arcs() -> None:
    """tiago_lite.c's calls for 12 s: each step the Hokuyo's image is the closed form's at the robot's pose
    (1e-5) and the robot on the two-wheel arc of the speeds the rule set (1e-9), 0.0985 m up throughout. The
    lidar sits where the PMB-2 base's does (0.202 m ahead, 0.091 m above the wheels' bottom), the body above
    its plane, so the run is sweep 31's (its speeds within 1e-9, the C rule dividing in float32): cruising at
    3 rad/s until 8.8 s, 43 steps pivoting left about the stopped left wheel (the right one from 5.113733 rad/s)
    to 10.208 s, at (−1.339437, 1.576264) heading 0.938508 rad at 12 s."""
    (x, y, h), rows = run_lite(12000)
    turning = [r for r in rows if r[1:3] != (CRUISING_SPEED, CRUISING_SPEED)]
    assert (len(turning), turning[0][0], turning[-1][0]) == (43, 8800, 10208)
    assert all(r[1] == 0.0 and 1.37 < r[2] < 5.12 for r in turning) and not any(r[3] for r in rows)
    assert turning[0][2] == pytest.approx(5.113733, abs=1e-6)
    assert (x, y, h) == pytest.approx((-1.339437, 1.576264, 0.938508), abs=1e-6)


# our own C making tiago_lite.c's calls in its order, the "Astra" look-ups and enables included (only the prints
# are the test's)
LITE_CONTROLLER = r"""/* Sensorium's stand-in for tiago_lite.c (sweep 33): our own C making its calls in its order. */
#include <math.h>
#include <stdio.h>
#include <webots/camera.h>
#include <webots/lidar.h>
#include <webots/motor.h>
#include <webots/range_finder.h>
#include <webots/robot.h>

#define MAX_SPEED 6.4
#define UNUSED_POINT 83
#define N_SECTOR 5

static double capped(double s) { return s > MAX_SPEED ? MAX_SPEED : s; }

int main(void) {
  wb_robot_init();
  const int step = (int)wb_robot_get_basic_time_step();
  WbDeviceTag lidar = wb_robot_get_device("Hokuyo URG-04LX-UG01");
  WbDeviceTag left_wheel = wb_robot_get_device("wheel_left_joint");
  WbDeviceTag right_wheel = wb_robot_get_device("wheel_right_joint");
  WbDeviceTag rgb = wb_robot_get_device("Astra rgb");
  WbDeviceTag depth = wb_robot_get_device("Astra depth");
  wb_camera_enable(rgb, step);
  wb_range_finder_enable(depth, step);
  wb_lidar_enable(lidar, step);
  const int width = wb_lidar_get_horizontal_resolution(lidar);
  const int size = (width - 2.0 * UNUSED_POINT - 1.0) / N_SECTOR;
  int bound[N_SECTOR];
  for (int k = 0; k < N_SECTOR; ++k)
    bound[k] = UNUSED_POINT + (k + 1) * size;
  const float max_range = wb_lidar_get_max_range(lidar);
  const double threshold = max_range / 2.0;
  wb_motor_set_position(left_wheel, INFINITY);
  wb_motor_set_position(right_wheel, INFINITY);
  wb_motor_set_velocity(left_wheel, 0.0);
  wb_motor_set_velocity(right_wheel, 0.0);
  while (wb_robot_step(step) != -1) {
    const float *r = wb_lidar_get_range_image(lidar);
    double s[N_SECTOR] = {0.0, 0.0, 0.0, 0.0, 0.0};  /* left, front left, front, front right, right */
    for (int i = UNUSED_POINT; i < width - UNUSED_POINT - 1; ++i) {
      if (r[i] >= threshold)
        continue;
      const double w = 1.0 - r[i] / max_range;
      if (i < bound[0])
        s[0] += w;
      if (bound[0] <= i && i < bound[1])
        s[1] += w;
      if (bound[1] <= i && i < bound[2])
        s[2] += w;
      if (bound[2] <= i && i < bound[3])
        s[3] += w;
      if (bound[3] <= i && i < bound[4] + 1)
        s[4] += w;
    }
    for (int k = 0; k < N_SECTOR; ++k)
      s[k] /= size;
    double ls = 3.0, rs = 3.0, f;
    int extra = 0;
    if (s[0] > s[4] && s[0] > 0.7) {
      f = (1.0 - 0.9 * s[0]) * MAX_SPEED / s[0];
      ls = capped(f * s[0]);
      rs = capped(f * s[4]);
    } else if (s[1] > s[3] && s[1] > 0.4) {
      f = (1.0 - 0.5 * s[1]) * MAX_SPEED / s[1];
      ls = capped(f * s[1]);
      rs = capped(f * s[3]);
    } else if (s[3] > s[1] && s[3] > 0.4) {
      f = (1.0 - 0.5 * s[3]) * MAX_SPEED / s[3];
      ls = capped(f * s[1]);
      rs = capped(f * s[3]);
    } else if (s[4] > s[0] && s[4] > 0.7) {
      f = (1.0 - 0.9 * s[4]) * MAX_SPEED / s[4];
      ls = capped(f * s[0]);
      rs = capped(f * s[4]);
    } else if (s[2] > 0.7) {
      f = (1.0 - 0.9 * s[2]) * MAX_SPEED / s[2];
      if (s[3] > s[1] || s[4] > s[0]) {
        ls = -capped(f * s[2]);
        rs = capped(f * s[2]);
      } else {
        ls = capped(f * s[2]);
        rs = -capped(f * s[2]);
      }
      wb_robot_step(1);
      extra = 1;
    }
    wb_motor_set_velocity(left_wheel, ls);
    wb_motor_set_velocity(right_wheel, rs);
    printf("%d %.17g %.17g %d\n", (int)lround(wb_robot_get_time() * 1000), ls, rs, extra);
    fflush(stdout);
  }
  wb_robot_cleanup();
  return 0;
}
"""


@pytest.mark.slow
def test_tiago_lite_calls_in_c_under_sensorium_run_set_the_in_process_speeds(tmp_path: Path) -> None:
    """Our C controller making tiago_lite.c's calls, compiled against Sensorium's libController, under
    ``sensorium run`` for 12 s: each look-up of the empty camera slot's "Astra rgb" and "Astra depth" is one
    warning and each enable of their tag 0 one error line, as in Webots, and the controller runs on; every
    control step sets exactly the speeds the in-process run's closed-form-checked steps set, at the same
    times (375 steps)."""
    if shutil.which("cc") is None or shutil.which("make") is None:
        pytest.skip("needs a C toolchain (build-essential, libzmq3-dev, libmsgpack-dev, libpng-dev, libjpeg-dev)")
    build = tmp_path / "cbuild"
    done = subprocess.run(["make", "-s", "-C", str(CLIB), f"BUILD={build}"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    libs = subprocess.run(["make", "-s", "-C", str(CLIB), "libs"], capture_output=True, text=True, timeout=60).stdout.split()
    (tmp_path / "worlds").mkdir()
    shutil.copytree(DATA / "protos", tmp_path / "worlds" / "protos")
    world = tmp_path / "worlds" / "tiago_lite.wbt"
    shutil.copy(LITE, world)
    folder = tmp_path / "controllers" / "tiago_lite"
    folder.mkdir(parents=True)
    (folder / "tiago_lite.c").write_text(LITE_CONTROLLER)
    done = subprocess.run(["cc", "-std=c99", "-Wall", "-Werror", f"-I{CLIB / 'include'}", str(folder / "tiago_lite.c"),
                           "-o", str(folder / "tiago_lite"), str(build / "libController.a"), *libs, "-lm"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    done = subprocess.run(sensorium("run", str(world), "--until", "12000", "--rpc", "tcp://127.0.0.1:0",
                                    "--pub", "tcp://127.0.0.1:0"),
                          env=child_env(), cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    for name in ("Astra rgb", "Astra depth"):
        assert done.stderr.count(f'has no device "{name}"') == 1, done.stderr
    for func in ("wb_camera_enable", "wb_range_finder_enable"):
        assert done.stderr.count(f"Error: {func}(): invalid device tag 0") == 1, done.stderr
    rows = [line.split("] ", 1)[1].split() for line in done.stdout.splitlines()
            if line.startswith(f"[{LITE_NAME}] ")]
    _, want = run_lite(12000)
    got = [(int(r[0]), float(r[1]), float(r[2]), r[3] == "1") for r in rows]
    assert len(got) == 375 and got == want


VIEW_AT = (-6.55, 0.74, 0.6)          # our Viewpoint's written position
LITE_AT = (-4.416, 1.063, 0.095)      # the robot's translation in the world file


def test_the_viewpoint_follows_the_tiago_lite_as_it_drives() -> None:
    """The sample's Viewpoint follows "TIAGo LITE" with followSmoothness 0 (Webots' "Tracking Shot" at once):
    after every step its position is the written one moved by the robot's displacement from its place in
    the world file (1e-12), so the load's 3.5 mm settling lifts it on the first step, and driven straight at
    3 rad/s for 6.4 s, then on an arc left (left wheel 1 rad/s), the robot takes it 2.0526 m east and 0.7744 m
    north by 12 s, its orientation as written; pictures and movies are made from there
    (viewshot.viewpoint_of) and a Supervisor reads it. A reset puts the written position back and the view
    follows again from the world file's places (the settling counted again, as Webots' physics drops the
    robot again). Sensorium kept the Viewpoint where the file put it."""
    sim = Simulation(load_world(LITE), "exact")
    vp = next(s for s in sim.top_level.scenery if s.type == "Viewpoint")
    robot = sim.robot(LITE_NAME)
    for m in (robot.motor("wheel_left_joint"), robot.motor("wheel_right_joint")):
        m.set_position(math.inf)
        m.set_velocity(3.0)
    assert tuple(viewshot.viewpoint_of(sim).position) == VIEW_AT
    for k in range(375):
        if k == 200:
            robot.motor("wheel_left_joint").set_velocity(1.0)
        sim.step()
        at = robot.pose.translation
        want = [v + (a - b) for v, a, b in zip(VIEW_AT, at, LITE_AT)]
        assert vp.fields["position"] == pytest.approx(want, abs=1e-12), k
    assert list(viewshot.viewpoint_of(sim).position) == pytest.approx(want, abs=1e-12)
    assert vp.fields["orientation"] == [0.04, -0.37, -0.93, 6.04]
    assert [w - v for w, v in zip(want, VIEW_AT)] == pytest.approx([2.052571, 0.774372, 0.0035], abs=1e-6)
    assert (want[0] - VIEW_AT[0], want[1] - VIEW_AT[1], want[2] - VIEW_AT[2]) == pytest.approx(
        (at[0] - LITE_AT[0], at[1] - LITE_AT[1], 0.0035), abs=1e-12)
    sim.reset()
    assert vp.fields["position"] == list(VIEW_AT)
    for m in (robot.motor("wheel_left_joint"), robot.motor("wheel_right_joint")):
        m.set_position(math.inf)
        m.set_velocity(3.0)
    sim.step()
    moved = [a - b for a, b in zip(robot.pose.translation, LITE_AT)]
    assert moved == pytest.approx([3.0 * 0.0985 * 0.032, 0.0, 0.0035], abs=1e-12)
    assert vp.fields["position"] == pytest.approx([v + d for v, d in zip(VIEW_AT, moved)], abs=1e-12)


@pytest.mark.parametrize(("fields", "line"), [
    ('follow "nobody"', "Viewpoint follow 'nobody': no robot or top-level solid has that name; the view stays"),
    ('follow "TIAGo LITE" followType "Mounted Shot"',
     "Viewpoint followType 'Mounted Shot' is not followed (only 'Tracking Shot'); the view stays")])
def test_a_viewpoint_that_cannot_follow_is_one_line_and_stays(tmp_path: Path, fields: str, line: str) -> None:
    world = tmp_path / "stays.wbt"
    world.write_text(LITE.read_text().replace("protos/", f"{DATA}/protos/")
                     .replace('follow "TIAGo LITE"', fields))
    loaded = load_world(world)
    sim = Simulation(loaded, "exact")
    assert sum(line in w for w in loaded.warnings) == 1, loaded.warnings
    for m in (sim.robot(LITE_NAME).motor("wheel_left_joint"), sim.robot(LITE_NAME).motor("wheel_right_joint")):
        m.set_position(math.inf)
        m.set_velocity(3.0)
    for _ in range(10):
        sim.step()
    vp = next(s for s in sim.top_level.scenery if s.type == "Viewpoint")
    assert vp.fields["position"] == list(VIEW_AT)


def test_an_astra_in_the_camera_slot_reads_the_floor_and_the_box_by_their_closed_forms() -> None:
    """With an Astra in the camera slot (tiago_lite.c enables its "Astra rgb" and "Astra depth" when the slot
    holds one; the slot 0.6 m above the torso's origin is our place) the depth camera, 640 × 480 over 1.04 rad
    from 0.6 to 8 m at (−4.45, 1.1, 0.8985) looking along +x, reads each pixel's planar depth (its ray
    through (col + ½, row + ½) of the pinhole f = 320/tan 0.52) to the floor, our box's west face
    (3.55 m: 8930 pixels) or its top (613), float32 (3e-7), and inf where that is beyond 8 m (the walls are
    11.95 m away) or the ray rises: 191,787 pixels, every one where the closed form puts it."""
    sim = Simulation(load_world(DATA / "tiago_lite_astra.wbt"), "exact")
    depth = sim.device(f"{LITE_NAME}/Astra depth")
    assert (sim.device(f"{LITE_NAME}/Astra rgb").kind, depth.kind) == ("Camera", "RangeFinder")
    depth.enable(LITE_STEP)
    sim.step()
    got = np.asarray(depth.range_image, dtype=float).reshape(480, 640)
    f = 320.0 / math.tan(0.52)
    eye = (-4.416 - 0.054 + 0.02, 1.063 + 0.037, LITE_Z + 0.193 + 0.6 + 0.007)
    left = -(np.arange(640) + 0.5 - 320.0) / f          # each column's ray: (1, left, −down) per metre ahead
    down = (np.arange(480) + 0.5 - 240.0) / f
    left, down = np.meshgrid(left, down)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(down > 0, eye[2] / down, np.inf)                       # the floor
        ahead = -0.9 - eye[0]                                               # the box's west face, x = −0.9
        y, z = eye[1] + ahead * left, eye[2] - ahead * down
        face = (y >= 0.563) & (y <= 1.163) & (z >= 0.0) & (z <= 0.6)
        t = np.where(face, np.minimum(t, ahead), t)
        over = np.where(down > 0, (eye[2] - 0.6) / down, np.inf)           # its top, z = 0.6
        x, y = eye[0] + over, eye[1] + over * left
        top = (x >= -0.9) & (x <= -0.3) & (y >= 0.563) & (y <= 1.163)
        t = np.where(top, np.minimum(t, over), t)
    want = np.where((t >= 0.6) & (t < 8.0), t, np.inf)
    assert (int(face.sum()), int(top.sum()), int(np.isinf(want).sum())) == (8930, 613, 191787)
    assert np.array_equal(np.isinf(got), np.isinf(want))
    seen = np.isfinite(want)
    assert got[seen] == pytest.approx(want[seen], abs=3e-7)
