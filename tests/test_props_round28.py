"""Property tests (Hypothesis, derandomized) of round 28's paths, each failing case found fixed with a
regression test naming it.

Drive judgement (wbt/drive.py, convert.py ``_robot_up``; README "Wheels"): a two-wheel robot turned as a
whole by B (any of its six axes onto the world's up) and then a yaw h about the world's up is its upright
twin (heading 0) carried by B: the same drive (radius R, axle 2·Y, no reversed motor, forward in the world
(cos h, sin h, 0)) and, driven with the same wheel speeds, the twin's path turned by h about the start (1e-9),
its rotation the twin's times B, with Physics and without (upright without Physics: Webots' kinematic rule
for both); the batched simulation rolls it bit for bit. A wheel's axis off the other's by up to 4e-3 rad still
gives a drive; by more than 5e-3, one load line and no drive.

Nested lights as Supervisor nodes, the battery topic, and degenerate wheels, hinges, slots and lights: see
their sections below."""

from __future__ import annotations

import gc
import itertools
import math
from pathlib import Path

import msgpack
import numpy as np
import pytest
from _fuzz import example_counts
from _wheeled_wbt import STEP, R, Y
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS
from test_sweep19 import rot

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

LEFT, RIGHT = "left wheel motor", "right wheel motor"
X0, Y0 = 0.1, -0.2
# B: the robot's own frame -> its upright twin's, mapping the named own axis onto the world's up (z)
BASES = {"z up": np.eye(3), "x up": rot((0, 1, 0), -math.pi / 2), "y up": rot((1, 0, 0), math.pi / 2),
         "-x up": rot((0, 1, 0), math.pi / 2), "-y up": rot((1, 0, 0), -math.pi / 2), "-z up": rot((1, 0, 0), math.pi)}


def axis_angle(m: np.ndarray) -> str:
    """A .wbt rotation field (axis, angle) of the rotation matrix ``m`` (via its quaternion)."""
    w = math.sqrt(max(0.0, 1.0 + m[0, 0] + m[1, 1] + m[2, 2])) / 2.0
    x = math.copysign(math.sqrt(max(0.0, 1.0 + m[0, 0] - m[1, 1] - m[2, 2])) / 2.0, m[2, 1] - m[1, 2])
    y = math.copysign(math.sqrt(max(0.0, 1.0 - m[0, 0] + m[1, 1] - m[2, 2])) / 2.0, m[0, 2] - m[2, 0])
    z = math.copysign(math.sqrt(max(0.0, 1.0 - m[0, 0] - m[1, 1] + m[2, 2])) / 2.0, m[1, 0] - m[0, 1])
    s = math.sqrt(x * x + y * y + z * z)
    if s < 1e-300:
        return "0 0 1 0"
    return vec((x / s, y / s, z / s, 2.0 * math.atan2(s, w)))


def num(v: float) -> str:
    """A world file's number: 0 for what is nearer 0 than 1e-30 (the loader's limit: README "Limits")."""
    return f"{float(v) if abs(v) >= 1e-30 else 0.0:.17g}"


def vec(v) -> str:
    return " ".join(num(c) for c in v)


def hinge(name: str, anchor, axis, part) -> str:
    """A motorised wheel hinge through ``anchor`` about ``axis`` (the robot's own frame), its end point a
    cylinder of radius R whose own z (its axis) ``part`` turns onto the hinge's axis."""
    return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis {vec(axis)} anchor {vec(anchor)} }}\n'
            f'  device [ RotationalMotor {{ name "{name}" maxVelocity 20 }} ]\n'
            f'  endPoint Solid {{ translation {vec(anchor)} children [ DEF W Pose {{ rotation {axis_angle(part)}\n'
            f'    children [ Shape {{ geometry Cylinder {{ radius {R} height 0.003 }} }} ] }} ] boundingObject USE W }} }}\n')


