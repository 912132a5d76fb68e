"""Sweep 25: Webots samples not run before, each on a stand-in world of ours (tests/data/sweep25/: the
sample's poses, sizes and devices, our own text, PROTO meshes stood in for by plain shapes) driven in
process by the calls its controller makes and checked against closed forms."""

from __future__ import annotations

import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from _serve import child_env, sensorium
from test_sweep19 import rot

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data" / "sweep25"

# ----------------------------------------------------------------------------------------------- boomer
# boomer (projects/vehicles, R2023b): the Boomer 3050 tractor, Webots' Tractor PROTO (a 4x4 Car: front
# wheels of radius 0.38 m steering 1.76 m ahead of the rear ones of radius 0.6 m, tracks 1.4 m, every wheel's
# centre at the origin's height; its default rotation 0 1 0 0.13 leans it nose down), at (2.79493, −17.8,
# 0.609281), running boomer.c: 20 ms steps, each wheel motor at 10 km/h over its radius, the steering motors
# never set, the five LEDs blinking with the simulated second, GPS speed from successive positions.
SPEED = 10.0 / 3.6                 # m/s
FRONT_R, REAR_R, WHEELBASE = 0.38, 0.6, 1.76
LEAN = math.asin((REAR_R - FRONT_R) / WHEELBASE)      # both axles' wheels on the floor: L sin θ = r_rear − r_front
START = (2.79493, -17.8)
LEDS = ("left_flasher", "right_flasher", "tail_lights", "work_head_lights", "road_head_lights")


def tractor_world(tmp_path: Path, rotation: str) -> Path:
    """boomer.wbt with the tractor's rotation written out (``rotation``: its field's text)."""
    text = (DATA / "boomer.wbt").read_text().replace("  controller \"boomer\"\n",
                                                     f"  rotation {rotation}\n  controller \"boomer\"\n")
    (tmp_path / "protos").mkdir(exist_ok=True)
    for p in (DATA / "protos").iterdir():
        (tmp_path / "protos" / p.name).write_text(p.read_text())
    out = tmp_path / "boomer.wbt"
    out.write_text(text)
    return out


def test_the_tractor_loads_as_a_4x4_car_and_lands_leaning_on_its_wheels_of_two_sizes() -> None:
    """The tractor loads without a line with the 18 devices boomer.c asks for and the car's 4x4 drive (its
    radii 0.38 and 0.6 m, its axles' bottoms 0.38 and 0.6 m below its origin). Webots' physics lays it on its
    four wheels: leaning asin(0.22/1.76) = 0.12533 rad (the PROTO's 0.13 is 4.7 mrad off), its rear wheels'
    centres 0.6 m up, from the 0.609281 the world gives; here it settles so at load, one line saying so, and
    both axles' wheels touch the floor (1e-12)."""
    w = load_world(DATA / "boomer.wbt")
    assert w.warnings == []
    (robot,) = w.world.robots
    names = {d.name for d in robot.devices}
    assert len(names) == 18 and {"left_steer", "right_steer", "left_front_wheel", "right_front_wheel",
                                 "left_rear_wheel", "right_rear_wheel", "camera", "Sick LMS 291", "gps",
                                 "gyro", *LEDS} <= names
    car = robot.ackermann_drive
    assert (car.type, car.wheelbase, car.track_front, car.track_rear) == ("4x4", WHEELBASE, 1.4, 1.4)
    assert (car.front_wheel_radius, car.rear_wheel_radius) == (FRONT_R, REAR_R)
    assert car.axle_bottoms == pytest.approx((-REAR_R, -FRONT_R), abs=1e-12)
    sim = Simulation(w, "exact")
    (said,) = w.warnings
    assert said.endswith("boomer.wbt: robot 'vehicle' settled on the ground at load, as Webots' physics drops it: "
                         "leaning 0.1253 rad about its y on its wheels of two sizes (both axles now touch the ground "
                         "under it), its origin's z from 0.6093 to 0.6000 m")
    pose = sim.robot("vehicle").pose
    body = rot((0, 1, 0), LEAN)
    assert np.asarray(pose.rotation) == pytest.approx(body, abs=1e-12)
    assert list(pose.translation) == pytest.approx([*START, REAR_R], abs=1e-12)
    t = np.asarray(pose.translation)
    for x, radius in ((0.0, REAR_R), (WHEELBASE, FRONT_R)):
        assert float((t + body @ np.array([x, 0.0, 0.0]))[2]) - radius == pytest.approx(0.0, abs=1e-12)


