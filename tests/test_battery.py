"""Robots' batteries and Webots' Chargers (README "Battery and Charger"): a battery [E0, Emax, r] with
cpuConsumption P reads E0 - P t at its sensor's sample times, stops at 0 and reads 0 at once; a full
Charger within its radius gives a robot r dt a step until its maximum, an idle one gathers its own
speed, the robot leaving empties it; a robot away from it gets nothing; the .wbt import reads the
fields; Python and C controllers under `sensorium run` read the same values."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from test_run import clib, compile_controller, project, run  # noqa: F401  (clib: the fixture)

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, load_world, parse_world

DT = 32          # basic step (ms)


def world(robots: list[dict], chargers: list[dict] = (), solids: list[dict] = ()) -> Simulation:  # type: ignore[assignment]
    return Simulation(parse_world({"world_info": {"basic_time_step": DT}, "robots": robots,
                                   "chargers": list(chargers), "solids": list(solids)}))


def test_the_battery_reads_its_energy_less_cpu_consumption_at_each_sample() -> None:
    e0, p = 100.0, 5.0
    sim = world([{"name": "r", "battery": [e0, 200.0, 20.0], "cpu_consumption": p}])
    r = sim.robots["r"]
    sim.step()                                   # enabled at 32 ms with a 64 ms period: samples at 96, 160, ...
    sim.enable_battery_sensor(r, 64)
    seen = []
    for _ in range(8):
        sim.step()
        seen.append((sim.time_ms, r.battery_value))
    assert math.isnan(seen[0][1])                # before its first sample, as Webots
    for t, v in seen:
        last = t - (t - 32) % 64                 # the latest sample time
        if last > 32:
            assert v == pytest.approx(e0 - p * last / 1000, abs=1e-9)
    assert r.battery.energy == pytest.approx(e0 - p * sim.time_ms / 1000, abs=1e-9)
    sim.enable_battery_sensor(r, 0)              # disabled: the last value stays
    last_value = r.battery_value
    sim.step()
    assert r.battery_value == last_value and r.battery_schedule.period_ms == 0


def test_an_empty_battery_reads_zero_at_once_and_stays_empty() -> None:
    # 1 J at 10 W (the default cpuConsumption): 0.32 J a step, empty in the 4th step (128 ms)
    sim = world([{"name": "r", "battery": [1.0]}, {"name": "none"}])
    r, none = sim.robots["r"], sim.robots["none"]
    sim.enable_battery_sensor(r, 1000)
    sim.enable_battery_sensor(none, DT)
    for _ in range(3):
        sim.step()
    assert r.battery.energy == pytest.approx(1.0 - 10 * 0.096) and math.isnan(r.battery_value)
    sim.step()
    assert r.battery.energy == 0.0 and r.battery_value == 0.0 and sim.time_ms == 128   # refreshed when it emptied
    for _ in range(40):
        sim.step()
    assert r.battery.energy == 0.0 and r.battery_value == 0.0
    assert none.battery_value == -1.0            # a robot without a battery: Webots' -1
    sim.reset()                                  # simulationReset: the battery as loaded
    assert r.battery.energy == 1.0


CHARGER = {"solid": "dock", "battery": [50.0, 50.0, 10.0], "radius": 0.2}
DOCK = {"name": "dock", "pose": {"translation": [1.0, 0.0, 0.0]}}


def test_a_full_charger_within_its_radius_charges_one_robot_until_its_maximum() -> None:
    e0, emax, rate, p = 100.0, 103.0, 20.0, 5.0
    sim = world([{"name": "r", "battery": [e0, emax, rate], "cpu_consumption": p,
                  "pose": {"translation": [1.15, 0.0, 0.0]}},
                 {"name": "q", "battery": [e0, emax, rate], "cpu_consumption": p,      # also within: second in line
                  "pose": {"translation": [0.9, 0.0, 0.0]}}],
                [CHARGER], [DOCK])
    r, q, charger = sim.robots["r"], sim.robots["q"], sim.chargers[0]
    net = (rate - p) * DT / 1000                 # 0.48 J a step
    for k in range(1, 6):
        sim.step()
        assert r.battery.energy == pytest.approx(e0 + k * net, abs=1e-9)
        assert q.battery.energy == pytest.approx(e0 - k * p * DT / 1000, abs=1e-9)
        assert charger.energy == pytest.approx(50.0 - k * rate * DT / 1000, abs=1e-9)
    sim.step()                                   # 103.36 > 103: the battery keeps its maximum, less this step's use
    assert r.battery.energy == pytest.approx(emax - p * DT / 1000, abs=1e-9)
    assert charger.energy == pytest.approx(50.0 - 6 * rate * DT / 1000, abs=1e-9)
    for k in range(1, 4):                        # full: the Charger still gives, the energy is lost
        sim.step()
        assert r.battery.energy == pytest.approx(emax - (k + 1) * p * DT / 1000, abs=1e-9)
        assert charger.energy == pytest.approx(50.0 - (6 + k) * rate * DT / 1000, abs=1e-9)
    r.set_pose([1.21, 0.0, 0.0])                 # beyond the radius, within 1.1 radius: still held
    sim.step()
    assert charger.robot == 0
    r.set_pose([3.0, 0.0, 0.0])                  # gone: the Charger is emptied, then gathers 10 W
    sim.step()
    assert charger.robot is None and charger.energy == pytest.approx(10.0 * DT / 1000, abs=1e-12)
    before = q.battery.energy
    sim.step()                                   # q within the radius is not taken: the Charger is not full
    assert charger.robot is None and q.battery.energy == pytest.approx(before - p * DT / 1000, abs=1e-9)


def test_a_robot_away_from_the_charger_gets_nothing_and_the_charger_gathers_up_to_its_maximum() -> None:
    sim = world([{"name": "r", "battery": [100.0, 200.0, 20.0], "cpu_consumption": 0.0,
                  "pose": {"translation": [1.25, 0.0, 0.0]}}],
                [{**CHARGER, "battery": [49.0, 50.0, 10.0]}], [DOCK])
    charger = sim.chargers[0]
    for k in range(1, 5):
        sim.step()
        assert charger.energy == pytest.approx(min(50.0, 49.0 + k * 10.0 * DT / 1000), abs=1e-12)
    assert sim.robots["r"].battery.energy == 100.0 and charger.robot is None


def test_a_charger_names_a_top_level_solid() -> None:
    with pytest.raises(WorldError, match=r"chargers\[0\]\.solid: no top-level solid named 'dock'"):
        world([{"name": "r"}], [CHARGER])


WBT = """#VRML_SIM R2023b utf8
WorldInfo { basicTimeStep 32 }
Charger {
  translation 1 0 0
  children [ Shape { appearance Appearance { material Material { emissiveColor 0 1 0 } } geometry Box { size 0.1 0.1 0.1 } } ]
  name "dock"
  battery [ 40, 50, 10 ]
  radius 0.3
}
Robot { name "plain" battery [ 80, 100, 5 ] cpuConsumption 2.5 }
Robot {
  name "heavy"
  battery [ 10, 10, 1 ]
  children [ HingeJoint { device [ RotationalMotor { name "m" } ] endPoint Solid { } } ]
  physics Physics { }
}
Robot { name "thrifty" battery [ 10 ] physics Physics { }
  children [ HingeJoint { device [ RotationalMotor { name "m" consumptionFactor 0 } ] endPoint Solid { } } ] }
