"""A robot's battery on its topic (PROTOCOL.md §4, README "For ROS 2 users"): ``/<robot>/battery``,
``sensor_msgs/msg/BatteryState``, published at each sample of the controller's battery sensor or, a
subscriber alone covering it, at every basic step; ``percentage`` = energy ÷ maximum, the number the
battery service reads over the maximum; the status CHARGING while a Charger gives it energy; nothing
sampled or sent otherwise; a robot without a battery has no topic. Recorded, exported to ROS 2 and
read back by Foxglove's TypeScript decoders with the same numbers; ``sensorium echo`` prints it."""

from __future__ import annotations

import json
import math
import signal

import msgpack
import numpy as np
import pytest
import yaml

from sensorium.schemas import messages as M
from sensorium.schemas.wire import pack
from sensorium.server.daemon.services import Core
from sensorium.server.daemon.topics import Topics
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world

DT = 32                                   # basic step (ms)
E0, EMAX, P = 100.0, 200.0, 10.0          # the battery [100, 200, 0] and cpuConsumption 10 W
WORLD = {"world_info": {"basic_time_step": DT},
         "robots": [{"name": "r", "battery": [E0, EMAX, 0.0], "cpu_consumption": P},
                    {"name": "plain"}]}                  # no battery: no topic
SUB, UNSUB = b"\x01", b"\x00"
NAN_FIELDS = ("voltage", "temperature", "current", "charge", "capacity", "design_capacity")


def sim_of(world: dict = WORLD) -> Simulation:
    return Simulation(parse_world(world))


def expected(n: int) -> float:
    """The percentage after n basic steps: (E0 - P·0.032·n) / EMAX."""
    return (E0 - P * DT / 1000 * n) / EMAX


def decoded(frames: list[list[bytes]]) -> list[tuple[str, dict, dict]]:
    return [(f[0][:-1].decode(), msgpack.unpackb(f[1]), msgpack.unpackb(f[2])) for f in frames]


class Controller:
    """One ROUTER peer of a sans-IO core: service calls, and steps whose published frames it keeps."""

    def __init__(self, core: Core, peer: bytes = b"ctl"):
        self.core, self.peer, self.rid = core, peer, 0
        self.published: list[list[bytes]] = []

    def call(self, service: str, args: dict | None = None) -> dict:
        self.rid += 1
        (frames,) = self.core.handle([self.peer, pack({"id": self.rid, "service": service, "args": args or {}})], 0.0)
        reply = msgpack.unpackb(frames[-1], raw=False)
        assert reply["ok"], reply
        return reply["result"]

    def step(self) -> None:
        self.rid += 1
        assert self.core.handle([self.peer, pack({"id": self.rid, "service": "/r/robot/step", "args": {}})], 0.0) == []
        while True:
            replies, pubs = self.core.step_once(0.0)
            self.published += pubs
            if replies:
                return


def attached() -> tuple[Core, Controller]:
    core = Core(sim_of(), new_token=lambda: "s0", log=lambda *_: None)
    ctl = Controller(core)
    ctl.call("attach", {"robot": "r"})
    return core, ctl


def test_the_percentage_is_what_the_battery_service_reads_over_the_maximum_at_each_sample() -> None:
    core, ctl = attached()
    assert {"name": "/r/battery", "type": M.BATTERY_STATE} in ctl.call("get_info")["topics"]
    core.subscription(SUB + b"/r/battery\0")
    ctl.call("/r/robot/battery_sensor_enable", {"value": DT})
    for n in range(1, 9):
        ctl.step()
        (topic, env, body), = decoded(ctl.published)
        ctl.published.clear()
        value = ctl.call("/r/robot/battery_sensor_get_value")["value"]
        assert topic == "/r/battery" and env == {"type": M.BATTERY_STATE, "seq": n - 1, "stamp_ns": n * DT * 1_000_000}
        assert body["percentage"] == value / EMAX                     # the very number, over the maximum
        assert body["energy"] == value                                # and the very number itself
        assert body["percentage"] == pytest.approx(expected(n), abs=1e-13)
        assert body["header"] == {"stamp": {"sec": 0, "nanosec": n * DT * 1_000_000}, "frame_id": "r"}
        assert body["power_supply_status"] == M.BatteryState.STATUS_DISCHARGING
    M.BatteryState.model_validate(body)
    assert list(body) == M.field_order(M.BatteryState)                # the ROS message's fields, in its order, then energy
    assert all(math.isnan(body[k]) for k in NAN_FIELDS)               # not modelled by Webots: not measured
    assert (body["power_supply_health"], body["power_supply_technology"], body["present"]) == (0, 0, True)
    assert (body["cell_voltage"], body["cell_temperature"], body["location"], body["serial_number"]) == (b"", b"", "", "")


