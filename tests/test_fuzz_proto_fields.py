"""Hypothesis fuzz of the Supervisor's PROTO-field services (get_field and set_field with a level,
get_proto) on the sans-IO core, on tests/worlds/proto/supervisor_proto_fields.wbt: node ids real and
not, levels in and out of range and of the wrong type, field names of every length, values of every
type for a set through IS (NaN, infinities, huge, the wrong width). Every request gets one reply; a
refusal is one line with a protocol code other than INTERNAL and changes nothing; an accepted get
answers a type and a value of that type."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS, Fuzzed
from test_fuzz_new_devices import send, values

R = "/keeper/robot/"
FIELDS = ["translation", "rotation", "name", "reach", "level", "active", "footprint", "color", "gains", "waypoints",
          "tags", "ids", "flags", "bodySlot", "size", "weight", "controller", "supervisor", "children", "samples", ""]


@pytest.fixture(scope="module")
def fuzzed() -> tuple[Fuzzed, list[int]]:
    f = Fuzzed("proto/supervisor_proto_fields.wbt")
    [reply] = send(f, "attach", {"robot": "keeper"})
    assert reply["ok"], reply
    tag = send(f, R + "get_from_def", {"name": "TAG"})[0]["result"]["node"]
    return f, [0, 1, 2, 3, 4, tag]


def _snapshot(f: Fuzzed, ids: list[int]) -> list:
    """Every node's pose and the fields a set could reach, through the services."""
    out = [send(f, R + "get_node_pose", {"node": i})[0]["result"] for i in ids[1:]]
    return out + [send(f, R + "get_field", {"node": i, "field": name})[0].get("result") for i in ids
                  for name in ("translation", "rotation", "name", "size", "reach")]


_TYPE_OF = {"SFBool": bool, "SFInt32": int, "SFFloat": float, "SFString": str}


def _check_value(kind: str, value: object) -> None:
    if kind in _TYPE_OF:
        assert type(value) is _TYPE_OF[kind], (kind, value)
    elif kind in ("SFVec2f", "SFVec3f", "SFColor", "SFRotation"):
        width = {"SFVec2f": 2, "SFVec3f": 3, "SFColor": 3, "SFRotation": 4}[kind]
        assert isinstance(value, list) and len(value) == width and all(type(v) is float for v in value), value
    elif kind.startswith("MF"):
        assert isinstance(value, list), (kind, value)


def test_proto_field_services_answer_or_refuse_in_one_line_and_change_nothing(fuzzed) -> None:
    f, ids = fuzzed
    node = st.sampled_from(ids) | st.sampled_from(ids) | st.integers(-3, 40) | st.integers(-(1 << 63), (1 << 64) - 1) | values
    level = (st.integers(-2, 5) | st.sampled_from([16, 17, -1 << 40, 1 << 63, (1 << 64) - 1, 1.0, 1.5, True, "1", None])
             | values)
    name = (st.sampled_from(FIELDS) | st.text(max_size=10)
            | st.sampled_from(["x" * 256, "x" * 257, "x" * 4096, "x" * 100_000, "é" * 300, "\0", "translation\0"])
            | values)
    num = st.floats(allow_nan=True, allow_infinity=True) | st.sampled_from([1e308, -1e308, 5e-324, (1 << 64) - 1, -0.0])
    value = (num | st.booleans() | st.lists(num, min_size=0, max_size=6) | values)
    maybe = st.just(None) | st.just(None)

    def args(**parts):
        return st.fixed_dictionaries({}, optional=parts)

    requests = st.one_of(
        st.tuples(st.just("get_field"), args(node=node, field=name, level=level | maybe)),
        st.tuples(st.just("get_field"), st.fixed_dictionaries({"node": st.sampled_from(ids), "field": st.sampled_from(FIELDS),
                                                                "level": st.integers(-1, 4)})),
        st.tuples(st.just("get_proto"), args(node=node, level=level)),
        st.tuples(st.just("get_proto"), st.fixed_dictionaries({"node": st.sampled_from(ids), "level": st.integers(-1, 4)})),
        st.tuples(st.just("set_field"), args(node=node, field=name, level=level, value=value)),
        st.tuples(st.just("set_field"), st.fixed_dictionaries({"node": st.sampled_from(ids),
                                                                "field": st.sampled_from(FIELDS),
                                                                "level": st.integers(-1, 4) | st.just(-1),
                                                                "value": value})))

    @SETTINGS
    @given(st.lists(requests, min_size=1, max_size=6))
    def run(batch):
        for item, a in batch:
            a = {k: v for k, v in a.items() if v is not None} if isinstance(a, dict) else a
            before = _snapshot(f, ids)
            [reply] = send(f, R + item, a)
            if not reply["ok"]:
                assert _snapshot(f, ids) == before, (item, a, reply)
            elif item == "get_field" and reply["result"]["type"]:
                _check_value(reply["result"]["type"], reply["result"]["value"])
            elif item == "get_proto":
                got = reply["result"]
                assert isinstance(got["type_name"], str) and isinstance(got["fields"], list), got
            f.assert_healthy()
        for i in ids[1:]:
            pose = send(f, R + "get_node_pose", {"node": i})[0]["result"]
            assert all(math.isfinite(v) for v in pose["position"] + pose["orientation"]), (i, pose)
        f.steps()
        f.assert_healthy()

    run()
