"""What Webots' robot-family controllers need of a world, on small worlds of our own: a NAO-like
robot (device names holding '/', as NAO's 'Sonar/Left' and 'Ears/Led/Right'; forty joints that are
no wheels) loads with one warning for its joints, and a Python controller reads its sonar's closed
form and drives its LED by those names; names that would leave an empty topic segment are one line."""

from __future__ import annotations

from pathlib import Path

import pytest

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, load_world

WALL_X = 1.0          # the wall's face is at x = 0.95 (a 0.1 m thick box centred on x = 1)
SONAR_X = 0.05        # the sonar's origin, looking along +x: it reads 0.95 - 0.05 = 0.9 m


def nao_like(tmp_path: Path, joints: int = 40, extra: str = "") -> Path:
    hinges = "".join(
        f'  HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 }} device [ RotationalMotor {{ '
        f'name "J{k}" minPosition -1 maxPosition 1 }} PositionSensor {{ name "J{k}S" }} ] '
        f'endPoint Solid {{ name "link{k}" translation 0 0 {0.01 * k} }} }}\n' for k in range(joints))
    p = tmp_path / "nao_like.wbt"
    p.write_text("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 40 }\n"
                 f'Solid {{ name "wall" translation {WALL_X} 0 0.3 children [ DEF B Shape {{ geometry Box {{ size 0.1 2 0.6 }} }} ] '
                 "boundingObject USE B }\n"
                 'Robot { name "nao" translation 0 0 0.3 controller "<extern>" children [\n' + hinges +
                 f'  DistanceSensor {{ name "Sonar/Left" translation {SONAR_X} 0 0 lookupTable [ 0 0 0, 2.55 2.55 0 ] }}\n'
                 '  LED { name "Ears/Led/Right" color [ 0 0 1 ] gradual TRUE }\n'
                 '  TouchSensor { name "LFoot/Bumper/Left" translation 0 0 -0.29 boundingObject Box { size 0.01 0.01 0.01 } }\n'
                 + extra + "] }\n")
    return p


def test_a_nao_like_robot_loads_with_one_warning_for_its_forty_joints(tmp_path) -> None:
    loaded = load_world(nao_like(tmp_path))
    names = [d.name for d in loaded.world.robots[0].devices]
    assert {"Sonar/Left", "Ears/Led/Right", "LFoot/Bumper/Left"} <= set(names)
    joints = [w for w in loaded.warnings if "no wheel" in w]
    assert len(joints) == 1, joints
    assert ":4:1: robot 'nao': its 40 motorised joints are no wheels" in joints[0]
    assert "('J0', 'J1', 'J2', 'J3' and 36 more)" in joints[0]
    few = load_world(nao_like(tmp_path, joints=3))          # a few joints: one line each, as before
    assert len([w for w in few.warnings if "no wheel" in w]) == 3


@pytest.mark.parametrize("bad, why", [("/Sonar", "must not start or end with '/' nor hold '//'"),
                                      ("Sonar/", "must not start or end with '/' nor hold '//'"),
                                      ("Sonar//Left", "must not start or end with '/' nor hold '//'"),
                                      ("robot", "is reserved"), ("robot/x", "is reserved"),
                                      ("Sonar/Left/value", "lies under device 'Sonar/Left'")])
def test_a_device_name_that_would_leave_an_empty_topic_segment_is_one_line(tmp_path, bad, why) -> None:
    with pytest.raises(WorldError) as err:
        load_world(nao_like(tmp_path, joints=1, extra=f'  GPS {{ name "{bad}" }}\n'))
    lines = str(err.value).strip().splitlines()
    assert len(lines) == 1 and f"name '{bad}' {why}" in lines[0] and "nao_like.wbt:" in lines[0], lines


def test_a_python_controller_reads_and_drives_devices_named_with_a_slash(tmp_path) -> None:
    from _inproc import inproc_server

    from sensorium.client import wb
    with inproc_server(heartbeat_ms=5000, world=nao_like(tmp_path, joints=5)) as (core, transport):
        assert "/nao/Sonar/Left/value" in {t.name for t in core.topics.topics}
        wb.wb_robot_init(f"{transport.rpc_endpoint}/nao")
        try:
            from controller import Robot
        except ImportError:
            from sensorium.client.webots.controller import Robot
        try:
            robot = Robot()
            sonar, ears = robot.getDevice("Sonar/Left"), robot.getDevice("Ears/Led/Right")
            bumper = robot.getDevice("LFoot/Bumper/Left")
            sonar.enable(40)
            bumper.enable(40)
            assert robot.step(40) != -1
            assert sonar.getValue() == pytest.approx(WALL_X - 0.05 - SONAR_X, abs=1e-6)   # float32 rays (precision "fast")
            assert bumper.getValue() == 0.0
            ears.set(128)
            robot.step(40)
            assert ears.get() == 128
        finally:
            wb.wb_robot_cleanup()
            from sensorium.client.webots.controller.robot import Robot as _R
            _R.created = None