def wheeled(path: Path, base: np.ndarray, yaw: float, physics: bool, tilt: np.ndarray | None = None) -> Path:
    """Robot "bot" at (X0, Y0, 0) turned by yaw·``base``, its wheels its upright twin's carried by base⁻¹
    (through (0, ±Y, R) about the twin's +y); ``tilt`` turns the left wheel's axis further (own frame)."""
    inv = base.T
    left_axis = inv @ np.array([0.0, 1.0, 0.0])
    part = inv @ rot((1, 0, 0), -math.pi / 2)          # the cylinder's z onto the twin's +y
    left_part = part
    if tilt is not None:
        left_axis, left_part = tilt @ left_axis, tilt @ part
    wheels = (hinge(LEFT, inv @ [0.0, Y, R], left_axis, left_part)
              + hinge(RIGHT, inv @ [0.0, -Y, R], inv @ [0.0, 1.0, 0.0], part))
    path.write_text(f'#VRML_SIM R2023b utf8\nWorldInfo {{ basicTimeStep {STEP} }}\n'
                    f'Robot {{ name "bot" translation {X0} {Y0} 0 rotation {axis_angle(rot((0, 0, 1), yaw) @ base)}\n'
                    f'  children [\n{wheels}]\n  boundingObject Box {{ size 0.01 0.01 0.01 }}'
                    + (' physics Physics { }' if physics else '') + ' }\n')
    return path


def roll(path: Path, speeds: tuple[float, float], steps: int) -> Simulation:
    sim = simulation(load_world(path))
    for name, w in zip((LEFT, RIGHT), speeds):
        sim.robot("bot").motor(name).set_position(math.inf)
        sim.robot("bot").motor(name).set_velocity(w)
    sim.run(steps)
    return sim


speeds = st.floats(-10.0, 10.0, allow_nan=False)
_built = itertools.count()


def simulation(loaded) -> Simulation:
    """A Simulation of ``loaded``; every 20th collects the ones gone first (each holds an Embree device
    until the collector frees its cycles: about a thousand at once make rtcNewDevice fail)."""
    if next(_built) % 20 == 19:
        gc.collect()
    return Simulation(loaded)


def drives_as_its_twin(tmp_path: Path, up: str, yaw: float, physics: bool, wl: float, wr: float, steps: int) -> None:
    """The robot turned by yaw·BASES[up]: its drive, and its path against its upright twin's at heading 0."""
    base = BASES[up]
    path = wheeled(tmp_path / "turned.wbt", base, yaw, physics)
    lw = load_world(path)
    assert not [w for w in lw.warnings if "drive" in w or "motor" in w], lw.warnings
    dd = lw.world.robots[0].differential_drive
    assert dd is not None and (dd.left_motor, dd.right_motor, dd.reversed_motors) == (LEFT, RIGHT, [])
    assert dd.wheel_radius == pytest.approx(R, abs=1e-12)
    # upright without Physics: Webots' kinematic rule (its axle the cylinders' distances from the origin);
    # on its side, where Webots' rule would tumble it about its rotation's axis, the arc as with Physics
    webots_rule = up == "z up" and not physics
    assert dd.axle_length == pytest.approx(2 * math.hypot(Y, R) if webots_rule else 2 * Y, abs=1e-12)
    assert dd.step_rule == ("mid_heading" if webots_rule else "arc")
    forward = np.zeros(3)
    forward[:len(dd.forward)] = dd.forward
    world_forward = rot((0, 0, 1), yaw) @ base @ forward
    assert world_forward == pytest.approx([math.cos(yaw), math.sin(yaw), 0.0], abs=1e-9)
    # the twin: upright, heading 0; the turned robot's path is the twin's turned by the yaw about the start
    twin = roll(wheeled(tmp_path / "twin.wbt", np.eye(3), 0.0, physics or up != "z up"), (wl, wr), steps)
    start = np.array([X0, Y0, 0.0])
    turn = rot((0, 0, 1), yaw)
    pose = roll(path, (wl, wr), steps).robot("bot").pose
    expected = start + turn @ (np.asarray(twin.robot("bot").pose.translation) - start)
    assert np.asarray(pose.translation) == pytest.approx(expected, abs=1e-9)
    assert np.asarray(pose.rotation) == pytest.approx(turn @ np.asarray(twin.robot("bot").pose.rotation) @ base,
                                                      abs=1e-9)


