"""Hypothesis fuzz of the newer devices' services on the sans-IO core (the style of
tests/test_fuzz_core.py): the Connector's lock/unlock/is_locked/enable, the Brake's get_type, the
VacuumGripper's set_on, the Speaker's play_sound/stop/speak, a coupled motor pair's commands (its
own services and a step's ``motors``) on tests/worlds/new_devices.yaml, and a Supervisor's services
(get_field/set_field, SFNode jointParameters included, node poses and velocities, get_from_def/id,
remove_node, set_joint_position, save/load_node_state) on the nested nodes of
tests/worlds/nested_joints.wbt and nested_nodes.wbt.

Arguments are mostly the service's own names with malformed types, out-of-range values (NaN, inf,
huge numbers, huge strings), missing or extra fields. Every request gets one well-formed reply;
a refusal is one error with a protocol code other than INTERNAL and a one-line message, and leaves
the simulation as it was (the attach description of every device, the motors' commands, the
simulated time). Accepted commands keep the devices' invariants (finite velocities within
maxVelocity, targets within the limits or +-inf)."""

from __future__ import annotations

import math
import re
from pathlib import Path

import msgpack
import pytest
from _fuzz import example_counts
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_core import CODES, SETTINGS, Fuzzed

from sensorium.schemas.wire import ErrorCode
from sensorium.server.sim.joints import JointMotor

WORLDS = Path(__file__).resolve().parent / "worlds"
PEER = b"P"

SERVICES = {
    "/bot/dock/lock": {}, "/bot/dock/unlock": {}, "/bot/dock/is_locked": {}, "/bot/socket/lock": {},
    "/bot/dock/enable": {"value": 16}, "/bot/socket/unlock": {}, "/bot/arm brake/get_type": {},
    "/bot/gripper/set_on": {"value": True}, "/bot/gripper/enable": {"value": 16},
    "/bot/speaker/play_sound": {"sound": "beep.wav", "frames": 3200, "rate": 32000, "volume": 1.0, "pitch": 1.0,
                                "balance": 0.0, "loop": False, "side": 0},
    "/bot/speaker/stop": {"value": ""}, "/bot/speaker/speak": {"text": "hello there", "volume": 1.0},
    "/bot/grip::a/set_position": {"value": 0.2}, "/bot/grip::b/set_velocity": {"value": 1.0},
    "/bot/grip::b/set_position": {"value": -0.4}, "/bot/grip::a/set_velocity": {"value": 0.5},
    "/bot/robot/step": {"duration": 0, "motors": {"grip::a": {"position": 0.1, "velocity": 0.5}}},
}
odd = st.sampled_from([math.nan, math.inf, -math.inf, -1, -1.0, 0, 0.0, 1e308, -1e308, 1 << 62, (1 << 64) - 1, -(1 << 63),
                       True, False, None, "", "x" * 5000, "x" * ((1 << 20) + 1), "word " * 1000, [], {}, [1.0, 2.0],
                       b"\xff", "grip::a", "en-US", 256, -2, 2, 1e9, 1e10])
plain = (st.none() | st.booleans() | st.integers(-(1 << 63), (1 << 64) - 1) | st.floats(allow_nan=True)
         | st.text(max_size=12) | st.binary(max_size=8))
values = odd | plain | st.lists(plain, max_size=3)
motor_command = st.dictionaries(st.sampled_from(["position", "velocity", "acceleration", "available_force", "torque"]),
                                values, max_size=3)
motors = st.dictionaries(st.sampled_from(["grip::a", "grip::b", "ds", "nobody", ""]), motor_command | values, max_size=3)


@st.composite
def requests(draw) -> tuple[str, object]:
    """A service of the new devices with its own arguments, some of them broken, some missing, some extra."""
    service = draw(st.sampled_from(sorted(SERVICES)))
    good = dict(SERVICES[service])
    how = draw(st.sampled_from(range(8)))
    if how == 0:
        return service, draw(values)                                           # not a map
    args = {k: v for k, v in good.items() if draw(st.booleans()) or how > 3}   # some fields missing
    for key in draw(st.lists(st.sampled_from(sorted(good) or ["value"]), max_size=3)):
        args[key] = draw(motors if key == "motors" else values)                # broken values
    if how == 1:
        args[draw(st.sampled_from(["extra", "session", "robot", "values"]))] = draw(values)
    return service, args


def snapshot(f: Fuzzed) -> tuple:
    core = f.core
    motors = tuple((m.name, m.target_position, m.velocity, m.acceleration, m.available_force)
                   for m in f.sim.robots["bot"].motors.values())
    return repr(core._describe_robot("bot")), motors, f.sim.time_ms