def test_the_controllers_period_wins_and_a_subscriber_alone_gets_every_basic_step() -> None:
    core, ctl = attached()
    core.subscription(SUB + b"/r/")                                   # a prefix covering it
    ctl.call("/r/robot/battery_sensor_enable", {"value": 3 * DT})    # its own period: every third step
    for _ in range(6):
        ctl.step()
    battery = [(env["stamp_ns"], body["percentage"]) for t, env, body in decoded(ctl.published) if t == "/r/battery"]
    assert battery == [(n * DT * 1_000_000, pytest.approx(expected(n), abs=1e-13)) for n in (3, 6)]
    ctl.published.clear()
    ctl.call("/r/robot/battery_sensor_enable", {"value": 0})         # disabled: the subscriber's basic step
    for _ in range(3):
        ctl.step()
    battery = [(env["stamp_ns"], body["percentage"]) for t, env, body in decoded(ctl.published) if t == "/r/battery"]
    assert battery == [(n * DT * 1_000_000, pytest.approx(expected(n), abs=1e-13)) for n in (7, 8, 9)]
    # the controller's sensor stays as it asked: off, its last value (at 6 steps) kept
    assert ctl.call("/r/robot/battery_sensor_get_sampling_period")["value"] == 0
    assert ctl.call("/r/robot/battery_sensor_get_value")["value"] == pytest.approx(E0 - P * 6 * DT / 1000, abs=1e-12)


def test_nothing_is_sampled_or_sent_without_a_subscriber_and_a_robot_without_battery_has_no_topic() -> None:
    sim = sim_of()
    topics = Topics(sim)
    r = sim.robots["r"]
    assert "/r/battery" in topics.by_name and not any(t.name.startswith("/plain/battery") for t in topics.topics)
    assert not topics.accepts(b"/plain/battery")                     # no topic to subscribe to
    sim.enable_battery_sensor(r, DT)                                  # the controller's sensor alone
    for _ in range(3):
        sim.step()
        assert topics.publish(sim.time_ms) == []
    assert r.battery_samples == 0 and r.battery_value == pytest.approx(E0 - P * 3 * DT / 1000, abs=1e-12)
    sim.enable_battery_sensor(r, 0)
    topics.subscription(SUB + b"/r/battery\0")                        # a subscriber: every basic step
    for _ in range(2):
        sim.step()
    assert [n for n, _, _ in decoded(topics.publish(sim.time_ms))] == ["/r/battery"]   # the latest sample only
    assert r.battery_samples == 2
    topics.subscription(UNSUB + b"/r/battery\0")                      # gone: no more samples
    for _ in range(3):
        sim.step()
        assert topics.publish(sim.time_ms) == []
    assert r.battery_samples == 2 and r.battery_sampled_at_ms == 5 * DT
    rec: list[str] = []
    topics.set_recorder(lambda t, *_: rec.append(t), ["/r/battery"])  # a recording demands it too
    sim.step()
    topics.publish(sim.time_ms)
    assert rec == ["/r/battery"]


CHARGE_SPEED = 50.0                     # W the Charger gives
CHARGER_WORLD = {"world_info": {"basic_time_step": DT},
                 "solids": [{"name": "dock", "pose": {"translation": [1.0, 0.0, 0.0]}}],
                 "chargers": [{"solid": "dock", "battery": [1000.0, 1000.0, 0.0], "radius": 0.2}],
                 "robots": [{"name": "r", "battery": [E0, EMAX, CHARGE_SPEED], "cpu_consumption": P,
                             "pose": {"translation": [3.0, 0.0, 0.0]}}]}


def test_on_a_charger_the_status_is_charging_and_the_percentage_grows_at_the_recharge_speed() -> None:
    sim = sim_of(CHARGER_WORLD)
    topics = Topics(sim)
    topics.subscription(SUB + b"/r/battery\0")
    r = sim.robots["r"]

    def sample() -> dict:
        sim.step()
        (_, _, body), = decoded(topics.publish(sim.time_ms))
        return body

    away = sample()
    assert away["power_supply_status"] == M.BatteryState.STATUS_DISCHARGING
    assert away["percentage"] == pytest.approx(expected(1), abs=1e-13)
    r.set_pose([1.1, 0.0, 0.0])                                      # within the Charger's radius
    net = (CHARGE_SPEED - P) * DT / 1000 / EMAX                      # 0.0064 a step
    for k in range(1, 6):
        body = sample()
        assert body["power_supply_status"] == M.BatteryState.STATUS_CHARGING
        assert body["percentage"] == pytest.approx(expected(1) + k * net, abs=1e-12)
    r.set_pose([3.0, 0.0, 0.0])                                      # off the Charger: discharging again
    body = sample()
    assert body["power_supply_status"] == M.BatteryState.STATUS_DISCHARGING
    assert body["percentage"] == pytest.approx(expected(1) + 5 * net - P * DT / 1000 / EMAX, abs=1e-12)


