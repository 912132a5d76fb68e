"""Sweep 18: Webots robots' own demo controllers not run before (projects/robots), each on a stand-in world
of ours (tests/data/sweep18/: the robot's PROTO device names, places, tables and joints, our own text and
textures), driven in process by the calls its controller makes and checked against closed forms; the
slow tests run the controllers under ``sensorium run`` (Webots' own when $WEBOTS_HOME holds them, else
our C controllers making the same calls, tests/c/)."""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest
from _serve import child_env, sensorium

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data" / "sweep18"
TESTS_C = Path(__file__).parent / "c"
REPO = Path(__file__).resolve().parent.parent


def yaw_of(robot) -> float:
    r = robot.pose.rotation
    return math.atan2(r[1, 0], r[0, 0])


# ------------------------------------------------------------------------------------- Thymio II demo
# thymio2_demo (mobsya/thymio): 10 ms steps; no key and no robot-window click headless, so the wheels stay
# at 0; each step it lights circle LED ⌊t⌋ mod 8 (32: the last of its 32 colours), the top and bottom RGB
# LEDs from the time, the proximity LEDs from the sensors and sends the nine readings (scaled) to the
# robot window.
THYMIO = "Thymio II"
LED_FREQ = 4.0


def thymio_colour(t: float) -> int:
    """generate_color_from_time: three sines 120° apart, period LED_FREQ s, each byte ⌊(0.5 sin + 0.5)·255⌋."""
    w = 2 * math.pi / LED_FREQ
    parts = [int((0.5 * math.sin(w * t + phase) + 0.5) * 0xFF) for phase in (0.0, math.pi / 3, 2 * math.pi / 3)]
    return (parts[0] << 16) + (parts[1] << 8) + parts[2]


def thymio_world(tmp_path: Path) -> Path:
    """The stand-in with its sensors' 1 % noise taken out."""
    text = re.sub(r"(\S+ \d+) 0\.01\b", r"\1 0", (DATA / "thymio2.wbt").read_text())   # (distance, value, noise)
    path = tmp_path / "thymio2.wbt"
    path.write_text(text)
    return path


def test_the_thymio_stand_in_loads_with_every_device_its_demo_asks_for() -> None:
    """The Thymio II stand-in loads with the arena's stand-in line only; its wheels (radius 0.021 m at y
    ±0.05) are a two-wheel drive and every device thymio2_demo looks up is there, of its PROTO's kind: 26
    LEDs (the top and bottom ones RGB, the others 32 steps of their colour), 5 buttons, 7 + 2 infra-red
    sensors, the accelerometer."""
    w = load_world(DATA / "thymio2.wbt")
    assert len(w.warnings) == 1 and "built-in stand-ins used for CircleArena" in w.warnings[0], w.warnings
    robot = w.world.robots[0]
    drive = robot.differential_drive
    assert drive is not None and (drive.wheel_radius, drive.axle_length) == (0.021, 0.1)
    kinds = {d.name: type(d).__name__ for d in robot.devices}
    leds = [f"leds.buttons.led{i}" for i in range(4)] + [f"leds.circle.led{i}" for i in range(8)] + \
        [f"leds.prox.h.led{i}" for i in range(8)] + ["leds.prox.v.led0", "leds.prox.v.led1", "leds.sound", "leds.rc",
                                                     "leds.temperature.red", "leds.temperature.blue", "leds.top",
                                                     "leds.bottom.left", "leds.bottom.right"]
    sensors = [f"prox.horizontal.{i}" for i in range(7)] + ["prox.ground.0", "prox.ground.1"]
    buttons = [f"button.{b}" for b in ("backward", "left", "center", "forward", "right")]
    names = set(leds) | set(sensors) | set(buttons) | {"acc", "motor.left", "motor.right"}
    assert names <= set(kinds), sorted(names - set(kinds))
    by_name = {d.name: d for d in robot.devices}
    for name in leds:
        gradual = name in ("leds.top", "leds.bottom.left", "leds.bottom.right")
        assert (by_name[name].gradual, len(by_name[name].color)) == ((True, 0) if gradual else (False, 32)), name