def check_invariants(f: Fuzzed) -> None:
    for m in f.sim.robots["bot"].motors.values():
        assert isinstance(m, JointMotor)
        assert math.isfinite(m.velocity) and abs(m.velocity) <= m.max_velocity, (m.name, m.velocity)
        t = m.target_position
        assert math.isinf(t) or m.min_position <= t <= m.max_position, (m.name, t)
        assert m.acceleration == -1.0 or 0.0 <= m.acceleration < math.inf, (m.name, m.acceleration)
        assert 0.0 <= m.available_force <= m.max_force, (m.name, m.available_force)


def reply_of(frames: list[bytes]) -> dict:
    assert frames[0] == PEER, frames
    reply = msgpack.unpackb(frames[-1], raw=False, strict_map_key=False)
    assert isinstance(reply, dict) and reply.get("ok") in (True, False), reply
    if reply["ok"]:
        assert isinstance(reply["result"], dict), reply
    else:
        err = reply["error"]
        assert err["code"] in CODES and err["code"] != ErrorCode.INTERNAL, reply
        assert isinstance(err["message"], str) and err["message"] and "\n" not in err["message"], reply
    return reply


def send(f: Fuzzed, service: str, args: object, rid: int = 7) -> list[dict]:
    body = msgpack.packb({"id": rid, "service": service, "args": args})
    return [reply_of(frames) for frames in f.core.handle([PEER, body], f.now)]


@pytest.fixture(scope="module")
def attached() -> Fuzzed:
    f = Fuzzed("new_devices.yaml")
    [reply] = send(f, "attach", {"robot": "bot"})
    assert reply["ok"], reply
    return f


@pytest.mark.parametrize("examples", example_counts(400))
def test_the_new_devices_services_refuse_bad_arguments_in_one_line_and_change_nothing(attached: Fuzzed, examples: int) -> None:
    f = attached

    @settings(SETTINGS, max_examples=examples)
    @given(st.lists(requests(), min_size=1, max_size=6))
    def run(batch):
        for service, args in batch:
            before = snapshot(f)
            replies = send(f, service, args)
            assert len(replies) <= 1, replies                         # a step answers once the world advanced
            if replies and not replies[0]["ok"]:
                assert snapshot(f) == before, (service, args, replies)
            check_invariants(f)
            f.assert_healthy()
        f.steps()
        check_invariants(f)
        f.assert_healthy()

    run()


def test_a_string_argument_that_is_not_utf8_is_one_error_and_no_change(attached: Fuzzed) -> None:
    """msgpack str bytes that are no UTF-8 (a C controller's sound name read from a Latin-1 file system)."""
    f = attached
    packer = msgpack.Packer()
    bad = b"\xa3\xff\xfe\xfd"                                        # fixstr of 3 bytes, invalid UTF-8
    for service, key in (("/bot/speaker/stop", "value"), ("/bot/speaker/speak", "text")):
        before = snapshot(f)
        body = (b"\x83" + packer.pack("id") + packer.pack(9) + packer.pack("service") + packer.pack(service)
                + packer.pack("args") + b"\x81" + packer.pack(key) + bad)
        [frames] = f.core.handle([PEER, body], f.now)
        reply = reply_of(frames)
        assert reply["ok"] is False and "is not UTF-8 text (at b'\\xff')" in reply["error"]["message"], reply
        assert snapshot(f) == before
    f.assert_healthy()


SUPERVISOR_FIELDS = ["jointParameters", "position", "endPoint", "translation", "rotation", "children", "name",
                     "device", "", "x" * 5000, "jointParameters2", "axis", "anchor"]
GETTERS = {"get_field", "get_node_pose", "get_node_velocity", "get_from_def", "get_from_id"}