def test_a_tractor_placed_upright_leans_onto_its_front_wheels_and_one_turned_far_keeps_its_pose(tmp_path: Path) -> None:
    """Placed upright and turned 0.7 rad about z, the tractor (its front wheels 0.22 m above the floor when
    upright) leans the same 0.12533 rad about its own y, its heading kept: Webots' physics drops its nose onto
    its front wheels. Turned 0.5 rad about y (beyond 0.35 rad of upright) it keeps the world's pose, as any
    tilted robot does."""
    sim = Simulation(load_world(tractor_world(tmp_path, "0 0 1 0.7")), "exact")
    pose = sim.robot("vehicle").pose
    assert np.asarray(pose.rotation) == pytest.approx(rot((0, 0, 1), 0.7) @ rot((0, 1, 0), LEAN), abs=1e-12)
    assert list(pose.translation) == pytest.approx([*START, REAR_R], abs=1e-12)
    far = Simulation(load_world(tractor_world(tmp_path, "0 1 0 0.5")), "exact").robot("vehicle").pose
    assert np.asarray(far.rotation) == pytest.approx(rot((0, 1, 0), 0.5), abs=1e-12)
    assert list(far.translation) == pytest.approx([*START, 0.609281], abs=1e-12)


def test_boomers_calls_drive_the_tractor_straight_at_10_kmh_leaning_as_it_landed() -> None:
    """boomer.c's calls for 4 s (200 steps of 20 ms): the front wheels at 2.7778/0.38 = 7.3099 rad/s, the rear
    ones at 4.6296 rad/s roll the car at 10 km/h along its heading (the world's +x: its lean is about its
    y), so the GPS reads (2.79493 + 2.7778·t, −17.8, 0.6) each step (1e-9) and the controller's GPS speed,
    |Δp| / 20 ms · 3600, is 10 km/h from the second step (1e-9); the gyro reads 0, the tractor keeps its lean
    and height; the LEDs blink with the simulated second (on in odd seconds); the SICK LMS 291 (180 rays over
    π, 80 m) looks 0.0150 rad above the horizon (its 0.140345 rad up less the body's 0.12533 down), so it sees
    no floor: every ray reads inf, as in Webots' empty field."""
    sim = Simulation(load_world(DATA / "boomer.wbt"), "exact")
    robot = sim.robot("vehicle")
    step = sim.basic_time_step
    assert step == 20
    for name, radius in (("left_front_wheel", FRONT_R), ("right_front_wheel", FRONT_R),
                         ("left_rear_wheel", REAR_R), ("right_rear_wheel", REAR_R)):
        robot.motor(name).set_position(math.inf)
        robot.motor(name).set_velocity(10.0 * 1000.0 / 3600.0 / radius)
    camera, sick = sim.device("vehicle/camera"), sim.device("vehicle/Sick LMS 291")
    gps, gyro = sim.device("vehicle/gps"), sim.device("vehicle/gyro")
    for d in (camera, sick, gps, gyro):
        d.enable(step)
    assert (camera.config.width, camera.config.height, camera.fov) == (128, 64, 1.0)
    assert (sick.config.horizontal_resolution, sick.config.max_range) == (180, 80.0)
    leds = [sim.device(f"vehicle/{n}") for n in LEDS]
    body = rot((0, 1, 0), LEAN)
    last = np.zeros(3)
    for k in range(1, 201):
        sim.step()
        now = k * step
        x = START[0] + SPEED * now / 1000.0
        got = np.asarray(gps.values, dtype=float)
        assert list(got) == pytest.approx([x, START[1], REAR_R], abs=1e-9), k
        if k > 1:
            assert float(np.linalg.norm(got - last)) / step * 3600.0 == pytest.approx(10.0, abs=1e-9), k
        last = got
        assert list(np.asarray(gyro.values, dtype=float)) == pytest.approx([0.0, 0.0, 0.0], abs=1e-12)
        assert np.asarray(robot.pose.rotation) == pytest.approx(body, abs=1e-12)
        assert np.all(np.isinf(np.asarray(sick.range_image, dtype=float)))
        on = int(now / 1000.0) % 2
        for led in leds:
            led.set(on, now)
        assert [led.value for led in leds] == [on] * 5


