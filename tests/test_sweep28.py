"""Sweep 28: Webots' ``projects/samples`` worlds not run before, each on a stand-in world of ours
(tests/data/sweep28/: the sample's poses, sizes, joints and devices, our own text, PROTO meshes and textures
left out) driven in process by the calls its controllers make and checked against closed forms."""

from __future__ import annotations

import math
import subprocess
from pathlib import Path

import numpy as np
import pytest
from test_display import midpoint_oval
from test_supervisor import A, Live
from test_sweep18 import REPO
from test_sweep18 import clib as built_library  # noqa: F401 - a fixture: our libController, built once
from test_sweep19 import KinematicMotor

from sensorium.client import wb
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data" / "sweep28"

# ------------------------------------------------------------------------------------------------ muscle
# muscle (projects/samples/geometries, R2023b): three robots running the same `muscle` controller, 16 ms
# steps: "hinge" (a HingeJoint about −y, its motor "muscle" maxTorque 0.5, two Muscle nodes), "hinge2" (a
# Hinge2Joint, "muscle" and "muscle2", maxTorque 0.5 each) and "slider" (a SliderJoint along x, its
# LinearMotor "muscle" maxForce 0.3). Each step the controller asks its motor for p, then reads the position
# sensor: at or below 0 it heads up, at or above `max` (2 rad; 0.08 m for the slider) down, p being the
# reading plus or minus `step` (0.4 rad; 0.05 m); hinge2's second motor is asked 2 − p.
MUSCLE_DT = 0.016
MUSCLE_ROBOTS = {"hinge": (2.0, 0.4, 0.5), "hinge2": (2.0, 0.4, 0.5), "slider": (0.08, 0.05, 0.3)}


def test_the_muscle_robots_load_with_their_motors_and_sensors_and_stand_where_the_world_puts_them() -> None:
    """The three robots load with the devices the controller asks for (the sensors' default name "position
    sensor", hinge2's "position sensor2"), each motorised joint said once (it moves kinematically); the
    Muscle nodes, which Webots draws and stretches with the joint, are no device and need no line. No
    robot has wheels, so each keeps the world's pose: hinge2's base box (its bottom 0.04 m below the origin
    at z 0.035) stays 5 mm into the floor, where Webots' physics would push it out (only wheels settle a
    robot: README "Settling on the ground")."""
    w = load_world(DATA / "muscle.wbt")
    assert len(w.warnings) == 4
    assert sum("motor 'muscle'" in x and "moves kinematically" in x for x in w.warnings) == 3
    assert sum("motor 'muscle2'" in x for x in w.warnings) == 1
    devices = {r.name: {(d.name, type(d).__name__) for d in r.devices} for r in w.world.robots}
    assert devices == {
        "hinge": {("muscle", "RotationalMotor"), ("position sensor", "PositionSensor")},
        "hinge2": {("muscle", "RotationalMotor"), ("position sensor", "PositionSensor"),
                   ("muscle2", "RotationalMotor"), ("position sensor2", "PositionSensor")},
        "slider": {("muscle", "LinearMotor"), ("position sensor", "PositionSensor")}}
    sim = Simulation(w, "exact")
    for name, at in (("hinge", (0, 0, 0.04)), ("hinge2", (0.07, 0.17, 0.035)), ("slider", (-0.01, -0.21, 0.04))):
        assert list(sim.robot(name).pose.translation) == pytest.approx(at, abs=1e-15)