@pytest.mark.parametrize("examples", example_counts(200, 4))
def test_a_two_wheel_robot_drives_alike_whichever_of_its_axes_is_up(tmp_path: Path, examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(st.sampled_from(sorted(BASES)), st.floats(-math.pi, math.pi), st.booleans(), speeds, speeds,
           st.integers(1, 25))
    def check(up: str, yaw: float, physics: bool, wl: float, wr: float, steps: int) -> None:
        drives_as_its_twin(tmp_path, up, yaw, physics, wl, wr, steps)

    check()


@pytest.mark.parametrize("examples", example_counts(80, 4))
def test_the_batched_simulation_rolls_a_turned_robot_as_simulation_does_bit_for_bit(tmp_path: Path, examples: int) -> None:
    """The turned robot of the property above in a BatchedSimulation copy: its pose is the single
    Simulation's, bit for bit, at every step, with the C drive pass and with numpy's."""
    from sensorium.gym.views import CopySim
    from sensorium.server.raycast import packets
    from sensorium.server.sim.batched import BatchedSimulation

    @settings(SETTINGS, max_examples=examples)
    @given(st.sampled_from(sorted(BASES)), st.floats(-math.pi, math.pi), st.booleans(), st.booleans(), speeds,
           speeds)
    def check(up: str, yaw: float, physics: bool, helper: bool, wl: float, wr: float) -> None:
        lw = load_world(wheeled(tmp_path / "batched.wbt", BASES[up], yaw, physics))
        batched = BatchedSimulation(lw, 1)
        if not helper or packets.library() is None:
            batched._drive_step = None
        batched.reset(np.arange(1), [1])
        if next(_built) % 20 == 19:
            gc.collect()
        single = Simulation(lw, "exact")
        for sim in (single, CopySim(batched, 0)):
            for name, w in zip((LEFT, RIGHT), (wl, wr)):
                sim.robot("bot").motors[name].set_position(math.inf)
                sim.robot("bot").motors[name].set_velocity(w)
        slot = batched.slot("bot")
        for t in range(20):
            batched.step()
            single.step()
            pose = single.robot("bot").pose
            assert batched.pos[0, slot].tobytes() == pose.translation.tobytes(), t
            assert batched.rot[0, slot].tobytes() == pose.rotation.tobytes(), t

    check()


@pytest.mark.parametrize("up", ["-x up", "-y up", "-z up"])
def test_regression_a_robot_with_an_axis_negative_end_up_drives_forward(tmp_path: Path, up: str) -> None:
    """Found by the property above: a robot whose −x or −y was the world's up was judged with its z (lying
    sideways: forward straight down, or no wheel at all), and one upside down (−z up) drove backward (its
    forward axis × z, not axis × −z). Now each rolls as its upright twin."""
    drives_as_its_twin(tmp_path, up, 0.3, True, 3.0, 5.0, 30)
    drives_as_its_twin(tmp_path, up, -2.0, False, -4.0, 1.0, 30)


@pytest.mark.parametrize("examples", example_counts(200, 4))
def test_a_wheel_axis_off_by_4e_3_still_drives_and_by_over_5e_3_gives_one_line(tmp_path: Path, examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(st.sampled_from(sorted(BASES)), st.floats(-math.pi, math.pi), st.floats(-math.pi, math.pi),
           st.floats(0.0, 4e-3) | st.floats(5.2e-3, 0.5))
    def check(up: str, yaw: float, about: float, off: float) -> None:
        base = BASES[up]
        # turn the left axis by ``off`` about a direction perpendicular to it (own frame): toe or camber
        a = base.T @ np.array([0.0, 1.0, 0.0])
        p = base.T @ np.array([math.cos(about), 0.0, math.sin(about)])
        path = wheeled(tmp_path / "off.wbt", base, yaw, False, tilt=rot(p, off))
        lw = load_world(path)
        dd = lw.world.robots[0].differential_drive
        lines = [w for w in lw.warnings if "no differential drive" in w or "drive" in w]
        assert np.dot(rot(p, off) @ a, a) == pytest.approx(math.cos(off), abs=1e-12)
        if off <= 4e-3:
            assert dd is not None and not lines, lw.warnings
            assert dd.wheel_radius == pytest.approx(R, abs=1e-6)
        else:
            assert dd is None and len(lines) == 1 and "\n" not in lines[0], lw.warnings

    check()


# --- the battery topic (sim/battery.py, daemon/topics.py; PROTOCOL.md §4) ---------------------------------

STATUS = {"full": 4, "charging": 1, "discharging": 2, "idle": 3}       # sensor_msgs/BatteryState's
CHARGER_AT, CHARGER_RADIUS = (1.0, 0.0, 0.0), 0.2


class BatteryModel:
    """The closed form of one robot's battery each basic step of ``dt`` ms: a full Charger holding it (its
    energy ``c``) gives min(speed·dt, c) until the battery passes its maximum (kept at it; the Charger then
    gives it nothing more), then cpuConsumption takes P·dt, stopping at 0; its status: full (at its maximum,
    a maximum > 0), charging (given energy this step), discharging (energy left and P > 0), else idle."""

    def __init__(self, e: float, emax: float, speed: float, p: float, dt: int, charger: float | None) -> None:
        self.e, self.emax, self.speed, self.p, self.dt = e, emax, speed, p, dt
        self.c, self.done, self.gained = charger, charger is None, 0.0

    def step(self) -> None:
        self.gained = 0.0
        if self.c is not None:
            given = min(self.speed * self.dt * 0.001, self.c)
            self.c -= given
            if not self.done:
                if self.e > self.emax:
                    self.done = True
                else:
                    self.e += given
                    self.gained = given
                    if self.e > self.emax:
                        self.e, self.done = self.emax, True
        if self.e > 0.0:
            self.e -= self.p * self.dt * 0.001
            if self.e <= 0.0:
                self.e = 0.0

    @property
    def status(self) -> int:
        if self.emax > 0.0 and self.e >= self.emax:
            return STATUS["full"]
        if self.gained > 0.0:
            return STATUS["charging"]
        return STATUS["discharging"] if self.e > 0.0 and self.p > 0.0 else STATUS["idle"]


battery_ops = st.lists(st.one_of(st.tuples(st.just("step"), st.integers(1, 6)),
                                 st.tuples(st.just("enable"), st.integers(0, 4)),       # period: k basic steps
                                 st.tuples(st.just("subscribe"), st.booleans())), max_size=14)


@pytest.mark.parametrize("examples", example_counts(200, 4))
def test_battery_messages_meet_the_closed_form_and_none_come_unwanted(examples: int) -> None:
    from sensorium.server.daemon.topics import Topics
    from sensorium.server.world.loader import parse_world

    @settings(SETTINGS, max_examples=examples)
    @given(st.floats(0.0, 300.0), st.floats(0.0, 300.0), st.floats(0.0, 500.0), st.floats(0.0, 400.0),
           st.sampled_from([1, 8, 16, 32, 64]), st.booleans(), battery_ops)
    def check(e: float, emax: float, speed: float, p: float, dt: int, charging: bool, ops: list) -> None:
        e, emax, speed, p = (v if v == 0.0 or v >= 1e-30 else 0.0 for v in (e, emax, speed, p))
        world = {"world_info": {"basic_time_step": dt},
                 "solids": [{"name": "dock", "pose": {"translation": list(CHARGER_AT)}}],
                 "chargers": [{"solid": "dock", "battery": [1000.0, 1000.0, 0.0], "radius": CHARGER_RADIUS}],
                 "robots": [{"name": "r", "battery": [e, emax, speed], "cpu_consumption": p,
                             "pose": {"translation": [1.05 if charging else 3.0, 0.0, 0.0]}}]}
        sim = simulation(parse_world(world))
        topics = Topics(sim)
        robot = sim.robots["r"]
        model = BatteryModel(e, emax, speed, p, dt, 1000.0 if charging else None)
        period, last = 0, 0                         # the controller's sensor: period (ms), last value's time
        subscribers = 0                             # (XPUB events count: one leaving leaves the others')
        for op, arg in ops:
            if op == "enable":
                period, last = arg * dt, sim.time_ms
                sim.enable_battery_sensor(robot, period)
            elif op == "subscribe":
                subscribers = subscribers + 1 if arg else max(subscribers - 1, 0)
                topics.subscription((b"\x01" if arg else b"\x00") + b"/r/battery\0")
                topics.publish(sim.time_ms)         # (the demand takes effect at a publish)
            else:
                for _ in range(arg):
                    sim.step()
                    model.step()
                    due = period > 0 and sim.time_ms - last >= period
                    if due:
                        last = sim.time_ms
                        assert robot.battery_value == pytest.approx(model.e, rel=1e-9, abs=1e-9)
                    sent = [msgpack.unpackb(f[2]) for f in topics.publish(sim.time_ms) if f[0] == b"/r/battery\0"]
                    if not subscribers or (period > 0 and not due):
                        assert sent == [], (op, arg, period, subscribers)
                        continue
                    (body,) = sent
                    if period > 0 and emax > 0.0:   # the controller's sample: the service's very value
                        assert body["percentage"] == robot.battery_value / emax
                    if emax > 0.0:
                        assert body["percentage"] == pytest.approx(model.e / emax, rel=1e-9, abs=1e-12)
                    else:
                        assert math.isnan(body["percentage"])
                    assert body["power_supply_status"] == model.status, (model.e, model.emax, model.gained)
                    assert body["header"]["stamp"]["sec"] * 1000 + body["header"]["stamp"]["nanosec"] // 1_000_000 \
                        == sim.time_ms

    check()


# --- lights inside robots and solids as Supervisor nodes (daemon/supervisor.py, nested.py, export.py) -----

NESTED = Path(__file__).resolve().parent / "worlds" / "nested_lights.wbt"
SPOT_LS2 = 1.0          # SPOT (intensity 4, 2 m above ls2, aimed at it): 4 / 2²; ls is past its cut-off


def light_world(name: str, loc, carrier=(0.0, 0.0, 1.0)) -> tuple[float, float, float]:
    """HEADLIGHT's location (its parent's frame) in the world: the robot at ``carrier``, its Pose 0.5 m up
    turned +pi/2 about y ((x, y, z) -> (z, y, -x)); BULB's: the lamp at (10, 0, 0)."""
    if name == "HEADLIGHT":
        return (carrier[0] + loc[2], carrier[1] + loc[1], carrier[2] + 0.5 - loc[0])
    return (10.0 + loc[0], loc[1], loc[2])


LOADED = {"HEADLIGHT": {"on": True, "intensity": 2.0, "color": [1.0, 1.0, 1.0], "location": [0.0, 0.0, 0.5]},
          "BULB": {"on": True, "intensity": 3.0, "color": [1.0, 1.0, 1.0], "location": [0.0, 0.0, 1.0]}}
# (numbers a world file takes, 0 or at least 1e-30: an exported light's text is imported as a world file's)
unit = st.floats(0.0, 1.0).map(lambda v: v if v >= 1e-30 else 0.0)
light_ops = st.lists(st.one_of(
    st.tuples(st.sampled_from(["HEADLIGHT", "BULB"]), st.just("on"), st.booleans()),
    st.tuples(st.sampled_from(["HEADLIGHT", "BULB"]), st.just("intensity"), unit.map(lambda v: 10.0 * v)),
    st.tuples(st.sampled_from(["HEADLIGHT", "BULB"]), st.just("color"), st.lists(unit, min_size=3, max_size=3)),
    # (HEADLIGHT's world z is 1.5 − x: x in [-1, 1]; BULB's z its own: both stay 0.5 m or more above the sensors)
    st.tuples(st.sampled_from(["HEADLIGHT", "BULB"]), st.just("location"),
              st.tuples(st.floats(-1.0, 1.0).map(lambda v: v if abs(v) >= 1e-30 else 0.0),
                        st.floats(-1.0, 1.0).map(lambda v: v if abs(v) >= 1e-30 else 0.0), st.floats(0.5, 3.0))),
    st.tuples(st.sampled_from(["HEADLIGHT", "BULB"]), st.sampled_from(["remove", "export"]), st.none()),
    st.tuples(st.just("CARRIER"), st.just("translation"),        # the robot moves: HEADLIGHT with it
              st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0), st.floats(1.0, 2.0))),
    st.tuples(st.just("-"), st.just("reset"), st.none())), max_size=10)