@pytest.mark.parametrize("battery, cpu, status, percentage", [
    ([EMAX, EMAX, 0.0], 0.0, M.BatteryState.STATUS_FULL, 1.0),        # at its maximum
    ([E0, EMAX, 0.0], 0.0, M.BatteryState.STATUS_NOT_CHARGING, 0.5),  # nothing takes energy
    ([0.0, EMAX, 0.0], P, M.BatteryState.STATUS_NOT_CHARGING, 0.0),   # empty: nothing left to lose
    ([E0], P, M.BatteryState.STATUS_DISCHARGING, math.nan),           # no maximum: no percentage
])
def test_the_status_and_percentage_of_a_full_idle_empty_or_unbounded_battery(battery, cpu, status, percentage) -> None:
    sim = sim_of({"world_info": {"basic_time_step": DT}, "robots": [{"name": "r", "battery": battery, "cpu_consumption": cpu}]})
    topics = Topics(sim)
    topics.subscription(SUB + b"/r/battery\0")
    sim.step()
    (_, _, body), = decoded(topics.publish(sim.time_ms))
    assert body["power_supply_status"] == status
    assert body["percentage"] == percentage or (math.isnan(percentage) and math.isnan(body["percentage"]))


@pytest.mark.parametrize("battery", [[E0], [E0, 0.0], [E0, 0.0, 0.0]])
def test_a_battery_without_a_maximum_carries_the_energy_the_sensor_reads(battery) -> None:
    """Webots' sensor reads the battery's first value whatever else the field holds (WbRobot::currentEnergy):
    the topic's ``energy`` is that number where ``percentage`` has no maximum to divide by."""
    world = {"world_info": {"basic_time_step": DT}, "robots": [{"name": "r", "battery": battery, "cpu_consumption": P}]}
    core = Core(sim_of(world), new_token=lambda: "s0", log=lambda *_: None)
    ctl = Controller(core)
    ctl.call("attach", {"robot": "r"})
    core.subscription(SUB + b"/r/battery\0")
    ctl.call("/r/robot/battery_sensor_enable", {"value": DT})
    for n in range(1, 4):
        ctl.step()
        (_, _, body), = decoded(ctl.published)
        ctl.published.clear()
        value = ctl.call("/r/robot/battery_sensor_get_value")["value"]
        assert value == pytest.approx(E0 - P * DT / 1000 * n, abs=1e-12)
        assert body["energy"] == value and math.isnan(body["percentage"])
    M.BatteryState.model_validate(body)


def record_run(path, steps: int = 5) -> list[float]:
    """A Foxglove-ready recording of the battery topic over ``steps`` basic steps; the service's values."""
    from sensorium.server.recording.writer import McapRecorder

    core, ctl = attached()
    rec = McapRecorder(path, world_text=yaml.safe_dump(WORLD), world_name="battery.yaml", background_flush=False)
    core.topics.set_recorder(rec, ["/r/battery"])
    ctl.call("/r/robot/battery_sensor_enable", {"value": DT})
    values = []
    for _ in range(steps):
        ctl.step()
        values.append(ctl.call("/r/robot/battery_sensor_get_value")["value"])
    core.topics.set_recorder(None)
    rec.close()
    return values


def check_decoded(messages: list[dict], values: list[float]) -> None:
    """Foxglove's decoded messages: float32 fields as CDR carries them (the percentage rounded once)."""
    assert [m["log_time"] for m in messages] == [n * DT * 1_000_000 for n in range(1, len(values) + 1)]
    for m, value in zip(messages, values):
        msg = m["msg"]
        assert msg["percentage"] == float(np.float32(value / EMAX))
        assert all(math.isnan(msg[k]) for k in NAN_FIELDS)
        assert (msg["power_supply_status"], msg["power_supply_health"], msg["present"]) == (2, 0, True)
        assert (msg["cell_voltage"], msg["location"], msg["header"]["frame_id"]) == ([], "", "r")
        stamp = msg["header"]["stamp"]
        assert stamp["sec"] * 1_000_000_000 + stamp["nanosec"] == m["log_time"]