def test_the_muscle_controller_swings_each_joint_between_its_bounds_by_the_kinematic_rule() -> None:
    """muscle.c's calls in process for 800 steps (12.8 s): each motor follows Webots' kinematic rule with
    its own acceleration, the available torque or force (0.5 rad/s², 0.3 m/s²: `acceleration` is −1), its
    target always `step` ahead, so its speed grows 0.008 rad/s (0.0048 m/s) a step and never drops when the
    target flips behind it: the hinge covers 2 rad in about √(2·2/0.5) = 2.83 s (its first reading at or
    over 2, 2.016384 rad, at step 178), then swings back faster each half-period. Every reading is the
    closed form's (1e-12); hinge2's second motor, asked 2 − p, mirrors the first about 1 (1e-12)."""
    sim = Simulation(load_world(DATA / "muscle.wbt"), "exact")
    assert sim.basic_time_step == 16
    robots, twins, sensors, state = {}, {}, {}, {}
    for name, (_, step, accel) in MUSCLE_ROBOTS.items():
        robots[name] = sim.robot(name)
        twins[name] = [KinematicMotor(10.0, accel)] + ([KinematicMotor(10.0, accel)] if name == "hinge2" else [])
        sensors[name] = sim.device(f"{name}/position sensor")
        sensors[name].enable(16)
        state[name] = [0.0, step]                 # p, dp
    second = sim.device("hinge2/position sensor2")
    second.enable(16)
    first_top = None
    for k in range(1, 801):
        for name, (p, _) in state.items():
            robots[name].motor("muscle").set_position(p)
            twins[name][0].target = p
            if name == "hinge2":
                robots[name].motor("muscle2").set_position(2.0 - p)
                twins[name][1].target = 2.0 - p
        sim.step()
        for name, (top, step, _) in MUSCLE_ROBOTS.items():
            for twin in twins[name]:
                twin.step(MUSCLE_DT)
            pos = sensors[name].value
            assert pos == pytest.approx(twins[name][0].x, abs=1e-12), (k, name)
            if pos <= 0.0:
                state[name][1] = -step
            elif pos >= top:
                state[name][1] = step
                if name == "hinge" and first_top is None:
                    first_top = (k, pos)
            state[name][0] = pos - state[name][1]
        assert second.value == pytest.approx(twins["hinge2"][1].x, abs=1e-12), k
    # the first half-swing: after k steps the speed is 0.008·(k−1) rad/s and the angle 0.5·0.016²·k(k−1)/2,
    # 1.99373 after 177 steps, 2.016384 after 178
    assert first_top == (178, pytest.approx(0.5 * MUSCLE_DT ** 2 * 178 * 177 / 2, abs=1e-12))
    assert 0.5 * MUSCLE_DT ** 2 * 177 * 176 / 2 < 2.0
    assert twins["hinge"][0].speed == pytest.approx(0.5 * 799 * MUSCLE_DT, abs=1e-9)   # never reset: 6.392 rad/s


# ----------------------------------------------------------------------------------------------- display
# display (projects/samples/devices, R2025a): MyBot runs `display` (64 ms: its camera 256 × 128 shown on its
# "camera_display" with a yellow frame around the yellow blob; an emoticon pasted every 30 steps; two
# distance sensors; wheels at 4 rad/s plus a random part, here 0: rand() % 4 − 2 taken as 0, so it drives
# straight), the supervisor runs `display_supervisor` (64 ms: the 64 × 64 "ground_display" lying on the 1 m
# floor, grey, a red and a green axis, then each step a 4-pixel blue oval at opacity 0.03 where MYBOT's
# translation field puts it; an image copy every 50 steps). The world's basicTimeStep is Webots' default, 32.
BOT0 = np.array([0.202001, 0.131552])
BOT_YAW = 3.63077
BOT_SPEED = 4.0 * 0.025                       # 4 rad/s on wheels of radius 0.025 m
FOCAL = 128 / math.tan(1.047 / 2)             # the camera's focal length in pixels (256 wide)
BOX4 = np.array([(-0.284296 + sx * 0.04, -0.253659 + sy * 0.075, z)
                 for sx in (-1, 1) for sy in (-1, 1) for z in (0.0, 0.1)])
GROUND = 64
LIGHT_GRAY, RED, GREEN, BLUE = 0x505050, 0xBB2222, 0x22BB11, 0x2222BB