"""


def test_the_wbt_import_reads_batteries_cpu_consumption_and_chargers(tmp_path: Path) -> None:
    p = tmp_path / "w.wbt"
    p.write_text(WBT)
    w = load_world(p)
    robots = {r.name: r for r in w.world.robots}
    assert robots["plain"].battery == [80.0, 100.0, 5.0] and robots["plain"].cpu_consumption == 2.5
    assert robots["heavy"].cpu_consumption == 10.0 and robots["thrifty"].battery == [10.0]
    (charger,) = w.world.chargers
    assert (charger.solid, charger.battery, charger.radius) == ("dock", [40.0, 50.0, 10.0], 0.3)
    said = [x.split(": ", 1)[1] for x in w.warnings if "battery" in x or "Charger" in x]
    assert said == ["Robot 'heavy': its motors' energy consumption (torque x consumptionFactor) is not simulated "
                    "(no torques here): its battery drains by cpuConsumption only"]
    sim = Simulation(w)
    sim.step()
    assert sim.robots["plain"].battery.energy == pytest.approx(80.0 - 2.5 * 0.032)


PY_READER = '''from controller import Robot
robot = Robot()
robot.batterySensorEnable(32)
while robot.step(16) != -1:
    print(round(robot.getTime() * 1000), f"{robot.batterySensorGetValue():.6f}", robot.batterySensorGetSamplingPeriod())
'''

C_READER = r'''#include <math.h>
#include <stdio.h>
#include <webots/robot.h>

int main(void) {
  wb_robot_init();
  wb_robot_battery_sensor_enable(32);
  while (wb_robot_step(16) != -1) {
    double v = wb_robot_battery_sensor_get_value();
    if (isnan(v))
      printf("%ld nan %d\n", lround(wb_robot_get_time() * 1000), wb_robot_battery_sensor_get_sampling_period());
    else
      printf("%ld %.6f %d\n", lround(wb_robot_get_time() * 1000), v, wb_robot_battery_sensor_get_sampling_period());
    fflush(stdout);
  }
  wb_robot_cleanup();
  return 0;
}
'''


@pytest.mark.slow
def test_python_and_c_controllers_read_the_same_battery(tmp_path: Path, clib: tuple[Path, list[str]]) -> None:  # noqa: F811
    """0.5 J at 3 W, 16 ms steps, a 32 ms period: 0.5 - 0.003 t at t = 32, 64, ...; empty in the step
    ending at 176 ms (0.5 / 0.048 J a step), read 0 at once."""
    battery = "battery [ 0.5, 1, 1 ] cpuConsumption 3"
    world = project(tmp_path, f'Robot {{ name "py" controller "py_reader" {battery} }}\n'
                              f'Robot {{ name "c" controller "c_reader" {battery} }}', {"py_reader.py": PY_READER})
    compile_controller(clib, tmp_path / "controllers" / "c_reader", "c_reader", C_READER)
    proc = run(world, "--until", "224")
    assert proc.wait() == 0, proc.stderr()
    expected = []
    for t in range(16, 225, 16):
        sampled = t - t % 32
        value = "nan" if sampled == 0 else f"{max(0.0, 0.5 - 3 * sampled / 1000) if t < 176 else 0.0:.6f}"
        expected.append(f"{t} {value} 32")
    out = proc.stdout().splitlines()
    for robot in ("py", "c"):
        assert [line.split("] ", 1)[1] for line in out if line.startswith(f"[{robot}]")] == expected, proc.stdout()


def test_the_battery_services_serve_the_attached_controller_and_reset_when_it_leaves() -> None:
    import msgpack

    from sensorium.schemas import wire
    from sensorium.server.daemon.services import Core

    core = Core(world([{"name": "r", "battery": [10.0, 20.0, 1.0], "cpu_consumption": 2.0}]),
                new_token=lambda: "s0", log=lambda *_: None)
    rid = iter(range(1, 100))

    def call(service: str, args: dict, who: bytes = b"A") -> dict:
        (frames,) = core.handle([who, wire.pack({"id": next(rid), "service": service, "args": args})], 0.0)
        return msgpack.unpackb(frames[-1])

    assert call("attach", {"robot": "r"})["ok"] is True
    refused = call("/r/robot/battery_sensor_enable", {"value": DT}, who=b"B")     # not its controller
    assert refused["ok"] is False
    assert call("/r/robot/battery_sensor_enable", {"value": DT})["result"] == {"success": True}
    assert math.isnan(call("/r/robot/battery_sensor_get_value", {})["result"]["value"])
    for _ in range(3):
        assert core.handle([b"A", wire.pack({"id": next(rid), "service": "/r/robot/step", "args": {}})], 0.0) == []
        core.step_once(0.0)
    assert call("/r/robot/battery_sensor_get_value", {})["result"]["value"] == pytest.approx(10.0 - 2.0 * 0.096)
    assert call("/r/robot/battery_sensor_get_sampling_period", {}, who=b"B")["result"]["value"] == DT
    assert call("detach", {"session": "s0"})["ok"] is True
    assert call("/r/robot/battery_sensor_get_sampling_period", {}, who=b"B")["result"]["value"] == 0
    assert math.isnan(call("/r/robot/battery_sensor_get_value", {}, who=b"B")["result"]["value"])


def test_a_supervisor_reads_the_battery_field_with_its_present_energy() -> None:
    import msgpack

    from sensorium.schemas import wire
    from sensorium.server.daemon.services import Core

    sim = world([{"name": "r", "def_name": "R", "battery": [10.0, 20.0], "cpu_consumption": 2.0},
                 {"name": "boss", "supervisor": True}])
    core = Core(sim, new_token=lambda: "s0", log=lambda *_: None)
    rid = iter(range(1, 100))

    def call(service: str, args: dict) -> dict:
        (frames,) = core.handle([b"A", wire.pack({"id": next(rid), "service": service, "args": args})], 0.0)
        return msgpack.unpackb(frames[-1])["result"]

    call("attach", {"robot": "boss"})
    node = call("/boss/robot/get_from_def", {"name": "R"})["node"]
    for _ in range(5):
        sim.step()
    # the world's two values, the first the energy now (Webots' WbRobot::setCurrentEnergy writes the field)
    got = call("/boss/robot/get_field", {"node": node, "field": "battery"})
    assert got["type"] == "MFFloat" and got["value"] == pytest.approx([10.0 - 2.0 * 0.16, 20.0], abs=1e-12)
    assert call("/boss/robot/get_field", {"node": node, "field": "cpuConsumption"}) == {"type": "SFFloat", "value": 2.0}


# an empty battery powers its robot off (WbRobot::powerOn(false)) until a Charger gives it energy
DRAIN = 31.25            # W: 1.0 J a 32 ms step, exactly
FACE = 0.95              # the wall's face (m) ahead of the robot's distance sensor


def powered_world(e0: float, boss: bool = False) -> Simulation:
    """A robot at the origin driving +x at 0.1 m/s (wheels 0.05 m at 2 rad/s) towards a wall, its
    distance sensor reading the range (table 0..2 m), and a full Charger's solid far away (``boss``: the
    robot DEF R, and a supervisor robot 'boss')."""
    sim = world([{"name": "r", "def_name": "R", "battery": [e0, 100.0, 62.5], "cpu_consumption": DRAIN,
                  "differential_drive": {"wheel_radius": 0.05, "axle_length": 0.1},
                  "devices": [{"device": "DistanceSensor", "name": "d", "lookup_table": [[0, 0, 0], [2, 2, 0]]},
                              {"device": "PositionSensor", "name": "enc", "motor": "left wheel motor"}]},
                 *([{"name": "boss", "supervisor": True}] if boss else [])],
                [{**CHARGER, "battery": [50.0, 50.0, 10.0], "radius": 0.2}],
                [{"name": "dock", "pose": {"translation": [5.0, 3.0, 0.0]}},
                 {"name": "wall", "pose": {"translation": [1.0, 0, 0]}, "geometry": {"type": "box", "size": [0.1, 4, 1]}}])
    for m in sim.robots["r"].motors.values():
        m.set_position(math.inf)
        m.set_velocity(2.0)
    sim.device("r/d").enable(DT)
    sim.device("r/enc").enable(DT)
    return sim


def test_an_empty_battery_stops_the_robot_at_v_e0_over_p_and_freezes_its_sensors_until_a_charger_refills_it() -> None:
    e0, v = 5.0, 0.1
    sim = powered_world(e0)
    r, d, enc = sim.robots["r"], sim.device("r/d"), sim.device("r/enc")
    for k in range(1, 5):
        sim.step()
        assert r.pose.translation[0] == pytest.approx(v * k * DT / 1000, abs=1e-12)
        assert d.value == pytest.approx(FACE - v * k * DT / 1000, abs=1e-12)
    sim.step()                        # the 5th step empties it: it moved, its sensors did not refresh (Webots)
    stop = v * e0 / DRAIN             # 0.016 m
    assert r.battery.energy == 0.0 and not r.battery.powered
    assert r.pose.translation[0] == pytest.approx(stop, abs=1e-12)
    assert d.value == pytest.approx(FACE - v * 4 * DT / 1000, abs=1e-12)
    assert enc.value == pytest.approx(2.0 * 4 * DT / 1000, abs=1e-12)
    for _ in range(20):               # off: no motion, the last values kept
        sim.step()
    assert r.pose.translation[0] == pytest.approx(stop, abs=1e-12)
    assert d.value == pytest.approx(FACE - v * 4 * DT / 1000, abs=1e-12)
    assert enc.value == pytest.approx(2.0 * 4 * DT / 1000, abs=1e-12) and d.schedule.last_update_ms == 4 * DT
    sim.set_solid_pose("dock", [stop, 0.0, 0.0])       # the Charger comes: 62.5 W gives 2 J a step
    sim.step()                        # energy at the step's start: on again, it drives and samples this step
    assert r.battery.powered and r.battery.energy == pytest.approx(2.0 - 1.0, abs=1e-12)
    assert r.pose.translation[0] == pytest.approx(stop + v * DT / 1000, abs=1e-12)
    assert d.value == pytest.approx(FACE - stop - v * DT / 1000, abs=1e-12)
    assert enc.value == pytest.approx(2.0 * 6 * DT / 1000, abs=1e-12)    # the wheel turned 5 + 1 steps
    sim.reset()                       # simulationReset: as loaded, powered
    assert r.battery.powered and r.battery.energy == e0


def test_a_robot_loaded_with_an_empty_battery_is_powered_as_in_webots() -> None:
    # Webots powers a robot off only when a step empties its battery; one loaded with 0 J runs
    sim = powered_world(0.0)
    sim.run(3)
    assert sim.robots["r"].pose.translation[0] == pytest.approx(0.1 * 3 * DT / 1000, abs=1e-12)


def test_an_empty_battery_turns_the_leds_and_their_lights_off_while_get_reads_the_set_value() -> None:
    from test_led_lights import COLORS, FILTER, D, I, closed_form

    sim = world([{"name": "eye", "devices": [{"device": "LightSensor", "name": "ls", "color_filter": list(FILTER)}]},
                 {"name": "r", "battery": [2.0, 10.0, 62.5], "cpu_consumption": DRAIN,
                  "pose": {"translation": [D, 0.0, 0.0]},
                  "devices": [{"device": "LED", "name": "led", "color": [list(c) for c in COLORS],
                               "lights": [{"type": "PointLight", "intensity": I, "attenuation": [0, 0, 1]}]}]}],
                [{**CHARGER, "radius": 0.1}], [{"name": "dock", "pose": {"translation": [9.0, 0.0, 0.0]}}])
    ls, led = sim.device("eye/ls"), sim.device("r/led")
    ls.enable(DT)
    led.set(2, sim.time_ms)
    sim.step()
    assert ls.value == pytest.approx(closed_form(COLORS[1]), rel=1e-12)
    sim.step()                        # empty (2 J at 1 J a step): WbLed::powerOn(false) sets its value 0
    assert ls.value == 0.0 and led.rgb() == (0.0, 0.0, 0.0)
    assert led.value == 2             # what wb_led_get reads: libController's last set
    sim.set_solid_pose("dock", [D, 0.0, 0.0])
    sim.step()                        # powered again: Webots' LED stays off until the controller sets it
    assert sim.robots["r"].battery.powered and ls.value == 0.0
    led.set(2, sim.time_ms)
    sim.step()
    assert ls.value == pytest.approx(closed_form(COLORS[1]), rel=1e-12)


def test_an_empty_battery_holds_the_robots_joints_where_they_are() -> None:
    # a hinge at 2 rad/s (1e6 N m available: WbMotor's kinematic control reaches it in a step) turns
    # 0.064 rad a step for the 3 steps the 3 J last, then holds; a Charger's energy starts it again
    sim = world([{"name": "r", "battery": [3.0, 10.0, 62.5], "cpu_consumption": DRAIN,
                  "devices": [{"device": "RotationalMotor", "name": "pan", "axis": [0, 0, 1], "max_velocity": 2.0,
                               "max_torque": 1e6}]}],
                [CHARGER], [{"name": "dock", "pose": {"translation": [9.0, 0.0, 0.0]}}])
    pan = sim.robots["r"].motor("pan")
    pan.set_position(math.inf)
    pan.set_velocity(2.0)
    sim.run(3)
    assert pan.position == pytest.approx(3 * 0.064, abs=1e-12)
    sim.run(10)
    assert pan.position == pytest.approx(3 * 0.064, abs=1e-12) and pan.speed == 0.0
    sim.set_solid_pose("dock", [0.0, 0.0, 0.0])
    sim.step()
    assert pan.position == pytest.approx(4 * 0.064, abs=1e-12)


def test_the_batched_simulation_refuses_a_battery_that_can_empty_in_one_line() -> None:
    from sensorium.server.sim.batched import BatchedError, BatchedSimulation

    def batched(robot: dict, chargers: list[dict] = ()) -> BatchedSimulation:  # type: ignore[assignment]
        return BatchedSimulation(parse_world({"world_info": {"basic_time_step": DT}, "robots": [robot],
                                              "chargers": list(chargers), "solids": [DOCK]}), 2)

    with pytest.raises(BatchedError) as err:
        batched({"name": "r", "battery": [5.0, 10.0], "cpu_consumption": 2.0})
    assert str(err.value).endswith("robot 'r': its battery (5 J, cpu_consumption 2 W) can empty and power it off; "
                                   "the batched simulation drains no battery (use Simulation, or cpu_consumption: 0)")
    with pytest.raises(BatchedError, match="can empty"):      # empty now, but a Charger could fill it
        batched({"name": "r", "battery": [0.0, 10.0, 1.0], "cpu_consumption": 2.0}, [CHARGER])
    # nothing a battery changes: none drawn, or an empty one nothing fills (Webots keeps such a robot on)
    assert batched({"name": "r", "battery": [5.0, 10.0], "cpu_consumption": 0.0}, [CHARGER]).copies == 2
    assert batched({"name": "r", "battery": [0.0], "cpu_consumption": 2.0}).copies == 2


# a Supervisor's setMFFloat on a robot's battery: Webots' WbRobot reads the field's items live
def supervised(sim: Simulation) -> tuple[Simulation, object, int]:
    """``sim`` with a supervisor robot attached through the server's services: (sim, call, node of 'r')."""
    import msgpack

    from sensorium.schemas import wire
    from sensorium.server.daemon.services import Core

    core = Core(sim, new_token=lambda: "s0", log=lambda *_: None)
    rid = iter(range(1, 1000))

    def call(service: str, args: dict) -> dict:
        (frames,) = core.handle([b"A", wire.pack({"id": next(rid), "service": service, "args": args})], 0.0)
        return msgpack.unpackb(frames[-1])

    assert call("attach", {"robot": "boss"})["ok"] is True
    node = call("/boss/robot/get_from_def", {"name": "R"})["result"]["node"]
    return sim, call, node


