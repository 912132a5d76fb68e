"""Hypothesis fuzz of the Supervisor's PROTO-field services (get_field and set_field with a level,
get_proto) on the sans-IO core, on tests/worlds/proto/supervisor_proto_fields.wbt: node ids real and
not, levels in and out of range and of the wrong type, field names of every length, values of every
type for a set through IS (NaN, infinities, huge, the wrong width). Every request gets one reply; a
refusal is one line with a protocol code other than INTERNAL and changes nothing; an accepted get
answers a type and a value of that type."""

from __future__ import annotations

import math

import pytest
from _fuzz import example_counts
from hypothesis import HealthCheck, given, settings
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


@pytest.mark.parametrize("examples", example_counts(400))
def test_proto_field_services_answer_or_refuse_in_one_line_and_change_nothing(fuzzed, examples: int) -> None:
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

    @settings(SETTINGS, max_examples=examples)
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


# ---------------------------------------------------------------- random PROTO interfaces read back

_finite = st.floats(allow_nan=False, allow_infinity=False, width=64)
_edge = st.sampled_from([0.0, -0.0, 5e-324, -5e-324, 2.2250738585072014e-308, 1.7976931348623157e308, -1.7976931348623157e308,
                         0.1, 1 / 3, 1e-300, 123456789.123456789])
num = _edge | _finite
_int = st.integers(-(1 << 31), (1 << 31) - 1) | st.sampled_from([0, -1, (1 << 31) - 1, -(1 << 31)])
# strings as a world file can hold them: any printable text, quotes and backslashes written escaped
text = st.text(st.characters(blacklist_categories=("Cc", "Cs", "Zl", "Zp")), max_size=12) | st.sampled_from(
    ["", '"', "\\", 'a"b\\c', "é中😀", "x" * 300])
WIDTH = {"Vec2f": 2, "Vec3f": 3, "Color": 3, "Rotation": 4}


def _vrml(kind: str, value: object) -> str:
    if kind == "Bool":
        return "TRUE" if value else "FALSE"
    if kind == "String":
        return '"' + str(value).replace("\\", "\\\\").replace('"', '\\"') + '"'
    if kind in WIDTH:
        return " ".join(repr(float(v)) for v in value)
    return repr(value)


def _item(kind: str) -> st.SearchStrategy:
    if kind in WIDTH:
        return st.lists(num if kind != "Color" else st.floats(0, 1), min_size=WIDTH[kind], max_size=WIDTH[kind])
    return {"Bool": st.booleans(), "Int32": _int, "Float": num, "String": text}[kind]


@st.composite
def interfaces(draw) -> list[tuple[str, str, object, object]]:
    """(name, type, default, instance value or None) per field."""
    out = []
    for i in range(draw(st.integers(1, 8))):
        kind = draw(st.sampled_from(["Bool", "Int32", "Float", "String", "Vec2f", "Vec3f", "Color", "Rotation"]))
        if draw(st.booleans()):
            size = st.sampled_from([0, 1, 2, 5]) | st.integers(0, 12)
            default = draw(st.lists(_item(kind), min_size=draw(size), max_size=12))
            given_ = draw(st.none() | st.lists(_item(kind), max_size=6))
            out.append((f"f{i}", "MF" + kind, default, given_))
        else:
            out.append((f"f{i}", "SF" + kind, draw(_item(kind)), draw(st.none() | _item(kind))))
    return out


def _expected(ftype: str, value: object) -> object:
    kind = ftype[2:]
    one = (lambda v: [float(x) for x in v]) if kind in WIDTH else (
        float if kind == "Float" else (lambda v: v))
    return [one(v) for v in value] if ftype.startswith("MF") else one(value)


def _write(folder, fields) -> object:
    decl = "\n".join(
        f"  field {t} {n} " + (f"[ {', '.join(_vrml(t[2:], v) for v in d)} ]" if t.startswith("MF") else _vrml(t[2:], d))
        for n, t, d, _ in fields)
    (folder / "Rand.proto").write_text(HEADER + f"PROTO Rand [\n{decl}\n]\n{{\n  Solid {{ name \"rand\" }}\n}}\n")
    given_ = " ".join(f"{n} " + (f"[ {' '.join(_vrml(t[2:], v) for v in g)} ]" if t.startswith("MF") else _vrml(t[2:], g))
                      for n, t, _, g in fields if g is not None)
    world = folder / "rand.wbt"
    world.write_text(HEADER + 'EXTERNPROTO "Rand.proto"\n'
                     f"Rand {{ {given_} }}\n"
                     'Robot { name "boss" supervisor TRUE controller "<extern>" }\n')
    return world


HEADER = "#VRML_SIM R2023b utf8\n"


@settings(max_examples=60, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(interfaces())
def test_random_proto_interfaces_read_back_as_the_world_file_says(fields) -> None:
    import tempfile
    from pathlib import Path

    from sensorium.server.daemon import supervisor
    from sensorium.server.sim.simulation import Simulation
    from sensorium.server.world.loader import load_world

    with tempfile.TemporaryDirectory() as d:
        sim = Simulation(load_world(_write(Path(d), fields)))
    node = supervisor.node_by_id(sim, 2)
    assert supervisor.get_proto(sim, node, 1)["fields"] == [n for n, *_ in fields]
    for name, ftype, default, given_ in fields:
        got = supervisor.get_field(sim, node, name)
        want = _expected(ftype, default if given_ is None else given_)
        assert got["type"] == ftype, (name, got)
        assert repr(got["value"]) == repr(want), (name, ftype, got["value"], want)     # -0.0 and every bit kept


@pytest.mark.parametrize(("ftype", "item", "want"), [
    ("MFFloat", "0.1", 0.1), ("MFVec3f", "1e-7 -0 3", [1e-7, -0.0, 3.0]), ("MFInt32", "-2147483648", -(1 << 31)),
    ("MFString", '"é"', "é"), ("MFBool", "TRUE", True), ("MFRotation", "0 0 1 -3.5", [0.0, 0.0, 1.0, -3.5])])
def test_an_mf_value_of_4096_items_is_kept_and_of_4097_is_said_not_kept(tmp_path, ftype, item, want) -> None:
    from sensorium.server.daemon import supervisor
    from sensorium.server.sim.simulation import Simulation
    from sensorium.server.world.loader import load_world

    (tmp_path / "Many.proto").write_text(HEADER + f"PROTO Many [\n  field {ftype} a [ ]\n  field {ftype} b [ ]\n"
                                         f"  field {ftype} c [ ]\n]\n{{\n  Solid {{ name \"many\" }}\n}}\n")
    world = tmp_path / "many.wbt"
    world.write_text(HEADER + 'EXTERNPROTO "Many.proto"\n'
                     f"Many {{ a [ {' '.join([item] * 4096)} ] b [ {' '.join([item] * 4097)} ] }}\n")
    sim = Simulation(load_world(world))
    node = supervisor.node_by_id(sim, 1)
    got = supervisor.get_field(sim, node, "a")
    assert got["type"] == ftype and len(got["value"]) == 4096 and repr(got["value"][-1]) == repr(want)
    assert supervisor.get_field(sim, node, "b") == {
        "type": ftype, "value": [], "note": f"field 'b' ({ftype}) of PROTO Many (Solid 'many' (node 1)): its value is "
                                            "over 4096 items, not kept here"}
    assert supervisor.get_field(sim, node, "c") == {"type": ftype, "value": []}           # empty: [] as written
