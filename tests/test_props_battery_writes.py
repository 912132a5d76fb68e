"""Property tests of a Supervisor's writes of a robot's ``battery`` items and ``cpuConsumption`` (daemon/
supervisor.py, sim/battery.py; README "Battery and Charger"), through the server's services on the sans-IO
core, without a Charger.

Closed form: a battery holding E (J) at a write, drained at P (W) by 32 ms steps (x = 0.032 P J a step),
holds max(0, E − n·x) n steps later; the step that empties it is the ⌈E/x⌉-th, which powers the robot off;
a write of energy left powers a robot that is off on again at the end of its next step if that step's drain
leaves some. Its sensor, enabled with a period T (a multiple of the step) at t0, reads the energy at
the step where T has passed since t0 or its last reading (NaN before the first); the step that empties the
battery gives it 0 and starts its period again (WbSensor::updateTimer), enabled or not (Webots sends it).
A world file's extremes (0, 1e-30, the 1e9 magnitude limit) follow the closed form; a value a world file
refuses (no finite number >= 0, nearer 0 than 1e-30, over 1e9), an index out of the world's items, an insert
or remove is one refusal line that changes nothing; no value read is ever NaN but the sensor's before its first sample."""

from __future__ import annotations

import math

import pytest
from _fuzz import example_counts
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from test_battery import DT, supervised, world
from test_fuzz_core import SETTINGS

from sensorium.schemas import wire

FAR = [0.0, 1e-30, 1e-20, 1e8, 1e9]           # (a world file's extremes: 0 or in [1e-30, 1e9])
energies = st.floats(0.0, 50.0).filter(lambda v: v == 0.0 or v >= 1e-30) | st.sampled_from(FAR)
powers = st.floats(0.0, 400.0).filter(lambda v: v == 0.0 or v >= 1e-30) | st.sampled_from(FAR)
bad_values = st.sampled_from([-1.0, -5e-324, -1e300, 5e-324, 2.2e-308, 1e-31, 1.000001e9, 1e300, True, False, None,
                              "1", [1.0, 2.0], {"a": 1}, b"x"])


class Model:
    """The closed form's state: the energy at the last write of the energy or the power (``e0``), the steps
    since (``n``), the power, whether the robot is on, and the sensor's (period, enabled at, last value)."""

    def __init__(self, e0: float, p: float) -> None:
        self.e0, self.n, self.p, self.on = e0, 0, p, True
        self.period, self.last, self.value = 0, 0, math.nan

    def per_step(self) -> float:
        return self.p * DT * 0.001

    def energy(self, n: int | None = None) -> float:
        n = self.n if n is None else n
        if not self.e0 > 0.0:
            return self.e0
        return max(0.0, self.e0 - n * self.per_step()) if n else self.e0

    def emptying_step(self) -> float:
        """The step (1-based) after the write that empties the battery; inf when none does."""
        if not self.e0 > 0.0:
            return math.inf
        x = self.per_step()
        steps = self.e0 / x if x > 0.0 else math.inf
        return math.inf if not math.isfinite(steps) else max(1, math.ceil(steps))

    def restart(self) -> None:          # a write of the energy or the power: a new segment
        self.e0, self.n = self.energy(), 0

    def step(self, t_ms: int) -> None:
        was = self.energy()
        self.n += 1
        now = self.energy()
        if was > 0.0:
            self.on = now > 0.0
        if self.period and t_ms - self.last >= self.period or was > 0.0 == now:
            self.value, self.last = now, t_ms    # a sample, or the step that emptied it (WbSensor::updateTimer)


steps = st.integers(0, 12)
ops = st.one_of(
    st.tuples(st.just("energy"), energies, steps),
    st.tuples(st.just("maximum"), energies, steps),
    st.tuples(st.just("speed"), powers, steps),
    st.tuples(st.just("cpu"), powers, steps),
    st.tuples(st.just("bad"), st.tuples(st.sampled_from(["battery", "cpuConsumption"]), st.integers(-5, 5),
                                        bad_values, st.just("set")), steps),
    st.tuples(st.just("bad"), st.tuples(st.just("battery"), st.sampled_from([3, 4, 1 << 40, -4, -(1 << 40)]),
                                        energies, st.just("set")), steps),
    st.tuples(st.just("bad"), st.tuples(st.just("battery"), st.integers(-3, 3), energies,
                                        st.sampled_from(["insert", "remove"])), steps),
    st.tuples(st.just("sensor"), st.sampled_from([0, DT, 2 * DT, 5 * DT]), steps))