@pytest.mark.parametrize("examples", example_counts(400, 4))
def test_nested_lights_follow_a_model_of_their_fields_through_sets_removals_resets_and_imports(examples: int) -> None:
    """Random Supervisor sequences on HEADLIGHT (inside a robot, under a turned Pose) and BULB (inside a
    solid): set on, intensity, colour, location; remove; simulationReset (the fields as loaded, the removed
    ones staying removed, the imported ones gone: README, as in Webots); exportString then importMFNodeFromString
    of its text at the root (a top-level light at the exported location). The model's fields read back,
    and both light sensors read the closed form of every light as it should be (test_supervisor_nested_lights'
    ``point``)."""
    from test_supervisor import A, Live
    from test_supervisor_nested_lights import point

    @settings(SETTINGS, max_examples=examples)
    @given(light_ops)
    def check(ops: list) -> None:
        lv = Live(simulation(load_world(NESTED)))
        lv.ok(A, "attach", {"robot": "probe"})
        bot = lv.sim.robot("probe")
        bot.device("ls").enable(8)
        bot.device("ls2").enable(8)

        def call(item: str, args: dict | None = None):
            return lv.ok(A, f"/probe/robot/{item}", args)

        ids = {n: call("get_from_def", {"name": n})["node"] for n in LOADED}
        lights = {n: {k: (list(v) if isinstance(v, list) else v) for k, v in f.items()} for n, f in LOADED.items()}
        imported: list[dict] = []           # top-level copies: (world location, fields)
        carrier, robot = (0.0, 0.0, 1.0), call("get_from_def", {"name": "CARRIER"})["node"]
        for name, op, value in ops:
            if op == "translation":
                carrier = tuple(v if abs(v) >= 1e-30 else 0.0 for v in value)
                call("set_field", {"node": robot, "field": "translation", "value": list(carrier)})
                continue
            if op == "reset":
                call("simulation_reset")
                imported.clear()
                carrier = (0.0, 0.0, 1.0)
                for n in lights:
                    if lights[n] is not None:
                        lights[n] = {k: (list(v) if isinstance(v, list) else v) for k, v in LOADED[n].items()}
            elif lights[name] is None:
                continue
            elif op == "remove":
                call("remove_node", {"node": ids[name]})
                lights[name] = None
            elif op == "export":
                text = call("node_export_string", {"node": ids[name]})["value"]
                text = text.replace(f"DEF {name} ", "", 1)      # (its DEF name stays the nested light's)
                call("import_node_from_string", {"node": 0, "field": "children", "position": -1, "node_string": text})
                imported.append({**lights[name], "location": list(lights[name]["location"])})
            else:
                v = list(value) if isinstance(value, tuple) else value
                call("set_field", {"node": ids[name], "field": op, "value": v})
                lights[name][op] = v
        for n, fields in lights.items():
            if fields is not None:
                for k, v in fields.items():
                    got = call("get_field", {"node": ids[n], "field": k})["value"]
                    assert got == (pytest.approx(v, abs=1e-12) if k != "on" else v), (n, k)
        lv.step(A, "probe")
        for sensor, at, spot in (("ls", (0.0, 0.0, 0.0), 0.0), ("ls2", (10.0, 0.0, 0.0), SPOT_LS2)):
            expected = spot
            for n, f in lights.items():
                if f is not None and f["on"]:
                    expected += point(light_world(n, f["location"], carrier), f["intensity"], at, f["color"])
            for f in imported:
                if f["on"]:
                    expected += point(tuple(f["location"]), f["intensity"], at, f["color"])
            assert bot.device(sensor).value == pytest.approx(expected, rel=1e-9, abs=1e-12), (sensor, ops)

    check()


