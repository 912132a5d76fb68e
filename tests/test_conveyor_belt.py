"""A conveyor belt (one ``Track`` on a robot, its LinearMotor moving the belt, as Webots' ConveyorBelt
PROTO is built) carries the solids with physics lying on its top face by the motor's travel, as Webots'
physics does with the Track's moving contact surface; past its end they land on what is under them.
Before, the belt did not move and neither did what lay on it. Our own worlds; closed-form poses."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from sensorium.server.sim.batched import BatchedError, BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

TOP = 0.2          # the belt's top face: a 1 x 0.3 x 0.1 box centred at z 0.15, x from -0.5 to 0.5
X0 = -0.3          # the box's start: 0.1 m cube resting on the belt (its origin 0.05 above the face)


def box(name: str, x: float, y: float = 0.0, z: float = TOP + 0.05, physics: str = "physics Physics { }") -> str:
    return (f'Solid {{ name "{name}" translation {x} {y} {z} children [ DEF {name.upper()} Shape {{ geometry Box '
            f'{{ size 0.1 0.1 0.1 }} }} ] boundingObject USE {name.upper()} {physics} }}\n')


def world(tmp_path: Path, extra: str = "", bounding: str = "USE BELT", place: str = "") -> Path:
    p = tmp_path / "conveyor.wbt"
    p.write_text(
        '#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 10 }\n'
        'Solid { name "floor" children [ DEF F Shape { geometry Plane { size 10 10 } } ] boundingObject USE F }\n'
        f'Robot {{ name "conveyor" {place} controller "<none>" children [\n'
        '  Track { name "belt" translation 0 0 0.15 children [ DEF BELT Shape { geometry Box { size 1 0.3 0.1 } } ]\n'
        f'    boundingObject {bounding} device [ LinearMotor {{ name "belt motor" maxVelocity 1 maxForce 1000 }}\n'
        '    PositionSensor { name "belt sensor" } ] }\n] }\n'
        # an observer looking along +x at the carried box's back face (0.25 m up: above the belt)
        'Robot { name "eye" translation -1 0 0.25 controller "<none>" children [\n'
        '  DistanceSensor { name "ds" lookupTable [ 0 0 0, 3 3 0 ] } ] }\n'
        + box("box", X0) + box("side", X0, y=1.0, z=0.05) + extra)
    return p


def belt(sim: Simulation, velocity: float, position: float = math.inf) -> None:
    m = sim.robot("conveyor").motor("belt motor")
    m.set_position(position)
    m.set_velocity(velocity)


def at(sim: Simulation, name: str = "box") -> list[float]:
    return [float(v) for v in sim.scene.solid_poses[name].translation]


def test_a_box_on_a_belt_moves_at_the_belt_speed(tmp_path: Path) -> None:
    w = load_world(world(tmp_path))
    assert any("its belt carries the solids" in x for x in w.warnings), w.warnings
    assert not any("the belt and its wheels do not move" in x for x in w.warnings), w.warnings
    b = w.world.robots[0].belts[0]
    assert (b.motor, b.top, b.along, b.length, b.width) == ("belt motor", (0.0, 0.0, TOP), (1.0, 0.0, 0.0), 1.0, 0.3)
    sim = Simulation(w)
    ds, sensor = sim.device("eye/ds"), sim.device("conveyor/belt sensor")
    ds.enable(10)
    sensor.enable(10)
    belt(sim, 0.2)
    for n in range(1, 151):        # 1.5 s at 0.2 m/s: x = X0 + 0.2 t
        sim.step()
        assert at(sim) == pytest.approx([X0 + 0.2 * 0.01 * n, 0.0, TOP + 0.05], abs=1e-12)
    assert sensor.value == pytest.approx(0.3, abs=1e-12)
    # the observer's ray meets the box's back face where the box now is: 1 m to x = -1
    assert ds.value == pytest.approx(X0 + 0.3 - 0.05 + 1.0, abs=1e-9)
    assert at(sim, "side") == [X0, 1.0, 0.05]      # beside the belt: not carried


def test_a_stopped_belt_leaves_it_and_reverse_moves_it_back(tmp_path: Path) -> None:
    sim = Simulation(load_world(world(tmp_path)))
    sim.run(50)
    assert at(sim) == [X0, 0.0, TOP + 0.05]        # velocity 0 (no command): nothing moves
    belt(sim, 0.0)
    sim.run(50)
    assert at(sim) == [X0, 0.0, TOP + 0.05]
    belt(sim, -0.1)                                # reverse: back along -x
    sim.run(100)
    assert at(sim) == pytest.approx([X0 - 0.1, 0.0, TOP + 0.05], abs=1e-12)
    belt(sim, 0.5, position=-0.05)     # position control: the belt (at -0.1) travels to -0.05 and stops
    sim.run(100)
    assert at(sim) == pytest.approx([X0 - 0.1 + 0.05, 0.0, TOP + 0.05], abs=1e-12)


def _ride_off(sim: Simulation, x0: float, edge: float) -> float:
    """At 0.2 m/s the box rides along the world's x from x0 at y 0, at x0 + 0.2 t every 10 ms step
    (1e-12), until its origin passes ``edge`` (within that step's 2 mm); from there it falls onto the
    floor (:func:`_falls_to_floor`). Where it landed, x."""
    belt(sim, 0.2)
    steps = 0
    while at(sim)[0] <= edge:
        sim.step()
        steps += 1
        assert steps < 1000
        assert at(sim) == pytest.approx([x0 + 0.2 * 0.01 * steps, 0.0, TOP + 0.05], abs=1e-12)
    x = at(sim)[0]
    assert edge < x <= edge + 0.002 + 1e-12
    _falls_to_floor(sim, x)
    return x


def _falls_to_floor(sim: Simulation, x: float) -> None:
    """The box, just past the belt's edge at height TOP + 0.05, falls straight down under gravity
    (9.81 m/s², sim/falling.py): TOP + 0.05 - g t²/2 after each 10 ms step (1e-12), x and y kept, until
    it rests on the floor at its half height, 0.05."""
    k = 0
    while at(sim)[2] > 0.05:
        sim.step()
        k += 1
        assert k < 100
        z = TOP + 0.05 - 0.5 * 9.81 * (0.01 * k) ** 2
        assert at(sim) == pytest.approx([x, 0.0, max(z, 0.05)], abs=1e-12)
    assert at(sim) == pytest.approx([x, 0.0, 0.05], abs=1e-12)


def test_past_the_belts_end_it_lands_on_the_floor(tmp_path: Path) -> None:
    sim = Simulation(load_world(world(tmp_path)))
    x = _ride_off(sim, X0, 0.5)                    # carried until its origin passes x = 0.5
    sim.run(50)
    assert at(sim) == pytest.approx([x, 0.0, 0.05], abs=1e-12)     # off the belt: it stays


def test_a_wall_stops_the_box_and_the_one_behind_it(tmp_path: Path) -> None:
    """A fixed wall (no physics) across the belt at x 0.3 (its face at 0.29): the carried box stops
    less than one step's travel (2 mm) short of it; a second box in a row behind it stops with it."""
    wall = box("wall", 0.34, physics="").replace("size 0.1 0.1 0.1", "size 0.1 0.5 0.1")
    sim = Simulation(load_world(world(tmp_path, extra=wall + box("second", X0 - 0.2))))
    belt(sim, 0.2)
    sim.run(400)
    front = at(sim)[0] + 0.05
    assert 0.29 - 0.002 < front <= 0.29 + 1e-9      # (contact's EPS: touching is not overlapping)
    assert at(sim, "second")[0] + 0.05 <= at(sim)[0] - 0.05 + 1e-12     # behind it, not into it
    assert at(sim, "second")[0] - 0.05 > at(sim)[0] - 0.05 - 0.1 - 0.002 - 1e-12   # stopped against it
    assert at(sim, "wall") == [0.34, 0.0, TOP + 0.05]


def test_reset_restores_the_box_and_the_belt(tmp_path: Path) -> None:
    sim = Simulation(load_world(world(tmp_path)))
    belt(sim, 0.2)
    sim.run(100)
    assert at(sim)[0] == pytest.approx(X0 + 0.2, abs=1e-12)
    sim.reset()
    assert at(sim) == [X0, 0.0, TOP + 0.05]
    sim.run(100)                                   # the motor's command is reset too (velocity control off)
    assert at(sim) == [X0, 0.0, TOP + 0.05]
    belt(sim, 0.2)
    sim.run(100)
    assert at(sim)[0] == pytest.approx(X0 + 0.2, abs=1e-12)


def test_a_turned_conveyor_carries_along_its_tracks_x(tmp_path: Path) -> None:
    """The conveyor robot turned 90 degrees about z: its belt runs along the world's +y; the box on it
    (put at the belt's world position) goes along +y."""
    p = world(tmp_path, place="rotation 0 0 1 1.5707963267948966")
    p.write_text(p.read_text().replace(f'name "box" translation {X0} 0.0 ', f'name "box" translation 0 {X0} '))
    sim = Simulation(load_world(p))
    belt(sim, 0.2)
    sim.run(100)
    assert at(sim) == pytest.approx([0.0, X0 + 0.2, TOP + 0.05], abs=1e-12)


def test_a_belt_without_a_box_bounding_object_keeps_its_warning(tmp_path: Path) -> None:
    """Only a Box (or a Shape of one, or one inside a Pose/Transform) is read as a belt's top face: a
    Cylinder inside a Transform is not."""
    w = load_world(world(tmp_path, bounding="Transform { children [ Cylinder { height 0.1 radius 0.5 } ] }"))
    assert w.world.robots[0].belts == []
    assert any("the belt and its wheels do not move here" in x for x in w.warnings), w.warnings
    sim = Simulation(w)
    assert sim._belts is None                      # nothing to carry: nothing computed per step
    belt(sim, 0.2)
    sim.run(50)
    assert at(sim) == [X0, 0.0, TOP + 0.05]


def test_the_batched_simulation_refuses_a_belt(tmp_path: Path) -> None:
    w = load_world(world(tmp_path))
    with pytest.raises(BatchedError, match=r"robot 'conveyor': its conveyor belt \(motor 'belt motor'\) carries "
                       r"solids; the batched simulation moves no belt \(use Simulation\)"):
        BatchedSimulation(w.world, 2)


YAML = """world_info: {{name: belt, basic_time_step: 10}}
solids:
  - {{name: floor, geometry: {{type: plane, size: [4, 4]}}}}
  - {{name: parcel, physics: true, pose: {{translation: [0, 0, 0.15]}}, geometry: {{type: box, size: [0.1, 0.1, 0.1]}}}}
robots:
  - name: conveyor
    controller: "<none>"
    body: {{geometry: {{type: box, size: [1, 0.3, 0.1]}}}}
    pose: {{translation: [0, 0, 0.05]}}
    devices: [{{name: belt motor, device: LinearMotor, max_velocity: 1, max_force: 1000}}]
    belts: [{{motor: {motor}, top: [0, 0, 0.05], along: [0, 1, 0], across: [-1, 0, 0], length: 1, width: 0.3}}]
"""


def test_a_yaml_robot_gives_its_belt(tmp_path: Path) -> None:
    """A YAML world's robot names its belt (schemas ConveyorBelt): along its +y here, 0.1 m top face."""
    p = tmp_path / "belt.yaml"
    p.write_text(YAML.format(motor='"belt motor"'))
    sim = Simulation(load_world(p))
    belt(sim, 0.25)
    sim.run(100)
    assert at(sim, "parcel") == pytest.approx([0.0, 0.25, 0.15], abs=1e-12)


def test_a_belt_naming_no_linear_motor_is_one_clear_line(tmp_path: Path) -> None:
    p = tmp_path / "belt.yaml"
    p.write_text(YAML.format(motor="roller"))
    with pytest.raises(Exception, match=r"belts\[0\]\.motor: 'roller' is not one of the robot's LinearMotor devices"):
        load_world(p)


def test_a_tilted_belt_carries_nothing_and_says_so(tmp_path: Path) -> None:
    """Only a level face carries (no slope rule here): a conveyor tilted 0.1 rad about its x warns once."""
    from sensorium.server.sim.ground import GroundWarning

    w = load_world(world(tmp_path, place="rotation 1 0 0 0.1"))
    with pytest.warns(GroundWarning, match=r"robot 'conveyor': the belt of 'belt motor' is not level .*: it carries "
                      "nothing"):
        sim = Simulation(w)
    before = at(sim)
    belt(sim, 0.2)
    sim.run(20)
    assert at(sim) == before


def test_a_python_controller_sees_the_belts_linear_motor_and_sensor(tmp_path: Path,
                                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    """The conveyor's LinearMotor and its PositionSensor answer Webots' linear types (the sensor
    answered rotational before), over a real server in a thread."""
    from _inproc import inproc_server

    import sensorium.client.webots.controller as controller
    from sensorium.client import wb

    path = world(tmp_path)
    text = path.read_text()
    assert text.count('name "conveyor"  controller "<none>"') == 1       # the conveyor robot takes a controller
    path.write_text(text.replace('name "conveyor"  controller "<none>"', 'name "conveyor"'))
    with inproc_server(heartbeat_ms=2000, world=path) as (_core, transport):
        monkeypatch.setenv("SENSORIUM_CONTROLLER_URL", f"{transport.rpc_endpoint}/conveyor")
        try:
            robot = controller.Robot()
            motor, sensor = robot.getDevice("belt motor"), robot.getDevice("belt sensor")
            assert isinstance(motor, controller.LinearMotor) and motor.getType() == controller.Motor.LINEAR
            assert sensor.getType() == controller.PositionSensor.LINEAR and sensor.getMotor() is motor
            assert motor.getMaxVelocity() == 1.0
        finally:
            wb.wb_robot_cleanup()
            controller.Robot.created = None


def nue_twin(tmp_path: Path) -> tuple[Path, Path]:
    """An ENU world whose conveyor runs north (turned 90 degrees about z) and its NUE twin (x north, y up,
    z east; ENU (e, n, u) is NUE (n, u, e)): the twin's robot built y-up as Webots' were before R2022a,
    its Track's Box 1 long (x), 0.1 high (y), 0.3 wide (z)."""
    enu = world(tmp_path, place="rotation 0 0 1 1.5707963267948966")
    enu.write_text(enu.read_text().replace(f'name "box" translation {X0} 0.0 ', f'name "box" translation 0 {X0} '))
    nue = tmp_path / "conveyor_nue.wbt"
    nue.write_text(
        '#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 10 coordinateSystem "NUE" }\n'
        # the floor: a Plane turned so its normal is the world's y
        'Solid { name "floor" rotation 1 0 0 -1.5707963267948966 children [ DEF F Shape { geometry Plane '
        '{ size 10 10 } } ] boundingObject USE F }\n'
        'Robot { name "conveyor" controller "<none>" children [\n'
        '  Track { name "belt" translation 0 0.15 0 children [ DEF BELT Shape { geometry Box { size 1 0.1 0.3 } } ]\n'
        '    boundingObject USE BELT device [ LinearMotor { name "belt motor" maxVelocity 1 maxForce 1000 } ] }\n'
        '] }\n' + box("box", X0, y=TOP + 0.05, z=0.0) + box("side", X0, y=0.05, z=-1.0))
    return enu, nue


def test_a_nue_belt_carries_as_its_enu_twin(tmp_path: Path) -> None:
    """A belt in a NUE world carries along its Track's +x (north) as the ENU twin's does, every step,
    and past its end the box lands where the twin's does, mapped through the axes (1e-12). Before, the
    y-up Track's face was read about its z: not level, it carried nothing."""
    enu, nue = nue_twin(tmp_path)
    w = load_world(nue)
    assert any("its belt carries the solids" in x for x in w.warnings), w.warnings
    sims = Simulation(load_world(enu)), Simulation(w)
    for sim in sims:
        belt(sim, 0.23)        # (its end, 0.8 m ahead, is not met on a step's boundary: no tie to round)
    for n in range(1, 451):
        for sim in sims:
            sim.step()
        e, u = at(sims[0]), at(sims[1])
        assert [u[2], u[0], u[1]] == pytest.approx(e, abs=1e-12)
        if n == 100:
            assert e == pytest.approx([0.0, X0 + 0.23, TOP + 0.05], abs=1e-12)
    assert e[2] == pytest.approx(0.05, abs=1e-12) and e[1] > 0.5        # past the end: on the floor
    assert at(sims[1], "side") == [X0, 0.05, -1.0]                      # beside the belt: not carried


def test_a_wall_on_a_nue_belt_stops_the_box_as_on_its_enu_twin(tmp_path: Path) -> None:
    """A fixed wall across each twin's belt, 0.34 m ahead of its centre: the NUE box stops where the
    ENU one does, mapped through the axes (1e-12), short of the wall's face at 0.29."""
    enu, nue = nue_twin(tmp_path)
    enu.write_text(enu.read_text() + box("wall", 0.0, y=0.34, physics="").replace("size 0.1 0.1 0.1", "size 0.5 0.1 0.1"))
    nue.write_text(nue.read_text() + box("wall", 0.34, y=TOP + 0.05, z=0.0, physics="").replace(
        "size 0.1 0.1 0.1", "size 0.1 0.1 0.5"))
    sims = Simulation(load_world(enu)), Simulation(load_world(nue))
    for sim in sims:
        belt(sim, 0.2)
        sim.run(400)
    e, u = at(sims[0]), at(sims[1])
    assert [u[2], u[0], u[1]] == pytest.approx(e, abs=1e-12)
    assert 0.29 - 0.002 < e[1] + 0.05 <= 0.29 + 1e-9


def test_a_box_inside_a_pose_is_the_belts_face(tmp_path: Path) -> None:
    """The Track's Box inside a Pose 0.2 m along x and 0.05 m up (the Track 0.05 lower), turned a
    quarter about the Track's up: the face is 0.3 x 1 in the Box's frame, 1 m along the Track's x,
    centred at x 0.2; the belt carries along the Track's +x and the box falls past x 0.7. Before, the
    Track kept its warning and nothing moved."""
    pose = "Pose { translation 0.2 0 0.05 rotation 0 0 1 1.5707963267948966 children [ Box { size 0.3 1 0.1 } ] }"
    p = world(tmp_path, bounding=pose)
    p.write_text(p.read_text().replace('Track { name "belt" translation 0 0 0.15', 'Track { name "belt" translation 0 0 0.1'))
    w = load_world(p)
    assert not any("the belt and its wheels do not move" in x for x in w.warnings), w.warnings
    b = w.world.robots[0].belts[0]
    assert b.top == pytest.approx((0.2, 0.0, TOP), abs=1e-15)
    assert (b.along, b.length, b.width) == (pytest.approx((1.0, 0.0, 0.0), abs=1e-15), 1.0, 0.3)
    _ride_off(Simulation(w), X0, 0.7)


def test_a_box_turned_half_about_up_still_carries_along_the_tracks_x(tmp_path: Path) -> None:
    """A Transform turning the Box half a turn about the Track's up: the belt still moves along the
    Track's +x (its face's sides are taken facing it)."""
    p = world(tmp_path, bounding="Transform { rotation 0 0 1 3.141592653589793 children [ USE BELT ] }")
    sim = Simulation(load_world(p))
    belt(sim, 0.2)
    sim.run(100)
    assert at(sim) == pytest.approx([X0 + 0.2, 0.0, TOP + 0.05], abs=1e-12)


def test_a_box_tilted_inside_a_pose_carries_nothing_and_says_so(tmp_path: Path) -> None:
    from sensorium.server.sim.ground import GroundWarning

    w = load_world(world(tmp_path, bounding="Pose { rotation 1 0 0 0.1 children [ USE BELT ] }"))
    with pytest.warns(GroundWarning, match=r"robot 'conveyor': the belt of 'belt motor' is not level"):
        sim = Simulation(w)
    before = at(sim)
    belt(sim, 0.2)
    sim.run(20)
    assert at(sim) == before



def test_each_box_of_a_group_is_a_face_carrying_along_the_tracks_x(tmp_path: Path) -> None:
    """The Track's boundingObject a Group: a Pose holding a 0.5 m Box 0.25 m behind the Track's origin,
    and a Transform holding another 0.5 m Box 0.25 m ahead with a Cylinder (an end roller) beside it.
    Each Box's top face carries, as every contact of a Track's bounding object moves in Webots: the box
    rides across the seam at x 0 at x0 + 0.2 t every step (1e-12) and falls past x 0.5. Before, a Group
    was no belt: the Track kept its warning and nothing moved."""
    group = ("Group { children [ Pose { translation -0.25 0 0 children [ Box { size 0.5 0.3 0.1 } ] }\n"
             "  Transform { translation 0.25 0 0 children [ Box { size 0.5 0.3 0.1 }\n"
             "    Pose { translation 0.25 0 0 rotation 1 0 0 1.5707963267948966 children [ Cylinder { radius 0.05 height 0.3 } ] } ] } ] }")
    w = load_world(world(tmp_path, bounding=group))
    assert not any("the belt and its wheels do not move" in x for x in w.warnings), w.warnings
    faces = w.world.robots[0].belts
    assert [(b.top, b.along, b.direction, b.length, b.width) for b in faces] == [
        ((-0.25, 0.0, TOP), (1.0, 0.0, 0.0), None, 0.5, 0.3), ((0.25, 0.0, TOP), (1.0, 0.0, 0.0), None, 0.5, 0.3)]
    _ride_off(Simulation(w), X0, 0.5)


def test_a_box_turned_30_degrees_carries_along_the_tracks_x(tmp_path: Path) -> None:
    """The Track's 1 x 0.3 Box turned 30 degrees about its up in a Pose: the face is the turned Box's top,
    but the belt moves along the Track's own +x, as Webots' contact motion does: the box stays at y 0
    every step (1e-12), and falls once its origin leaves the face across it (|x| sin 30 > 0.15: x > 0.3).
    Before, it went along the Box's side, 30 degrees off."""
    X1 = -0.25          # (at X0 the origin would sit on the face's side edge: 0.3 sin 30 = 0.15)
    p = world(tmp_path, bounding="Pose { rotation 0 0 1 0.5235987755982988 children [ USE BELT ] }")
    p.write_text(p.read_text().replace(f'name "box" translation {X0} 0.0 ', f'name "box" translation {X1} 0.0 '))
    w = load_world(p)
    b = w.world.robots[0].belts[0]
    assert b.direction == (1.0, 0.0, 0.0)
    assert b.along == pytest.approx((math.sqrt(3) / 2, 0.5, 0.0), abs=1e-15)
    _ride_off(Simulation(w), X1, 0.3)


def test_a_blocked_box_stops_with_its_face_on_the_walls(tmp_path: Path) -> None:
    """A fixed wall across the belt, its face at x 0.29, the belt at 0.23 m/s (2.3 mm a step: the box's
    front face, 0.54 m away, meets it mid-step): the box stops with its front face on the wall's, and the
    box behind it with its front face on the first one's back (1e-9). Before, each stopped up to one
    step's travel short."""
    wall = box("wall", 0.34, physics="").replace("size 0.1 0.1 0.1", "size 0.1 0.5 0.1")
    sim = Simulation(load_world(world(tmp_path, extra=wall + box("second", X0 - 0.2))))
    belt(sim, 0.23)
    sim.run(400)
    assert at(sim) == pytest.approx([0.29 - 0.05, 0.0, TOP + 0.05], abs=1e-9)
    assert at(sim, "second") == pytest.approx([0.29 - 0.15, 0.0, TOP + 0.05], abs=1e-9)
    assert at(sim, "wall") == [0.34, 0.0, TOP + 0.05]
