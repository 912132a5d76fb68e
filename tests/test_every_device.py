"""One Python controller touching every Webots device kind (tests/controllers/every_device.py, Webots'
Python classes, on tests/worlds/every_device.yaml): Webots' device order and node types, the
simulated devices' closed-form readings of a robot at rest, Webots' "no value" with one warning per
listed-only device, no crash. tests/test_c_client.py runs its C twin and compares the lines."""

from __future__ import annotations

import math
import struct
import subprocess
import sys
from pathlib import Path

from _serve import serve

from sensorium.schemas.devices import WEBOTS_NODE_TYPES as N

REPO = Path(__file__).resolve().parents[1]
WORLD = REPO / "tests" / "worlds" / "every_device.yaml"
CONTROLLER = REPO / "tests" / "controllers" / "every_device.py"
LISTED = ("Skin 'skin'",)      # (the linear and arm motors move their joints)


def python_run(url: str) -> tuple[list[str], str]:
    done = subprocess.run([sys.executable, "-m", "sensorium", "controller", "--url", url, str(CONTROLLER)],
                          capture_output=True, text=True, timeout=180, cwd=str(REPO))
    assert done.returncode == 0, done.stderr
    return done.stdout.splitlines(), done.stderr


def python_lines(url: str) -> list[str]:
    return python_run(url)[0]


def _bits(hexes: str) -> list[float]:
    return [struct.unpack("<d", struct.pack("<Q", int(x, 16)))[0] for x in hexes.split(",")]


def check_lines(lines: list[str], stderr: str) -> None:
    """The every-device lines (either client's) against the world's closed forms."""
    got = {line.split(" ", 1)[0]: line.split(" ")[1:] for line in lines if not line.startswith("device ")}
    devices = [line.split(" ") for line in lines if line.startswith("device ")]
    # Webots' tree order (the drive's wheel motors last), Webots' node types, the world's model
    names = [" ".join(d[2:-2]) for d in devices]
    assert names[:4] == ["radar", "gps", "camera", "speaker"] and names[-2:] == ["left wheel motor", "right wheel motor"]
    assert len(devices) == 28 and [int(d[1]) for d in devices] == list(range(28))
    assert devices[0][-2:] == [str(N["WB_NODE_RADAR"]), "u-blox"]
    kinds = {v for k, v in N.items() if N["WB_NODE_ACCELEROMETER"] <= v <= N["WB_NODE_VACUUM_GRIPPER"]}
    assert {int(d[-2]) for d in devices} == kinds - {N["WB_NODE_PROPELLER"]}       # every device kind
    # NaN before the first value; then the robot at rest at (0.5, -0.25, 0) heading +x (ENU, g = 9.81)
    assert all(math.isnan(v) for part in got["before"] for v in _bits(part))
    assert _bits(got["gps"][0]) == [0.5, -0.25, 0.0] and math.isnan(_bits(got["gps"][1])[0])   # no speed yet
    assert got["gps"][3] == "0"
    assert _bits(got["accelerometer"][0]) == [0.0, 0.0, 9.81]
    assert _bits(got["altimeter"][0]) == [0.04]
    assert _bits(got["compass"][0]) == [0.0, 1.0, 0.0]           # north (+y) in the device frame
    assert _bits(got["gyro"][0]) == [0.0, 0.0, 0.0]
    assert _bits(got["imu"][0]) == [0.0, 0.0, 0.0] and _bits(got["imu"][1]) == [0.0, 0.0, 0.0, 1.0]
    assert _bits(got["ds"][0]) == [1000.0]                        # nothing ahead: the table's far value
    assert _bits(got["lidar"][0]) == [math.inf] * 4 and _bits(got["light"][0]) == [0.0]
    assert _bits(got["bumper"][0]) == [0.0] and got["bumper"][1:] == ["0", "none"]
    assert got["send"][:3] == ["1", "1", "2"] and got["led"] == ["2"] and got["receiver"][:2] == ["0", "1"]
    assert got["wheel"][1] == "0" and math.isnan(_bits(got["wheel"][2])[0])
    assert got["radar"] == ["0", "0", "0"] and got["brake"] == ["0", "1"] and got["connector"] == ["-1", "0"]
    assert got["display"] == ["64", "64"] and got["skin"] == ["0", "1"] and got["speaker"] == ["0", "1"]   # (simulated)
    assert got["gripper"] == ["0", "0"] and got["linear"][0] == "1" and got["arm"][0] == "0"
    assert _bits(got["linear"][1]) == [1.0] and _bits(got["arm"][1]) == [0.0]     # joints: real answers
    assert got["joystick"] == ["0", "-1"] and got["mouse"] == ["1", "0"] and got["battery"] == ["1"]
    assert got["wait"] == ["0", "112"]       # WB_EVENT_NO_EVENT after 100 ms rounded up to whole 16 ms steps
    # one warning line per listed-only device, however many calls
    warned = [line for line in stderr.splitlines() if "does not simulate" in line]
    for name in LISTED:
        assert sum(name in w for w in warned) == 1, (name, warned)
    assert not [w for w in warned if "Brake" in w or "Connector" in w], warned      # simulated now


def test_every_device_through_webots_python_classes():
    with serve(WORLD, "--mode", "fast") as server:
        lines, stderr = python_run(server.url("bot"))
    check_lines(lines, stderr)