def test_a_supervisor_put_and_the_batched_simulation_land_the_tractor_as_the_load_does() -> None:
    """Where a Supervisor puts the tractor (its world-file pose, upright 2 m up, turned 1 rad about z), it
    lands leaning as at load, its heading kept (the load's bits for the world-file pose); the batched
    simulation's copies load it leaning and drive it at 10 km/h bit for bit as Simulation does."""
    from sensorium.gym.views import CopySim
    from sensorium.server.sim.batched import BatchedSimulation
    from sensorium.server.world.geometry import Pose

    lw = load_world(DATA / "boomer.wbt")
    single = Simulation(lw, "exact")
    model = single.world.robots[0]
    landed = single.robot("vehicle").pose
    put = single.settled(model, Pose(rot((0, 1, 0), 0.13), np.array([*START, 0.609281])))
    assert put.translation.tobytes() == landed.translation.tobytes()
    assert put.rotation.tobytes() == landed.rotation.tobytes()
    put = single.settled(model, Pose(rot((0, 0, 1), 1.0), np.array([1.0, 2.0, 2.0])))
    assert np.asarray(put.rotation) == pytest.approx(rot((0, 0, 1), 1.0) @ rot((0, 1, 0), LEAN), abs=1e-12)
    assert list(put.translation) == pytest.approx([1.0, 2.0, REAR_R], abs=1e-12)
    batched = BatchedSimulation(lw, 2)
    batched.reset(np.arange(2), [1, 2])
    for sim in (single, CopySim(batched, 0), CopySim(batched, 1)):
        for name, radius in (("left_front_wheel", FRONT_R), ("right_front_wheel", FRONT_R),
                             ("left_rear_wheel", REAR_R), ("right_rear_wheel", REAR_R)):
            motor = sim.robot("vehicle").motors[name]
            motor.set_position(math.inf)
            motor.set_velocity(10.0 * 1000.0 / 3600.0 / radius)
    slot = batched.slot("vehicle")
    for t in range(50):
        batched.step()
        single.step()
        p = single.robot("vehicle").pose
        for c in range(2):
            assert batched.pos[c, slot].tobytes() == p.translation.tobytes(), (t, c)
            assert batched.rot[c, slot].tobytes() == p.rotation.tobytes(), (t, c)
    assert float(p.translation[0]) == pytest.approx(START[0] + SPEED, abs=1e-9)


