"""Sweep 34: Webots' ``projects/languages/matlab`` world ``e-puck_matlab``, not run before, on a stand-in world
of ours (tests/data/sweep34/: the sample's arena, boxes and cylinder where it puts them, sweep 22's E-puck with
the 52 x 39 Display in its turret slot, the Supervisor's Emitter and Receiver on channel 1) driven in process
by the calls its two controllers make (``matlab.m`` on the e-puck, ``e-puck_position_supervisor.c`` on the
Supervisor) and checked against closed forms."""

from __future__ import annotations

import math
import struct
from pathlib import Path

import numpy as np
import pytest
from test_supervisor import A, Live

from sensorium.client.wb_display import WB_IMAGE_RGB, _to_bgra
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data"
WORLD = DATA / "sweep34" / "e-puck_matlab.wbt"
EPUCK = "e-puck camera"
SUPERVISOR = "robot"
START = (-0.616022, 0.463251, 5.85439)       # the e-puck's place and heading in the world file
WHEEL_RADIUS = 0.02                          # the stand-in's (and Webots' bounding) wheel radius
SPEED_UNIT = 0.00628                         # matlab.m
BRAITENBERG = [(150, -35), (100, -15), (80, -10), (-10, -10), (-10, -10), (-10, 80), (-30, 100), (-20, 150)]


def braitenberg(values: list[float]) -> tuple[float, float]:
    """matlab.m's wheel speeds (rad/s) for the eight distance readings: (1 − v/500) · matrix · 5, each capped
    at 1000 units, times SPEED_UNIT."""
    speed = [sum((1 - v / 500) * row[j] for v, row in zip(values, BRAITENBERG)) * 5 for j in range(2)]
    return SPEED_UNIT * min(speed[0], 1000), SPEED_UNIT * min(speed[1], 1000)