def draw(display, *commands) -> None:
    """What a step request's ``displays`` entry does to the display (services.Core._draw)."""
    display.apply(display.check([list(c) for c in commands]), 0)


def blob_box(at: np.ndarray) -> tuple[float, float, float, float]:
    """The box 4's silhouette in the camera of MyBot at ``at`` (heading BOT_YAW): the extremes of its
    corners' pinhole projections, in pixels (u right, v down; the camera 0.04 m ahead, 0.0915 m up)."""
    c, s = math.cos(BOT_YAW), math.sin(BOT_YAW)
    d = BOX4 - np.array([at[0] + 0.04 * c, at[1] + 0.04 * s, 0.0915])
    ahead, left = d[:, 0] * c + d[:, 1] * s, -d[:, 0] * s + d[:, 1] * c
    u, v = 128 - FOCAL * left / ahead, 64 - FOCAL * d[:, 2] / ahead
    return float(u.min()), float(v.min()), float(u.max()), float(v.max())


def box_distance(at: np.ndarray) -> float:
    """The floor distance from ``at`` to box 4 (0.08 × 0.15 m, not turned)."""
    dx = max(abs(float(at[0]) + 0.284296) - 0.04, 0.0)
    dy = max(abs(float(at[1]) + 0.253659) - 0.075, 0.0)
    return math.hypot(dx, dy)