def test_recorded_and_exported_batteries_read_back_in_foxglove_with_the_same_numbers(tmp_path) -> None:
    pytest.importorskip("rosbags")
    from _node import require_node, run_script

    from sensorium.server.recording.export import export_ros2
    from sensorium.server.recording.reader import Recording

    require_node()
    src, out = tmp_path / "run.mcap", tmp_path / "ros2.mcap"
    values = record_run(src)
    with Recording(src) as rec:
        got = [(m.stamp_ns, m.decode()["percentage"]) for m in rec.messages(["/r/battery"])]
    assert got == [(n * DT * 1_000_000, v / EMAX) for n, v in enumerate(values, 1)]      # msgpack: float64, exact
    export_ros2(src, out, views=False)
    for path in (src, out):           # the recording's own CDR view, then the ROS 2 export (mcap-ros2-support)
        read = run_script("read_mcap.js", str(path), "/r/battery")[0]
        assert read["errors"] == []
        assert {c["topic"]: c["schemaName"] for c in read["channels"]}["/r/battery"] == M.BATTERY_STATE
        check_decoded(read["every"], values)


def test_a_rosbag2_export_holds_the_battery_for_both_distros(tmp_path) -> None:
    pytest.importorskip("rosbags")
    from rosbags.rosbag2 import Reader

    from sensorium.server.recording.export import export_ros2, typestore_for

    src = tmp_path / "run.mcap"
    values = record_run(src)
    for distro in ("humble", "jazzy"):
        out = tmp_path / f"bag-{distro}"
        export_ros2(src, out, distro=distro, fmt="bag", views=False)
        store = typestore_for(distro)
        with Reader(out) as reader:
            conns = [c for c in reader.connections if c.topic == "/r/battery"]
            assert [c.msgtype for c in conns] == [M.BATTERY_STATE]
            msgs = [store.deserialize_cdr(raw, M.BATTERY_STATE) for _, _, raw in reader.messages(connections=conns)]
        assert [float(m.percentage) for m in msgs] == [float(np.float32(v / EMAX)) for v in values]
        assert all(math.isnan(m.voltage) and m.present and m.power_supply_status == 2 for m in msgs)


def test_a_layout_plots_every_robots_battery_percentage(tmp_path) -> None:
    pytest.importorskip("foxglove.layouts")
    from sensorium.server.viewer.layout import layout_for

    world = tmp_path / "battery.yaml"
    world.write_text(yaml.safe_dump({**WORLD, "robots": [*WORLD["robots"], {"name": "q", "battery": [1.0]}]}))
    lay = json.loads(layout_for(world))
    side = lay["content"]["items"][1]["content"]["items"]
    (plot,) = [item["content"]["config"] for item in side if item["content"].get("panelType") == "Plot"]
    assert [p["value"] for p in plot["paths"]] == ["/q/battery.percentage", "/r/battery.percentage"]


ECHO_WORLD = """\
world_info: {name: battery, basic_time_step: 32}
robots:
  - {name: bot, controller: "<none>", battery: [100.0, 200.0, 0.0], cpu_consumption: 10.0}
"""


@pytest.mark.slow
def test_echo_prints_the_battery_at_every_basic_step(tmp_path) -> None:
    """`sensorium echo /bot/battery`: a subscriber alone, so one message per basic step; the
    percentage (100 − 10·t)/200 at each stamp t."""
    import subprocess
    import sys

    from _serve import serve

    world = tmp_path / "battery.yaml"
    world.write_text(ECHO_WORLD)
    with serve(world, "--mode", "realtime", stop_signal=signal.SIGTERM) as server:
        res = subprocess.run([sys.executable, "-m", "sensorium", "echo", "/bot/battery", "--url", server.rpc,
                              "--count", "3", "--json"], capture_output=True, text=True, timeout=120)
        assert res.returncode == 0, res.stderr
        printed = [json.loads(line) for line in res.stdout.splitlines()]
        yml = subprocess.run([sys.executable, "-m", "sensorium", "echo", "/bot/battery", "--url", server.rpc,
                              "--count", "1"], capture_output=True, text=True, timeout=120)
    assert yml.returncode == 0, yml.stderr
    assert yml.stdout.startswith("# /bot/battery [sensor_msgs/msg/BatteryState] seq=")
    doc = yaml.safe_load(yml.stdout.split("\n---")[0])
    assert doc["power_supply_status"] == 2 and doc["present"] is True and math.isnan(doc["voltage"])
    stamps = [m["stamp_ns"] for m in printed]
    assert all(b - a == DT * 1_000_000 for a, b in zip(stamps, stamps[1:]))      # every basic step
    for m in printed:
        assert m["type"] == M.BATTERY_STATE
        assert m["body"]["percentage"] == pytest.approx((E0 - P * m["stamp_ns"] / 1e9) / EMAX, abs=1e-12)