def test_a_supervisor_write_of_the_energy_drains_from_there_and_an_empty_battery_powers_off_until_a_refill() -> None:
    # 1 J a step (DRAIN): written 4.5 J it reads 4.5 - n after n steps, empties in the 5th (off: no motion, no
    # sample); 2.5 J written then: the next step drains 1 J and leaves 1.5: on at its end (WbRobot::setCurrentEnergy
    # in the post-physics step), sampling then, driving from the step after
    v = 0.1
    sim, call, node = supervised(powered_world(7.0, boss=True))
    r, d = sim.robots["r"], sim.device("r/d")
    sim.enable_battery_sensor(r, DT)
    sim.step()
    assert r.battery_value == pytest.approx(6.0, abs=1e-12)
    write = {"node": node, "field": "battery", "index": 0, "op": "set"}
    assert call("/boss/robot/set_field", {**write, "value": 4.5})["ok"] is True
    got = call("/boss/robot/get_field", {"node": node, "field": "battery"})["result"]
    assert got["value"] == pytest.approx([4.5, 100.0, 62.5], abs=0.0)        # the field holds it at once
    assert r.battery_value == pytest.approx(6.0, abs=1e-12)                   # the sensor: at its next sample
    for n in range(1, 5):
        sim.step()
        assert r.battery.energy == pytest.approx(4.5 - n, abs=1e-12) and r.battery_value == r.battery.energy
    sim.step()
    assert r.battery.energy == 0.0 and not r.battery.powered and r.battery_value == 0.0
    stop = r.pose.translation[0]
    assert stop == pytest.approx(v * 6 * DT / 1000, abs=1e-12)               # it moved in the step it emptied
    sensed = d.value
    for _ in range(3):
        sim.step()
    assert r.pose.translation[0] == stop and d.value == sensed
    assert call("/boss/robot/set_field", {**write, "value": 2.5})["ok"] is True
    sim.step()                        # off through the motion, on at the post-physics step: samples, no motion
    assert r.battery.powered and r.battery.energy == pytest.approx(1.5, abs=1e-12) and r.battery_value == 1.5
    assert r.pose.translation[0] == stop
    assert d.value == pytest.approx(FACE - stop, abs=1e-12)
    sim.step()                        # powered from the step's start: it drives
    assert r.pose.translation[0] == pytest.approx(stop + v * DT / 1000, abs=1e-12)
    assert r.battery.energy == pytest.approx(0.5, abs=1e-12)
    sim.step()                        # 0.5 J: empty again
    assert not r.battery.powered
    assert call("/boss/robot/set_field", {**write, "value": 0.5})["ok"] is True
    sim.step()                        # less than a step's drain: it empties in that step and stays off
    assert not r.battery.powered and r.battery.energy == 0.0
    sim.reset()                       # simulationReset: the world's battery, powered
    assert r.battery.powered and r.battery.energy == 7.0