def test_the_thymio_demo_calls_read_the_floor_and_light_the_leds_by_the_closed_form(tmp_path: Path) -> None:
    """thymio2_demo's calls in process for 9 s (900 steps of 10 ms), the noise taken out: the robot stands
    at the arena's centre; the horizontal sensors see nothing within their 0.0933 m (0), each ground
    sensor looks straight down from 0.008 m onto the arena's plain white floor (our stand-in's; Webots'
    is its Parquetry texture) and reads 1000·(1 − 0.008/0.05) = 840 (1e-9: its float32 ray), so the
    ground LEDs show ⌊840·32/1000⌋ = 26. Circle LED ⌊t⌋ mod 8 alone shows its
    32nd colour, 31/32 of (0.5, 0.25, 0.125); the top LED shows the RGB of the three sines at t."""
    sim = Simulation(load_world(thymio_world(tmp_path)), "exact")
    robot = sim.robot(THYMIO)
    dev = lambda name: sim.device(f"{THYMIO}/{name}")  # noqa: E731
    horizontal = [dev(f"prox.horizontal.{i}") for i in range(7)]
    ground = [dev(f"prox.ground.{i}") for i in range(2)]
    for s in horizontal + ground:
        s.enable(10)
    circle = [dev(f"leds.circle.led{i}") for i in range(8)]
    prox_v = [dev(f"leds.prox.v.led{i}") for i in range(2)]
    top, left, right = dev("leds.top"), dev("leds.bottom.left"), dev("leds.bottom.right")
    for m in (robot.motor("motor.left"), robot.motor("motor.right")):
        m.set_position(math.inf)
        m.set_velocity(0.0)
    start = [float(c) for c in robot.pose.translation]
    for k in range(1, 901):
        sim.run(1)
        t = sim.time_ms / 1000
        assert sim.time_ms == 10 * k
        lit = int(t) % 8
        for i, led in enumerate(circle):
            led.set(32 if i == lit else 0, sim.time_ms)
        top.set(thymio_colour(t), sim.time_ms)
        left.set(thymio_colour(t + 0.333 * LED_FREQ), sim.time_ms)
        right.set(thymio_colour(t + 0.666 * LED_FREQ), sim.time_ms)
        values = [float(s.value) for s in horizontal + ground]
        assert values[:7] == [0.0] * 7, k
        assert values[7:] == pytest.approx([1000 * (1 - 0.008 / 0.05)] * 2, abs=1e-9), k
        for led, v in zip(prox_v, values[7:]):
            led.set(int(v * 32 / 1000), sim.time_ms)
            assert led.value == 26
        assert circle[lit].rgb() == pytest.approx((31 / 32 * 0.5, 31 / 32 * 0.25, 31 / 32 * 0.125), abs=1e-12)
        assert all(led.rgb() == (0.0, 0.0, 0.0) for i, led in enumerate(circle) if i != lit)
        c = thymio_colour(t)
        assert top.rgb() == pytest.approx((((c >> 16) & 255) / 255, ((c >> 8) & 255) / 255, (c & 255) / 255), abs=1e-12)
    assert thymio_colour(0.0) == 0x7FEDED and thymio_colour(1.0) == 0xFFBF3F    # t = 1: sines 1, 0.5, -0.5
    assert [float(c) for c in robot.pose.translation] == start


# --------------------------------------------------------------------------------- Mindstorms Rover
# Rover (lego/mindstorms): 64 ms steps; the ground sensor S2 (infra-red, 0 m -> 0, 0.1 m -> 150: the
# farther, the higher) looks down from 0.01 m above the robot's origin, 0.0146 m ahead; over the line
# (> 43) the left wheel turns at 1 rad/s and the right at 0.2 (a right turn), else 0.2 and 1; a bumper
# (S1, S3) touching starts its avoidance. Wheels of radius 0.01 m at y 0.0227 and -0.0225.
ROVER = "MindstormsRover"
ROVER_R, ROVER_AXLE, ROVER_CY, ROVER_STEP = 0.01, 0.0452, 0.0001, 64
ARENA_TURN = -3.1415853071795863
TEXELS = 1024