# --- degenerate input to the new paths: a load line or a drive, never a traceback; steps stay finite ------

EXTREMES = [0.0, 1e-30, 1e-9, 1e-3, 0.02, 1.0, 1e3, 1e6]


def odd_hinge(name: str, kind: str, radius: float, y: float, axis, base: np.ndarray) -> str:
    """A motorised hinge at (0, y, radius) of the upright twin's frame carried by base⁻¹, of ``kind``:
    a cylinder wheel, no end point, an empty Solid, a Solid of no boundingObject, a sphere, or a device slot
    holding nothing."""
    inv = base.T
    at = inv @ np.array([0.0, y, radius])
    part = inv @ rot((1, 0, 0), -math.pi / 2)
    joint = f'HingeJoint {{ jointParameters HingeJointParameters {{ axis {vec(inv @ np.asarray(axis))} anchor {vec(at)} }}\n'
    device = f'  device [ RotationalMotor {{ name "{name}" maxVelocity 20 }} ]\n'
    if kind == "no end point":
        return joint + device + '}\n'
    if kind == "empty slot":
        return joint + '  device [ ]\n}\n'
    if kind == "empty solid":
        return joint + device + f'  endPoint Solid {{ translation {vec(at)} }} }}\n'
    geometry = (f'Sphere {{ radius {num(radius)} }}' if kind == "sphere"
                else f'Cylinder {{ radius {num(radius)} height 0.003 }}')
    bounding = '' if kind == "no bounding" else ' boundingObject USE W'
    return (joint + device + f'  endPoint Solid {{ translation {vec(at)} children [ DEF W Pose {{ rotation '
            f'{axis_angle(part)}\n    children [ Shape {{ geometry {geometry} }} ] }} ]{bounding} }} }}\n')