BOOMER_CONTROLLER = '''\
import math
from controller import Keyboard, Robot

FRONT_WHEEL_RADIUS, REAR_WHEEL_RADIUS = 0.38, 0.6
robot = Robot()
step = int(robot.getBasicTimeStep())
wheels = {n: robot.getDevice(n) for n in ("left_front_wheel", "right_front_wheel", "left_rear_wheel",
                                          "right_rear_wheel")}
for m in wheels.values():
    m.setPosition(math.inf)
steer = [robot.getDevice("left_steer"), robot.getDevice("right_steer")]
camera = robot.getDevice("camera")
camera.enable(step)
sick = robot.getDevice("Sick LMS 291")
sick.enable(step)
gps = robot.getDevice("gps")
gps.enable(step)
leds = [robot.getDevice(n) for n in ("left_flasher", "right_flasher", "tail_lights", "work_head_lights",
                                     "road_head_lights")]
print(f"camera {camera.getWidth()} {camera.getHeight()} {camera.getFov():g} sick "
      f"{sick.getHorizontalResolution()} {sick.getMaxRange():g} {sick.getFov():.5f}", flush=True)
kmh = 10.0
for name, m in wheels.items():
    m.setVelocity(kmh * 1000.0 / 3600.0 / (FRONT_WHEEL_RADIUS if "front" in name else REAR_WHEEL_RADIUS))
keyboard = Keyboard()
keyboard.enable(step)
last = [0.0, 0.0, 0.0]
while robot.step(step) != -1:
    key = keyboard.getKey()
    coords = gps.getValues()
    speed = math.dist(coords, last) / step * 3600.0
    last = list(coords)
    on = int(robot.getTime()) % 2
    for led in leds:
        led.set(on)
    t = round(robot.getTime() * 1000)
    if t % 1000 == 0:
        ranges = sick.getRangeImage()
        print(f"{t} {key} {coords[0]:.9f} {coords[1]:.9f} {coords[2]:.9f} {speed:.9f} {leds[0].get()} "
              f"{sum(math.isinf(r) for r in ranges)}", flush=True)
'''