def _near_a_whole_step(e: float, x: float) -> bool:
    """Whether E/x is so close to a whole number that the repeated subtraction may empty a step apart."""
    if not (e > 0.0 and x > 0.0) or not math.isfinite(e / x) or e / x > 1e6:
        return False
    r = e / x
    return abs(r - round(r)) < 1e-6 * max(1.0, r)


@pytest.mark.parametrize("examples", example_counts(400))
def test_written_batteries_drain_by_the_closed_form_and_refusals_change_nothing(examples: int) -> None:
    loaded = st.just(0.0) | st.floats(1e-3, 50.0)       # (a world file's numbers: 0 or in [1e-30, 1e9])

    @settings(SETTINGS, max_examples=examples)
    @given(e0=loaded, p=loaded, script=st.lists(ops, min_size=1, max_size=6))
    def run(e0: float, p: float, script: list) -> None:
        assume(not _near_a_whole_step(e0, p * DT * 0.001))
        sim, call, node = supervised(world([{"name": "r", "def_name": "R", "battery": [e0, 100.0, 1.0],
                                             "cpu_consumption": p}, {"name": "boss", "supervisor": True}]))
        r = sim.robots["r"]
        model, maximum, speed = Model(e0, p), 100.0, 1.0
        for kind, value, n in script:
            if kind == "sensor":
                sim.enable_battery_sensor(r, value)
                model.period, model.last = value, sim.time_ms
            elif kind == "bad":
                field, index, v, op = value
                before = (r.battery.energy, r.battery.maximum, r.battery.speed, r.battery.cpu)
                args = {"node": node, "field": field, "value": v}
                if field == "battery":
                    args |= {"index": index, "op": op}
                got = call("/boss/robot/set_field", args)
                assert got["ok"] is False, (args, got)
                line = got["error"]["message"]
                assert "\n" not in line and line and got["error"]["code"] != wire.ErrorCode.INTERNAL, line
                assert (r.battery.energy, r.battery.maximum, r.battery.speed, r.battery.cpu) == before
            else:
                if kind == "cpu":
                    args = {"node": node, "field": "cpuConsumption", "value": value}
                else:
                    args = {"node": node, "field": "battery", "op": "set",
                            "index": ("energy", "maximum", "speed").index(kind), "value": value}
                got = call("/boss/robot/set_field", args)
                assert got["ok"] is True, (args, got)
                model.restart()
                if kind == "energy":
                    model.e0 = value
                elif kind == "cpu":
                    model.p = value
                elif kind == "maximum":
                    maximum = value
                else:
                    speed = value
                assume(not _near_a_whole_step(model.e0, model.per_step()))
            for _ in range(n):
                before_on = r.battery.powered
                sim.step()
                model.step(sim.time_ms)
                e = model.energy()
                assert r.battery.energy == pytest.approx(e, rel=1e-9, abs=1e-9 * max(1.0, model.e0)), (model.n, e)
                assert not math.isnan(r.battery.energy)
                if model.n == model.emptying_step():
                    assert r.battery.energy == 0.0 and not r.battery.powered         # off exactly then
                elif model.e0 > 0.0 and model.n < model.emptying_step():
                    assert r.battery.powered, (model.n, model.emptying_step())
                else:
                    assert r.battery.powered == before_on
                assert r.battery.powered == model.on
                if math.isnan(model.value):
                    assert math.isnan(r.battery_value)
                else:
                    assert r.battery_value == pytest.approx(model.value, rel=1e-9, abs=1e-9 * max(1.0, model.e0))
            got = call("/boss/robot/get_field", {"node": node, "field": "battery"})["result"]["value"]
            assert got[1:] == [maximum, speed] and not any(math.isnan(v) for v in got)
            assert got[0] == r.battery.energy
            assert call("/boss/robot/get_field", {"node": node, "field": "cpuConsumption"})["result"]["value"] \
                == model.p
    run()