@pytest.mark.parametrize("examples", example_counts(400, 4))
def test_degenerate_wheels_and_lights_load_with_a_line_or_a_drive_and_step_finite(tmp_path: Path, examples: int) -> None:
    """Zero, tiny and huge wheels, hinges with no end point, empty Solids, slots holding nothing, spheres,
    lights of zero intensity or huge attenuation inside the robot, the robot on any side, with Physics or
    not: the load gives lines (each one line, no traceback) or a world whose simulation steps stay finite
    (poses, the light sensor's value)."""
    kinds = st.sampled_from(["cylinder", "cylinder", "sphere", "no end point", "empty slot", "empty solid", "no bounding"])

    @settings(SETTINGS, max_examples=examples)
    @given(st.sampled_from(sorted(BASES)), st.booleans(), kinds, kinds, st.sampled_from(EXTREMES),
           st.sampled_from(EXTREMES), st.sampled_from([0.0, 1e-30, 1.0, 1e6]),
           st.sampled_from(["0 0 1", "1e6 1e6 1e6", "0 0 1e-30", "1 0 0"]), st.booleans(), speeds, speeds)
    def check(up: str, physics: bool, k1: str, k2: str, r1: float, r2: float, intensity: float,
              attenuation: str, tilted: bool, wl: float, wr: float) -> None:
        loads_and_steps_finite(tmp_path, up, physics, k1, k2, r1, r2, intensity, attenuation, tilted, wl, wr)

    check()