@pytest.mark.slow
def test_boomers_calls_drive_the_tractor_under_sensorium_run(tmp_path: Path) -> None:
    """Our Python controller making boomer.c's calls under ``sensorium run`` for 3 s: the load report says
    the tractor settled leaning 0.1253 rad; the camera is 128 × 64 with fov 1, the SICK 180 rays over π to
    80 m; no key is pressed (−1); at 1, 2 and 3 s the GPS reads (2.79493 + 2.7778·t, −17.8, 0.6) and the
    controller's GPS speed 10 km/h (1e-9), the LEDs on in odd seconds, every SICK ray inf."""
    (tmp_path / "worlds").mkdir()
    shutil.copytree(DATA / "protos", tmp_path / "worlds" / "protos")
    world = tmp_path / "worlds" / "boomer.wbt"
    world.write_text((DATA / "boomer.wbt").read_text())
    (tmp_path / "controllers" / "boomer").mkdir(parents=True)
    (tmp_path / "controllers" / "boomer" / "boomer.py").write_text(BOOMER_CONTROLLER)
    done = subprocess.run(sensorium("run", str(world), "--until", "3000", "--rpc", "tcp://127.0.0.1:0",
                                    "--pub", "tcp://127.0.0.1:0"),
                          env=child_env(), cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "robot 'vehicle' settled on the ground at load, as Webots' physics drops it: leaning 0.1253 rad" in \
        done.stdout + done.stderr
    lines = [line.split("] ", 1)[1] for line in done.stdout.splitlines() if line.startswith("[vehicle] ")]
    assert lines[0] == "camera 128 64 1 sick 180 80 3.14159"
    rows = [line.split() for line in lines[1:]]
    assert [int(r[0]) for r in rows] == [1000, 2000, 3000]
    for t, key, x, y, z, speed, led, inf in rows:
        assert int(key) == -1
        assert [float(x), float(y), float(z)] == pytest.approx(
            [START[0] + SPEED * int(t) / 1000.0, START[1], REAR_R], abs=1e-9)
        assert float(speed) == pytest.approx(10.0, abs=1e-9)
        assert (int(led), int(inf)) == (int(t) // 1000 % 2, 180)


# -------------------------------------------------------------------------------------------------- url
# url (projects/samples/howto, R2025a): assets named by https URLs (the background's cube maps, the robot's
# body texture, its camera's noise mask, a mesh, a contact sound), the MyBot supervisor robot (wheels of radius
# 0.025 m 0.09 m apart, turned 1 rad at (0, −0.15)) running url.c: 32 ms steps, both wheels at 1 rad/s, its
# camera's image read each step, its body's ImageTexture (DEF IMAGE_TEXTURE, inside the robot) found by
# getFromDef, its url set at the 81st step to a file that does not exist and at the 160th to another https URL.
URL_R, URL_START, URL_HEADING = 0.025, (0.0, -0.15), 1.0


def test_the_url_how_to_names_each_remote_asset_and_downloads_nothing() -> None:
    """Every https asset is named in one line (the mesh a loss, the noise mask and the body texture warnings:
    nothing is downloaded; the texture read as Webots reads one it cannot load, the body's baseColor), the
    robot loads with its 7 devices and a two-wheel drive (radius 0.025 m, axle 0.09 m), the ball settles on the
    floor (z 0.04)."""
    w = load_world(DATA / "url.wbt")
    said = "\n".join(w.warnings + [str(x) for x in w.report.lines()])
    for asset in ("meshes/suzanne.obj", "textures/noise_mask.png", "textures/varnished_pine_base_color.jpg"):
        assert said.count(f"https://example.org/{asset}") >= 1, asset
    assert "nothing is downloaded" in said
    (robot,) = w.world.robots
    assert robot.name == "MyBot" and robot.supervisor
    assert {d.name for d in robot.devices} == {"left wheel motor", "right wheel motor", "left wheel sensor",
                                               "right wheel sensor", "ds0", "ds1", "camera"}
    drive = robot.differential_drive
    assert (drive.wheel_radius, drive.axle_length) == pytest.approx((URL_R, 0.09), abs=1e-12)
    sim = Simulation(w, "exact")
    assert list(sim.scene.solid_poses["soccer ball"].translation) == pytest.approx([0.04, -0.06, 0.04], abs=1e-12)


def test_urls_calls_drive_mybot_and_set_its_texture_url_as_webots_does() -> None:
    """url.c's calls in process: both wheels at 1 rad/s carry MyBot along its heading at 0.025 m/s (1e-9 each
    step for 0.48 s, before its body meets the ball, which kinematic contact does not push); its Supervisor
    finds the ImageTexture DEF'd inside its own body and reads its url (the world's https one, never
    downloaded: the body loads untextured). Setting it to a file that does not exist, or to another https URL,
    sets the field with one line (the server's log), the body still untextured: Webots sets the field, warns,
    and draws the body untextured (a failed download likewise; Webots would download a reachable one)."""
    from sensorium.server.daemon import supervisor as sv

    sim = Simulation(load_world(DATA / "url.wbt"), "exact")
    robot = sim.robot("MyBot")
    step = sim.basic_time_step
    assert step == 32
    sim.device("MyBot/camera").enable(step)
    left, right = robot.motor("left wheel motor"), robot.motor("right wheel motor")
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(1.0)
    for k in range(1, 16):
        sim.step()
        s = URL_R * 1.0 * k * step / 1000.0
        assert list(robot.pose.translation[:2]) == pytest.approx(
            [URL_START[0] + s * math.cos(URL_HEADING), URL_START[1] + s * math.sin(URL_HEADING)], abs=1e-9), k
    texture = sv.find_node(sim, "IMAGE_TEXTURE")
    assert texture is not None and texture.type == "ImageTexture"
    written = ["https://example.org/textures/varnished_pine_base_color.jpg"]
    assert sv.get_field(sim, texture, "url")["value"] == written
    for url, problem in (("this_file_doesnt_exist.jpg", "texture file 'this_file_doesnt_exist.jpg' not found"),
                         ("https://example.org/textures/brushed_steel_base_color.jpg",
                          "only local image files are read here")):
        (line,) = sv.change_item(sim, texture, "url", "set", 0, url)
        assert problem in line and line.endswith("the shape is drawn without its texture (as Webots draws an image "
                                                 "it cannot load)") and "\n" not in line, line
        assert sv.get_field(sim, texture, "url")["value"] == [url]
        k = sv._table(sim).get(texture.id).shape.index
        assert sim.scene.shape_model(k).appearance.texture is None
