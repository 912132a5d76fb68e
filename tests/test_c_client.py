"""The C controller library (sensorium/client/c) against a live server, built with AddressSanitizer
and UBSan: Webots-style C controllers read exactly (bit for bit) what the Python client reads on
the same world, step in lockstep beside Python controllers, are released when SIGKILLed, keep
their session while computing, and fail with one clear line on a bad URL or a missing server. Every
Webots controller header is here and compiles alone as C and C++; the last ones added (console,
lidar/contact points, string/system helpers, Microphone, Radio, robot window messages, the vehicle
library's one-line refusal) are used by tests/c/headers.c and tests/c/vehicle_cpp.cpp.
"""

from __future__ import annotations

import json
import math
import os
import re
import shutil
import signal
import struct
import subprocess
import sys
import time
from pathlib import Path

import pytest
from _serve import Served, serve

REPO = Path(__file__).resolve().parents[1]
CLIB = REPO / "sensorium" / "client" / "c"
TESTS_C = REPO / "tests" / "c"
ARENA = REPO / "sensorium" / "worlds" / "arena.yaml"
TRIO = REPO / "tests" / "worlds" / "trio.yaml"
SCRIPT_PY = REPO / "tests" / "controllers" / "script.py"
BRAITENBERG_PY = REPO / "sensorium" / "client" / "examples" / "braitenberg.py"
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=1:exitcode=86", "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"}
ENV = {**os.environ, "PYTHONUNBUFFERED": "1", **SAN_ENV}
CDEVICES = REPO / "tests" / "worlds" / "cdevices.yaml"
ENCODERS_PY = REPO / "tests" / "controllers" / "encoders.py"
CONTROLLERS = ["script", "light_sequence", "proximity", "lidar_reader", "braitenberg", "encoders", "supervisor_check",
               "wire_vectors", "every_device", "headers", "car_driver", "car_lights", "car_hostile", "supervisor_scene",
               "supervisor_remove", "supervisor_import", "ignores_minus_one", "root_children", "supervisor_protos",
               "nested_nodes", "top_groups", "robot_window", "window_echo", "world_names"]
API_TESTS = ["motion_sensors", "emitter_receiver", "robot_devices"]      # tests/c/api: Webots-style API tests
C_API_WORLD = REPO / "tests" / "worlds" / "c_api.yaml"
HEADERS_WORLD = REPO / "tests" / "worlds" / "headers.yaml"
CAR_WORLD = REPO / "tests" / "worlds" / "car.yaml"
CAR_LIGHTS_WORLD = REPO / "tests" / "worlds" / "car_lights.yaml"
SCENE_WORLD = REPO / "tests" / "worlds" / "supervisor_scene.yaml"
REMOVE_WORLD = REPO / "tests" / "worlds" / "supervisor_remove.yaml"
ROOT_WORLD = REPO / "tests" / "worlds" / "root_children.wbt"
PROTOS_WORLD = REPO / "tests" / "worlds" / "proto" / "supervisor_protos.wbt"
NESTED_WORLD = REPO / "tests" / "worlds" / "nested_nodes.wbt"
GROUPS_WORLD = REPO / "tests" / "worlds" / "top_groups.wbt"
CONTROL_NAMES_WORLD = REPO / "tests" / "worlds" / "control_names.yaml"

pytestmark = pytest.mark.skipif(sys.platform == "win32" or shutil.which("cc") is None,
                                reason="needs a POSIX C toolchain (build-essential, libzmq3-dev, libmsgpack-dev, libpng-dev)")