def loads_and_steps_finite(tmp_path: Path, up: str, physics: bool, k1: str, k2: str, r1: float, r2: float,
                           intensity: float, attenuation: str, tilted: bool, wl: float, wr: float) -> None:
    """The degenerate robot's world loads with lines or steps 10 times finite (see the property above)."""
    from sensorium.server.world.loader import WorldError

    base = BASES[up]
    axis = (0.0, 1.0, 0.0) if not tilted else (0.0, 1.0, 1e-3)
    wheels = (odd_hinge(LEFT, k1, r1, max(r1, 1e-3) + Y, axis, base)
              + odd_hinge(RIGHT, k2, r2, -max(r2, 1e-3) - Y, axis, base))
    light = (f'PointLight {{ location 0 0 0.1 intensity {num(intensity)} attenuation {attenuation} }}\n'
             'LightSensor { name "ls" }\n')
    path = tmp_path / "odd.wbt"
    path.write_text(f'#VRML_SIM R2023b utf8\nWorldInfo {{ basicTimeStep {STEP} }}\n'
                    'Solid { children [ Shape { geometry DEF FLOOR Plane { size 10 10 } } ] boundingObject USE FLOOR }\n'
                    f'Robot {{ name "bot" translation {X0} {Y0} 0.05 rotation {axis_angle(base)}\n'
                    f'  children [\n{light}{wheels}]\n  boundingObject Box {{ size 0.01 0.01 0.01 }}'
                    + (' physics Physics { }' if physics else '') + ' }\n')
    try:
        lw = load_world(path)
    except WorldError as exc:
        assert str(exc).strip() and "Traceback" not in str(exc)
        return
    assert all(w.strip() and "Traceback" not in w for w in lw.warnings)
    sim = simulation(lw)
    bot = sim.robot("bot")
    bot.device("ls").enable(STEP)
    for name, w in zip((LEFT, RIGHT), (wl, wr)):
        if name in bot.motors:
            bot.motor(name).set_position(math.inf)
            bot.motor(name).set_velocity(w)
    sim.run(10)
    pose = bot.pose
    assert np.all(np.isfinite(np.asarray(pose.translation))) and np.all(np.isfinite(np.asarray(pose.rotation)))
    assert math.isfinite(bot.device("ls").value)


@pytest.mark.parametrize("up", ["z up", "-x up"])
def test_regression_wheels_of_1e_30_spheres_build_a_contact_footprint(tmp_path: Path, up: str) -> None:
    """Found by the property above: two wheels whose round parts are spheres of radius 1e-30 (outlines of no
    area) made the contact footprint's grouping divide by their union's area of 0 (ZeroDivisionError at
    Simulation()); now the robot loads and steps finite."""
    loads_and_steps_finite(tmp_path, up, False, "sphere", "sphere", 1e-30, 1e-30, 0.0, "0 0 1", False, 2.0, 3.0)