def datestr(step: int) -> bytes:
    """The e-puck's packet: MATLAB's ``uint8([datestr(now) 0])``, a null-terminated 20-character date
    (a fixed date here, its seconds the step's count)."""
    return b"08-Dec-2026 00:%02d:%02d\0" % (step // 60 % 60, step % 60)


def test_the_e_puck_matlab_world_loads_with_the_turret_display_and_the_supervisors_radio() -> None:
    """One load line (the arena's built-in stand-in); the e-puck's 36 devices and the turret's 52 × 39 Display
    ("display", the size of the camera whose inverse it shows), both radios on channel 1 on either robot."""
    w = load_world(WORLD)
    assert len(w.warnings) == 1 and "RectangleArena" in w.warnings[0]
    assert [r.name for r in w.world.robots] == [EPUCK, SUPERVISOR]
    sim = Simulation(w, "exact")
    display, camera = sim.device(f"{EPUCK}/display"), sim.device(f"{EPUCK}/camera")
    assert (display.width, display.height, camera.config.width, camera.config.height) == (52, 39, 52, 39)
    for robot in (EPUCK, SUPERVISOR):
        assert sim.device(f"{robot}/emitter").channel == sim.device(f"{robot}/receiver").channel == 1
    pose = sim.robot(EPUCK).pose
    assert list(pose.translation) == pytest.approx([*START[:2], 0.0], abs=1e-12)


class Supervisor:
    """e-puck_position_supervisor.c's calls, in process: every 320 ms it sends the e-puck's ``translation``
    as three doubles and shows each string it received as label 0 (a C string: up to its NUL)."""

    def __init__(self, sim: Simulation) -> None:
        self.lv = Live(sim)
        self.lv.ok(A, "attach", {"robot": SUPERVISOR})
        node = self.lv.ok(A, f"/{SUPERVISOR}/robot/get_from_def", {"name": "E_PUCK"})["node"]
        self.trans = {"node": node, "field": "translation"}
        self.emitter = sim.device(f"{SUPERVISOR}/emitter")
        self.receiver = sim.device(f"{SUPERVISOR}/receiver")
        self.receiver.enable(320)
        self.labels: list[str] = []

    def step(self) -> list[float]:
        pos = self.lv.ok(A, f"/{SUPERVISOR}/robot/get_field", self.trans)["value"]
        assert self.emitter.send(struct.pack("<3d", *pos))
        for packet in self.receiver.take():
            text = packet.data.split(b"\0", 1)[0].decode()
            self.lv.ok(A, f"/{SUPERVISOR}/robot/set_label", {"id": 0, "text": text, "x": 0.01, "y": 0.01,
                                                                "size": 0.1, "color": 0, "transparency": 0.0,
                                                                "font": "Arial"})
            self.labels.append(text)
        return pos


def test_the_matlab_controller_drives_straight_shows_the_inverse_image_and_hears_the_supervisor() -> None:
    """matlab.m's calls for 6.4 s (64 ms steps; the Supervisor's every 320 ms), the e-puck meeting nothing:
    its eight distance sensors read 67.19 (nothing within their range), so both wheels turn at the capped
    1000 units, 6.28 rad/s, and it drives straight along its heading at 0.1256 m/s from the first step
    (1e-12 each step). Each step its Display shows the camera's image inverted (255 − r, g, b, opaque:
    WB_IMAGE_RGB pasted without blending) with the two black gunsight lines, row 19 and column 25, pixel for
    pixel. The Supervisor reads the e-puck's translation every 320 ms and the e-puck gets those three
    doubles at its next step (the packet leaves at the next basic step); the Supervisor gets every date
    string the e-puck sent, in order, each shown as label 0 up to its NUL."""
    sim = Simulation(load_world(WORLD), "exact")
    sup = Supervisor(sim)
    ps = [sim.device(f"{EPUCK}/ps{i}") for i in range(8)]
    for d in ps:
        d.enable(64)
    display, camera = sim.device(f"{EPUCK}/display"), sim.device(f"{EPUCK}/camera")
    camera.enable(64)
    emitter, receiver = sim.device(f"{EPUCK}/emitter"), sim.device(f"{EPUCK}/receiver")
    receiver.enable(64)
    bot = sim.robot(EPUCK)
    left, right = bot.motor("left wheel motor"), bot.motor("right wheel motor")
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(0.0)
    display.apply(display.check([["color", 0x000000]]), 0)
    x0, y0, heading = START
    sent: list[bytes] = []
    told: list[tuple[int, list[float]]] = []        # (time the Supervisor read it, translation)
    heard: list[tuple[int, list[float]]] = []
    speed = 0.0
    moving_since = 0
    for step in range(1, 101):
        for _ in range(2):                          # two basic steps of 32 ms
            sim.step()
            if sim.time_ms % 320 == 0:
                told.append((sim.time_ms, sup.step()))
        travelled = speed * WHEEL_RADIUS * (sim.time_ms - moving_since) / 1000.0
        want = [x0 + travelled * math.cos(heading), y0 + travelled * math.sin(heading)]
        assert list(bot.pose.translation[:2]) == pytest.approx(want, abs=1e-12), step
        assert emitter.send(datestr(step))
        sent.append(datestr(step))
        values = [d.value for d in ps]
        assert values == pytest.approx([67.19] * 8, abs=0.01), step
        bgra = np.asarray(camera.image, dtype=np.uint8).reshape(39, 52, 4)
        assert len(np.unique(bgra.reshape(-1, 4), axis=0)) > 2, step   # the sky and the floor's shades at least
        rgb = np.ascontiguousarray(bgra[:, :, 2::-1])                # wb_camera_get_image's RGB, as MATLAB's
        inverse = 255 - rgb
        display.apply(display.check([["load", 1, 52, 39, _to_bgra(inverse.tobytes(), WB_IMAGE_RGB, 52 * 39)],
                                     ["paste", 1, 0, 0, False], ["delete", 1],
                                     ["line", 0, 19, 51, 19], ["line", 25, 0, 25, 38]]), sim.time_ms)
        words = (0xFF << 24) | (inverse[:, :, 0].astype(np.uint32) << 16) \
            | (inverse[:, :, 1].astype(np.uint32) << 8) | inverse[:, :, 2].astype(np.uint32)
        words[19, :] = 0xFF000000
        words[:, 25] = 0xFF000000
        assert (np.asarray(display.pixels, dtype=np.uint32).reshape(39, 52) == words).all(), step
        for packet in receiver.take():
            heard.append((sim.time_ms, list(struct.unpack("<3d", packet.data))))
        v_left, v_right = braitenberg(values)
        assert (v_left, v_right) == (SPEED_UNIT * 1000, SPEED_UNIT * 1000) == (6.28, 6.28)
        if speed == 0.0:
            speed, moving_since = v_left, sim.time_ms
        left.set_velocity(v_left)
        right.set_velocity(v_right)
    assert speed * WHEEL_RADIUS == pytest.approx(0.1256, abs=1e-15)
    # the Supervisor's positions, each heard by the e-puck at its step after the Supervisor's (to 1e-15)
    assert len(told) == 20 and [t for t, _ in heard] == [t + 64 for t, _ in told[:-1]]
    for (t, pos), (_, got) in zip(told, heard):
        travelled = 0.1256 * (t - 64) / 1000.0
        assert got == pos == pytest.approx([x0 + travelled * math.cos(heading), y0 + travelled * math.sin(heading),
                                            0.0], abs=1e-12), t
    # every date string the e-puck sent up to the Supervisor's last step, in order, each label 0's text
    assert sup.labels == [s[:-1].decode() for s in sent[:len(sup.labels)]] and len(sup.labels) >= 95


def test_a_python_supervisor_showing_a_received_c_string_labels_it_up_to_its_nul(monkeypatch) -> None:
    """A Python Supervisor making e-puck_position_supervisor.c's calls passes ``Receiver.getString()`` (the
    packet's bytes, the sender's NUL kept, as Webots' Python gives them) to ``setLabel``. Webots hands the
    str to libController as a C string, so the label reads up to the NUL; the client sent the NUL on and the
    server refused the label ("only characters 32..127"), one error line per packet and no label shown. Now
    the client cuts text (and font) at the first NUL, and the server takes the label."""
    from types import SimpleNamespace

    from sensorium.client import wb_supervisor
    from sensorium.server.sim import viewshot

    sent: list[dict] = []
    fake = SimpleNamespace(supervisor=True, name=SUPERVISOR)
    monkeypatch.setattr(wb_supervisor, "current", lambda: fake)
    monkeypatch.setattr(wb_supervisor, "_call", lambda r, item, args=None: sent.append(args) or {"success": True})
    text = datestr(7).decode()
    assert text.endswith("\0")
    wb_supervisor.wb_supervisor_set_label(0, text, 0.01, 0.01, 0.1, 0x000000, 0.0, "Arial\0Bold")
    (args,) = sent
    assert (args["text"], args["font"]) == ("08-Dec-2026 00:00:07", "Arial")
    labels = viewshot.Labels()
    labels.set(**{k: args[k] for k in ("id", "text", "x", "y", "size", "color", "transparency", "font")})
    assert [label.text for _, label in labels.items()] == ["08-Dec-2026 00:00:07"]
    with pytest.raises(ValueError, match="only characters 32..127"):        # what the server said before
        labels.set(0, text, 0.01, 0.01, 0.1, 0, 0.0, "Arial")


MATLAB_CONTROLLER = '''
# matlab.m's calls in Python (our own text): the distance sensors, the camera's inverse on the turret's
# Display with its gunsight lines, a date string to the Supervisor each step, its positions read back, and
# the Braitenberg wheel speeds; it prints the positions it hears and each 25th step's readings.
import struct
from controller import Display, Robot

BRAITENBERG = [(150, -35), (100, -15), (80, -10), (-10, -10), (-10, -10), (-10, 80), (-30, 100), (-20, 150)]
robot = Robot()
ps = [robot.getDevice(f"ps{i}") for i in range(8)]
for p in ps:
    p.enable(64)
display = robot.getDevice("display")
display.setColor(0x000000)
camera = robot.getDevice("camera")
camera.enable(64)
emitter, receiver = robot.getDevice("emitter"), robot.getDevice("receiver")
receiver.enable(64)
left, right = robot.getDevice("left wheel motor"), robot.getDevice("right wheel motor")
for m in (left, right):
    m.setPosition(float("inf"))
    m.setVelocity(0.0)
print("Hello!", flush=True)
step = 0
while robot.step(64) != -1:
    step += 1
    emitter.send(b"08-Dec-2026 00:%02d:%02d\\0" % (step // 60 % 60, step % 60))
    values = [p.getValue() for p in ps]
    w, h, image = camera.getWidth(), camera.getHeight(), camera.getImage()
    inverse = bytes(255 - image[4 * i + c] for i in range(w * h) for c in (2, 1, 0))
    ref = display.imageNew(inverse, Display.RGB, w, h)
    display.imagePaste(ref, 0, 0, False)
    display.imageDelete(ref)
    display.drawLine(0, 19, 51, 19)
    display.drawLine(25, 0, 25, 38)
    while receiver.getQueueLength() > 0:
        print("heard %d %r %r %r" % (round(robot.getTime() * 1000), *struct.unpack("3d", receiver.getBytes())),
              flush=True)
        receiver.nextPacket()
    speed = [min(sum((1 - v / 500) * row[j] for v, row in zip(values, BRAITENBERG)) * 5, 1000) for j in range(2)]
    if step % 25 == 0:
        copy = display.imageCopy(0, 0, w, h)
        display.imageSave(copy, f"display_{step}.png")
        display.imageDelete(copy)
        print("step", step, *(f"{v:.2f}" for v in values), *speed, flush=True)
    left.setVelocity(0.00628 * speed[0])
    right.setVelocity(0.00628 * speed[1])
'''


@pytest.mark.slow
def test_the_controllers_run_the_straight_drive_under_sensorium_run(tmp_path: Path) -> None:
    """Our Python text of matlab.m on the e-puck and the Supervisor's C calls (Webots'
    e-puck_position_supervisor.c from $WEBOTS_HOME, unchanged, else tests/c/epuck_position_supervisor.c) built
    against our libController, under ``sensorium run`` for 8 s: no error line; the Supervisor sends the
    e-puck's translation on the closed form's straight line at 0.1256 m/s (1e-12), which the e-puck hears one
    step later; label 0 shows each date string the e-puck sent, in order (the C string up to its NUL); the
    wheels stay at the capped 1000 units while the sensors read 67.19; the Display's saved images are the
    inverted camera under black gunsight lines."""
    import os
    import shutil
    import subprocess

    from _serve import child_env, sensorium
    from PIL import Image

    if shutil.which("cc") is None or shutil.which("make") is None:
        pytest.skip("needs a C toolchain (build-essential, libzmq3-dev, libmsgpack-dev, libpng-dev, libjpeg-dev)")
    clib = Path(__file__).parent.parent / "sensorium" / "client" / "c"
    build = tmp_path / "cbuild"
    done = subprocess.run(["make", "-s", "-C", str(clib), f"BUILD={build}"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    libs = subprocess.run(["make", "-s", "-C", str(clib), "libs"], capture_output=True, text=True, timeout=60).stdout.split()
    webots = Path(os.environ.get("WEBOTS_HOME") or "/nonexistent") / "projects" / "languages" / "matlab" / \
        "controllers" / "e-puck_position_supervisor" / "e-puck_position_supervisor.c"
    source = webots if webots.is_file() else Path(__file__).parent / "c" / "epuck_position_supervisor.c"
    folder = tmp_path / "controllers" / "e-puck_position_supervisor"
    folder.mkdir(parents=True)
    done = subprocess.run(["cc", "-std=c99", f"-I{clib / 'include'}", str(source), "-o",
                           str(folder / "e-puck_position_supervisor"), str(build / "libController.a"), *libs, "-lm"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    (tmp_path / "controllers" / "matlab").mkdir()
    (tmp_path / "controllers" / "matlab" / "matlab.py").write_text(MATLAB_CONTROLLER)
    for folder_name in ("sweep34", "sweep22"):
        shutil.copytree(DATA / folder_name, tmp_path / folder_name)
    world = tmp_path / "sweep34" / "e-puck_matlab.wbt"
    head, tail = world.read_text().split('controller "<extern>"', 1)
    world.write_text(head + 'controller "matlab"' + tail.replace('controller "<extern>"',
                                                                 'controller "e-puck_position_supervisor"'))
    run = subprocess.run(sensorium("run", str(world), "--until", "8000", "--rpc", "tcp://127.0.0.1:0",
                                   "--pub", "tcp://127.0.0.1:0"),
                         env=child_env(), cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    assert "Error" not in run.stdout + run.stderr and "Traceback" not in run.stderr, run.stderr[-2000:]
    lines = run.stdout.splitlines()
    epuck = [ln.split("] ", 1)[1] for ln in lines if ln.startswith(f"[{EPUCK}] ")]
    sup = [ln.split("] ", 1)[1] for ln in lines if ln.startswith("[robot] ")]
    assert epuck[0] == "Hello!"
    x0, y0, heading = START

    def on_line(t_ms: float) -> list[float]:
        travelled = 0.1256 * (t_ms - 64) / 1000.0
        return [x0 + travelled * math.cos(heading), y0 + travelled * math.sin(heading), 0.0]

    sent = [[float(v) for v in ln.split()[1:]] for ln in sup if ln.startswith("sent")]
    assert [s[0] for s in sent] == [1600.0, 3200.0, 4800.0, 6400.0, 8000.0]
    for t, *pos in sent:
        assert pos == pytest.approx(on_line(t), abs=1e-12), t
    heard = [[float(v) for v in ln.split()[1:]] for ln in epuck if ln.startswith("heard")]
    assert [h[0] for h in heard] == [320.0 * k + 64 for k in range(1, 25)]
    for t, *pos in heard:
        assert pos == pytest.approx(on_line(t - 64), abs=1e-12), t
    labels = [ln.split(" ", 2)[1:] for ln in sup if ln.startswith("label")]
    assert len(labels) >= 5 and all(text == datestr(int(n)).decode()[:-1] for n, text in labels), labels
    steps = [ln.split()[1:] for ln in epuck if ln.startswith("step")]
    assert [int(s[0]) for s in steps] == [25, 50, 75, 100, 125]
    assert all(s[1:9] == ["67.19"] * 8 and s[9:] == ["1000", "1000"] for s in steps), steps
    for k in (25, 125):
        with Image.open(tmp_path / "controllers" / "matlab" / f"display_{k}.png") as im:   # its own folder
            shown = np.asarray(im.convert("RGB"))
        assert shown.shape == (39, 52, 3)
        assert (shown[19] == 0).all() and (shown[:, 25] == 0).all()
        assert shown.mean() > 0


# ------------------------------------------------------------------------------------------------ cpp example
# example (projects/languages/cpp, R2023b): three MyBots (wheels r 0.025 m, 0.09 m apart) running slave.cpp
# (32 ms; mode "avoid obstacles" at first: 5 ± 0.1·(ds0 − ds1) rad/s, "move forward" 10, "turn" 5/−5, "stop"),
# the `driver` Supervisor (128 ms) sending the order of the key pressed, null-terminated, and 'R' moving
# ROBOT1 to (−0.3, −0.1). No key can be pressed headless: the orders are sent here at the driver's steps.
CPP_WORLD = DATA / "sweep34" / "example_cpp.wbt"
SLAVES = {"robot1": (-0.140251, 0.362306, -0.221754), "robot2": (-0.511288, -0.288898, -2.67372),
          "robot3": (0.0, -0.15, 2.54759)}
ORDERS = {512: b"move forward", 1024: b"turn", 1536: b"stop", 2560: b"avoid obstacles"}


def slave_speeds(mode: str, ds0: float, ds1: float) -> tuple[float, float]:
    """slave.cpp's wheel speeds in ``mode``."""
    delta = ds0 - ds1
    return {"avoid obstacles": (min(10.0, max(-10.0, 5 + 0.1 * delta)), min(10.0, max(-10.0, 5 - 0.1 * delta))),
            "move forward": (10.0, 10.0), "turn": (5.0, -5.0), "stop": (0.0, 0.0)}[mode]


def test_the_cpp_example_world_loads_its_three_slaves_and_the_driver() -> None:
    """One load line (the arena's built-in stand-in); three two-wheel MyBots where the world puts them and
    the Driver with its Emitter, every receiver on channel 0 as the emitter."""
    w = load_world(CPP_WORLD)
    assert len(w.warnings) == 1 and "CircleArena" in w.warnings[0]
    sim = Simulation(w, "exact")
    assert [r.name for r in w.world.robots] == [*SLAVES, "Driver"]
    for name, (x, y, heading) in SLAVES.items():
        pose = sim.robot(name).pose
        assert list(pose.translation) == pytest.approx([x, y, 0.0], abs=1e-12)
        assert math.atan2(pose.rotation[1, 0], pose.rotation[0, 0]) == pytest.approx(heading, abs=1e-12)
        assert sim.device(f"{name}/receiver").channel == 0
    assert sim.device("Driver/emitter").channel == 0


def test_the_slaves_follow_the_drivers_orders_by_the_closed_forms() -> None:
    """slave.cpp's calls on the three robots and the driver's orders (its 'F', 'T', 'S', 'A' at 512, 1024,
    1536 and 2560 ms; 'R' and 'G' at 2048) for 3.2 s. Each robot reads the order at its first step after
    the driver's (the packet leaves at the next basic step) and its C string, up to the NUL, picks the mode:
    avoiding at 0.125 m/s straight while both sensors read 0 (nothing within 0.15 m), forward at 0.25 m/s,
    turning in place at 0.025 · (−5 − 5) / 0.09 = −2.78 rad/s, standing. Every pose is the exact arc of the
    speeds set the step before (1e-12 m and rad, each 32 ms step); 'R' puts ROBOT1 at (−0.3, −0.1, 0), its
    heading kept, which 'G' reads back, and the last 'A' drives it on from there."""
    sim = Simulation(load_world(CPP_WORLD), "exact")
    lv = Live(sim)
    lv.ok(A, "attach", {"robot": "Driver"})
    robot1 = lv.ok(A, "/Driver/robot/get_from_def", {"name": "ROBOT1"})["node"]
    emitter = sim.device("Driver/emitter")
    slaves = {}
    for name, start in SLAVES.items():
        ds = [sim.device(f"{name}/ds0"), sim.device(f"{name}/ds1")]
        for d in ds:
            d.enable(32)
        sim.device(f"{name}/camera").enable(128)
        receiver = sim.device(f"{name}/receiver")
        receiver.enable(32)
        motors = [sim.robot(name).motor("left wheel motor"), sim.robot(name).motor("right wheel motor")]
        for m in motors:
            m.set_position(math.inf)
            m.set_velocity(0.0)
        slaves[name] = {"ds": ds, "receiver": receiver, "motors": motors, "mode": "avoid obstacles",
                        "pose": list(start), "speeds": (0.0, 0.0), "heard": [], "queue": []}
    for _ in range(100):
        sim.step()
        t = sim.time_ms
        if t in ORDERS:
            assert emitter.send(ORDERS[t] + b"\0")
        for name, s in slaves.items():
            vl, vr = s["speeds"]
            x, y, th = s["pose"]
            v, om = 0.025 * (vl + vr) / 2, 0.025 * (vr - vl) / 0.09
            if om == 0.0:
                x, y = x + v * 0.032 * math.cos(th), y + v * 0.032 * math.sin(th)
            else:
                x += v / om * (math.sin(th + om * 0.032) - math.sin(th))
                y -= v / om * (math.cos(th + om * 0.032) - math.cos(th))
                th += om * 0.032
            if name == "robot1" and t == 2080:          # where the Supervisor put it (standing: "stop")
                x, y = -0.3, -0.1
            s["pose"] = [x, y, th]
            pose = sim.robot(name).pose
            assert list(pose.translation[:2]) == pytest.approx([x, y], abs=1e-12), (name, t)
            yaw = math.atan2(pose.rotation[1, 0], pose.rotation[0, 0])
            assert math.remainder(yaw - th, 2 * math.pi) == pytest.approx(0.0, abs=1e-12), (name, t)
            s["queue"] += s["receiver"].take()
            if s["queue"]:                               # one packet a step, as slave.cpp reads them
                s["mode"] = s["queue"].pop(0).data.split(b"\0", 1)[0].decode()
                s["heard"].append((t, s["mode"]))
            ds0, ds1 = (d.value for d in s["ds"])
            if s["mode"] == "avoid obstacles":
                assert (ds0, ds1) == (0.0, 0.0), (name, t)
            s["speeds"] = slave_speeds(s["mode"], ds0, ds1)
            for m, speed in zip(s["motors"], s["speeds"]):
                m.set_velocity(speed)
        if t == 2048:                                   # 'R' after the driver's step, then 'G' at its next
            lv.ok(A, "/Driver/robot/set_field", {"node": robot1, "field": "translation", "value": [-0.3, -0.1, 0.0]})
        if t == 2176:
            assert lv.ok(A, "/Driver/robot/get_field", {"node": robot1, "field": "translation"})["value"] == \
                pytest.approx([-0.3, -0.1, 0.0], abs=1e-15)
    for name, s in slaves.items():
        assert s["heard"] == [(t + 32, order.decode()) for t, order in ORDERS.items()], name
    # the turn: 480 ms of −2.78 rad/s, and 32 ms more of the forward motion before it was heard
    turned = slaves["robot3"]["pose"][2] - SLAVES["robot3"][2]
    assert math.remainder(turned + 0.025 * 10 / 0.09 * 0.512, 2 * math.pi) == pytest.approx(0.0, abs=1e-12)


@pytest.mark.slow
def test_the_cpp_controllers_follow_the_scheduled_keys_under_sensorium_run(tmp_path: Path) -> None:
    """Our C++ texts of slave.cpp (tests/c/example_slave.cpp) on the three robots and of driver.cpp
    (tests/c/example_driver.cpp: the keys from a schedule, none can be pressed headless) built against our
    libController's C++ layer, under ``sensorium run`` for 3.2 s: each slave hears each order one basic step
    after the driver sent it (544, 1056, 1568, 2592 ms) and sets the wheels the mode gives (5/5 avoiding with
    both sensors at 0, 10/10, 5/−5, 0/0); 'G' reads ROBOT1 where 'R' put it, (−0.3, −0.1), then 0.06 m on
    along its heading after 480 ms of avoiding at 0.125 m/s (the turn's −2.78 rad/s for 512 ms, 1e-12)."""
    import shutil
    import subprocess

    from _serve import child_env, sensorium

    if shutil.which("c++") is None or shutil.which("make") is None:
        pytest.skip("needs a C++ toolchain (build-essential, libzmq3-dev, libmsgpack-dev, libpng-dev, libjpeg-dev)")
    clib = Path(__file__).parent.parent / "sensorium" / "client" / "c"
    build = tmp_path / "cbuild"
    done = subprocess.run(["make", "-s", "-C", str(clib), f"BUILD={build}"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    libs = subprocess.run(["make", "-s", "-C", str(clib), "libs"], capture_output=True, text=True, timeout=60).stdout.split()
    for name in ("slave", "driver"):
        folder = tmp_path / "controllers" / name
        folder.mkdir(parents=True)
        done = subprocess.run(["c++", "-std=c++11", "-Wall", "-Werror", f"-I{clib / 'include'}",
                               str(Path(__file__).parent / "c" / f"example_{name}.cpp"), "-o", str(folder / name),
                               str(build / "libController.a"), *libs, "-lm"], capture_output=True, text=True, timeout=180)
        assert done.returncode == 0, done.stderr
    (tmp_path / "worlds").mkdir()
    world = tmp_path / "worlds" / "example.wbt"
    text = CPP_WORLD.read_text()
    head, driver = text.rsplit('controller "<extern>"', 1)
    world.write_text(head.replace('controller "<extern>"', 'controller "slave"') + 'controller "driver"' + driver)
    run = subprocess.run(sensorium("run", str(world), "--until", "3200", "--rpc", "tcp://127.0.0.1:0",
                                   "--pub", "tcp://127.0.0.1:0"),
                         env=child_env(), cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    assert "Error" not in run.stdout + run.stderr, run.stderr[-2000:]
    lines = run.stdout.splitlines()
    said = [ln.split("] ", 1)[1] for ln in lines if ln.startswith("[Driver] ")]
    assert [ln for ln in said if ln.startswith("Please")] == \
        ["Please, move forward 512", "Please, turn 1024", "Please, stop 1536", "Please, avoid obstacles 2560"]
    for name in SLAVES:
        out = [ln.split("] ", 1)[1] for ln in lines if ln.startswith(f"[{name}] ")]
        assert [ln for ln in out if ln.startswith("I should")] == \
            ["I should move forward! 544", "I should turn! 1056", "I should stop! 1568", "I should avoid obstacles! 2592"]
        speeds = [ln.split()[1:] for ln in out if ln.startswith("speeds")]
        assert [s[0] for s in speeds] == ["512", "1024", "1536", "2048", "2560", "3072"]
        assert [s[1:3] for s in speeds] == [["5", "5"], ["10", "10"], ["5", "-5"], ["0", "0"], ["0", "0"], ["5", "5"]]
        assert all(s[3:] == ["0", "0"] for s in speeds if s[1:3] == ["5", "5"]), name
    where = [ln for ln in said if ln.startswith("ROBOT1 is located")]
    got = [[float(v) for v in ln.split("(")[1].rstrip(")").split(",")] for ln in where]
    heading = SLAVES["robot1"][2] - 0.025 * 10 / 0.09 * 0.512
    assert got[0] == pytest.approx([-0.3, -0.1], abs=1e-15)
    assert got[1] == pytest.approx([-0.3 + 0.06 * math.cos(heading), -0.1 + 0.06 * math.sin(heading)], abs=1e-12)