def test_a_recording_names_the_device_of_a_topic_whose_device_name_holds_a_slash(tmp_path) -> None:
    import msgpack
    from mcap.reader import make_reader

    from sensorium.server.recording.envelope import pack_envelope
    from sensorium.server.recording.writer import McapRecorder

    path = tmp_path / "nao.mcap"
    body = msgpack.packb({"range": 0.9})
    with McapRecorder(path, foxglove=False, demand=False) as rec:
        for topic in ("/nao/Sonar/Left/value", "/nao/gps/value", "/nao/pose"):
            rec.record(topic, "sensor_msgs/msg/Range", pack_envelope("sensor_msgs/msg/Range", 0, 1000), body, 1000, 0)
    with open(path, "rb") as f:
        channels = {ch.topic: ch.metadata for ch in make_reader(f).get_summary().channels.values()}
    assert (channels["/nao/Sonar/Left/value"]["robot"], channels["/nao/Sonar/Left/value"]["device"]) == ("nao", "Sonar/Left")
    assert channels["/nao/gps/value"]["device"] == "gps"
    assert "device" not in channels["/nao/pose"]


def legged(tmp_path: Path, feet: str) -> Path:
    """A hexapod of our own (Mantis-like): six legs of three chained hinges, its feet `feet`."""
    legs = ""
    for k, (x, y) in enumerate([(-0.25, -0.15), (0, -0.15), (0.25, -0.15), (-0.25, 0.15), (0, 0.15), (0.25, 0.15)]):
        s = 1 if y > 0 else -1
        legs += (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 0 1 anchor {x} {y} 0 }} '
                 f'device [ RotationalMotor {{ name "leg{k} base" }} ] endPoint Solid {{ translation {x} {y} 0 name "coxa{k}" children [ '
                 f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 1 0 0 }} device [ RotationalMotor {{ name "leg{k} shoulder" }} ] '
                 f'endPoint Solid {{ translation 0 {s * 0.05} 0 name "femur{k}" children [ '
                 f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 1 0 0 anchor 0 {s * 0.2} 0 }} device [ RotationalMotor {{ name "leg{k} knee" }} ] '
                 f'endPoint Solid {{ translation 0 {s * 0.2} 0 name "tibia{k}" children [ {feet} ] }} }} ] }} }} ] }} }}\n')
    p = tmp_path / "legged.wbt"
    p.write_text('#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n'
                 'Robot { name "hexapod" translation 0 0 0.5 children [ Shape { geometry Box { size 0.6 0.3 0.1 } }\n' + legs + '] }\n')
    return p


@pytest.mark.parametrize("feet, why", [
    ("Shape { geometry Box { size 0.03 0.03 0.3 } }", "(18 with no cylinder or sphere at their end point to roll on)"),
    ("Pose { translation 0 0 -0.15 children [ Shape { geometry Sphere { radius 0.02 } } ] }",   # round feet: chains
     "(6 steering none; 12 links of a chain of motorised joints)")])
def test_a_legged_robot_gets_one_line_for_its_joints_whatever_its_feet(tmp_path, feet, why) -> None:
    loaded = load_world(legged(tmp_path, feet))
    said = [w for w in loaded.warnings if "no wheel" in w]
    assert len(said) == 1, said
    assert f"robot 'hexapod': its 18 motorised joints are no wheels {why}: they move kinematically" in said[0]
    assert said[0].endswith("and 14 more)")
    assert not loaded.world.robots[0].differential_drive


def test_a_legged_robot_with_physics_is_told_its_body_stays(tmp_path: Path) -> None:
    """Webots' Spot lies down, sits and stands by its physics; here its joints move its legs and its
    body stays where it is: one line says so for a robot with physics, many joints and no drive."""
    feet = "Shape { geometry Box { size 0.03 0.03 0.3 } }"
    p = legged(tmp_path, feet)
    p.write_text(p.read_text().replace('Robot { name "hexapod"', 'Robot { name "hexapod" physics Physics { }'))
    loaded = load_world(p)
    said = [w for w in loaded.warnings if "never its body" in w]
    assert said == [f"{p}:3:1: robot 'hexapod': its joints move its parts, never its body: without physics nothing "
                    "here stands it on its limbs, walks, sits or drops it (its body stays where the world file or a "
                    "Supervisor puts it)"]
    sim = Simulation(loaded)
    knees = [sim.robot("hexapod").motor(f"leg{k} knee") for k in range(6)]
    for knee in knees:
        knee.set_position(0.8)
    sim.run(40)
    assert [knee.position for knee in knees] == [0.8] * 6          # the legs moved ...
    assert list(sim.robot("hexapod").pose.translation) == [0.0, 0.0, 0.5]   # ... the body did not
    # without physics (Webots' kinematic robot), or with fewer joints, nothing more to say
    assert not [w for w in load_world(legged(tmp_path, feet)).warnings if "never its body" in w]