def turned_x(axis: tuple[float, float, float], angle: float) -> tuple[float, float, float]:
    """+x turned by the rotation ``axis`` (normalised), ``angle`` (Rodrigues' formula)."""
    n = math.sqrt(sum(a * a for a in axis))
    ux, uy, uz = (a / n for a in axis)
    c, s = math.cos(angle), math.sin(angle)
    return (c + ux * ux * (1 - c), uy * ux * (1 - c) + uz * s, uz * ux * (1 - c) - uy * s)


S2_DIR = turned_x((0.707108, -0.000279, -0.707105), 3.14104)      # the PROTO's S2: down, 0.045° off


def line_black(x: float, y: float) -> bool:
    """Whether the floor texel under world (x, y) is black: the arena's frame is the world turned by
    ARENA_TURN, its 1 m Plane maps onto the 1024-texel image (nearest texel), and a texel is black when its
    centre lies in the 0.02 m frame at half-side 0.38 m (the image is symmetric, so the image's row and
    column directions do not matter)."""
    c, s = math.cos(-ARENA_TURN), math.sin(-ARENA_TURN)
    lx, ly = c * x - s * y, s * x + c * y
    col, row = (min(math.floor((u + 0.5) * TEXELS), TEXELS - 1) for u in (lx, ly))
    cx, cy = (abs((i + 0.5) / TEXELS - 0.5) for i in (col, row))
    band = lambda a: 0.37 <= a <= 0.39  # noqa: E731
    return (band(cx) and cy <= 0.39) or (band(cy) and cx <= 0.39)


def s2_closed_form(x: float, y: float, yaw: float, height: float) -> float:
    """S2's reading from the robot's origin at (x, y, yaw), the sensor ``height`` above the floor: its ray
    meets the floor at d = height / |dz|, read by the infra-red rule at d / (0.2 + 0.8·red·(1 − 0.5·1))
    (the floor's roughness 1), red 0 on the line and 1 off it, in the table 150·d/0.1."""
    t = height / -S2_DIR[2]
    fx, fy = 0.0146 + t * S2_DIR[0], t * S2_DIR[1]
    hx, hy = x + math.cos(yaw) * fx - math.sin(yaw) * fy, y + math.sin(yaw) * fx + math.cos(yaw) * fy
    red = 0.0 if line_black(hx, hy) else 1.0
    return 150 * (t / (0.2 + 0.8 * red * 0.5)) / 0.1


def rover_rule(reading: float, bumped: bool, counter: int) -> tuple[float, float, int]:
    """Rover.c's step: (left, right, avoidance counter)."""
    if counter == 0:
        if bumped:
            return -0.6, -1.0, 1000
        return (1.0, 0.2, 0) if reading > 43 else (0.2, 1.0, 0)
    if counter > 800:
        left, right = -0.6, -1.0
    elif counter > 600:
        left, right = 1.0, 1.0
    else:
        left, right = (0.7, 1.0) if counter > 70 else (1.0, 1.0)
        if reading > 43:
            counter = 1
    return left, right, counter - 1


def rover_move(x: float, y: float, yaw: float, wl: float, wr: float, dt: float) -> tuple[float, float, float]:
    """One step of the two-wheel drive: the wheels' centre, (0, 0.0001) in the robot's frame, on the arc of
    v = r(ωl + ωr)/2, ω = r(ωr − ωl)/axle; the origin carried with it."""
    cx, cy = x - math.sin(yaw) * ROVER_CY, y + math.cos(yaw) * ROVER_CY
    v, w = ROVER_R * (wl + wr) / 2, ROVER_R * (wr - wl) / ROVER_AXLE
    if w == 0.0:
        cx, cy = cx + v * dt * math.cos(yaw), cy + v * dt * math.sin(yaw)
    else:
        cx, cy = cx + v / w * (math.sin(yaw + w * dt) - math.sin(yaw)), cy - v / w * (math.cos(yaw + w * dt) - math.cos(yaw))
        yaw = math.remainder(yaw + w * dt, 2 * math.pi)
    return cx + math.sin(yaw) * ROVER_CY, cy - math.cos(yaw) * ROVER_CY, yaw