def test_a_written_maximum_and_recharge_speed_are_what_a_charger_gives_to() -> None:
    # the dock under the robot: 62.5 W gives 2 J a step against 1 J drained: +1 J a step up to the maximum;
    # written speed 93.75 W: 3 J a step, +2 J a step; written maximum 12 J: it stops there (Charger's rule)
    sim, call, node = supervised(world(
        [{"name": "r", "def_name": "R", "battery": [5.0, 100.0, 62.5], "cpu_consumption": DRAIN},
         {"name": "boss", "supervisor": True}],
        [{"solid": "dock", "battery": [500.0, 500.0, 0.0], "radius": 0.2}], [{"name": "dock"}]))
    r = sim.robots["r"]
    sim.step()
    assert r.battery.energy == pytest.approx(6.0, abs=1e-12)
    write = {"node": node, "field": "battery", "op": "set"}
    assert call("/boss/robot/set_field", {**write, "index": 2, "value": 93.75})["ok"] is True
    assert call("/boss/robot/set_field", {**write, "index": -2, "value": 12.0})["ok"] is True   # from the end, as Webots
    for n in range(1, 3):
        sim.step()
        assert r.battery.energy == pytest.approx(6.0 + 2.0 * n, abs=1e-12)
    sim.step()                        # 13 J capped at 12 J by the Charger, then the step's drain
    assert r.battery.energy == pytest.approx(11.0, abs=1e-12)
    assert call("/boss/robot/get_field", {"node": node, "field": "battery"})["result"]["value"] == \
        pytest.approx([11.0, 12.0, 93.75], abs=1e-12)
    assert call("/boss/robot/set_field", {"node": node, "field": "cpuConsumption", "value": 0.0})["ok"] is True
    sim.run(3)                        # no drain now, and the Charger holds a full robot: nothing more given
    assert r.battery.energy == 11.0
    sim.reset()                       # the world's values again
    assert (r.battery.energy, r.battery.maximum, r.battery.speed, r.battery.cpu) == (5.0, 100.0, 62.5, DRAIN)