def test_the_step_that_empties_a_battery_gives_its_sensor_0_enabled_or_not_and_starts_its_period_again() -> None:
    """Regression (WbRobot::postPhysicsStep calls WbSensor::updateTimer, and writeAnswer sends the pending value
    whether the sensor is enabled or not): a sensor never enabled read NaN after its battery emptied. 1 J at
    31.25 W (1 J a step) written 2.5 J empties in the 3rd step."""
    sim, call, node = supervised(world([{"name": "r", "def_name": "R", "battery": [10.0, 20.0, 1.0],
                                         "cpu_consumption": 31.25}, {"name": "boss", "supervisor": True}]))
    r = sim.robots["r"]
    assert call("/boss/robot/set_field", {"node": node, "field": "battery", "index": 0, "value": 2.5})["ok"]
    sim.run(2)
    assert math.isnan(r.battery_value)                   # never enabled: nothing sampled
    sim.step()
    assert r.battery.energy == 0.0 and r.battery_value == 0.0 and sim.time_ms == 3 * DT
    sim, call, node = supervised(world([{"name": "r", "def_name": "R", "battery": [10.0, 20.0, 1.0],
                                         "cpu_consumption": 31.25}, {"name": "boss", "supervisor": True}]))
    r = sim.robots["r"]
    sim.enable_battery_sensor(r, 2 * DT)                # samples at 64, 128, ...
    assert call("/boss/robot/set_field", {"node": node, "field": "battery", "index": 0, "value": 2.5})["ok"]
    sim.run(2)
    assert r.battery_value == 0.5
    sim.step()                                          # 96: emptied, 0 at once; the period from 96: 160, 224
    assert r.battery_value == 0.0 and r.battery_schedule.last_update_ms == 3 * DT
    assert call("/boss/robot/set_field", {"node": node, "field": "battery", "index": 0, "value": 7.0})["ok"]
    sim.step()                                          # 128: no sample (was one before the empty step)
    assert r.battery_value == 0.0 and r.battery.energy == 6.0
    sim.step()                                          # 160
    assert r.battery_value == 5.0


def test_export_string_and_world_save_write_the_battery_and_cpu_consumption_now(tmp_path) -> None:
    """Regression: WbRobot writes its energy in its battery field each step (and a Supervisor's writes land in
    the fields), so exportString and worldSave write the values now; they wrote the world file's. A robot
    without a battery and a PROTO robot's fields through IS (our Cell PROTO: 1 J a step) alike; the saved
    world loads to the same battery."""
    from pathlib import Path

    from sensorium.server.daemon import supervisor as sv
    from sensorium.server.daemon.export import node_string, world_string
    from sensorium.server.sim.simulation import Simulation
    from sensorium.server.world.loader import load_world
    from sensorium.server.world.wbt.parser import parse_wbt

    world = tmp_path / "w.wbt"
    world.write_text('#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 32 }\n'
                     'DEF R Robot { name "r" battery [ 5, 10, 1 ] cpuConsumption 2 }\nDEF N Robot { name "n" }\n')
    sim = Simulation(load_world(world))
    r, n = sv.find_node(sim, "R"), sv.find_node(sim, "N")
    assert sv.change_item(sim, r, "battery", "set", 1, 7.5) == [] and sv.set_field(sim, r, "cpuConsumption", 3.0) == []
    sim.run(2)                                             # 3 W: 0.096 J a step
    (got,) = parse_wbt("#VRML_SIM R2023b utf8\n" + node_string(sim, r)).nodes
    assert got.fields["battery"] == pytest.approx([5.0 - 0.192, 7.5, 1.0], abs=1e-12)
    assert got.fields["cpuConsumption"] == 3.0
    assert node_string(sim, n) == 'DEF N Robot {\n  name "n"\n}'
    saved = tmp_path / "saved.wbt"
    saved.write_text(world_string(sim))
    again = {x.name: x for x in load_world(saved).world.robots}
    assert again["r"].battery == pytest.approx([4.808, 7.5, 1.0], abs=1e-12) and again["r"].cpu_consumption == 3.0
    assert again["n"].battery == []

    cells = Simulation(load_world(Path(__file__).parent / "worlds" / "battery_proto.wbt"))
    cell = sv.find_node(cells, "CELL")
    assert sv.change_item(cells, cell, "battery", "set", 0, 3.5) == [] and sv.set_field(cells, cell, "cpu", 0.5) == []
    cells.run(2)                                           # 0.5 W: 0.016 J a step
    (got,) = parse_wbt("#VRML_SIM R2023b utf8\n" + node_string(cells, cell)).nodes
    assert got.type == "Cell" and got.fields["battery"] == pytest.approx([3.5 - 0.032, 10.0, 1.0], abs=1e-12)
    assert got.fields["cpu"] == 0.5