def rover_closed_form(steps: int) -> list[tuple[float, float, float, float]]:
    """Rover.c's rule on the closed-form readings and drive, step by step: (x, y, yaw, reading) after each
    step, from the world's start (-0.23, -0.38, 0.00934632), no bumper touching."""
    x, y, yaw = -0.23, -0.38, 0.00934632
    wl = wr = 0.0
    counter, out = 0, []
    for _ in range(steps):
        x, y, yaw = rover_move(x, y, yaw, wl, wr, ROVER_STEP / 1000)
        reading = s2_closed_form(x, y, yaw, 0.01 - 0.0019)
        out.append((x, y, yaw, reading))
        wl, wr, counter = rover_rule(reading, False, counter)
    return out


def test_the_rover_stand_in_loads_as_a_two_wheel_robot_settled_on_its_wheels() -> None:
    """The Mindstorms Rover stand-in: its two wheels (the PROTO's bounding cylinders, radius 0.01 m, turned
    onto the hinges' y axis by the end points' rotations) are a two-wheel drive 0.0452 m apart whose centre
    is 0.1 mm left of the origin; the wheels' bottom 1.9 mm above the origin, the robot settles from z 0 to
    -0.0019 at load (one line), as Webots' physics drops it onto its wheels."""
    w = load_world(DATA / "rover.wbt")
    assert any("built-in stand-ins used for RectangleArena" in x for x in w.warnings), w.warnings
    drive = w.world.robots[0].differential_drive
    assert drive is not None
    assert (drive.wheel_radius, drive.left_motor, drive.right_motor) == (ROVER_R, "left wheel motor", "right wheel motor")
    assert drive.axle_length == pytest.approx(ROVER_AXLE, abs=1e-15)
    assert drive.axle_center == pytest.approx((0.0, ROVER_CY), abs=1e-15)
    assert drive.wheel_bottom == pytest.approx(0.0019, abs=1e-15)
    sim = Simulation(w, "exact")
    assert [float(c) for c in sim.robot(ROVER).pose.translation] == pytest.approx([-0.23, -0.38, -0.0019], abs=1e-15)