@pytest.mark.parametrize(("args", "says"), [
    ({"index": 3, "op": "set", "value": 1.0}, "out-of-bound index 3 (should be between -3 and 2)"),
    ({"index": 0, "op": "insert", "value": 1.0}, "its values are set here, not inserted or removed"),
    ({"index": 0, "op": "remove"}, "its values are set here, not inserted or removed"),
    ({"index": 0, "op": "set", "value": -1.0}, "item 0 takes a finite number >= 0 (J), got -1.0; nothing changed"),
    ({"index": 2, "op": "set", "value": math.inf}, "should be a finite number (got inf)"),     # (the wire refuses it)
    ({"index": 0, "op": "set", "value": "full"}, "item 0 takes a finite number >= 0 (J), got 'full'"),
])
def test_a_battery_write_out_of_its_values_is_one_line_and_changes_nothing(args: dict, says: str) -> None:
    sim, call, node = supervised(world([{"name": "r", "def_name": "R", "battery": [5.0, 10.0, 1.0]},
                                        {"name": "boss", "supervisor": True}]))
    got = call("/boss/robot/set_field", {"node": node, "field": "battery", **args})
    assert got["ok"] is False and says in got["error"]["message"] and "\n" not in got["error"]["message"]
    b = sim.robots["r"].battery
    assert (b.energy, b.maximum, b.speed) == (5.0, 10.0, 1.0)