@pytest.mark.parametrize(("world", "robot"), [("nested_joints.wbt", "armbot"), ("nested_nodes.wbt", "rover")])
@pytest.mark.parametrize("examples", example_counts(400))
def test_supervisor_services_on_nested_nodes_answer_or_refuse_in_one_line(world: str, robot: str, examples: int) -> None:
    """get_field and set_field (SFNode jointParameters included), get_node_pose/velocity, get_from_def
    (DEF names, dotted paths, noise), get_from_id, remove_node, set_joint_position and
    save/load_node_state on every node id and ids that are none: one reply each; a refusal, or a
    getter's answer, changes nothing."""
    f = Fuzzed(world)
    [reply] = send(f, "attach", {"robot": robot})
    assert reply["ok"], reply
    defs = sorted(set(re.findall(r"DEF (\w+)", (WORLDS / world).read_text())))
    real = sorted({0} | {r["result"]["node"] for d in defs for r in send(f, f"/{robot}/robot/get_from_def", {"name": d})
                         if r["ok"]})
    assert len(real) > len(defs) // 2, real
    real_ids = st.sampled_from(real)                                   # mostly nodes that are there
    node_ids = st.one_of(real_ids, real_ids, real_ids, st.integers(-2, 64) | st.integers(1 << 24, (1 << 24) + 64),
                         st.sampled_from([1 << 31, 1 << 63]) | values)
    names = st.one_of(st.sampled_from(defs), st.lists(st.sampled_from(defs), min_size=2, max_size=3).map(".".join),
                      values)
    fields = st.one_of(st.sampled_from(SUPERVISOR_FIELDS), st.sampled_from(SUPERVISOR_FIELDS), values)
    item_args = st.one_of(
        st.tuples(st.just("get_field"), st.fixed_dictionaries({"node": node_ids, "field": fields})),
        st.tuples(st.just("set_field"), st.fixed_dictionaries({"node": node_ids, "field": fields, "value": values})),
        st.tuples(st.sampled_from(["get_node_pose", "get_node_velocity", "remove_node"]),
                  st.fixed_dictionaries({"node": node_ids})),
        st.tuples(st.just("get_from_def"), st.fixed_dictionaries({"name": names})),
        st.tuples(st.just("get_from_id"), st.fixed_dictionaries({"id": node_ids})),
        st.tuples(st.just("set_joint_position"),
                  st.fixed_dictionaries({"node": node_ids, "position": values | st.floats(-4.0, 4.0),
                                         "index": st.integers(-1, 4) | values})),
        st.tuples(st.sampled_from(["save_node_state", "load_node_state"]),
                  st.fixed_dictionaries({"node": node_ids, "state": st.sampled_from(["__init__", "a", ""]) | values})),
        st.tuples(st.sampled_from(sorted(GETTERS)), st.dictionaries(st.sampled_from(["node", "id", "name", "field"]),
                                                                    values, max_size=3)))

    def state() -> tuple:
        return repr(f.core._describe_robot(robot)), f.sim.time_ms, repr(
            [(m.name, m.position, m.target_position) for m in f.sim.robots[robot].motors.values()]), \
            repr(f.sim.root_order), repr(f.sim.world.solids)

    # every node there (the jointParameters nodes SFNode fields answer included) x every field name,
    # read, and written with values of every kind: answered, and a refusal changes nothing
    seen, todo, kinds = set(), list(real), 0
    while todo:
        node = todo.pop()
        if node in seen:
            continue
        seen.add(node)
        for field in SUPERVISOR_FIELDS:
            before = state()
            [reply] = send(f, f"/{robot}/robot/get_field", {"node": node, "field": field})
            assert reply["ok"] == (1 <= len(field) <= 64) and state() == before, (node, field, reply)
            got = reply["result"] if reply["ok"] else {"type": ""}
            kinds += got["type"] == "SFNode"
            if got["type"] == "SFNode" and got["value"]:
                todo.append(got["value"])
            for value in (math.nan, math.inf, 1e308, True, [1.0, 2.0, 3.0], [math.nan] * 4, "x", None, []):
                before = state()      # (a set taken, as a solid's Pose's translation, changes what follows)
                [reply] = send(f, f"/{robot}/robot/set_field", {"node": node, "field": field, "value": value})
                if not reply["ok"]:
                    assert state() == before, (node, field, value, reply)
            f.assert_healthy()
    assert len(seen) > len(real) or world != "nested_joints.wbt", seen      # jointParameters nodes reached
    assert kinds or world != "nested_joints.wbt"

    @settings(SETTINGS, max_examples=examples)
    @given(st.lists(item_args, min_size=1, max_size=6))
    def run(batch):
        for item, args in batch:
            before = state()
            [reply] = send(f, f"/{robot}/robot/{item}", args)
            if reply["ok"] and item == "get_field":
                result = reply["result"]
                assert isinstance(result.get("type"), str), reply
                if result["type"] == "SFNode":                        # a node id, 0 for NULL
                    assert isinstance(result["value"], int) and result["value"] >= 0, reply
            if not reply["ok"] or item in GETTERS:
                assert state() == before, (item, args, reply)
            f.assert_healthy()
        f.steps()
        f.assert_healthy()

    run()