def blended(old: int, colour: int, opacity: int) -> int:
    """WbDisplay's blend of one opaque pixel: each channel ((255 − o)·old + o·colour) // 255."""
    out = 0xFF000000
    for shift in (16, 8, 0):
        out |= (((255 - opacity) * ((old >> shift) & 255) + opacity * ((colour >> shift) & 255)) // 255) << shift
    return out


def filled_oval(cx: int, cy: int, r: int) -> set[tuple[int, int]]:
    """A filled oval's pixels: each row of WbDisplay's outline loop spanned from its first to last pixel."""
    rows: dict[int, list[int]] = {}
    for x, y in midpoint_oval(cx, cy, r, r):
        rows.setdefault(y, []).append(x)
    return {(x, y) for y, xs in rows.items() for x in range(min(xs), max(xs) + 1)}


def test_the_display_world_loads_with_the_sizes_the_controllers_assert() -> None:
    """The stand-in loads without a line; MyBot's two wheels are its drive; display.c's asserts hold (the
    camera display is the camera's 256 × 128), the emoticon display is 14 × 14 and the ground display
    Webots' default 64 × 64."""
    w = load_world(DATA / "display.wbt")
    assert w.warnings == []
    sim = Simulation(w, "exact")
    assert w.warnings == [] and sim.basic_time_step == 32
    cam, shown = sim.device("MyBot/camera"), sim.device("MyBot/camera_display")
    assert (cam.config.width, cam.config.height) == (256, 128) == (shown.width, shown.height)
    assert (sim.device("MyBot/emoticon_display").width, sim.device("MyBot/emoticon_display").height) == (14, 14)
    ground = sim.device("supervisor/ground_display")
    assert (ground.width, ground.height) == (GROUND, GROUND)
    assert {d.name for d in w.world.robots[0].devices} >= {"ds0", "ds1", "left wheel motor", "right wheel motor"}


def test_the_display_controllers_frame_the_yellow_box_and_trace_the_robot_by_the_closed_form(tmp_path: Path) -> None:
    """Both controllers' calls for 3 s (47 steps of 64 ms). MyBot drives straight along its heading at
    0.1 m/s (its pose the closed form's, 1e-12); its distance sensors read 0, nothing within their 0.15 m
    table (to 3.4·10⁻¹³: the four rays' weighted sum of 0.15 m is 0.14999999999999997 m, in Webots' order
    of sums too). Its camera sees only box 4 yellow, and
    display.c's yellow test (r, g > 80, b < 40, |r − g| < 5) finds the pixels whose centres the box's
    silhouette holds: the corners' projections' extremes, clipped to the image, give the frame's left,
    top and right (exact) and its bottom within one pixel (the nearest bottom corner is a V's tip a pixel
    centre may miss); the camera display shows the yellow frame over the camera's image. The supervisor
    reads MYBOT's translation through its field (the closed form, 1e-12) and draws each oval where C's
    truncation puts it: every ground pixel is the closed form's (integer blends at opacity 0.03, the byte
    7, over the grey and the two axes); its image copy at step 50 is not reached (3 s), the one asked at
    step 47 is the display's pixels."""
    sim = Simulation(load_world(DATA / "display.wbt"), "exact")
    lv = Live(sim)
    lv.ok(A, "attach", {"robot": "supervisor"})
    bot = sim.robot("MyBot")
    cam, ds = sim.device("MyBot/camera"), [sim.device("MyBot/ds0"), sim.device("MyBot/ds1")]
    for d in (cam, *ds):
        d.enable(64)
    shown, ground = sim.device("MyBot/camera_display"), sim.device("supervisor/ground_display")
    for m in ("left wheel motor", "right wheel motor"):
        bot.motor(m).set_position(math.inf)
        bot.motor(m).set_velocity(0.0)
    draw(shown, ["attach", "camera"], ["color", 0xFFFF00])
    node = lv.ok(A, "/supervisor/robot/get_from_def", {"name": "MYBOT"})["node"]
    # the ground display's background, as display_supervisor.c paints it
    draw(ground, ["color", LIGHT_GRAY], ["rectangle", 0, 0, GROUND, GROUND, True], ["color", RED],
         ["line", GROUND // 2, 0, GROUND // 2, GROUND - 1], ["color", GREEN], ["line", 0, GROUND // 2, GROUND - 1, GROUND // 2])
    want = np.full((GROUND, GROUND), 0xFF000000 | LIGHT_GRAY, dtype=np.int64)
    want[:, GROUND // 2] = 0xFF000000 | RED
    want[GROUND // 2, :] = 0xFF000000 | GREEN
    assert (ground.pixels == want).all()
    heading = np.array([math.cos(BOT_YAW), math.sin(BOT_YAW)])
    for k in range(1, 48):
        for _ in range(2):                              # 64 ms: two basic steps
            sim.step()
        t = sim.time_ms / 1000.0
        # MyBot's calls: the readings, then the wheels (the first step's readings come with speeds 0)
        for m in ("left wheel motor", "right wheel motor"):
            bot.motor(m).set_velocity(4.0)
        at = BOT0 + BOT_SPEED * max(t - 0.064, 0.0) * heading
        got = lv.ok(A, "/supervisor/robot/get_field", {"node": node, "field": "translation"})["value"]
        assert got == pytest.approx([*at, 0.0], abs=1e-12), k
        assert [d.value for d in ds] == pytest.approx([0.0, 0.0], abs=1e-12), k
        image = np.asarray(cam.image)
        b, g, r = (image[..., i].astype(int) for i in range(3))
        ys, xs = np.nonzero((r > 80) & (g > 80) & (b < 40) & (abs(r - g) < 5))
        u0, v0, u1, v1 = blob_box(at)
        assert (xs.min(), ys.min(), xs.max()) == (max(math.ceil(u0 - 0.5), 0), max(math.ceil(v0 - 0.5), 0),
                                                  min(math.ceil(u1 - 0.5) - 1, 255)), k
        assert min(math.ceil(v1 - 0.5) - 1, 127) - ys.max() in (0, 1), k
        x0, y0, x1, y1 = int(xs.min()), int(ys.min()), int(xs.max()), int(ys.max())
        draw(shown, ["alpha", 0.0], ["rectangle", 0, 0, 256, 128, True], ["alpha", 1.0],
             ["rectangle", x0, y0, x1 - x0, y1 - y0, False])
        seen = shown.composed()
        assert int(seen[y0, x0]) == int(seen[y1 - 1, x1 - 1]) == 0xFFFFFF00, k      # the frame: width x1 − x0 from x0
        inside = image[y0 + 1, x0 + 1].astype(int)
        assert int(seen[y0 + 1, x0 + 1]) == 0xFF000000 | int(inside[2]) << 16 | int(inside[1]) << 8 | int(inside[0])
        # the supervisor's oval at C's truncation of the field's translation, blended at opacity 0.03
        cx, cy = int(GROUND - GROUND * (got[1] + 0.5)), int(GROUND - GROUND * (got[0] + 0.5))
        draw(ground, ["opacity", 0.03], ["color", BLUE], ["oval", cx, cy, 4, 4, True])
        for x, y in filled_oval(cx, cy, 4):
            if 0 <= x < GROUND and 0 <= y < GROUND:
                want[y, x] = blended(int(want[y, x]), BLUE, int(0.03 * 255))
        assert (ground.pixels == want).all(), k
        # nothing within the sensors' 0.15 m: box 4 and the walls farther from the body's centre than
        # 0.15 m and the sensors' 0.047 m from it
        assert min(box_distance(at), 0.5 - abs(float(at[0])), 0.5 - abs(float(at[1]))) > 0.15 + 0.047, k
    draw(ground, ["copy", 1, 0, 0, GROUND, GROUND])
    assert (ground.images[1] == want).all()


def floor_texels(at: np.ndarray, rows: range) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """For MyBot at ``at`` (heading BOT_YAW), each camera pixel of ``rows`` whose centre's ray meets the
    floor: (row, column, the ground display's texel column and row under the hit, how far the hit is from
    a texel's edge in texels). The ground display's Plane (1 m, the supervisor robot turned −π/2) maps
    world (x, y) to texel (⌊(0.5 − y)·64⌋, ⌊(0.5 − x)·64⌋): display_supervisor.c's own formula."""
    c, s = math.cos(BOT_YAW), math.sin(BOT_YAW)
    j, i = np.meshgrid(np.arange(rows.start, rows.stop), np.arange(256), indexing="ij")
    left, up = (128 - (i + 0.5)) / FOCAL, (64 - (j + 0.5)) / FOCAL
    t = 0.0915 / -up
    x = at[0] + 0.04 * c + t * (c - left * s)
    y = at[1] + 0.04 * s + t * (s + left * c)
    u, v = (0.5 - y) * GROUND, (0.5 - x) * GROUND
    edge = np.minimum(np.abs(u - np.round(u)), np.abs(v - np.round(v)))
    return j.ravel(), i.ravel(), np.floor(u).astype(int).ravel(), np.floor(v).astype(int).ravel(), edge.ravel()


def test_a_camera_sees_the_ground_display_drawn_on_its_screen_shape() -> None:
    """The ground display's first child is a Shape whose PBRAppearance has a baseColorMap (an ImageTexture
    without url, as the sample's emoticon screen has): Webots replaces that texture with the display's
    image, so MyBot's camera sees on the floor what the supervisor draws. Black before anything is drawn
    (Webots' new display), then the grey with its red axis: each floor pixel of the camera (rows 96 to 127,
    their centres' rays meeting the floor 0.37 to 0.66 m ahead) shows the texel under its ray's hit, the
    closed form (the rays within 0.05 texel of a texel's edge, and the yellow box's pixels, left out): red
    exactly where that texel is column 32, the axis, grey elsewhere, every grey pixel the same shade; after a
    simulation reset the display and the floor are black again."""
    w = load_world(DATA / "display.wbt")
    (ground_cfg,) = [d for d in w.world.robots[1].devices if d.name == "ground_display"]
    (emoticons,) = [d for d in w.world.robots[0].devices if d.name == "emoticon_display"]
    assert ground_cfg.screen_shape == 0 and emoticons.screen_shape is not None
    assert [d.screen_shape for d in w.world.robots[0].devices if d.name == "camera_display"] == [None]
    sim = Simulation(w, "exact")
    cam, ground = sim.device("MyBot/camera"), sim.device("supervisor/ground_display")
    cam.enable(32)
    sim.step()
    rows = range(96, 128)
    j, i, col, row, edge = floor_texels(BOT0, rows)
    image = np.asarray(cam.image)[..., :3].astype(int)          # B, G, R
    seen = image[j, i]
    yellow = (seen[:, 2] > 80) & (seen[:, 1] > 80) & (seen[:, 0] < 40)
    on_floor = (np.abs(col - 31.5) < 32) & (np.abs(row - 31.5) < 32) & ~yellow & (edge > 0.05)
    assert on_floor.sum() > 4000
    assert (seen[on_floor] == 0).all()                          # a new display is black
    draw(ground, ["color", LIGHT_GRAY], ["rectangle", 0, 0, GROUND, GROUND, True], ["color", RED],
         ["line", GROUND // 2, 0, GROUND // 2, GROUND - 1])
    sim.step()
    seen = np.asarray(cam.image)[..., :3].astype(int)[j, i]
    red = seen[:, 2] > seen[:, 1] + 40
    assert (red[on_floor] == (col[on_floor] == GROUND // 2)).all()
    assert red[on_floor].sum() > 20
    grey = seen[on_floor & ~red]
    assert (grey == grey[0]).all() and grey[0][0] == grey[0][1] == grey[0][2] > 0
    # a simulation reset makes the display black again (WbDisplay's reset), and so its screen
    sim.reset()
    cam.enable(32)
    sim.step()
    assert (np.asarray(cam.image)[..., :3].astype(int)[j, i][on_floor] == 0).all()


def test_a_screen_is_retextured_only_while_something_may_see_it() -> None:
    """A display drawn on every step while no ray-casting device is enabled (nothing can see its screen)
    leaves its screen shape's texture alone, the drawing's cost only; enabling the camera shows the latest
    drawing from that step, as if it had been shown all along; a Viewpoint picture shows it too."""
    from sensorium.server.sim import viewshot

    sim = Simulation(load_world(DATA / "display.wbt"), "exact")
    cam, ground = sim.device("MyBot/camera"), sim.device("supervisor/ground_display")
    assert not any(d.enabled for d in sim.all_devices() if d.kind in ("Camera", "DistanceSensor", "LightSensor"))
    (screen,) = [shape for _dev, shape, _shown in sim._screens if _dev is ground]
    loaded_texture = sim.scene.shape_model(screen).appearance.texture
    for k in range(5):
        draw(ground, ["color", LIGHT_GRAY if k % 2 else RED], ["rectangle", 0, 0, GROUND, GROUND, True])
        sim.step()
        assert sim.scene.shape_model(screen).appearance.texture is loaded_texture     # not retextured
    draw(ground, ["color", LIGHT_GRAY], ["rectangle", 0, 0, GROUND, GROUND, True], ["color", RED],
         ["line", GROUND // 2, 0, GROUND // 2, GROUND - 1])
    viewshot.render(sim, 32, 24)                           # a Viewpoint picture shows what was drawn
    assert sim.scene.shape_model(screen).appearance.texture.url == "display:supervisor/ground_display"
    cam.enable(32)
    sim.step()
    j, i, col, row, edge = floor_texels(BOT0, range(96, 128))
    seen = np.asarray(cam.image)[..., :3].astype(int)[j, i]
    yellow = (seen[:, 2] > 80) & (seen[:, 1] > 80) & (seen[:, 0] < 40)
    on_floor = (np.abs(col - 31.5) < 32) & (np.abs(row - 31.5) < 32) & ~yellow & (edge > 0.05)
    red = seen[:, 2] > seen[:, 1] + 40
    assert on_floor.sum() > 4000 and (red[on_floor] == (col[on_floor] == GROUND // 2)).all()


# ------------------------------------------------------------------------------------------ gps_lat_long
# gps_lat_long (projects/samples/devices, R2023b): a WGS84 world (gpsReference 40.67 −73.94 10); MyBot at
# (0, −0.15) heading 1 rad runs `gps_lat_long` (64 ms): GPS latitude, longitude, altitude and speed printed
# each step (degrees also as text), wheels at 6 rad/s (0.15 m/s) until ds1 passes 500, then it turns.
WGS_A, WGS_F = 6378137.0, 1 / 298.257223563
GPS_REF = (40.67, -73.94, 10.0)


def utm_convergence_and_scale() -> tuple[float, float]:
    """The grid convergence γ and point scale k of UTM zone 18 (central meridian 75° W) at the reference
    (the first terms of their series: γ = atan(tan Δλ · sin φ), k = 0.9996 (1 + (Δλ cos φ)²/2))."""
    phi, dlam = math.radians(GPS_REF[0]), math.radians(GPS_REF[1] + 75.0)
    return math.atan(math.tan(dlam) * math.sin(phi)), 0.9996 * (1 + (dlam * math.cos(phi)) ** 2 / 2)


def ground_step(lat0: float, lon0: float, lat1: float, lon1: float) -> tuple[float, float]:
    """The ground displacement between two nearby WGS84 points as (length m, direction from east rad):
    the ellipsoid's meridian and prime-vertical radii of curvature at the reference."""
    e2 = WGS_F * (2 - WGS_F)
    s2 = math.sin(math.radians(GPS_REF[0])) ** 2
    m, n = WGS_A * (1 - e2) / (1 - e2 * s2) ** 1.5, WGS_A / math.sqrt(1 - e2 * s2)
    north = math.radians(lat1 - lat0) * m
    east = math.radians(lon1 - lon0) * n * math.cos(math.radians(GPS_REF[0]))
    return math.hypot(north, east), math.atan2(north, east)


def test_gps_lat_long_reads_the_wgs84_track_of_the_robot_and_prints_it_as_webots_does() -> None:
    """gps_lat_long.c's calls in process: the GPS says WGS84; the robot drives straight at 0.15 m/s along its
    heading of 1 rad (its pose the closed form's, 1e-12) while ds1 reads under 500 (ds0 sees nothing: 0), 18
    steps; the altitude is the reference's 10 m (the GPS at the floor), the speed NaN at the first sample,
    then 0.15 m/s (1e-12); each 64 ms the latitude and longitude move by a ground step of 0.0096 m scaled by
    UTM's 1/k (1.000301: the reference's zone series, 1e-5) and turned by its grid convergence γ (0.012058
    rad: the track's true direction 1 − γ from east, 1e-6). At the 19th step ds1 passes 500 and the robot
    turns on the spot's arc the controller asks (wheels −ds1/100 and 0.5 rad/s): the next GPS speed is that
    arc's chord over 64 ms (1e-12). Its texts are libController's: "40° 40′ 11″" and "-73° -56′ -24″" at the
    start, "-73° -56′ -23″" once it moved 2 mm east of 73.94° W's 23.99…″ (whole seconds, truncated)."""
    w = load_world(DATA / "gps_lat_long.wbt")
    assert w.warnings == []
    sim = Simulation(w, "exact")
    bot, gps = sim.robot("MyBot"), sim.device("MyBot/gps")
    ds = [sim.device("MyBot/ds0"), sim.device("MyBot/ds1")]
    for d in (gps, *ds):
        d.enable(64)
    assert gps.coordinate_system == 1                       # WB_GPS_WGS84_COORDINATE
    for m in ("left wheel motor", "right wheel motor"):
        bot.motor(m).set_position(math.inf)
        bot.motor(m).set_velocity(0.0)
    gamma, k = utm_convergence_and_scale()
    text = wb.wb_gps_convert_to_degrees_minutes_seconds
    heading = np.array([math.cos(1.0), math.sin(1.0)])
    last = None
    left = right = 0.0
    for step in range(1, 21):
        sim.step()
        sim.step()
        t = sim.time_ms / 1000.0
        lat, lon, alt = (float(v) for v in gps.values)
        assert alt == pytest.approx(GPS_REF[2], abs=1e-9), step
        d0, d1 = ds[0].value, ds[1].value
        if step == 1:
            assert math.isnan(gps.speed)
            assert (text(lat), text(lon)) == ("40\u00b0 40\u2032 11\u2033", "-73\u00b0 -56\u2032 -24\u2033")
        elif step < 20:
            assert list(bot.pose.translation[:2]) == pytest.approx(
                list(np.array([0.0, -0.15]) + 0.15 * (t - 0.064) * heading), abs=1e-12), step
            assert gps.speed == pytest.approx(0.15, abs=1e-12), step
            length, direction = ground_step(*last, lat, lon)
            assert length == pytest.approx(0.15 * 0.064 / k, rel=1e-5), step
            assert direction == pytest.approx(1.0 - gamma, abs=1e-6), step
            assert text(lon) == "-73\u00b0 -56\u2032 -23\u2033"
        else:                                               # the arc asked at step 19, over 64 ms
            v, omega = (left + right) / 2 * 0.025, (right - left) * 0.025 / 0.09
            half = omega * 0.064 / 2
            assert gps.speed == pytest.approx(abs(v) * math.sin(half) / half, abs=1e-12)
        assert d0 == pytest.approx(0.0, abs=1e-12), step
        if step < 19:
            assert d1 <= 500, step
            left = right = 6.0
        elif step == 19:
            assert d1 > 500
            left, right = -d1 / 100, d0 / 100 + 0.5
        if step < 20:
            bot.motor("left wheel motor").set_velocity(left)
            bot.motor("right wheel motor").set_velocity(right)
        last = (lat, lon)


DMS_PROGRAM = r"""
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <webots/gps.h>
int main(void) {
  const double values[] = {40.66999864942021, -73.94000002138547, -73.93999995887448, 46.5202, -1.5, NAN};
  for (int i = 0; i < 6; i++) {
    const char *text = wb_gps_convert_to_degrees_minutes_seconds(values[i]);
    printf("%s\n", text);
    free((void *)text);     /* as gps_lat_long.c does: the string is the caller's */
  }
  return 0;
}
"""


@pytest.mark.slow
def test_the_c_librarys_degrees_minutes_seconds_text_is_webots_and_the_caller_frees_it(tmp_path: Path,
                                                                                      request) -> None:
    """gps_lat_long.c prints wb_gps_convert_to_degrees_minutes_seconds' text and frees it: built against our
    libController, it prints Webots' whole seconds ("%d° %d′ %d″" of C's (int)s) and the frees pass (the
    string was a static buffer, which free() aborts on); the Python client's text is the same."""
    build, libs = request.getfixturevalue("built_library")
    source = tmp_path / "dms.c"
    source.write_text(DMS_PROGRAM)
    made = subprocess.run(["cc", f"-I{REPO / 'sensorium' / 'client' / 'c' / 'include'}", str(source), "-o",
                           str(tmp_path / "dms"), str(build / "libController.a"), *libs, "-lm"],
                          capture_output=True, text=True, timeout=120)
    assert made.returncode == 0, made.stderr
    ran = subprocess.run([str(tmp_path / "dms")], capture_output=True, text=True, timeout=30)
    assert ran.returncode == 0, ran.stderr
    want = ["40\u00b0 40\u2032 11\u2033", "-73\u00b0 -56\u2032 -24\u2033", "-73\u00b0 -56\u2032 -23\u2033",
            "46\u00b0 31\u2032 12\u2033", "-1\u00b0 -30\u2032 0\u2033",
            "-2147483648\u00b0 -2147483648\u2032 -2147483648\u2033"]
    assert ran.stdout.splitlines() == want
    assert [wb.wb_gps_convert_to_degrees_minutes_seconds(v) for v in
            (40.66999864942021, -73.94000002138547, -73.93999995887448, 46.5202, -1.5, math.nan)] == want