def test_the_rover_follows_the_line_s_edge_by_its_closed_form_readings_and_arcs() -> None:
    """Rover.c's calls in process for 120 s (1875 steps of 64 ms): each step S2 reads the closed form
    (on the line 0.0081 / 0.2 → 60.75, off it 0.0081 / 0.6 → 20.25), no bumper touches, and the pose is the
    arc of the wheel speeds set the step before (1e-9). Started on the line's bottom band, it turns right
    until it leaves the band (2.688 s), then left back onto it, and so runs along the band's outer edge
    (y −0.38961, the last black texel's edge) at 0.01 × (1 + 0.2) / 2 = 0.006 m/s, its heading one of three
    values 0.01133 rad (one 64 ms step's turn) apart; at the frame's corner (104 s) it turns left and
    follows the right band up: (0.3898, −0.3007), heading 1.5725 at 120 s."""
    sim = Simulation(load_world(DATA / "rover.wbt"), "exact")
    robot = sim.robot(ROVER)
    s2, s1, s3 = (sim.device(f"{ROVER}/{n}") for n in ("S2", "S1", "S3"))
    for d in (s2, s1, s3):
        d.enable(ROVER_STEP)
    left, right = robot.motor("left wheel motor"), robot.motor("right wheel motor")
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(0.0)
    want = rover_closed_form(1875)
    counter = 0
    for k, (x, y, yaw, reading) in enumerate(want, 1):
        sim.run(ROVER_STEP // 32)                      # the world's basic step: Webots' default 32 ms
        got = [float(c) for c in robot.pose.translation[:2]] + [yaw_of(robot)]
        assert got == pytest.approx([x, y, yaw], abs=1e-9), k
        assert float(s2.value) == pytest.approx(reading, abs=1e-9), k
        assert (s1.value, s3.value) == (0.0, 0.0), k
        wl, wr, counter = rover_rule(float(s2.value), False, counter)
        left.set_velocity(wl)
        right.set_velocity(wr)
    readings = {round(r, 4) for *_, r in want}             # the ray 0.045° off the vertical: 1.0000003 d
    assert readings == {60.75, 20.25}
    assert next(k for k, (*_, r) in enumerate(want, 1) if r < 43) == 42             # off the line at 2.688 s
    edge = want[312:1500]                                                             # 20 s to 96 s: along the edge
    assert all(abs(y + 0.38961) < 2e-5 for _, y, _, _ in edge)
    assert {round(yaw, 6) for _, _, yaw, _ in edge} == {-0.013309, -0.001981, 0.009346}
    assert (edge[-1][0] - edge[0][0]) / ((len(edge) - 1) * 0.064) == pytest.approx(0.006, abs=1e-6)
    assert next(k for k, (_, _, yaw, _) in enumerate(want, 1) if yaw > 0.5) * 64 == 104000       # the corner
    assert want[-1][:3] == pytest.approx((0.389812, -0.300700, 1.572532), abs=1e-6)              # up the right band


# ---------------------------------------------------------------------- the controllers under sensorium run
# Webots' controllers are Webots' files, never this repository's: each test below copies one from
# $WEBOTS_HOME (an installation or a source tree) into its temporary project, or, without it, our own C
# controller making the same calls (tests/c/), builds it against our libController and runs the world
# with `sensorium run`.
WATCHER = '''import math

from controller import Supervisor

sup = Supervisor()
node = sup.getFromDef("ROVER")
while sup.step(64) != -1:
    p, r = node.getPosition(), node.getOrientation()
    print(f"pose {round(sup.getTime() * 1000)} {p[0]:.9f} {p[1]:.9f} {math.atan2(r[3], r[0]):.9f}", flush=True)
'''


@pytest.fixture(scope="module")
def clib(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[str]]:
    """Our libController built once for this file: (its build folder, the libraries to link)."""
    if shutil.which("cc") is None or shutil.which("make") is None:
        pytest.skip("needs a C toolchain (build-essential, libzmq3-dev, libmsgpack-dev, libpng-dev, libjpeg-dev)")
    build = tmp_path_factory.mktemp("cbuild")
    make = ["make", "-s", "-C", str(REPO / "sensorium" / "client" / "c")]
    done = subprocess.run([*make, f"BUILD={build}"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return build, subprocess.run([*make, "libs"], capture_output=True, text=True, timeout=60).stdout.split()


def project(tmp_path: Path, text: str, world: str, rel: str, ours: Path, clib: tuple[Path, list[str]],
            extra: str = "") -> tuple[Path, bool]:
    """A project: worlds/WORLD.wbt (``text`` and ``extra``, our textures beside it) and controllers/ holding
    Webots' controller folder projects/robots/REL from $WEBOTS_HOME, or without it ``ours`` under its name,
    its C file built against our libController. Returns (the world, whether Webots' controller runs)."""
    home = os.environ.get("WEBOTS_HOME")
    name = rel.rsplit("/", 1)[-1]
    folder = tmp_path / "controllers" / name
    webots = home is not None and (Path(home) / "projects" / "robots" / rel).is_dir()
    if webots:
        shutil.copytree(Path(home) / "projects" / "robots" / rel, folder)   # type: ignore[arg-type]
    else:
        folder.mkdir(parents=True)
        shutil.copy(ours, folder / f"{name}.c")
    build, libs = clib
    done = subprocess.run(["cc", f"-I{REPO / 'sensorium' / 'client' / 'c' / 'include'}", *sorted(str(x) for x in folder.glob("*.c")),
                           "-o", str(folder / name), str(build / "libController.a"), *libs, "-lm"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    shutil.copytree(DATA / "textures", tmp_path / "worlds" / "textures")
    path = tmp_path / "worlds" / f"{world}.wbt"
    path.write_text(text + extra)
    return path, webots


def run_world(world: Path, until_ms: int, *extra: str) -> subprocess.CompletedProcess:
    done = subprocess.run(sensorium("run", str(world), "--until", str(until_ms), "--rpc", "tcp://127.0.0.1:0",
                                    "--pub", "tcp://127.0.0.1:0", *extra),
                          env=child_env(), cwd=world.parent.parent, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "exited with status" not in done.stderr and "INVALID_ARGUMENT" not in done.stderr, done.stderr
    return done


@pytest.mark.slow
def test_thymio2_demo_sends_the_ground_readings_to_its_robot_window(tmp_path: Path, clib) -> None:
    """thymio2_demo (Webots' C, unchanged; without it tests/c/thymio_window.c) under ``sensorium run
    --robot-window-log`` (its lines on stderr) for 1 s, the noise taken out: every one of its 100 steps sends the nine scaled
    readings, the horizontal ones 0 and the ground ones ⌊840/10⌋ (83: the ray reads 840 less 2e-8), and
    every LED value it sets is accepted (no error line)."""
    text = (thymio_world(tmp_path).read_text())
    world, _ = project(tmp_path, text, "thymio2", "mobsya/thymio/controllers/thymio2_demo", TESTS_C / "thymio_window.c", clib)
    done = run_world(world, 1000, "--robot-window-log")
    sent = [x.split("robot window: ", 1)[1] for x in done.stderr.splitlines() if x.startswith("[Thymio II] robot window: ")]
    assert sent == ["0 0 0 0 0 0 0 83 83"] * 100, done.stderr[-2000:]
    assert "Error" not in done.stdout + done.stderr, done.stdout[-2000:] + done.stderr


@pytest.mark.slow
def test_rover_controller_follows_the_line_as_the_closed_form(tmp_path: Path, clib) -> None:
    """Rover (Webots' C, unchanged; without it tests/c/rover_edge.c) under ``sensorium run`` for 20 s with a
    watcher of ours (a supervisor added to the world's copy) printing the rover's pose each 64 ms: every
    pose is the in-process closed form's (rover_closed_form: the readings of our line texture and the arcs
    of the wheel speeds), 1e-8 (printed to 9 places)."""
    text = (DATA / "rover.wbt").read_text()
    extra = 'Robot { name "watcher" supervisor TRUE controller "watcher" }\n'
    world, _ = project(tmp_path, text, "rover", "lego/mindstorms/controllers/Rover", TESTS_C / "rover_edge.c", clib, extra)
    (tmp_path / "controllers" / "watcher").mkdir()
    (tmp_path / "controllers" / "watcher" / "watcher.py").write_text(WATCHER)
    done = run_world(world, 20000)
    poses = {}
    for line in done.stdout.splitlines():
        if line.startswith("[watcher] pose "):
            t, *values = line.split()[2:]
            poses[int(t)] = [float(v) for v in values]
    want = rover_closed_form(312)
    assert len(poses) == 312
    for k, (x, y, yaw, _) in enumerate(want, 1):
        assert poses[64 * k] == pytest.approx([x, y, yaw], abs=1e-8), k


# ----------------------------------------------------------------------------------------- Boe-Bot
# boebot (parallax/boebot): 64 ms steps; its two infra-red sensors lds and rds (0.05 m ahead, 0.028 m either
# side, turned 0.5 and -0.4 rad) read their table 0 up to 0.1 m, 1 from 0.101 m; each reading truncated to
# an int makes a two-bit state: both clear (3) forward at 8 rad/s; one sees (1: lds, 2: rds) a turn in place
# at 10 rad/s away from it; both (0) back off at (-10, -20) rad/s for 11 steps. Wheels of radius 0.034 m at
# y 0.0468861 and -0.046, their hinges 0.025 m ahead of the origin.
BOE = "BoeBot"
BOE_R, BOE_CX, BOE_CY = 0.034, 0.025, (0.0468861 - 0.046) / 2
BOE_AXLE = 0.0468861 + 0.046
BOE_BOXES = [(-0.683174, 0.2, 0.5), (0.35, 0.75, 4.96782), (-0.35471, -0.5, 5.36782), (0.36, 0.3, 5.36782),
             (-0.66, 0.65, 5.36782)]
BOE_SENSORS = [(0.05, 0.028, 0.500004), (0.05, -0.028, 5.88319)]        # lds, rds: x, y, heading


def boe_ray(x: float, y: float, heading: float) -> float:
    """The distance along ``heading`` from (x, y) to the nearest face the sensors' rays (0.0892 m up, under
    every top) meet: the arena's inner walls (x, y = ±1) and the 0.1 m wooden boxes, each turned by θ."""
    dx, dy = math.cos(heading), math.sin(heading)
    best = min([(1 - x) / dx if dx > 0 else math.inf, (-1 - x) / dx if dx < 0 else math.inf,
                (1 - y) / dy if dy > 0 else math.inf, (-1 - y) / dy if dy < 0 else math.inf])
    for bx, by, th in BOE_BOXES:
        a, b = (math.cos(th), math.sin(th)), (-math.sin(th), math.cos(th))
        px, py = (x - bx) * a[0] + (y - by) * a[1], (x - bx) * b[0] + (y - by) * b[1]
        ux, uy = dx * a[0] + dy * a[1], dx * b[0] + dy * b[1]
        lo, hi = -math.inf, math.inf
        for p, u in ((px, ux), (py, uy)):
            if abs(u) < 1e-15:
                if abs(p) > 0.05:
                    lo, hi = math.inf, -math.inf
                continue
            t0, t1 = sorted(((-0.05 - p) / u, (0.05 - p) / u))
            lo, hi = max(lo, t0), min(hi, t1)
        if lo <= hi and 0 < lo < best:
            best = lo
    return best


def boe_reading(d: float) -> float:
    """The table at d (the walls and the stand-in boxes have no appearance: white, infra-red at d itself)."""
    return 0.0 if d <= 0.1 else 1.0 if d >= 0.101 else (d - 0.1) / 0.001


def boe_move(x: float, y: float, yaw: float, wl: float, wr: float, dt: float) -> tuple[float, float, float]:
    """One step of the drive: the wheels' centre (0.025, 0.00044) in the robot's frame on the arc of the wheel
    speeds, the origin carried with it."""
    c, s = math.cos(yaw), math.sin(yaw)
    cx, cy = x + c * BOE_CX - s * BOE_CY, y + s * BOE_CX + c * BOE_CY
    v, w = BOE_R * (wl + wr) / 2, BOE_R * (wr - wl) / BOE_AXLE
    if w == 0.0:
        cx, cy = cx + v * dt * c, cy + v * dt * s
    else:
        cx, cy = cx + v / w * (math.sin(yaw + w * dt) - s), cy - v / w * (math.cos(yaw + w * dt) - c)
        yaw = math.remainder(yaw + w * dt, 2 * math.pi)
    c, s = math.cos(yaw), math.sin(yaw)
    return cx - (c * BOE_CX - s * BOE_CY), cy - (s * BOE_CX + c * BOE_CY), yaw


def boe_rule(left: float, right: float, back: int) -> tuple[float, float, int]:
    """boebot.c's step on the two readings: (left, right, backward counter)."""
    state = (int(left) << 1 | int(right)) if back == 0 else 0
    if state == 0:
        return -10.0, -20.0, (10 if back == 0 else back - 1)
    return {1: (10.0, -10.0), 2: (-10.0, 10.0), 3: (8.0, 8.0)}[state] + (back,)


def boe_run(sim: Simulation, steps: int) -> tuple[list[tuple[float, float, float]], list[tuple[int, float]]]:
    """boebot.c's calls in process for ``steps`` 64 ms steps: each step the readings are checked against the
    closed form from the pose and the pose against the arc of the wheel speeds from the last one; returns the
    poses and the steps where the arc was cut short (a part of the robot met a wall: (step, shortfall))."""
    robot = sim.robot(BOE)
    sensors = [sim.device(f"{BOE}/lds"), sim.device(f"{BOE}/rds")]
    for s in sensors:
        s.enable(64)
    left, right = robot.motor("left wheel motor"), robot.motor("right wheel motor")
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(0.0)
    x, y, yaw = 0.0, 0.0, 1.8318
    wl = wr = 0.0
    back, poses, held = 0, [], []
    for k in range(1, steps + 1):
        x, y, yaw = boe_move(x, y, yaw, wl, wr, 0.064)
        sim.run(2)
        gx, gy, gyaw = float(robot.pose.translation[0]), float(robot.pose.translation[1]), yaw_of(robot)
        if math.hypot(gx - x, gy - y) > 1e-9 or abs(math.remainder(gyaw - yaw, 2 * math.pi)) > 1e-9:
            held.append((k, math.hypot(gx - x, gy - y)))
            x, y, yaw = gx, gy, gyaw
        poses.append((x, y, yaw))
        got = [float(s.value) for s in sensors]
        want = [boe_reading(boe_ray(x + math.cos(yaw) * sx - math.sin(yaw) * sy, y + math.sin(yaw) * sx + math.cos(yaw) * sy,
                                    yaw + h)) for sx, sy, h in BOE_SENSORS]
        assert got == pytest.approx(want, abs=1e-6), k
        wl, wr, back = boe_rule(got[0], got[1], back)
        left.set_velocity(wl)
        right.set_velocity(wr)
    return poses, held


def test_the_boebot_stand_in_loads_with_its_drive_ahead_of_its_origin() -> None:
    """The Boe-Bot stand-in: its wheels (radius 0.034 m, 0.0928861 m apart) are a two-wheel drive whose
    centre is 0.025 m ahead of the origin and 0.44 mm to its left; put at z 0.038, it settles at load onto its
    wheels at 0.0392 (their bottom 0.0392 under the origin)."""
    w = load_world(DATA / "boebot.wbt")
    assert len(w.warnings) == 1 and "RectangleArena, WoodenBox" in w.warnings[0], w.warnings
    drive = w.world.robots[0].differential_drive
    assert drive is not None and drive.wheel_radius == BOE_R
    assert drive.axle_length == pytest.approx(BOE_AXLE, abs=1e-15)
    assert drive.axle_center == pytest.approx((BOE_CX, BOE_CY), abs=1e-15)
    sim = Simulation(w, "exact")
    assert float(sim.robot(BOE).pose.translation[2]) == pytest.approx(0.0392, abs=1e-15)


def test_the_boebot_avoids_the_walls_by_its_closed_form_readings_and_arcs() -> None:
    """boebot.c's calls in process for 60 s: every step both sensors read the closed form's table (the
    nearest wall or box face along their rays) and the pose is the arc of the wheel speeds set the step
    before (1e-9), but for one step: turning in place beside the west wall at 6.016 s, its footprint (the
    whiskers reach 0.127 m ahead) would sweep into the wall, and it is pushed 4.4 mm off it (Kinematic
    contact), its turn kept. It drives at 8 × 0.034 = 0.272 m/s and turns at 10 × 2 × 0.034 / 0.0928861 =
    7.32 rad/s, from wall to wall; at 59.968 s it is at (0.5205, 0.8842), heading −0.00034."""
    poses, held = boe_run(Simulation(load_world(DATA / "boebot.wbt"), "exact"), 937)
    first = poses[14]                  # 0.96 s: 14 steps straight on at 0.272 m/s (the first step's speeds 0)
    assert (first[0], first[1]) == pytest.approx((8 * BOE_R * 0.896 * math.cos(1.8318), 8 * BOE_R * 0.896 * math.sin(1.8318)), abs=1e-12)
    assert [k for k, _ in held] == [94] and held[0][1] == pytest.approx(0.00438, abs=1e-5)
    assert poses[-1] == pytest.approx((0.520491, 0.884204, -0.000343), abs=1e-6)


BOE_WATCHER = WATCHER.replace('"ROVER"', '"BOEBOT"')


@pytest.mark.slow
def test_boebot_controller_drives_as_the_in_process_closed_form(tmp_path: Path, clib) -> None:
    """boebot (Webots' C, unchanged; without it tests/c/boebot_states.c) under ``sensorium run`` for 30 s with
    a watcher printing the robot's pose each 64 ms: every pose is the in-process run's (boe_run: the closed
    form's readings and arcs, the one push off the west wall), 1e-8."""
    want, _ = boe_run(Simulation(load_world(DATA / "boebot.wbt"), "exact"), 468)
    extra = 'Robot { name "watcher" supervisor TRUE controller "watcher" }\n'
    world, _ = project(tmp_path, (DATA / "boebot.wbt").read_text(), "boebot", "parallax/boebot/controllers/boebot",
                       TESTS_C / "boebot_states.c", clib, extra)
    (tmp_path / "controllers" / "watcher").mkdir()
    (tmp_path / "controllers" / "watcher" / "watcher.py").write_text(BOE_WATCHER)
    done = run_world(world, 30000)
    poses = {}
    for line in done.stdout.splitlines():
        if line.startswith("[watcher] pose "):
            t, *values = line.split()[2:]
            poses[int(t)] = [float(v) for v in values]
    assert len(poses) == 469                                   # 30 s: 469 steps of 64 ms, to 30.016 s
    for k, pose in enumerate(want, 1):
        assert poses[64 * k] == pytest.approx(list(pose), abs=1e-8), k