def _make(*args: str) -> str:
    done = subprocess.run(["make", "-s", "-C", str(CLIB), *args], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout


def sanitized_controller(tmp_path_factory, src: Path) -> str:
    """One test controller (C) linked to the library built with -fsanitize=address,undefined, for a
    test file's own fixture; skipped without a C toolchain."""
    if sys.platform == "win32" or shutil.which("cc") is None:
        pytest.skip("needs a POSIX C toolchain (build-essential, libzmq3-dev, libmsgpack-dev, libpng-dev)")
    build = tmp_path_factory.mktemp("cbuild")
    _make(f"BUILD={build}", "SANITIZE=1")
    libs = _make("libs").split()
    exe = build / src.stem
    done = subprocess.run(["cc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-g", "-fsanitize=address,undefined",
                           "-fno-sanitize-recover=undefined", f"-I{CLIB / 'include'}", f"-I{TESTS_C}", str(src),
                           "-o", str(exe), str(build / "libController.a"), *libs, "-lm"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return str(exe)


@pytest.fixture(scope="module")
def cbin(tmp_path_factory) -> dict[str, str]:
    """The library built with -fsanitize=address,undefined and the test controllers linked to it."""
    build = tmp_path_factory.mktemp("cbuild")
    _make(f"BUILD={build}", "SANITIZE=1")
    libs = _make("libs").split()
    out = {}
    sources = ([(n, TESTS_C / f"{n}.c") for n in CONTROLLERS] + [(n, TESTS_C / "api" / f"{n}.c") for n in API_TESTS]
               + [("api_check", CLIB / "tests" / "api_check.c")])
    for name, src in sources:
        exe = build / name
        cmd = ["cc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-g", "-fsanitize=address,undefined",
               "-fno-sanitize-recover=undefined", f"-I{CLIB / 'include'}", f"-I{TESTS_C}", str(src), "-o", str(exe),
               str(build / "libController.a"), *libs, "-lm"]
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, done.stderr
        out[name] = str(exe)
    for name in ("braitenberg_cpp", "supervisor_cpp", "vehicle_cpp", "camera_cpp"):  # the header-only C++ layer
        exe = build / name
        cmd = ["c++", "-std=c++11", "-Wall", "-Wextra", "-Werror", "-g", "-fsanitize=address,undefined",
               f"-I{CLIB / 'include'}", str(TESTS_C / f"{name}.cpp"), "-o", str(exe), str(build / "libController.a"),
               *libs]
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        out[name] = str(exe)
    return out


@pytest.fixture
def servers():
    started: list[Served] = []

    def start(world: Path = ARENA, *extra: str, **endpoints: str) -> Served:
        started.append(serve(world, *extra, env=SAN_ENV, **endpoints))
        return started[-1]

    yield start
    for s in started:
        s.stop()


def start(cmd: list[str], url: str | None = None, **env: str) -> subprocess.Popen:
    full = {**ENV, **env}
    if url is not None:
        full["SENSORIUM_CONTROLLER_URL"] = url
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=full, cwd=str(REPO))


def finish(p: subprocess.Popen, timeout: float = 120.0) -> tuple[int, list[str], str]:
    try:
        out, err = p.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        p.kill()
        out, err = p.communicate()
        raise AssertionError(f"{p.args} still running after {timeout} s; stderr:\n{err}") from None
    assert "Sanitizer" not in err and "runtime error" not in err, err
    return p.returncode, out.splitlines(), err


def sanitized_run(tmp_path_factory, src: Path, world: Path, robot: str) -> tuple[int, list[str], str]:
    """``src`` built by :func:`sanitized_controller`, run as ``robot``'s controller against ``sensorium
    serve WORLD`` (sanitizers on) until it ends: :func:`finish`'s (code, stdout lines, stderr)."""
    exe = sanitized_controller(tmp_path_factory, src)
    with serve(world, env=SAN_ENV) as server:
        return finish(start([exe], server.url(robot)))


def run(cmd: list[str], url: str | None = None, **env: str) -> list[str]:
    code, out, err = finish(start(cmd, url, **env))
    assert code == 0, f"{cmd[0]} exited {code}:\n{err}"
    return out


def python_script(url: str, *ops: str) -> list[str]:
    return run([sys.executable, "-m", "sensorium", "controller", "--url", url, str(SCRIPT_PY), *ops])


def data(lines: list[str]) -> list[str]:
    return [line for line in lines if not line.startswith("#")]


def fields(line: str) -> dict[str, str]:
    t, status, *rest = line.split(" ")
    return {"t": t, "status": status, **dict(item.split("=", 1) for item in rest)}


NAN_BITS = "7ff8000000000000"


# ====================================================================== build

def test_library_builds_warning_free_as_shared_and_static_and_headers_stand_alone(tmp_path):
    _make(f"BUILD={tmp_path}", "check")   # -Wall -Wextra -Werror; each header alone: C99 -pedantic and C++11
    assert (tmp_path / "libController.a").is_file() and (tmp_path / "libController.so").is_file()
    symbols = subprocess.run(["nm", "-D", "--defined-only", str(tmp_path / "libController.so")],
                             capture_output=True, text=True, check=True).stdout
    for fn in ("wb_robot_init", "wb_robot_step", "wb_lidar_get_point_cloud", "wb_motor_set_velocity",
               "wb_distance_sensor_get_lookup_table", "wb_light_sensor_get_value"):
        assert f" T {fn}\n" in symbols, fn
    # every function a header declares is in the library (a controller that compiles also links)
    declaration = re.compile(r"^(?!\s*#)(?!\s*/?\*)[A-Za-z_][\w \*]*?\b(wbu?_\w+)\s*\(", re.M)
    declared = {name for h in (CLIB / "include" / "webots").rglob("*.h") for name in declaration.findall(h.read_text())}
    assert len(declared) > 550 and "wbu_driver_init" in declared and "wb_supervisor_node_get_root" in declared
    assert sorted(declared - set(re.findall(r" T (\w+)$", symbols, re.M))) == []


# Webots' controller headers (include/controller/c/webots and cpp/webots of Webots R2023–R2025), as a
# controller includes them; plugins/robot_window/robot_wwi.h is a controller's side of robot window
# messages (none here). Left out on purpose: the robot window plugins' own headers (robot_window.h,
# the old robot_wwi.h, plugins/robot_window/default.h and generic*.h, robot_window_utils/*,
# utils/default_robot_window.h: a headless server has no window), remote_control.h (a plugin's API,
# not a controller's), differential_wheels.h and vacuum_cup.h (Webots' removed and renamed devices) and
# transform_node_object.h (no function of the API uses it).
WEBOTS_C_HEADERS = """accelerometer altimeter brake camera camera_recognition_object compass connector console contact_point
    device display distance_sensor emitter gps gyro inertial_unit joystick keyboard led lidar lidar_point light_sensor
    microphone motor mouse mouse_state nodes pen position_sensor radar radar_target radio range_finder receiver robot
    skin speaker supervisor touch_sensor types vacuum_gripper utils/ansi_codes utils/motion utils/string utils/system
    vehicle/car vehicle/driver plugins/robot_window/robot_wwi""".split()
WEBOTS_CPP_HEADERS = """Accelerometer Altimeter Brake Camera Compass Connector Device Display DistanceSensor Emitter Field GPS Gyro
    ImageRef InertialUnit Joystick Keyboard LED Lidar LightSensor Motor Mouse Node Pen PositionSensor Proto Radar RangeFinder
    Receiver Robot Skin Speaker Supervisor TouchSensor VacuumGripper utils/AnsiCodes utils/Motion vehicle/Car
    vehicle/Driver""".split()
VEHICLE_LINE = ("Error: {func}(): robot 'car' has no ackermann_drive: Sensorium's vehicle library drives a car-like robot "
                "whose world entry has one (README \"World files\"; a .wbt car is mapped when its steering and wheel "
                "joints are a car's).")


def test_every_webots_controller_header_is_here():
    """Each compiles alone as C99 and C++11 (the .hpp as C++11, linked): `make check` above."""
    include = CLIB / "include" / "webots"
    missing = [h for h in WEBOTS_C_HEADERS if not (include / f"{h}.h").is_file()]
    missing += [h for h in WEBOTS_CPP_HEADERS if not (include / f"{h}.hpp").is_file()]
    assert missing == []
    assert "WbLidarPoint;" in (include / "lidar_point.h").read_text()          # one definition, where Webots has it
    assert "WbLidarPoint" not in (include / "types.h").read_text()
    assert '#include "lidar_point.h"' in (include / "lidar.h").read_text()
    assert '#include "contact_point.h"' in (include / "supervisor.h").read_text()


def test_console_strings_system_radio_messages_and_the_vehicle_no_values(cbin):
    env = {"HEADERS_TEST_VALUE": "v4lue"}
    full = {k: v for k, v in ENV.items() if k not in ("WEBOTS_INSTANCE_PATH", "HEADERS_TEST_UNSET")}
    p = subprocess.Popen([cbin["headers"]], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         env={**full, **env}, cwd=str(REPO))
    code, out, err = finish(p)
    assert code == 0, err
    assert out == ["lidar_point 1.5 -2 0.25 3 0.125",
                   "contact_point 1 -2 3.5 7",
                   "console to stdout",                                     # WB_STDOUT, in order with printf
                   "strsep [a] [b\\,c] [] [d] end",                        # an escaped delimiter does not split
                   "replace [three two three] [two one] (null) (null)",
                   "getenv v4lue (null)",
                   "short_path /a b/c tmpdir /tmp instance (null)",
                   "radio_message 5 hello bob refused",
                   "driver 0 -1 nan -1 0",                                  # not possible; step: the end
                   "car nan nan 0"]
    lines = err.splitlines()
    assert lines[0] == "console to stderr" and len(lines) == 3, err
    assert lines[1] == "Error: wb_console_print(): unknown stream 3 (WB_STDOUT is 1, WB_STDERR is 2)"
    assert lines[2].startswith("Error: wb_radio_message_new(): invalid body (-1 bytes")


@pytest.mark.parametrize("argv, func", [(["headers", "driver"], "wbu_driver_init"), (["headers", "car"], "wbu_car_init"),
                                        (["vehicle_cpp", "driver"], "wbu_driver_init"), (["vehicle_cpp"], "wbu_car_init")])
def test_the_vehicle_library_ends_a_controller_of_a_robot_that_is_not_a_car_with_one_line(cbin, servers, argv, func):
    p = start([cbin[argv[0]], *argv[1:]], servers(HEADERS_WORLD).url("car"))
    code, out, err = finish(p)
    assert code == 1 and err.splitlines() == [VEHICLE_LINE.format(func=func)], err
    assert "returned" not in out and "constructed" not in out
    assert out[:1] == (["\x1b[1m4 3\x1b[0m"] if argv[0] == "vehicle_cpp" else [])   # the C++ enums are Webots'


def test_a_webots_style_c_driver_controller_drives_the_closed_form_circle(cbin, servers):
    """tests/c/car_driver.c steers 0.2 rad at 20 km/h: from its first step the car is on the circle of
    radius L/tan 0.2 about (0, -radius), its rear axle's centre at 20 km/h (the same closed form as the
    Python Driver's test, tests/test_vehicle_driver.py)."""
    server = servers(CAR_WORLD, "--heartbeat-ms", "500")
    code, out, err = finish(start([cbin["car_driver"]], server.url("car")))
    assert code == 0, err
    # no engine model: one line per function, the first time only (set_throttle is called twice)
    assert [line.split("(")[0] for line in err.splitlines()] == ["Warning: wbu_driver_set_throttle",
                                                                 "Warning: wbu_driver_get_gear"], err
    (driver,) = [line.split()[1:] for line in out if line.startswith("driver ")]
    (car,) = [line.split()[1:] for line in out if line.startswith("car ")]
    L, T, R = 2.6, 1.5, 0.35
    cot, half = 1 / math.tan(0.2), T / (2 * L)
    right, left = math.atan(1 / (cot - half)), math.atan(1 / (cot + half))
    speed, target, angle, t, mode, gear = driver
    assert float(speed) == pytest.approx(20.0, abs=1e-9) and float(target) == 20.0 and (mode, gear) == ("0", "0")
    assert float(angle) == pytest.approx((right + left) / 2, abs=1e-12)      # Webots: the steering encoders' mean
    assert car[:4] == ["1", "2.6000000000000001", "1.5", "0.34999999999999998"] and float(car[4]) == pytest.approx(right, abs=1e-15)
    radius = L / math.tan(0.2)
    ratio = (radius - T / 2) / (2 * radius)                                    # Webots' rear differential
    assert float(car[5]) == pytest.approx(2 * 20 * (1 - ratio) / 3.6 / R, rel=1e-12)
    assert float(car[6]) > 0                                                   # the encoder rolled forward
    pose = server.conn.call("/car/robot/get_pose")
    time_ms = server.conn.call("get_info")["time_ms"]
    assert float(t) * 1000 == pytest.approx(time_ms)
    phi = 20 / 3.6 * time_ms / 1000 / radius
    x, y, _ = pose["translation"]
    assert (x, y) == pytest.approx((radius * math.sin(phi), -radius + radius * math.cos(phi)), abs=1e-9)


def test_the_c_vehicle_library_keeps_the_lights_indicators_and_brake_as_the_python_one(cbin, servers):
    """tests/c/car_lights.c prints the lines tests/controllers/car_lights.py prints: the engine type
    from the world, the brake and brake lights, reverse and the backwards lights, the indicators
    blinking by the simulated time and switching themselves off, the hazard flashers, the lights and
    their LEDs, a free wheel's encoder (tests/test_vehicle_driver.py checks both)."""
    from test_vehicle_driver import BRAKE_LINE, check_car_lights

    server = servers(CAR_LIGHTS_WORLD, "--heartbeat-ms", "500")
    code, out, err = finish(start([cbin["car_lights"]], server.url("car")))
    assert code == 0, err
    check_car_lights(out)
    assert err.splitlines() == [BRAKE_LINE], err       # nothing said to be unsimulated


def test_microphone_radio_contact_points_robot_window_and_unserved_supervisor_functions(cbin, servers):
    server = servers(HEADERS_WORLD)
    code, out, err = finish(start([cbin["headers"], "online"], server.url("car")))
    assert code == 0, err
    assert server.wait() == 3, server.stderr()                 # wb_supervisor_simulation_quit(3): as Webots quits
    online = out[out.index("car nan nan 0") + 1:]
    assert online == ["tags 2 3 omni",                       # Webots' indices: gps, mic, radio, light
                      "microphone 0 NULL 0",                 # no sound: Webots' "no value"
                      "radio 0 0 nan nan (null)",
                      "contacts 0 0 NULL nan NULL",          # a robot without Physics touches nothing
                      "wwi (null) (null) 0",                 # no robot window
                      "default window (null)",               # its default window's functions: compile, run, no effect
                      "step 0",
                      "supervisor NULL 1 SFRotation -1 12 0 0 0  1 0",   # beyond the subset: "no value"; 12 fields;
                      # getCenterOfMass served: 0 0 0 for a robot without Physics (Webots)
                      "after quit -1"]     # the simulation ended for this controller: the next step ends it
    warned = [line for line in err.splitlines() if "does not simulate" in line]
    assert "wbu_default_robot_window" not in err, err
    assert len(warned) == 2 and "Microphone 'mic'" in warned[0] and "Radio 'radio'" in warned[1], err
    assert "Error: wb_microphone_enable(): device tag 3 is 'radio', a Radio" in err
    unserved = sorted(line.split("(")[0] for line in err.splitlines() if "not served by Sensorium" in line)
    assert unserved == ["Error: wb_supervisor_" + f for f in ("node_get_selected", "virtual_reality_headset_is_used")], err
    assert "Error: wb_supervisor_node_export_string(): INVALID_ARGUMENT: node_export_string: Robot 'car' (node 1) has " \
        "no .wbt text here: the world was not loaded from a .wbt file" in err, err      # a YAML world: "" and one line
    # served for a PROTO's interface fields: Webots' line for the robot's SFRotation, 0; the robot (no PROTO)
    # counts the 12 fields served for a Robot (battery and cpuConsumption among them)
    assert "Error: wb_supervisor_field_get_mf_int32() called with wrong field type: SFRotation." in err
    assert "simulation_quit" not in err
    contacts = sorted(line for line in err.splitlines() if "contact" in line)   # Webots' deprecation lines, once each
    assert contacts == [f"Warning: wb_supervisor_node_{f}() is deprecated, use wb_supervisor_node_get_contact_points() "
                        "instead." for f in ("get_contact_point", "get_contact_point_node", "get_number_of_contact_points")], err


# ====================================================================== readings, bit for bit

def test_light_sequence_follows_webots_sampling_rules_and_matches_python(cbin, servers):
    c_lines = run([cbin["light_sequence"]], servers().url("epuck"))
    py_lines = python_script(servers().url("epuck"), "enable", "ls0", "96", "enable", "ls1", "40",
                             "step", "32", "6", "disable", "ls0", "step", "32", "2")
    assert data(c_lines) == py_lines
    rows = [fields(line) for line in py_lines]
    assert [r["t"] for r in rows] == [str(32 * k) for k in range(1, 9)]
    ls0 = [r["ls0"] for r in rows]
    ls1 = [r["ls1"] for r in rows]
    # enable(96) at 0: NaN after steps 1 and 2, first value after step 3, refreshed at 192
    assert ls0[0] == ls0[1] == NAN_BITS and ls0[2] != NAN_BITS
    assert ls0[2] == ls0[3] == ls0[4] and ls0[5] != ls0[4]     # noise makes each measurement new
    assert ls0[6] == ls0[7] == ls0[5]                          # disabled after step 6: last value kept
    # enable(40): effective period 64 (rounded up to basic steps): values at 64, 128, 192, 256
    assert ls1[0] == NAN_BITS and ls1[1] != NAN_BITS
    assert ls1[1] == ls1[2] != ls1[3] == ls1[4] != ls1[5] == ls1[6] != ls1[7]
    assert c_lines[-1] == "# periods 0 40 table 2"


def test_infra_red_and_sonar_readers_match_python(cbin, servers):
    server = servers(ARENA, "--mode", "pause")           # both robots attached before the world moves
    ir = [f"ps{i}" for i in range(8)]
    sonars = ["sonar_front", "sonar_left", "sonar_right", "sonar_back"]
    c_epuck = start([cbin["proximity"], *ir], server.url("epuck"), STEPS="6")
    c_scout = start([cbin["proximity"], *sonars], server.url("scout"), STEPS="6")
    server.wait_attached({"epuck", "scout"})
    server.conn.call("set_mode", {"mode": "fast"})
    outs = [finish(p) for p in (c_epuck, c_scout)]
    assert all(code == 0 for code, _, _ in outs), [err for _, _, err in outs]
    (_, epuck, _), (_, scout, _) = outs
    twin = servers(ARENA, "--mode", "pause")
    ops = lambda names: [x for n in names for x in ("enable", n, "32")] + ["step", "32", "6"]  # noqa: E731
    p_epuck = start([sys.executable, "-m", "sensorium", "controller", "--url", twin.url("epuck"), str(SCRIPT_PY),
                     *ops(ir)])
    p_scout = start([sys.executable, "-m", "sensorium", "controller", "--url", twin.url("scout"), str(SCRIPT_PY),
                     *ops(sonars)])
    twin.wait_attached({"epuck", "scout"})
    twin.conn.call("set_mode", {"mode": "fast"})
    py = [finish(p) for p in (p_epuck, p_scout)]
    assert all(code == 0 for code, _, _ in py), [err for _, _, err in py]
    assert data(epuck) == py[0][1] and data(scout) == py[1][1]
    assert len(data(epuck)) == 6 and len({fields(x)["ps0"] for x in data(epuck)}) == 6     # noisy IR: all new
    assert all(NAN_BITS not in x for x in data(scout))
    # constants against the world file: type, table output extremes, aperture, the table itself
    head = {line.split()[1]: line.split()[2:] for line in epuck + scout if line.startswith("# ")}
    assert head["ps3"][:4] == ["1", "67.189999999999998", "4095", "0.20000000000000001"] and head["ps3"][4] == "10"
    assert [float(v) for v in head["ps3"][5:8]] == [0.0, 4095.0, 0.002]
    assert head["sonar_back"][:5] == ["2", "0", "3", "0.40000000000000002", "2"]
    assert [float(v) for v in head["sonar_back"][5:]] == [0.0, 0.0, 0.0, 3.0, 3.0, 0.0]


def test_lidar_range_image_and_point_cloud_reader_matches_python(cbin, servers):
    c_lines = run([cbin["lidar_reader"], "lidar", "3"], servers().url("scout"))
    py_lines = python_script(servers().url("scout"), "enable", "lidar", "32", "pc", "lidar", "step", "32", "3")
    assert data(c_lines) == py_lines
    row = fields(py_lines[0])
    assert len(row["lidar.range"]) == 2 * 4 * 360 and len(row["lidar.cloud"]) == 2 * 20 * 360
    checks = [line.split() for line in c_lines if line.startswith("#")]
    assert len(checks) == 3
    for check in checks:
        got = dict(zip(check[1::2], check[2::2]))
        assert got == {"points": "360", "layers_ok": "1", "stable": "1", "norm_bad": "0", "null_before": "1",
                       "bad_layer": "1"}


def test_braitenberg_in_c_drives_exactly_like_the_python_example(cbin, servers):
    c_lines = run([sys.executable, "-m", "sensorium", "controller", "--url", servers().url("epuck"),
                   cbin["braitenberg"], "40"])
    py_lines = run([sys.executable, "-m", "sensorium", "controller", "--url", servers().url("epuck"),
                    str(BRAITENBERG_PY), "40"])
    assert len(c_lines) == 40 and c_lines == py_lines
    wheels = {line.split("wheels")[1] for line in c_lines}
    assert len(wheels) > 5 and all("+0.00 +0.00" not in w for w in wheels)       # it really steers
    cpp_lines = run([cbin["braitenberg_cpp"], "40"], servers().url("epuck"))      # the C++ layer, too
    assert cpp_lines == py_lines


def test_every_getter_matches_the_python_client(cbin, servers):
    from sensorium.client import wb

    for robot in ("epuck", "scout"):
        server = servers()
        wb.wb_robot_init(server.url(robot))
        try:
            want = {"robot.name": wb.wb_robot_get_name(), "robot.basic_time_step": wb.wb_robot_get_basic_time_step(),
                    "robot.number_of_devices": str(wb.wb_robot_get_number_of_devices())}
            for i in range(wb.wb_robot_get_number_of_devices()):
                tag = wb.wb_robot_get_device_by_index(i)
                name, kind = wb.wb_device_get_name(tag), wb.wb_device_get_type_name(tag)
                want[f"device {i}"] = f"{name} {kind} 1 |"
                if kind == "DistanceSensor":
                    want[f"{name}.min_value"] = wb.wb_distance_sensor_get_min_value(tag)
                    want[f"{name}.max_value"] = wb.wb_distance_sensor_get_max_value(tag)
                    want[f"{name}.aperture"] = wb.wb_distance_sensor_get_aperture(tag)
                    want[f"{name}.type"] = str(wb.wb_distance_sensor_get_type(tag))
                    want[f"{name}.lookup_table"] = wb.wb_distance_sensor_get_lookup_table(tag)
                elif kind == "LightSensor":
                    want[f"{name}.lookup_table"] = wb.wb_light_sensor_get_lookup_table(tag)
                elif kind == "Lidar":
                    for key in ("horizontal_resolution", "number_of_layers"):
                        want[f"{name}.{key}"] = str(getattr(wb, f"wb_lidar_get_{key}")(tag))
                    for key in ("fov", "vertical_fov", "min_range", "max_range", "frequency", "min_frequency",
                                "max_frequency"):
                        want[f"{name}.{key}"] = getattr(wb, f"wb_lidar_get_{key}")(tag)
                    want[f"{name}.point_cloud_enabled"] = str(int(wb.wb_lidar_is_point_cloud_enabled(tag)))
                else:
                    for key in ("max_velocity", "velocity", "target_position", "min_position", "max_position"):
                        want[f"{name}.{key}"] = getattr(wb, f"wb_motor_get_{key}")(tag)
                    want[f"{name}.type"] = str(wb.wb_motor_get_type(tag))
                    want[f"{name}.position_sensor"] = str(wb.wb_motor_get_position_sensor(tag))
                    want[f"{name}.clamped_velocity"] = wb.wb_motor_get_max_velocity(tag)
                    want[f"{name}.new_target"] = float("inf")
        finally:
            wb.wb_robot_cleanup()
        code, lines, err = finish(start([cbin["api_check"]], server.url(robot)))
        assert code == 0, err
        got = {}
        for line in lines:
            if line.startswith("device "):
                head, index, value = line.split(" ", 2)
                key = f"{head} {index}"
            elif ".lookup_table " in line:
                name, value = line.split(".lookup_table ", 1)
                key = f"{name}.lookup_table"
            else:
                key, _, value = line.rpartition(" ")
            got[key] = value
        for key, value in want.items():
            if isinstance(value, list):
                assert [float(v) for v in got[key].split()] == value, key
            elif isinstance(value, float):
                assert float(got[key]) == value, key
            else:
                assert got[key] == value, key
        assert got["error.no_device"] == got["error.by_index"] == "0"
        assert got["error.bad_tag_value"] == got["error.bad_tag_name"] == got["error.wrong_kind"] == "1"
        assert got["error.bad_step"] == "-1" and got["robot.step"] == "0"
        assert "step duration must be >= 0 ms" in err and "invalid device tag 9999" in err
        assert f'Warning: wb_robot_get_device(): robot "{robot}" has no device "no such device".' in err
        assert f"Error: wb_robot_get_device_by_index(): index {want['robot.number_of_devices']} is outside" in err
        assert float(got["robot.time_after"]) * 1000 == pytest.approx(want["robot.basic_time_step"])
        begun, again, status, t = got["pipelined"].split(",")          # a second step_begin is refused
        assert (begun, again, status) == ("0", "-1", "0") and float(t) * 1000 == pytest.approx(2 * want["robot.basic_time_step"])
        assert got["no_pending"] == "-1" and "a step is already pending" in err and "no step pending" in err


def test_braitenberg_with_encoders_matches_python_and_the_wheel_angles(cbin, servers):
    c_lines = run([cbin["encoders"], "60"], servers(CDEVICES).url("rover"))
    py_lines = run([sys.executable, "-m", "sensorium", "controller", "--url", servers(CDEVICES).url("rover"),
                    str(ENCODERS_PY), "60"])
    assert c_lines == py_lines and len(c_lines) == 60
    rows = [fields(x) for x in c_lines]
    f = lambda bits: struct.unpack("<d", bytes.fromhex(bits)[::-1])[0]  # noqa: E731
    # the first 10 steps at 2.0 / 1.0 rad/s: the noiseless left encoder reads 2.0 rad/s x t exactly
    for k, row in enumerate(rows[:10], start=1):
        assert f(row["left"]) == pytest.approx(2.0 * 0.016 * k, abs=1e-12)
        assert f(row["right"]) == pytest.approx(1.0 * 0.016 * k, abs=0.005)          # noise 0.001 rad
    assert f(rows[0]["ls0"]) != f(rows[0]["ls0"]) and f(rows[1]["ls0"]) == f(rows[1]["ls0"])   # period 32: NaN at 16
    speeds = {round(f(b["left"]) - f(a["left"]), 9) for a, b in zip(rows[10:], rows[11:])}
    assert len(speeds) > 5                                            # the driver steers from its readings


def test_robot_extras_led_keyboard_and_supervisor(cbin, servers):
    server = servers(CDEVICES, "--mode", "pause")
    rover = start([cbin["supervisor_check"]], server.url("rover"))
    buddy = start([cbin["supervisor_check"]], server.url("buddy"))
    server.wait_attached({"rover", "buddy"})
    server.conn.call("set_mode", {"mode": "fast"})
    (code_r, out_r, err_r), (code_b, out_b, err_b) = finish(rover), finish(buddy)
    assert code_r == 0 and code_b == 0, err_r + err_b
    got = dict(line.split(" ", 1) for line in out_r)
    assert got["model"] == "C-rover" and got["custom_data"] == "gain=2" and got["supervisor"] == "1"
    assert got["custom_data_after"] == "gain=3;from C" and got["mode"] == "0" and got["buddy_null"] == "0"
    assert got["led0_initial"] == "0" and got["led0"] == f"2 rgb {0x336699}"
    assert "value 3 out of range [0, 2] for LED 'led0'" in err_r
    assert got["dim"] == "128" and f"value {0x336699} out of range [0, 255] for LED 'dim'" in err_r
    assert got["keyboard_disabled_key"] == "-1" and got["keyboard"] == "16 -1" and got["keyboard_after"] == "0"
    assert got["self_null"] == "0 missing_null 1 same_ref 1"
    assert got["fields"] == "5 translation 6 rotation bogus_null 1"
    assert [float(v) for v in got["buddy_translation"].split()] == [-0.4, -0.4, 0.0]
    assert [float(v) for v in got["buddy_translation_after"].split()] == [0.25, -0.5, 0.0]
    assert [float(v) for v in got["buddy_rotation_after"].split()] == pytest.approx([0, 0, 1, math.pi / 2])
    assert [float(v) for v in got["buddy_position"].split()] == [0.25, -0.5, 0.0]
    assert [float(v) for v in got["buddy_orientation"].split()] == pytest.approx([0, -1, 0, 1, 0, 0, 0, 0, 1], abs=1e-12)
    assert [float(v) for v in got["self_position"].split()] == [0.0, 0.0, 0.01]
    assert got["sim_mode"] == "2" and got["sim_mode_after"] == "1"
    assert [float(v) for v in got["buddy_translation_reset"].split()] == [-0.4, -0.4, 0.0]
    assert got["led0_reset"] == "0"
    assert "has no field 'mass' in Sensorium" in err_r and "wrong field type: SFRotation" in err_r
    # the plain robot: supervisor calls refused with Webots' message
    assert dict(line.split(" ", 1) for line in out_b)["buddy_null"] == "1"
    assert "illegal call to wb_supervisor_node_get_from_def() in a 'Robot' controller" in err_b
    # what the C controller set is the server's state: a Python controller attaching next sees it
    from sensorium.client.wb import RobotClient
    with RobotClient(server.url("rover")) as py:
        assert py.custom_data == "after reset" and py.model == "C-rover"
        assert py.by_name["led0"].desc["value"] == 1


def test_c_supervisor_walks_the_tree_switches_a_light_and_reads_velocities(cbin, servers):
    """tests/c/supervisor_scene.c on tests/worlds/supervisor_scene.yaml (its closed forms): the same
    checkpoints as the Python supervisor of tests/test_supervisor_scene.py, built with sanitizers."""
    code, out, err = finish(start([cbin["supervisor_scene"]], servers(SCENE_WORLD).url("judge")))
    assert code == 0, err
    assert out[0] == "root 0 Group 1 1 7 MFNode"
    # Webots' WorldInfo and Viewpoint first (a YAML world's defaults, ids after its own nodes: no name field)
    assert out[1:3] == ["node 6 WorldInfo WorldInfo '' (none) 0", "node 7 Viewpoint Viewpoint '' (none) 0"]
    out = [out[0], *out[3:]]                     # then the robots, solids and lights, as without them
    assert out[1:6] == ["node 1 Robot Robot 'JUDGE' judge 0", "node 2 Robot Robot '' runner 0",
                        "node 3 Solid Solid 'CRATE' crate 0", "node 4 PointLight PointLight '' (none) 0",
                        "node 5 DirectionalLight DirectionalLight '' (none) 0"]     # lights have no name field
    assert out[6] == "me 1 1 1 team=red referee 1" and out[7] == "missing 1 1 1 1"
    lights = out[8].split()
    assert [float(v) for v in lights[1:4]] == pytest.approx([3.0, 0.0, 8.0 / 4.0], rel=1e-12)
    assert lights[4:] == ["1", "8", "0"]             # on, intensity; the float read as a bool: "no value"
    assert out[9] == "color 1 1 1"
    steps = int(out[10].split()[1])
    v, w, dt = 0.15, 0.5, 0.016
    for line, k in ((out[11], steps), (out[12], steps + 1)):
        key, *vals = line.split()
        yaw = w * dt * k
        assert [float(x) for x in vals] == pytest.approx([v * math.cos(yaw), v * math.sin(yaw), 0, 0, 0, w],
                                                         abs=1e-12), key
    assert out[13] == "crate 0 0 0 0 0 0" and out[14] == "null nan nan nan nan nan nan"
    assert "wb_supervisor_field_get_sf_bool() called with wrong field type: SFFloat." in err
    assert "has no field 'mass' in Sensorium" in err and "out-of-bound index: 7" in err
    assert "wb_supervisor_node_get_velocity() called with a NULL or invalid 'node' argument." in err
    from test_supervisor_scene import _pose_checks
    got = {line.split()[0]: [float(v) for v in line.split()[1:]] for line in out[15:]}
    _pose_checks(got["position"], got["orientation"], got["pose"], got["crate_from_me"], got["me_from_lamp"],
                 got["crate_from_root"], got["lamp_pose"])
    assert all(math.isnan(v) for v in got["null_pose"]) and "not served" not in err
    assert "wb_supervisor_node_get_pose() called with a NULL or invalid 'node' argument." in err


def test_c_supervisor_removes_a_solid_and_a_light(cbin, servers):
    """tests/c/supervisor_remove.c on tests/worlds/supervisor_remove.yaml (its closed forms), built with
    sanitizers: the distance sensor reads the crate at 1 m, then the wall at 3 m; the light sensor 3 + 4
    (lamp and bulb), then 3; the root's 9 children (WorldInfo and Viewpoint first) become 7; the crate's id answers NULL, the gate keeps
    its id; a robot and the root are refused with one line each; a reset brings nothing back; the removed
    crate's type name, DEF and parent read Webots' "no value" with its line."""
    code, out, err = finish(start([cbin["supervisor_remove"]], servers(REMOVE_WORLD).url("boss")))
    assert code == 0, err
    key, *vals = out[0].split()
    assert key == "before" and [float(v) for v in vals] == pytest.approx([1.0, 7.0, 9], abs=1e-9)
    key, *vals = out[1].split()
    assert key == "after" and [float(v) for v in vals] == pytest.approx([3.0, 3.0, 7], abs=1e-9)
    assert out[2] == "gone 4 1 1 5"
    key, *vals = out[3].split()
    assert key == "reset" and [float(v) for v in vals] == pytest.approx([3.0, 7], abs=1e-9)
    assert out[4] == "removed_pose nan nan nan nan nan nan"          # Webots' NaNs, never NULL
    assert out[5] == "custom_data []"                                   # the reset restored the world's (none)
    # the crate kept its type name "Solid" and DEF "CRATE" after remove(); Webots' libController drops a
    # removed node from its list, so every reader of its identity prints its line and answers "no value"
    assert out[6] == "stale [] [] 0 [] 1 -1 live Solid GATE"
    for func in ("get_type_name", "get_base_type_name", "get_type", "get_def", "get_parent_node"):
        assert f"Error: wb_supervisor_node_{func}() called with a NULL or invalid 'node' argument." in err
    assert ("Error: wb_supervisor_node_get_position(): INVALID_ARGUMENT: get_node_pose: node 4 (Solid 'crate') was "
            "removed") in err
    assert "Error: wb_supervisor_node_get_orientation() called with a NULL or invalid 'node' argument." in err
    assert ("Error: wb_supervisor_node_remove(): INVALID_ARGUMENT: remove_node: robot 'rover' (node 2) cannot be "
            "removed here") in err
    assert "Error: wb_supervisor_node_remove(): INVALID_ARGUMENT: remove_node: the root node cannot be removed" in err
    assert "wb_supervisor_node_remove() called with a NULL or invalid 'node' argument." in err


def test_c_supervisor_walks_the_roots_children_in_file_order(cbin, servers):
    """tests/c/root_children.c on tests/worlds/root_children.wbt, built with sanitizers: the children's
    type names and DEFs in file order (WorldInfo, Viewpoint, Background not simulated, then the solid
    before the robot), WorldInfo first with its gravity and time step, the Viewpoint's position as the
    file writes it; a solid imported at position 3 lands after the Background and leaves when removed."""
    code, out, err = finish(start([cbin["root_children"]], servers(ROOT_WORLD).url("boss")))
    assert code == 0, err
    order = "WorldInfo:INFO Viewpoint:VIEW Background:SKY Solid:BOX Robot:BOSS PointLight:LAMP"
    assert out[0] == f"children {order}"
    assert out[1] == "info 1 3.71 16 WGS84"
    assert out[2] == "view 0 -4 2"
    assert out[3] == "imported WorldInfo:INFO Viewpoint:VIEW Background:SKY Solid:BALL Solid:BOX Robot:BOSS PointLight:LAMP"
    assert out[4] == f"removed {order}"


def test_c_supervisor_walks_a_top_level_group_of_solids(cbin, servers):
    """tests/c/top_groups.c on tests/worlds/top_groups.wbt, built with sanitizers: getFromDef("TRIO") is a
    Pose of three solids at (1, 2, 0) + Rz(90°)·their translations (closed forms), the second the node
    getFromDef("MID") gives, the Pose's translation the file's."""
    code, out, err = finish(start([cbin["top_groups"]], servers(GROUPS_WORLD).url("boss")))
    assert code == 0, err
    assert out == ["group 1 Pose 3", "at 1.000000000 3.000000000 0.050000000", "at 0.500000000 2.000000000 0.000000000",
                   "at 1.000000000 1.000000000 0.000000000", "same 1", "translation 1 2 0"]


def test_c_robot_window_text_is_printed_on_stderr_when_asked(cbin, servers):
    """tests/c/robot_window.c, built with sanitizers: with SENSORIUM_ROBOT_WINDOW_LOG=1 (what `sensorium
    run --robot-window-log` sets) each wb_robot_wwi_send is one stderr line, line breaks shown as \\n, at
    most 65536 bytes shown and the rest counted, a size short of the text cutting it; without it nothing."""
    url = servers(ARENA).url("epuck")
    code, out, err = finish(start([cbin["robot_window"]], url, SENSORIUM_ROBOT_WINDOW_LOG="1"))
    assert code == 0, err
    assert out == ["scored nothing received"]
    said = [line for line in err.splitlines() if line.startswith("robot window:")]
    assert said == ["robot window: time:1.500", "robot window: record:0.87\\nsecond line",
                    "robot window: " + "x" * 4096 + " ... (65904 more characters not shown)", "robot window: byt"]
    code, out, err = finish(start([cbin["robot_window"]], servers(ARENA).url("epuck")))
    assert code == 0, err
    assert out == ["scored nothing received"] and "robot window" not in err


def test_c_controller_robot_window_receives_the_cli_texts_in_order_and_its_answers_are_published(cbin, servers):
    """tests/c/window_echo.c: texts queued before it attached come whole with its first step
    (wb_robot_wwi_receive: each followed by its NUL); `sensorium window` texts are read one per
    wb_robot_wwi_receive_text call, in order; its wb_robot_wwi_send_text answers are on
    /epuck/robot_window, bytes that are not UTF-8 as U+FFFD."""
    from _serve import child_env, sensorium, wait_until

    from sensorium.client.topics import Subscriber

    server = servers(ARENA, "--mode", "fast")
    for text in ("one", "two", "three"):
        server.conn.call("/epuck/robot/window_send", {"text": text})
    with Subscriber(server.pub, "/epuck/robot_window") as sub:
        wait_until(lambda: b"/epuck/robot_window\0" in server.conn.call("get_counters")["subscriptions"],
                   what="the subscription")
        ctl = start([cbin["window_echo"]], server.url("epuck"))
        ready = sub.recv(timeout=60)
        assert ready is not None and ready.body == {"data": "ready"}
        for text in ("go", "stop"):
            done = subprocess.run(sensorium("window", "epuck", text, "--url", server.rpc), capture_output=True,
                                  text=True, timeout=60, env=child_env())
            assert done.returncode == 0, done.stderr
            echo = sub.recv(timeout=60)
            assert echo is not None and echo.body == {"data": f"echo:{text}"}
        bad = sub.recv(timeout=60)
        assert bad is not None and bad.body == {"data": "bad\ufffd\ufffd!"}
        code, out, err = finish(ctl)
    assert code == 0, err
    assert out == ["raw 14 one two three", "then NULL", "received go", "received stop"]


def test_c_supervisor_reaches_nested_nodes(cbin, servers):
    """tests/c/nested_nodes.c on tests/worlds/nested_nodes.wbt (tests/test_supervisor_nested.py for
    Python and its closed forms), built with sanitizers: nested DEFs and dotted paths, parents, a
    device's node (a motor: no position), the robot's children; the camera at (1, 2.15, 0.3) moves
    10 steps · 32 ms · 2 rad/s · 0.05 m along +y with the robot and stays at (0.15, 0, 0.3) in its
    frame, and the solid ARM's centre of mass (with TIP's) moves with it; the left wheel's jointParameters
    (SFNode) hold its angle; the Pose BOARD inside the solid SHELF is a node; setting a nested field gets the
    server's one line."""
    code, out, err = finish(start([cbin["nested_nodes"]], servers(NESTED_WORLD).url("rover")))
    assert code == 0, err
    assert out[:6] == ["found Camera:CAM:cam Solid:TIP:tip Solid:LID:lid",
                       "parents MAST ARM 1",
                       "device 1 RotationalMotor LEFT_JOINT 1",
                       "camera 1",
                       "children Pose Solid DistanceSensor HingeJoint HingeJoint",
                       "tip 0.000000000000 0.000000000000 0.300000000000"]
    parameters = next(line for line in out if line.startswith("parameters")).split()
    assert parameters[:3] == ["parameters", "HingeJointParameters", "1"]
    assert float(parameters[3]) == pytest.approx(2.0 * 10 * 0.032, abs=1e-9)    # the wheel's angle: 2 rad/s, 10 steps
    values = {line.split()[0]: [float(v) for v in line.split()[1:]] for line in out[6:]
              if line.split()[0] not in ("parameters", "board")}
    board = next(line for line in out if line.startswith("board")).split()
    assert board[:5] == ["board", "Pose", "BOARD", "1", "1"]     # SHELF's Pose, its only child
    assert [float(v) for v in board[5:]] == pytest.approx([-2.0, 0.0, 0.75], abs=1e-12)   # SHELF at (-2, 0, 0.5)
    d = 2.0 * 0.05 * 10 * 0.032
    assert values["before"] == pytest.approx([1.0, 2.15, 0.3], abs=1e-9)
    assert values["after"] == pytest.approx([1.0, 2.15 + d, 0.3], abs=1e-9)
    assert values["in_robot"] == pytest.approx([0.15, 0.0, 0.3], abs=1e-9)
    # ARM (2 kg at (-0.1, 0, 0.1) in the robot) and TIP (1 kg at (-0.1, 0, 0.5)): (-0.1, 0, 0.7/3), turned
    assert values["com_before"] == pytest.approx([1.0, 1.9, 0.7 / 3], abs=1e-9)
    assert values["com_after"] == pytest.approx([1.0, 1.9 + d, 0.7 / 3], abs=1e-9)
    assert values["com_robot"] == [0.0, 0.0, 0.0]
    assert "not served" not in err
    assert "field 'translation' (SFVec3f) of Solid 'tip' is read-only here" in err


def test_c_supervisor_names_proto_instances_and_reads_scenery_values(cbin, servers):
    """tests/c/supervisor_protos.c on tests/worlds/proto/supervisor_protos.wbt (tests/test_supervisor_protos.py
    for Python), built with sanitizers: a PROTO instance's type name is its PROTO's (the outermost one),
    its base type name the base node's, is_proto 1; the Viewpoint's and Background's written values
    (skyColor an MFColor: index -1 the last, 2 out of bounds); tracking a field is accepted (a negative
    period gets Webots' line) and its getter answers the value set."""
    code, out, err = finish(start([cbin["supervisor_protos"]], servers(PROTOS_WORLD).url("boss")))
    assert code == 0, err
    assert out == ["names WorldInfo:WorldInfo:0 Viewpoint:Viewpoint:0 Sky:Background:1 Boss:Robot:1 Crate:Solid:1 "
                   "BigCrate:Solid:1 Beacon:PointLight:1 Solid:Solid:0",
                   "self Boss 1",
                   "view 1 2 3 0 0 1 1.5 0.5 top",
                   "sky MFColor 2 0.1 0.2 0.3 0.4 0.5 0.6 0.5 1",
                   "seed 0",
                   "tracked 0 0.5"]
    assert "not served" not in err
    assert "Error: wb_supervisor_field_enable_sf_tracking() called with negative sampling period." in err
    assert ("Error: wb_supervisor_field_get_mf_color() called with an out-of-bound index: 2 (should be between -2 "
            "and 1).") in err


def test_c_supervisor_imports_a_solid_and_a_light(cbin, servers):
    """tests/c/supervisor_import.c on tests/worlds/supervisor_remove.yaml (its closed forms), built with
    sanitizers: the distance sensor reads the crate at 1 m, then the imported box at 0.5 m; the light
    sensor 7, then 7 + 16; the root's 9 children (WorldInfo and Viewpoint first) become 11 (the light first); the box is node 10
    (DEF BALL: after the 9 nodes the world loaded with), the light 11; removing both restores 1 m, 7 and 9 children; a robot and a bad string are
    refused with the server's one line each, a NULL field with Webots' line."""
    code, out, err = finish(start([cbin["supervisor_import"]], servers(REMOVE_WORLD).url("boss")))
    assert code == 0, err
    key, *vals = out[0].split()
    assert key == "before" and [float(v) for v in vals] == pytest.approx([1.0, 7.0, 9], abs=1e-9)
    key, *vals = out[1].split()
    assert key == "after" and [float(v) for v in vals] == pytest.approx([0.5, 23.0, 11], abs=1e-9)
    assert out[2] == "ids 10 11 BALL Solid"
    key, *vals = out[3].split()
    assert key == "removed" and [float(v) for v in vals] == pytest.approx([1.0, 7.0, 9, 1], abs=1e-9)
    assert ("Error: wb_supervisor_field_import_mf_node_from_string(): INVALID_ARGUMENT: import_node_from_string: "
            "node string:1:1: Robot: a robot cannot be imported here") in err
    assert ("Error: wb_supervisor_field_import_mf_node_from_string(): INVALID_ARGUMENT: import_node_from_string: "
            "node string:2:3: Solid.translation: expected 3 numbers, got 1") in err
    assert "wb_supervisor_field_import_mf_node_from_string() called with NULL 'field' argument." in err


def test_supervisor_through_the_cpp_classes(cbin, servers):
    lines = run([cbin["supervisor_cpp"]], servers(CDEVICES).url("rover"))
    head = lines[0].split()
    assert head[0] == "C-rover" and head[1] == "5" and [float(v) for v in head[2:5]] == [0.125, 0.25, 0.0]
    assert head[5:] == ["1", "left", "wheel", "motor", "1", "2"]
    assert float(lines[1]) == pytest.approx(6.28 * 0.016, abs=1e-12)   # position control at maxVelocity, one step
    assert lines[2] == "0 1 nan 0 0 NULL 0"                               # no contact points, no robot window
    assert lines[3] == "1 1 SFVec3f -1 1 1"       # getSelected unserved, getType served; one Field object per field
    # WorldInfo, Viewpoint (a YAML world's defaults), rover, buddy, 3 solids, the lamp
    assert lines[4] == "8 PointLight buddy Group PointLight 0 1"


def test_webots_cpp_camera_and_range_finder_names(cbin, servers):
    """tests/c/camera_cpp.cpp: Webots' C++ Camera::imageGetRed/…/imageGetGrey, getRecognition*,
    RangeFinder::rangeImageGetDepth and Robot::getProjectPath/getWorldPath/getUrdf compile and answer
    as the C functions do; the centre depth pixel sees the crate's face 1 m away."""
    lines = run([cbin["camera_cpp"]], servers(REMOVE_WORLD).url("boss"))
    assert lines[0] == "depth 1 1"
    assert lines[1] == "pixel 1 1"
    period, n, same, first, segmentation = (int(v) for v in lines[2].split()[1:])
    assert (period, same, segmentation) == (16, 1, 0) and n >= 1 and first > 0
    assert lines[3] == 'paths [] [] [<?xml version="1.0"?>]'


def test_c_client_replays_the_conformance_session(cbin, servers):
    """sensorium/schemas/conformance/session.json: expected lines computed from the simulation."""
    session = json.loads((REPO / "sensorium" / "schemas" / "conformance" / "session.json").read_text())
    server = servers(REPO / "sensorium" / "schemas" / "conformance" / session["world"])
    lines = run([sys.executable, "-m", "sensorium", "controller", "--url", server.url(session["robot"]), cbin["script"],
                 *session["script"]])
    assert lines == session["lines"]


def test_infinite_velocity_is_clamped_alike_in_process_and_by_both_clients(cbin, servers):
    """setVelocity(+/-inf): the C and Python clients clamp it to maxVelocity (with Webots' warning,
    WbMotor::setVelocity's rule); the in-process API raised instead, so the lines the simulation
    computes for this script (server/sim/conformance.py) could not even be made. Now all three agree,
    in velocity control and as position control's speed limit."""
    from sensorium.server.sim import conformance

    script = ["enable", "left encoder", "16", "enable", "right encoder", "16", "enable", "gps", "16",
              "pos", "left wheel motor", "inf", "pos", "right wheel motor", "inf",
              "vel", "left wheel motor", "inf", "vel", "right wheel motor", "-inf", "step", "16", "3",
              "pos", "left wheel motor", "0.25", "vel", "left wheel motor", "inf", "step", "32", "2"]
    expected = conformance.expected_lines(script=script)
    server = servers(conformance.WORLD)
    c_code, c_lines, c_err = finish(start([cbin["script"], *script], server.url(conformance.ROBOT)))
    assert c_code == 0, c_err
    assert c_lines == expected
    assert "The requested velocity inf exceeds 'maxVelocity'" in c_err
    assert "The requested velocity -inf exceeds 'maxVelocity'" in c_err
    assert python_script(servers(conformance.WORLD).url(conformance.ROBOT), *script) == expected


def test_negative_velocity_in_position_control_is_ignored_alike_in_process_and_by_both_clients(cbin, servers):
    """setVelocity(-3) while in position control: both clients print libController's line and ignore it;
    the in-process API took it (the wheel then crept to its target at 3 rad/s instead of maxVelocity), so
    the lines the simulation computes for this script differed from the clients'. In velocity control a
    negative velocity is taken by all three."""
    from sensorium.server.sim import conformance

    script = ["enable", "left encoder", "16", "pos", "left wheel motor", "1", "vel", "left wheel motor", "-3",
              "step", "16", "2", "pos", "left wheel motor", "inf", "vel", "left wheel motor", "-3", "step", "16", "2"]
    expected = conformance.expected_lines(script=script)
    server = servers(conformance.WORLD)
    c_code, c_lines, c_err = finish(start([cbin["script"], *script], server.url(conformance.ROBOT)))
    assert c_code == 0, c_err
    assert c_lines == expected
    assert ("Error: wb_motor_set_velocity() called with negative 'velocity' argument in position control mode "
            "(1).") in c_err
    assert python_script(servers(conformance.WORLD).url(conformance.ROBOT), *script) == expected


def test_c_and_mixed_controllers_replay_the_radio_session(cbin, servers):
    """sensorium/schemas/conformance/radio.json: two C controllers, then a C rover and a Python buddy,
    talk by radio and print exactly the lines computed from the simulation (packets, signal
    strengths and directions bit for bit, the emitters' buffers and baud rates)."""
    from test_conformance import python_runner, replay_radio

    session = json.loads((REPO / "sensorium" / "schemas" / "conformance" / "radio.json").read_text())
    world = REPO / "sensorium" / "schemas" / "conformance" / session["world"]
    assert replay_radio(servers(world, "--mode", "pause"), {"rover": [cbin["script"]], "buddy": [cbin["script"]]}) \
        == session["lines"]
    assert replay_radio(servers(world, "--mode", "pause"), {"rover": [cbin["script"]], "buddy": python_runner()}) \
        == session["lines"]


def test_c_codec_replays_the_request_vectors(cbin, servers):
    """sensorium/schemas/conformance/requests.json through the library's own transport and msgpack
    decoding (tests/c/wire_vectors.c): ids, ok, error codes, result keys and scalar results."""
    import msgpack

    from sensorium.server.sim import conformance

    vectors = json.loads((REPO / "sensorium" / "schemas" / "conformance" / "requests.json").read_text())
    server = servers(REPO / "sensorium" / "schemas" / "conformance" / vectors["world"])
    p = subprocess.Popen([cbin["wire_vectors"], server.rpc], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env=ENV)
    saved: dict[str, str] = {}
    try:
        for case in vectors["cases"]:
            data = (bytes.fromhex(case["request_hex"]) if "request_hex" in case else
                    msgpack.packb(conformance.decode_value(case["request"], saved), use_bin_type=True))
            p.stdin.write(data.hex() + "\n")
            p.stdin.flush()
            line = p.stdout.readline().rstrip("\n")
            head, _, rest = line.partition(" keys=")
            got = dict(item.split("=", 1) for item in head.split())
            keys, *scalars = rest.split(" ")
            result = dict(item.split("=", 1) for item in scalars)
            expect = case["expect"]
            assert got["id"] == ("nil" if "id" in expect else str(case["request"]["id"])), (case["name"], line)
            assert got["ok"] == str(int(expect["ok"])), (case["name"], line)
            if not expect["ok"]:
                assert got["code"] == str(expect["code"]), (case["name"], line)
                continue
            names = set(keys.split(",")) - {""}
            want = conformance.decode_value(expect.get("result", {}))
            assert {k.split(".")[0] for k in expect.get("result_has", [])} | set(want) <= names, (case["name"], line)
            for key, value in want.items():
                if isinstance(value, bool):
                    assert result[key] == str(value).lower(), (case["name"], key)
                elif isinstance(value, (int, float)):
                    assert float(result[key]) == value, (case["name"], key)
                elif isinstance(value, str):
                    assert result[key] == value, (case["name"], key)
            if "save" in expect:
                saved[expect["save"]] = result[expect["save"]]
    finally:
        p.stdin.close()
        code = p.wait(60)
        err = p.stderr.read()
    assert code == 0 and "Sanitizer" not in err and "runtime error" not in err, err


# ====================================================================== lockstep with Python

PLANS = {  # robot -> (language, step ms, steps, device ops); 12*16 = 6*32 = 4*48 = 192 ms
    "ant": ("c", 16, 12, ["enable", "ir", "16", "enable", "eye", "32"]),
    "bee": ("py", 32, 6, ["enable", "lidar", "32", "pc", "lidar", "enable", "sonar", "48"]),
    "cat": ("c", 48, 4, ["enable", "eye", "16", "enable", "front", "64"]),
}


def _run_plans(server: Served, cbin: dict[str, str], languages: dict[str, str]) -> dict[str, list[str]]:
    procs = {}
    for robot, (_, duration, steps, ops) in PLANS.items():
        args = [*ops, "step", str(duration), str(steps)]
        if languages[robot] == "c":
            procs[robot] = start([cbin["script"], *args], server.url(robot))
        else:
            procs[robot] = start([sys.executable, str(SCRIPT_PY), *args], server.url(robot))
    server.wait_attached(set(PLANS))
    assert server.conn.call("set_mode", {"mode": "fast"})["mode"] == "fast"
    out = {}
    for robot, p in procs.items():
        code, lines, err = finish(p)
        assert code == 0, f"{robot}: {err}"
        out[robot] = lines
    return out


def test_c_and_python_controllers_step_together_in_lockstep(cbin, servers):
    mixed = _run_plans(servers(TRIO, "--mode", "pause"), cbin, {r: lang for r, (lang, *_) in PLANS.items()})
    python = _run_plans(servers(TRIO, "--mode", "pause"), cbin, dict.fromkeys(PLANS, "py"))
    assert mixed == python
    for robot, (_, duration, steps, _) in PLANS.items():
        assert [fields(x)["t"] for x in mixed[robot]] == [str(duration * k) for k in range(1, steps + 1)]
    assert len({fields(x)["ir"] for x in mixed["ant"]}) == 12                      # noisy: all new values
    assert fields(mixed["cat"][0])["front"] == NAN_BITS                            # first value due at 64 ms


# ====================================================================== liveness

def test_sigkilled_c_controller_releases_its_robot_and_server_quit_ends_steps(cbin, servers):
    server = servers(TRIO, "--heartbeat-ms", "200")
    ant = start([cbin["script"], "enable", "ir", "16", "step", "16", "1000000"], server.url("ant"))
    bee = start([cbin["script"], "enable", "sonar", "32", "step", "32", "1000000"], server.url("bee"))
    server.wait_attached({"ant", "bee"})
    before = server.conn.call("get_info")["time_ms"]
    deadline = time.monotonic() + 30
    while server.conn.call("get_info")["time_ms"] < before + 320:
        assert time.monotonic() < deadline
        time.sleep(0.01)
    ant.send_signal(signal.SIGKILL)                # mid-run: a step is pending or about to be
    ant.wait(10)
    killed_at = server.conn.call("get_info")["time_ms"]
    deadline = time.monotonic() + 30               # bee goes on once the dead session is dropped (3 x 200 ms)
    while server.conn.call("get_info")["time_ms"] < killed_at + 100 * 32:
        assert time.monotonic() < deadline, "the world stopped after the C controller was killed"
        time.sleep(0.02)
    deadline = time.monotonic() + 20               # a new C controller takes the robot
    while True:
        code, lines, err = finish(start([cbin["script"], "enable", "ir", "16", "step", "16", "3"], server.url("ant")))
        if code == 0:
            break
        assert "ROBOT_TAKEN" in err, err
        assert time.monotonic() < deadline, "the killed controller's robot was never released"
        time.sleep(0.1)
    assert len(lines) == 3 and all(int(fields(x)["t"]) > killed_at for x in lines)
    assert server.stop() == 0                      # the server quits: bee's loop ends with -1
    code, lines, err = finish(bee, 30)
    assert code == 0, err
    assert fields(lines[-1])["status"] == "-1" and all(fields(x)["status"] == "0" for x in lines[:-1])


def test_a_c_loop_that_ignores_minus_one_ends_at_the_next_step(cbin, servers):
    """libController's end of a controller: the step after the -1 (the server stopped at --until)
    ends the process with status 0 (tests/c/ignores_minus_one.c; the Python twin in
    tests/test_controller_end.py)."""
    code, lines, err = finish(start([cbin["ignores_minus_one"]], servers(ARENA, "--until", "160").url("epuck")), 60)
    assert code == 0, err
    assert lines[-1] == "-1" and lines[:-1] and set(lines[:-1]) == {"0"}, lines


def test_a_c_controller_that_cleans_up_at_minus_one_and_loops_on_ends_quietly(cbin, servers):
    """Webots' nao_demo calls wb_robot_cleanup() when a step answers -1 and its loop goes on (reading
    the keyboard, stepping): the first call after the cleanup ends the process, status 0, nothing said.
    A cleanup while the simulation still runs, then a step: one line saying so, status 1."""
    code, lines, err = finish(start([cbin["ignores_minus_one"], "cleanup"],
                                    servers(ARENA, "--until", "160").url("epuck")), 60)
    assert code == 0 and "Error" not in err, err
    assert lines[-2:] == ["-1", "cleaned up"] and set(lines[:-2]) == {"0"}, lines
    code, lines, err = finish(start([cbin["ignores_minus_one"], "early"], servers(ARENA).url("epuck")), 60)
    assert code == 1 and lines == ["0"], (lines, err)
    assert err.strip().splitlines()[-1] == "Error: wb_robot_step_begin(): no robot: called after wb_robot_cleanup()", err


def test_c_controller_ends_its_loop_when_the_server_dies(cbin, servers):
    """A server SIGKILLed mid-run: the heartbeat notices, wb_robot_step returns -1, no hang."""
    server = servers(ARENA, "--heartbeat-ms", "200")
    p = start([cbin["script"], "enable", "ps0", "32", "step", "32", "100000000"], server.url("epuck"))
    server.wait_attached({"epuck"})
    deadline = time.monotonic() + 30
    while server.conn.call("get_info")["time_ms"] < 320:
        assert time.monotonic() < deadline
        time.sleep(0.01)
    server.kill()
    code, lines, err = finish(p, 60)
    assert code == 0, err
    assert fields(lines[-1])["status"] == "-1" and all(fields(x)["status"] == "0" for x in lines[:-1])
    assert "CONNECTION_LOST" in err and "server gone" in err, err


def test_a_step_reply_over_the_clients_limit_ends_the_step_with_one_clear_line(cbin):
    """issue 28: a step reply above the C client's 64 MiB (its ZMQ_MAXMSGSIZE) made ZeroMQ close the
    connection for good, without reconnecting; wb_robot_step never returned. Now the step's retry
    finds no connection to queue on and the step returns -1 with the reason. (Sensorium's server
    never sends more than 64 MiB: tests/test_peer_bounds.py; this is a stand-in server that does.)"""
    from fake_router import FakeServer

    server = FakeServer(step_padding=(64 << 20) + 1)
    server.start()
    try:
        code, lines, err = finish(start([cbin["script"], "step", "32", "3"], f"{server.endpoint}/r1"), 60)
    finally:
        server.stop()
    assert code == 0, err
    assert [fields(x)["status"] for x in data(lines)] == ["-1"]
    assert "CONNECTION_LOST" in err and "64 MiB" in err and "for good" in err, err


def test_heartbeat_keeps_a_computing_c_controller_attached(cbin, servers):
    server = servers(ARENA, "--heartbeat-ms", "100")
    lines = run([cbin["script"], "enable", "ps0", "32", "step", "32", "1", "sleep", "1500", "step", "32", "2"],
                server.url("epuck"))
    assert [fields(x)["t"] for x in lines] == ["32", "64", "96"]
    assert all(fields(x)["status"] == "0" for x in lines)


# ====================================================================== bad input

@pytest.mark.parametrize("url, words", [
    ("ftp://127.0.0.1/epuck", ["BAD_URL", "unsupported scheme 'ftp'"]),
    ("tcp://127.0.0.1:99999/epuck", ["BAD_URL", "bad port '99999'"]),
    ("tcp:///epuck", ["BAD_URL", "no host"]),
    ("epuck/left", ["BAD_URL", "contains '/'"]),
    # a line break and a tab in the URL are shown escaped: the line stays one line
    ("tcp://127.0.0.1:9\n9/e\tpuck", ["BAD_URL", "controller URL 'tcp://127.0.0.1:9\\n9/e\\tpuck': bad port '9\\n9'"]),
    ("tcp://127.0.0\n.1:9/epuck", ["BAD_URL", "cannot connect to tcp://127.0.0\\n.1:9: "]),     # ZeroMQ's refusal
])
def test_bad_urls_give_one_clear_line(cbin, url, words):
    code, out, err = finish(start([cbin["script"], "step", "32", "1"], url))
    assert code == 1 and out == []
    assert len(err.strip().splitlines()) == 1 and all(w in err for w in words), err


def test_names_from_the_world_and_the_servers_error_texts_show_escaped_on_one_line(cbin, servers):
    """A robot named "tab\\there\\nline" and its LED "led\\nlamp" (tests/worlds/control_names.yaml): the
    library's lines naming them (a device's, a robot's) and the server's error text that lists the robots
    each stay one line, the control characters escaped as the Python client's repr shows them."""
    server = servers(CONTROL_NAMES_WORLD)
    code, out, err = finish(start([cbin["world_names"]], server.url("tab%09here%0Aline")))
    assert code == 0 and out == ["done"], err
    assert err.splitlines() == [
        "Error: wb_led_set(): value 5 out of range [0, 1] for LED 'led\\nlamp'.",
        "Error: wb_distance_sensor_get_value(): device tag 1 is 'led\\nlamp', a LED",
        'Warning: wb_robot_get_device(): robot "tab\\there\\nline" has no device "none".',
        "Warning: the step duration 20 ms of robot 'tab\\there\\nline' is not a multiple of the basic time step "
        "(16 ms); the server rounds it up."], err
    code, out, err = finish(start([cbin["world_names"]], server.url("nobody")))      # the server's text
    assert code == 1 and out == [] and err.splitlines() == [
        f"Error: wb_robot_init(): UNKNOWN_ROBOT: attaching to robot 'nobody' at {server.rpc}: no robot 'nobody' "
        "(robots: tab\\there\\nline, plain)"], err
    code, out, err = finish(start([cbin["world_names"]], server.rpc))                 # the names the server lists
    assert code == 1 and out == [] and err.splitlines() == [
        f"Error: wb_robot_init(): BAD_URL: the controller URL names no robot and the world at {server.rpc} has 2 "
        "(tab\\there\\nline, plain): add '/ROBOT' to the URL"], err


def test_a_callers_string_shows_in_an_error_line_escaped_and_bounded(tmp_path):
    """sn_shown (src/utils.c, compiled into tests/c/shown_names.c): control characters as the Python client's
    repr shows them, other bytes as they are; past 4096 bytes cut with "...", never inside a UTF-8 character."""
    exe = tmp_path / "shown_names"
    done = subprocess.run(["cc", "-std=c99", "-D_POSIX_C_SOURCE=200809L", "-Wall", "-Wextra", "-Werror", "-g",
                           "-fsanitize=address,undefined", "-fno-sanitize-recover=undefined", f"-I{CLIB / 'include'}",
                           f"-I{CLIB / 'src'}", str(TESTS_C / "shown_names.c"), "-o", str(exe)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    done = subprocess.run([str(exe)], capture_output=True, timeout=60)
    assert done.returncode == 0 and done.stderr == b"", done.stderr
    assert done.stdout.decode().splitlines() == [
        "[a\\nb\\tc\\rd\\x01e\\x7ff\\n \u00e9]",    # a backslash as it is (the Python client's repr doubles it)
        "[4098 xxx...]",                           # 4095 x: the é cut after its first byte goes whole
        "[4099 xxx...]",                           # 4096 x, the next cut
        "[4096 xxy]",                              # a line break and 4094 more bytes: 4096, not cut
        "[(null)]",
        "[1\\n 2\\t 3\\r 4\\x1b]",                  # four in one printf: each its own buffer
        "[a\\x00b\\nc]"]                             # sn_shown_n: a length, not a NUL, ends the string


def test_url_forms_and_variables(cbin, servers, tmp_path):
    """WEBOTS_CONTROLLER_URL works alone, SENSORIUM_CONTROLLER_URL wins over it, ipc:// URLs name
    the robot by their last path component, and a URL without a robot takes the only robot."""
    server = servers(TRIO, "--mode", "pause", rpc=f"ipc://{tmp_path}/rpc", pub=f"ipc://{tmp_path}/pub")
    assert server.rpc == f"ipc://{tmp_path}/rpc"
    env = {k: v for k, v in ENV.items() if k not in ("SENSORIUM_CONTROLLER_URL", "WEBOTS_CONTROLLER_URL")}
    procs = [
        subprocess.Popen([cbin["script"], "step", "16", "2"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         env={**env, "WEBOTS_CONTROLLER_URL": f"{server.rpc}/ant"}),
        subprocess.Popen([cbin["script"], "step", "16", "2"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         env={**env, "WEBOTS_CONTROLLER_URL": "ftp://ignored", "SENSORIUM_CONTROLLER_URL": f"{server.rpc}/bee"}),
        subprocess.Popen([cbin["script"], "step", "16", "2"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         env={**env, "SENSORIUM_CONTROLLER_URL": f" {server.rpc}/cat\n"}),
    ]
    server.wait_attached({"ant", "bee", "cat"})
    server.conn.call("set_mode", {"mode": "fast"})
    for p in procs:
        code, lines, err = finish(p)
        assert code == 0 and [fields(x)["t"] for x in lines] == ["16", "32"], err
    only = servers(REPO / "sensorium" / "schemas" / "conformance" / "world.yaml")
    code, _, err = finish(start([cbin["script"], "step", "16", "1"], only.rpc))       # two robots there: ambiguous
    assert code == 1 and "add '/ROBOT'" in err
    single = tmp_path / "single.yaml"
    single.write_text("world_info: {name: single, basic_time_step: 8}\nrobots:\n  - name: solo\n")
    code, lines, err = finish(start([cbin["script"], "step", "8", "1"], servers(single).rpc))
    assert code == 0 and lines == ["8 0"], err


def test_missing_server_times_out_with_a_message(cbin):
    t0 = time.monotonic()
    code, out, err = finish(start([cbin["script"], "step", "32", "1"], "tcp://127.0.0.1:9/epuck",
                                  SENSORIUM_CONTROLLER_TIMEOUT="1"))
    assert code == 1 and out == []
    assert "TIMEOUT" in err and "tcp://127.0.0.1:9" in err and "sensorium serve" in err, err
    assert time.monotonic() - t0 < 30


def test_unknown_robot_and_launcher_errors(cbin, servers, tmp_path):
    server = servers()
    code, _, err = finish(start([cbin["script"], "step", "32", "1"], server.url("nobody")))
    assert code == 1 and "UNKNOWN_ROBOT" in err and "nobody" in err, err
    code, _, err = finish(start([cbin["script"], "step", "32", "1"], server.rpc))      # two robots, none named
    assert code == 1 and "add '/ROBOT' to the URL" in err, err
    blob = tmp_path / "controller"
    blob.write_bytes(b"\x7fELF\x02\x01\x01\x00" + bytes(64))          # a binary without the execute bit
    done = subprocess.run([sys.executable, "-m", "sensorium", "controller", str(blob)], capture_output=True, text=True,
                          env=ENV, cwd=str(REPO), timeout=60)
    assert done.returncode == 2 and "chmod +x" in done.stderr
    done = subprocess.run([sys.executable, "-m", "sensorium", "controller", "--url", "ftp://x", cbin["script"]],
                          capture_output=True, text=True, env=ENV, cwd=str(REPO), timeout=60)
    assert done.returncode == 2 and "unsupported scheme" in done.stderr


def test_a_curve_server_serves_a_c_controller_that_has_its_key(cbin, servers, tmp_path):
    """CURVE from the C library: SENSORIUM_CURVE_SERVERKEY (hex or Z85) as for the Python client;
    without it, or with a wrong one, the server does not answer and the timeout says why (as the
    Python client's does); a malformed key is one clear line."""
    keys = tmp_path / "keys"
    made = subprocess.run([sys.executable, "-m", "sensorium", "keys", str(keys)], capture_output=True, text=True,
                          env=ENV, cwd=str(REPO), timeout=60)
    assert made.returncode == 0, made.stderr
    key = (made.stdout + made.stderr).split("SENSORIUM_CURVE_SERVERKEY=")[1].split()[0]
    server = servers(ARENA, "--curve-keys", str(keys))
    code, lines, err = finish(start([cbin["script"], "step", "32", "2"], server.url("epuck"),
                                    SENSORIUM_CURVE_SERVERKEY=key))
    assert code == 0 and [fields(x)["t"] for x in lines] == ["32", "64"], err
    code, lines, err = finish(start([cbin["script"], "step", "32", "1"], server.url("epuck"),
                                    SENSORIUM_CONTROLLER_TIMEOUT="2"))
    # refused, however libzmq ends it (a reconnection loop or a connection it gives up), the error says why
    assert code == 1 and lines == [] and "TIMEOUT" in err and "this client has no key" in err, err
    assert "SENSORIUM_CURVE_SERVERKEY" in err and "running there" not in err, err
    wrong = subprocess.run([sys.executable, "-c", "import zmq; print(zmq.curve_keypair()[0].decode())"],
                           capture_output=True, text=True, timeout=60).stdout.strip()
    code, lines, err = finish(start([cbin["script"], "step", "32", "1"], server.url("epuck"),
                                    SENSORIUM_CURVE_SERVERKEY=wrong, SENSORIUM_CONTROLLER_TIMEOUT="2"))
    assert code == 1 and lines == [] and "TIMEOUT" in err and "is wrong for this server" in err, err
    code, lines, err = finish(start([cbin["script"], "step", "32", "1"], server.url("epuck"),
                                    SENSORIUM_CURVE_SERVERKEY="not-a-key"))
    assert code == 1 and len(err.strip().splitlines()) == 1 and "CURVE key" in err, err


def test_every_device_in_c_reads_what_python_reads(cbin, servers):
    """tests/c/every_device.c prints exactly the lines of tests/controllers/every_device.py (Webots'
    Python classes; its closed forms are checked in tests/test_every_device.py): every Webots device
    kind, simulated or listed-only, through the C API, bit for bit, no crash, one warning per
    listed-only device."""
    from test_every_device import WORLD, check_lines, python_lines

    code, c_out, c_err = finish(start([cbin["every_device"]], servers(WORLD, "--mode", "fast").url("bot")))
    assert code == 0, c_err
    assert c_out[-1] == "infinity 1"                        # INFINITY from webots/types.h
    assert c_out[:-1] == python_lines(servers(WORLD, "--mode", "fast").url("bot"))
    check_lines(c_out[:-1], c_err)


# ====================================================================== Webots-style API tests

def _succeeded(p: subprocess.Popen, what: str) -> None:
    code, out, err = finish(p)
    assert code == 0 and out and out[-1] == "success", f"{what}: exit {code}\n{chr(10).join(out)}\n{err}"


def test_webots_style_api_tests(cbin, servers):
    """tests/c/api: our own API tests in the manner of Webots' (a controller asserting what the API
    answers, ending with "success"), built with the sanitizers: the motion sensors' closed forms, two
    controllers talking by radio, the robot and device API with listed-only devices."""
    _succeeded(start([cbin["motion_sensors"]], servers(C_API_WORLD, "--mode", "fast").url("walker")), "motion_sensors")
    _succeeded(start([cbin["robot_devices"]], servers(C_API_WORLD, "--mode", "fast").url("gadget")), "robot_devices")
    server = servers(C_API_WORLD, "--mode", "pause")           # both attached before the world runs
    pair = {robot: start([cbin["emitter_receiver"]], server.url(robot)) for robot in ("alice", "bob")}
    server.wait_attached(set(pair))
    assert server.conn.call("set_mode", {"mode": "fast"})["mode"] == "fast"
    for robot, p in pair.items():
        _succeeded(p, f"emitter_receiver as {robot}")


def test_a_careless_c_driver_gets_the_python_librarys_lines_and_no_sanitizer_report(cbin, servers):
    """tests/c/car_hostile.c prints what tests/controllers/car_hostile.py prints: NaN, infinite and
    out-of-range brake, indicator period, steering and speed (tests/test_vehicle_driver.py)."""
    from test_vehicle_driver import HOSTILE_LINES, check_car_hostile

    server = servers(CAR_LIGHTS_WORLD, "--heartbeat-ms", "500")
    code, out, err = finish(start([cbin["car_hostile"]], server.url("car")))
    assert code == 0, err
    check_car_hostile(out)
    assert err.splitlines() == HOSTILE_LINES, err