@pytest.mark.parametrize("value", [0.0, 1e-30, 5e-324, 1e-31, 9.99e-31, 1e9, 1e9 * (1 + 2 ** -52), 2e9, 1e300])
def test_a_battery_or_cpu_consumption_write_takes_exactly_what_a_world_file_takes(value: float) -> None:
    """The same number in a world file and in a Supervisor's write of each battery item and of
    cpuConsumption: both take it or both refuse it, the write's one line in the loader's words."""
    for field in ("battery[0]", "battery[1]", "battery[2]", "cpu_consumption"):
        battery = [5.0, 10.0, 1.0]
        at = int(field[-2]) if field.startswith("battery") else None
        robot: dict = {"name": "r", "battery": battery, "cpu_consumption": 2.0}
        if at is None:
            robot["cpu_consumption"] = value
        else:
            robot["battery"] = [value if i == at else b for i, b in enumerate(battery)]
        try:
            world([robot])
            loader = None
        except WorldError as e:
            (loader,) = str(e).splitlines()
            loader = loader.split(f"{field}: ", 1)[1]
        sim, call, node = supervised(world([{"name": "r", "def_name": "R", "battery": battery, "cpu_consumption": 2.0},
                                            {"name": "boss", "supervisor": True}]))
        args = {"field": "cpuConsumption", "value": value} if at is None else \
            {"field": "battery", "op": "set", "index": at, "value": value}
        got = call("/boss/robot/set_field", {"node": node, **args})
        b = sim.robots["r"].battery
        now = (b.energy, b.maximum, b.speed, b.cpu)
        if loader is None:
            assert got["ok"] is True, (field, got)
            assert now[3 if at is None else at] == value
        else:
            message = got["error"]["message"]
            assert got["ok"] is False and message.endswith(f"{loader}; nothing changed") and "\n" not in message, \
                (field, message)
            assert now == (5.0, 10.0, 1.0, 2.0)


def test_a_proto_robots_battery_field_passing_through_is_is_written_the_same_way() -> None:
    # tests/protos/battery/Cell.proto: battery IS battery ([5, 10, 1]), cpuConsumption IS cpu (31.25 W: 1 J a step)
    from sensorium.server.daemon import supervisor as sv

    sim = Simulation(load_world(Path(__file__).parent / "worlds" / "battery_proto.wbt"))
    cell, r = sv.find_node(sim, "CELL"), sim.robots["cell"]
    assert sv.change_item(sim, cell, "battery", "set", 0, 3.5) == []
    sim.run(2)
    assert r.battery.energy == pytest.approx(1.5, abs=1e-12)
    assert sv.get_field(sim, cell, "battery")["value"] == pytest.approx([1.5, 10.0, 1.0], abs=1e-12)
    assert sv.set_field(sim, cell, "cpu", 0.0) == []
    sim.run(2)
    assert r.battery.energy == pytest.approx(1.5, abs=1e-12)
    with pytest.raises(ValueError, match="PROTO internal field"):     # its base node's field: read-only, as Webots
        sv.change_item(sim, cell, "battery", "set", 0, 3.0, 0)