def test_every_class_webots_has_imports_from_controller():
    code = ("from controller import (Accelerometer, Altimeter, AnsiCodes, Brake, Camera, CameraRecognitionObject, "
            "Compass, Connector, ContactPoint, Display, DistanceSensor, Emitter, Field, GPS, Gyro, InertialUnit, "
            "Joystick, Keyboard, LED, Lidar, LidarPoint, LightSensor, Motion, Motor, Mouse, MouseState, Node, Pen, "
            "PositionSensor, Radar, RadarTarget, RangeFinder, Receiver, Robot, Skin, Speaker, Supervisor, "
            "TouchSensor, VacuumGripper); print(Node.GPS, Emitter.CHANNEL_BROADCAST, TouchSensor.FORCE3D)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60,
                          env={"PYTHONPATH": f"{REPO / 'sensorium' / 'client' / 'webots'}:{REPO}", "PATH": "/usr/bin"})
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == [str(N["WB_NODE_GPS"]), "-1", "2"]


def test_vehicle_classes_import_with_webots_constants():
    """``from vehicle import Driver, Car`` works with Webots' constants; constructing one drives a car
    (tests/test_vehicle_driver.py, with a server)."""
    from sensorium.client.webots.vehicle import Car, Driver

    assert (Car.FOUR_BY_FOUR, Car.WHEEL_REAR_LEFT, Driver.INDICATOR_LEFT, Driver.TORQUE, Driver.FAST) == (2, 3, 2, 1, 3)
    assert issubclass(Car, Driver)


# Webots' Python controller modules (lib/controller/python/controller/*.py) with their main class; left
# out: constants.py and wb.py (libController bindings, internal to Webots' package). Proto is not in
# the package's names (as in Webots), only in its module.
WEBOTS_PY_MODULES = {
    "accelerometer": "Accelerometer", "altimeter": "Altimeter", "ansi_codes": "AnsiCodes", "brake": "Brake",
    "camera": "Camera", "compass": "Compass", "connector": "Connector", "device": "Device", "display": "Display",
    "distance_sensor": "DistanceSensor", "emitter": "Emitter", "field": "Field", "gps": "GPS", "gyro": "Gyro",
    "inertial_unit": "InertialUnit", "joystick": "Joystick", "keyboard": "Keyboard", "led": "LED", "lidar": "Lidar",
    "lidar_point": "LidarPoint", "light_sensor": "LightSensor", "motion": "Motion", "motor": "Motor",
    "mouse": "Mouse", "node": "Node", "pen": "Pen", "position_sensor": "PositionSensor", "proto": "Proto", "radar": "Radar",
    "radar_target": "RadarTarget", "range_finder": "RangeFinder", "receiver": "Receiver", "robot": "Robot",
    "sensor": "Sensor", "skin": "Skin", "speaker": "Speaker", "supervisor": "Supervisor",
    "touch_sensor": "TouchSensor", "vacuum_gripper": "VacuumGripper"}


def test_every_webots_controller_module_imports_with_its_class():
    code = ("import importlib, controller\n"
            f"for module, cls in {WEBOTS_PY_MODULES!r}.items():\n"
            "    got = getattr(importlib.import_module('controller.' + module), cls)\n"
            "    assert got is getattr(controller, cls, got) and got.__name__ == cls, module\n"
            "print('ok')")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60,
                          env={"PYTHONPATH": f"{REPO / 'sensorium' / 'client' / 'webots'}:{REPO}", "PATH": "/usr/bin"})
    assert done.returncode == 0 and done.stdout == "ok\n", done.stderr


def test_python_supervisor_methods_beyond_the_subset_and_simulation_quit(tmp_path):
    """Webots' Supervisor, Node and Field methods that Sensorium does not serve answer Webots' "no
    value" with one error line each (the C library's words; getStaticBalance is served: a robot without
    physics answers false, no line; movieIsReady too: true, no movie recording); simulationQuit ends the steps: the next one
    answers -1, the one after ends the controller with status 0 (libController's rule); the server exits
    with the status given."""
    script = tmp_path / "sup.py"
    script.write_text(
        "from controller import Supervisor\n"
        "s = Supervisor()\n"
        "me = s.getSelf()\n"
        "rot = me.getField('rotation')\n"
        "print(s.getSelected(), s.getSelected(), s.movieIsReady(), me.getCenterOfMass(),\n"
        "      me.getId() > 0, rot.getTypeName(), rot.getCount(), rot.getSFInt32(), rot.getMFVec3f(0),\n"
        "      me.getStaticBalance())\n"
        "print(s.step(16))\n"
        "s.simulationQuit(3)\n"
        "print(s.step(16))\n"
        "print('not reached', s.step(16))\n")          # libController: the step after the -1 ends the process
    with serve(REPO / "tests" / "worlds" / "headers.yaml") as server:
        done = subprocess.run([sys.executable, "-m", "sensorium", "controller", "--url", server.url("car"),
                               str(script)], capture_output=True, text=True, timeout=120, cwd=str(REPO))
        assert server.wait() == 3, server.stderr()         # as Webots quits, with the status given
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == ["None None True [0.0, 0.0, 0.0] True SFRotation -1 0 None False",
                                     "0", "-1"]
    unserved = sorted(line.split("(")[0] for line in done.stderr.splitlines() if "not served by Sensorium" in line)
    assert unserved == ["Error: wb_supervisor_node_get_selected"], done.stderr   # movieIsReady is served: True, idle
    # getMFVec3f is served (a PROTO's interface fields): on an SFRotation it is Webots' wrong-type line, None
    assert "Error: wb_supervisor_field_get_mf_vec3f() called with wrong field type: SFRotation." in done.stderr
    # getSFInt32 is served (WorldInfo's randomSeed): on an SFRotation it is Webots' wrong-type line and 0
    assert "Error: wb_supervisor_field_get_sf_int32() called with wrong field type: SFRotation." in done.stderr
    assert "simulation_quit" not in done.stderr
