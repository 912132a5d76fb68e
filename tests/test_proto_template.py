"""PROTO templates (JavaScript in QuickJS): conditionals, expressions, loops, fields and context in
Webots' shapes, each template module against closed forms, wbrandom's determinism, errors at the
template's own lines, the sandbox."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from _protos import expanded, nodes_of, proto_file, world_file

from sensorium.server.world.loader import WorldError, load_world
from sensorium.server.world.proto import ProtoError
from sensorium.server.world.wbt.parser import Node

JS = "# template language: javascript\n"


def probe(tmp_path: Path, code: str, fields: str = "", instance: str = "", extra_protos: list[str] = ()) -> object:
    """Run ``code`` (JavaScript statements ending in ``out = ...``) in a PROTO template; the JSON
    value of ``out`` as the template wrote it into a WorldInfo title."""
    proto_file(tmp_path, "Probe", f"""[
  {fields}
]
{{
  %< {code} >%
  WorldInfo {{ title "%<= JSON.stringify(out).replace(/\\\\/g, '\\\\\\\\').replace(/"/g, '\\\\"') >%" }}
}}""", header=JS)
    w = world_file(tmp_path, f"Probe {{ {instance} }}\n", ["Probe.proto", *extra_protos])
    (root,) = expanded(w).nodes
    assert root.type == "WorldInfo" and root.proto == "Probe"
    return json.loads(root.fields["title"])


def test_conditionals_expressions_and_loops(tmp_path: Path) -> None:
    proto_file(tmp_path, "Row", """[
  field SFInt32 count 3
  field SFBool  tall  FALSE
  field SFFloat gap   0.25
  field SFString prefix "box"
]
{
  Group {
    children [
      %< for (let i = 0; i < fields.count.value; ++i) { >%
        Solid {
          translation %<= i * fields.gap.value >% 0 0
          name "%<= fields.prefix.value + '_' + i >%"
          %< if (fields.tall.value) { >%
            children [ Shape { geometry Box { size 0.1 0.1 1 } } ]
          %< } else { >%
            children [ Shape { geometry Box { size 0.1 0.1 0.1 } } ]
          %< } >%
        }
      %< } >%
    ]
  }
}""", header=JS)
    w = world_file(tmp_path, 'Row { count 5 tall TRUE }\nRow { prefix "flat" }\n', ["Row.proto"])
    tall, flat = expanded(w).nodes
    solids = tall.fields["children"]
    assert [s.fields["name"] for s in solids] == [f"box_{i}" for i in range(5)]
    assert [s.fields["translation"] for s in solids] == [(i * 0.25, 0.0, 0.0) for i in range(5)]
    assert all(s.fields["children"][0].fields["geometry"].fields["size"] == (0.1, 0.1, 1.0) for s in solids)
    assert [s.fields["name"] for s in flat.fields["children"]] == ["flat_0", "flat_1", "flat_2"]
    assert flat.fields["children"][0].fields["children"][0].fields["geometry"].fields["size"] == (0.1, 0.1, 0.1)


def test_dozens_of_nodes_from_a_loop_and_names_by_concatenation(tmp_path: Path) -> None:
    proto_file(tmp_path, "Ring", """[ field SFInt32 n 48 ]
{
  %< import * as wbgeometry from 'wbgeometry.js'; const c = wbgeometry.circle(2, fields.n.value, {x: 0, y: 0}, 0); >%
  Robot {
    name "ring"
    children [
      %< for (let i = 0; i < fields.n.value; ++i) { >%
      DistanceSensor { translation %<= c[i].x >% %<= c[i].y >% 0 name "%<= 'ds' + i >%" }
      %< } >%
    ]
  }
}""", header=JS)
    w = world_file(tmp_path, "Ring { }\n", ["Ring.proto"])
    (robot,) = load_world(w).world.robots
    assert [d.name for d in robot.devices] == [f"ds{i}" for i in range(48)]
    for i, d in enumerate(robot.devices):
        a = i * 2 * math.pi / 48
        assert d.pose.translation == pytest.approx((2 * math.cos(a), 2 * math.sin(a), 0.0), abs=1e-12)


def test_field_values_in_webots_shapes(tmp_path: Path) -> None:
    fields = """
  field SFBool     b   TRUE
  field SFInt32    i   -7
  field SFFloat    f   0.5
  field SFVec2f    v2  1 2
  field SFVec3f    v3  1 2 3
  field SFRotation r   0 0 1 1.5
  field SFColor    c   0.1 0.2 0.3
  field SFString   s   "a \\"quoted\\" string"
  field SFNode     n   NULL
  field SFNode     app PBRAppearance { baseColor 1 0 0 roughness 0.5 }
  field MFBool     mb  [TRUE FALSE]
  field MFInt32    mi  [1 2 3]
  field MFFloat    mf  []
  field MFVec2f    m2  [1 2, 3 4]
  field MFVec3f    m3  [1 2 3]
  field MFRotation mr  [0 1 0 3.14]
  field MFColor    mc  [1 0 0, 0 1 0]
  field MFString   ms  ["x", "y"]
  field MFNode     mn  [Box { size 1 2 3 }, Sphere { }]"""
    names = "b i f v2 v3 r c s n app mb mi mf m2 m3 mr mc ms mn".split()
    code = "const out = {};" + "".join(f"out.{k} = [fields.{k}.value === undefined ? null : fields.{k}.value, "
                                       f"fields.{k}.defaultValue === undefined ? null : fields.{k}.defaultValue];"
                                       for k in names)
    got = probe(tmp_path, code, fields, instance="i 42 v3 4 5 6 s \"given\" mf [0.25] n Box { size 3 2 1 }")
    assert got["b"] == [True, True]
    assert got["i"] == [42, -7] and got["f"] == [0.5, 0.5]
    assert got["v2"][0] == {"x": 1, "y": 2}
    assert got["v3"] == [{"x": 4, "y": 5, "z": 6}, {"x": 1, "y": 2, "z": 3}]
    assert got["r"][0] == {"x": 0, "y": 0, "z": 1, "a": 1.5}
    assert got["c"][0] == {"r": 0.1, "g": 0.2, "b": 0.3}
    assert got["s"] == ["given", 'a "quoted" string']
    assert got["n"] == [{"node_name": "Box", "fields": {"size": {"value": {"x": 3, "y": 2, "z": 1},
                                                                  "defaultValue": {"x": 3, "y": 2, "z": 1}}}}, None]
    assert got["app"][0]["node_name"] == "PBRAppearance"
    assert got["app"][0]["fields"]["baseColor"]["value"] == {"r": 1, "g": 0, "b": 0}
    assert got["mb"][0] == [True, False] and got["mi"][0] == [1, 2, 3] and got["mf"] == [[0.25], []]
    assert got["m2"][0] == [{"x": 1, "y": 2}, {"x": 3, "y": 4}]
    assert got["mr"][0] == [{"x": 0, "y": 1, "z": 0, "a": 3.14}]
    assert got["mc"][0] == [{"r": 1, "g": 0, "b": 0}, {"r": 0, "g": 1, "b": 0}]
    assert got["ms"][0] == ["x", "y"]
    assert [n["node_name"] for n in got["mn"][0]] == ["Box", "Sphere"]


def test_sfnode_of_a_proto_instance_lists_its_interface(tmp_path: Path) -> None:
    proto_file(tmp_path, "Leg", "[ field SFFloat length 0.3 field SFString side \"left\" ] { Pose { } }")
    got = probe(tmp_path, "const out = fields.part.value;", "field SFNode part NULL",
                instance='part Leg { side "right" }', extra_protos=["Leg.proto"])
    assert got == {"node_name": "Leg", "fields": {"length": {"value": 0.3, "defaultValue": 0.3},
                                                  "side": {"value": "right", "defaultValue": "left"}}}


def test_context(tmp_path: Path) -> None:
    got = probe(tmp_path, "const out = context;")
    w = tmp_path / "w.wbt"
    assert got["world"] == str(w.resolve()) and got["proto"] == str(tmp_path / "Probe.proto")
    assert got["coordinate_system"] == "ENU" and got["os"] in ("linux", "mac", "windows")
    assert got["webots_version"] == {"major": "R2023b", "revision": "0"}
    assert got["id"] == "1" and got["project_path"].endswith("/")
    assert set(got) == {"world", "proto", "project_path", "webots_home", "temporary_files_path", "os", "id",
                        "coordinate_system", "webots_version"}


def test_coordinate_system_comes_from_world_info(tmp_path: Path) -> None:
    proto_file(tmp_path, "Up", """[ ]
{
  %< const up = context.coordinate_system === 'NUE' ? '0 1 0' : '0 0 1'; >%
  Pose { translation %<= up >% }
}""", header=JS)
    w = world_file(tmp_path, 'WorldInfo { coordinateSystem "NUE" }\nUp { }\n', ["Up.proto"])
    assert expanded(w).nodes[1].fields["translation"] == (0.0, 1.0, 0.0)
    w = world_file(tmp_path, "Up { }\n", ["Up.proto"])
    assert expanded(w).nodes[0].fields["translation"] == (0.0, 0.0, 1.0)


# ------------------------------------------------------------------------------------ modules


def test_wbvector2_and_wbvector3_closed_forms(tmp_path: Path) -> None:
    got = probe(tmp_path, """
import * as v2 from 'wbvector2.js';
import {add, minus, multiply, dot, cross, norm, distance, normalize, equal} from 'wbvector3.js';
const a = {x: 3, y: 4}, b = {x: 1, y: 1};
const out = {
  add: v2.add(a, b), minus: v2.minus(a, b), mul: v2.multiply(a, 2), dot: v2.dot(a, b), cross: v2.cross(a, b),
  norm: v2.norm(a), dist: v2.distance(a, b), angle: v2.angle({x: 1, y: 1}, {x: 0, y: 0}), unit: v2.normalize(a),
  eq: [v2.equal(a, {x: 3, y: 4}), v2.equal(a, b)],
  hit: v2.intersection({x: 0, y: 0}, {x: 2, y: 2}, {x: 0, y: 2}, {x: 2, y: 0}),
  miss: v2.intersection({x: 0, y: 0}, {x: 1, y: 1}, {x: 0, y: 2}, {x: 0.5, y: 1.9}),
  parallel: v2.intersection({x: 0, y: 0}, {x: 1, y: 0}, {x: 0, y: 1}, {x: 1, y: 1}),
  a3: add({x: 1, y: 2, z: 3}, {x: 1, y: 1, z: 1}), m3: minus({x: 1, y: 2, z: 3}, {x: 1, y: 1, z: 1}),
  s3: multiply({x: 1, y: 2, z: 3}, -1), d3: dot({x: 1, y: 2, z: 3}, {x: 4, y: 5, z: 6}),
  c3: cross({x: 1, y: 0, z: 0}, {x: 0, y: 1, z: 0}), n3: norm({x: 2, y: 3, z: 6}),
  dd3: distance({x: 1, y: 1, z: 1}, {x: 1, y: 1, z: 4}), u3: normalize({x: 0, y: 0, z: 5}),
  e3: equal({x: 1, y: 2, z: 3}, {x: 1, y: 2, z: 3})
};""")
    assert got["add"] == {"x": 4, "y": 5} and got["minus"] == {"x": 2, "y": 3} and got["mul"] == {"x": 6, "y": 8}
    assert (got["dot"], got["cross"], got["norm"]) == (7, -1, 5)
    assert got["dist"] == pytest.approx(math.sqrt(13), abs=1e-15)
    assert got["angle"] == pytest.approx(math.pi / 4, abs=1e-15)
    assert got["unit"] == {"x": 0.6, "y": 0.8} and got["eq"] == [True, False]
    assert got["hit"] == {"x": 1, "y": 1} and got["miss"] is None and got["parallel"] is None
    assert got["a3"] == {"x": 2, "y": 3, "z": 4} and got["m3"] == {"x": 0, "y": 1, "z": 2}
    assert got["s3"] == {"x": -1, "y": -2, "z": -3} and got["d3"] == 32
    assert got["c3"] == {"x": 0, "y": 0, "z": 1} and got["n3"] == 7 and got["dd3"] == 3
    assert got["u3"] == {"x": 0, "y": 0, "z": 1} and got["e3"] is True


def test_wbrotation_closed_forms(tmp_path: Path) -> None:
    got = probe(tmp_path, """
import * as wbrotation from 'wbrotation.js';
const quarter = {x: 0, y: 0, z: 2, a: Math.PI / 2};
const out = {
  q: wbrotation.toQuaternion(quarter),
  back: wbrotation.fromQuaternion(wbrotation.toQuaternion({x: 1, y: 1, z: 0, a: 1})),
  m: wbrotation.toMatrix3(quarter),
  fromM: wbrotation.fromMatrix3(wbrotation.toMatrix3({x: 0, y: 1, z: 0, a: 2.5})),
  v: wbrotation.rotateVector3ByRotation(quarter, {x: 1, y: 0, z: 0}),
  vq: wbrotation.rotateVector3ByQuaternion({w: Math.SQRT1_2, x: Math.SQRT1_2, y: 0, z: 0}, {x: 0, y: 1, z: 0}),
  combined: wbrotation.combine({x: 0, y: 0, z: 1, a: 0.5}, {x: 0, y: 0, z: 1, a: 0.25}),
  zy: wbrotation.rotateVector3ByRotation(
        wbrotation.combine({x: 0, y: 0, z: 1, a: Math.PI / 2}, {x: 0, y: 1, z: 0, a: Math.PI / 2}), {x: 0, y: 0, z: 1}),
  norm: wbrotation.normalize({x: 0, y: 3, z: 4, a: 7}),
  id: [wbrotation.isIdentity({x: 0, y: 0, z: 1, a: 0}), wbrotation.isIdentity(quarter)],
  eq: wbrotation.equal(quarter, {x: 0, y: 0, z: 2, a: Math.PI / 2}),
  identity: wbrotation.fromQuaternion({w: 1, x: 0, y: 0, z: 0})
};""")
    h = math.sqrt(0.5)
    assert [got["q"][k] for k in "wxyz"] == pytest.approx([h, 0, 0, h], abs=1e-15)
    b = got["back"]
    assert [b["x"], b["y"], b["z"], b["a"]] == pytest.approx([h, h, 0, 1], abs=1e-15)
    m = got["m"]
    assert [m[str(i)] for i in range(9)] == pytest.approx([0, -1, 0, 1, 0, 0, 0, 0, 1], abs=1e-15)
    f = got["fromM"]
    assert [f["x"], f["y"], f["z"], f["a"]] == pytest.approx([0, 1, 0, 2.5], abs=1e-14)
    assert [got["v"][k] for k in "xyz"] == pytest.approx([0, 1, 0], abs=1e-15)
    assert [got["vq"][k] for k in "xyz"] == pytest.approx([0, 0, 1], abs=1e-15)     # a quarter turn about x
    c = got["combined"]
    assert [c["x"], c["y"], c["z"], c["a"]] == pytest.approx([0, 0, 1, 0.75], abs=1e-15)
    # combine(A, B) = A after B: z up, turned a quarter about y (to +x), then about z (to +y)
    assert [got["zy"][k] for k in "xyz"] == pytest.approx([0, 1, 0], abs=1e-15)
    n = got["norm"]
    assert [n["x"], n["y"], n["z"], n["a"]] == pytest.approx([0, 0.6, 0.8, 7 - 2 * math.pi], abs=1e-15)
    assert got["id"] == [True, False] and got["eq"] is True
    assert got["identity"] == {"x": 0, "y": 0, "z": 1, "a": 0}


def test_wbgeometry_closed_forms(tmp_path: Path) -> None:
    got = probe(tmp_path, """
import * as g from 'wbgeometry.js';
const square = [{x: 0, y: 0}, {x: 2, y: 0}, {x: 2, y: 2}, {x: 0, y: 2}];
const out = {
  circle: g.circle(2, 4, {x: 1, y: -1}, Math.PI / 2),
  inside: [g.isPoint2InPolygon({x: 1, y: 1}, square), g.isPoint2InPolygon({x: 3, y: 1}, square)],
  closest: g.findClosestPoint2InArray({x: 1.9, y: 0.2}, square),
  clockwise: [g.isPoint2ArrayClockwise(square), g.isPoint2ArrayClockwise(square.slice().reverse())],
  line: g.bSpline2([{x: 0, y: 0}, {x: 1, y: 0}, {x: 2, y: 0}, {x: 3, y: 0}], 4),
  curve: g.bSpline3([{x: 0, y: 0, z: 0}, {x: 1, y: 1, z: 0}, {x: 2, y: 0, z: 1}], 3),
  kept: (function () { const p = [{x: 0, y: 0}, {x: 1, y: 1}]; g.bSpline2(p, 2); return p.length; })()
};""")
    c = got["circle"]
    assert len(c) == 5                              # div + 1 points: the first repeated last
    expect = [(1 + 2 * math.cos(math.pi / 2 + i * math.pi / 2), -1 + 2 * math.sin(math.pi / 2 + i * math.pi / 2))
              for i in range(5)]
    assert [v for p in c for v in (p["x"], p["y"])] == pytest.approx([v for p in expect for v in p], abs=1e-15)
    assert got["inside"] == [True, False] and got["closest"] == {"x": 2, "y": 0}
    assert got["clockwise"] == [False, True]        # counter-clockwise in x right, y up axes
    # collinear, evenly spaced control points: the spline is the line itself, evenly subdivided
    line = got["line"]
    assert len(line) == 1 + 3 * 4 and [p["x"] for p in line] == pytest.approx([i / 4 for i in range(13)], abs=1e-15)
    assert all(abs(p["y"]) < 1e-15 for p in line)
    curve = got["curve"]
    assert len(curve) == 1 + 2 * 3
    assert [curve[0][k] for k in "xyz"] == [0, 0, 0] and [curve[-1][k] for k in "xyz"] == pytest.approx([2, 0, 1])
    # uniform cubic B-spline at t = 1/3 of the first segment (controls P-1 = 2 P0 - P1, P0, P1, P2)
    t = 1 / 3
    b = [(1 - t) ** 3 / 6, (3 * t**3 - 6 * t**2 + 4) / 6, (-3 * t**3 + 3 * t**2 + 3 * t + 1) / 6, t**3 / 6]
    ctrl = [(-1, -1, 0), (0, 0, 0), (1, 1, 0), (2, 0, 1)]
    assert [curve[1][k] for k in "xyz"] == pytest.approx([sum(w * p[i] for w, p in zip(b, ctrl)) for i in range(3)],
                                                         abs=1e-15)
    assert got["kept"] == 2                         # the control points are not changed


def test_wbutility(tmp_path: Path) -> None:
    got = probe(tmp_path, """
import * as u from 'wbutility.js';
const src = {a: [1, {b: 2}]};
const copy = u.deepCopy(src);
copy.a[1].b = 3;
const out = {
  orig: src.a[1].b, copy: copy.a[1].b, rad: u.degreesToRadians(180), deg: u.radiansToDegrees(Math.PI / 2),
  checks: [u.isScalar(1), u.isScalar('1'), u.isVector2({x: 1, y: 2}), u.isVector2({x: 1, y: 2, z: 3}),
           u.isVector3({x: 1, y: 2, z: 3}), u.isAxisAngle({x: 0, y: 0, z: 1, a: 0}), u.isQuaternion({w: 1, x: 0, y: 0, z: 0}),
           u.isMatrix3([1, 0, 0, 0, 1, 0, 0, 0, 1]), u.isArrayOfPoints([{x: 1, y: 2}], 2), u.isArrayOfPoints([{x: 1}], 2)]
};""")
    assert got["orig"] == 2 and got["copy"] == 3
    assert got["rad"] == math.pi and got["deg"] == 90
    assert got["checks"] == [True, False, True, False, True, True, True, True, True, False]


def test_wbrandom_is_deterministic_without_a_seed(tmp_path: Path) -> None:
    code = """
import * as wbrandom from 'wbrandom.js';
const first = [wbrandom.real(), wbrandom.real(-2, 3), wbrandom.integer(), wbrandom.integer(5, 9), wbrandom.integer(4)];
wbrandom.seed(12345);
const seeded = [wbrandom.real(), wbrandom.integer(0, 100)];
const out = {first, seeded, math: Math.random(), date: Date.now()};"""
    a = probe(tmp_path / "a", code)
    b = probe(tmp_path / "b", code)
    assert a == b                                          # the same every run, on every machine
    # the documented LCG (modulo 2^24, Visual Basic's coefficients) from seed 0, in double arithmetic
    state = 0.0

    def step() -> float:
        nonlocal state
        state = (1140671485.0 * state + 12820163.0) % 2.0**24      # doubles, as JavaScript computes it
        return state

    s1 = step()
    s2 = step()
    s3 = step()
    s4 = step()
    s5 = step()
    assert a["first"] == [s1 / (2**24 - 1), -2 + s2 * 5 / (2**24 - 1), s3, 5 + s4 % 5, 1 + s5 % 4]
    state = 12345.0
    t1, t2 = step(), step()
    assert a["seeded"] == [t1 / (2**24 - 1), t2 % 101]
    assert a["date"] == 0 and 0 <= a["math"] < 1


def test_identical_instances_reuse_one_template_run(tmp_path: Path, monkeypatch) -> None:
    """Deterministic output is reused (as Webots caches it) for instances whose template fields
    agree; a field the template does not read does not matter; nonDeterministic PROTOs run every time."""
    from sensorium.server.world.proto import template

    runs = []
    real = template.render
    monkeypatch.setattr(template, "render", lambda *a, **k: runs.append(1) or real(*a, **k))
    proto_file(tmp_path, "Box3", """[ field SFVec3f translation 0 0 0 field SFFloat size 0.1 ]
{ Solid { translation IS translation children [ Shape { geometry Box { size %<= fields.size.value >% 0.1 0.1 } } ] } }""",
               header=JS)
    proto_file(tmp_path, "Noisy", "[ ] { Pose { translation %<= context.id >% 0 0 } }", header=JS + "# tags: nonDeterministic\n")
    body = "".join(f"Box3 {{ translation {i} 0 0 }}\n" for i in range(10)) + "Box3 { size 0.2 }\nNoisy { }\nNoisy { }\n"
    nodes = expanded(world_file(tmp_path, body, ["Box3.proto", "Noisy.proto"])).nodes
    assert len(runs) == 2 + 2
    assert [n.fields["translation"] for n in nodes[:10]] == [(float(i), 0.0, 0.0) for i in range(10)]
    assert nodes[10].fields["children"][0].fields["geometry"].fields["size"] == (0.2, 0.1, 0.1)
    assert [n.fields["translation"][0] for n in nodes[11:]] == [12.0, 13.0]   # context.id: the instance's number


# ------------------------------------------------------------------------------------ errors and sandbox


def test_lua_templates_get_one_line(tmp_path: Path) -> None:
    proto_file(tmp_path, "Old", "[ field SFBool on TRUE ] {\n%{ if fields.on.value then }%\n Group { }\n%{ end }%\n}")
    w = world_file(tmp_path, "Old { }\n", ["Old.proto"])
    with pytest.raises(WorldError) as exc:
        load_world(w)
    msg = str(exc.value)
    assert "\n" not in msg and "PROTO Old: Lua templates (Webots before R2022b) are not supported" in msg
    assert f"{tmp_path / 'Old.proto'}:2:1" in msg


@pytest.mark.parametrize("code, line, what", [
    ("const x = ;", 7, "template error: SyntaxError"),
    ("\n\nnull.field;", 9, "template error: TypeError"),
    ("undefinedFunction();", 7, "template error: ReferenceError"),
    ("import * as x from 'wbfoo.js';", 7, "import of module 'wbfoo': not available here"),
    ("wbfile.readTextFile('/etc/passwd');", 7, "wbfile.readTextFile: templates have no file access here"),
    # imported as Webots' templates do, wbfile answers its calls alike (the import itself was refused)
    ("import * as wbfile from 'wbfile.js';\nwbfile.fileExists('x');", 8, "wbfile.fileExists: templates have no file access"),
    ("import { readTextFile } from 'wbfile.js'; readTextFile('x');", 7, "wbfile.readTextFile: templates have no file"),
])
def test_template_errors_point_at_the_template_line(tmp_path: Path, code: str, line: int, what: str) -> None:
    proto_file(tmp_path, "Bad", f"""[
  field SFFloat a 1
]
{{
  %< {code} >%
  Group {{ }}
}}""", header=JS)
    w = world_file(tmp_path, "Bad { }\n", ["Bad.proto"])
    with pytest.raises(ProtoError) as exc:
        expanded(w)
    assert str(exc.value).startswith(f"{tmp_path / 'Bad.proto'}:{line}:"), str(exc.value)
    assert what in str(exc.value) and "\n" not in str(exc.value)


def test_a_template_importing_wbfile_without_calling_it_loads(tmp_path: Path) -> None:
    proto_file(tmp_path, "Maybe", """[ field SFString file "" ]
{
  %< import * as wbfile from 'wbfile.js';
     const r = fields.file.value === '' ? 0.25 : Number(wbfile.readTextFile(fields.file.value)); >%
  Solid { children [ Shape { geometry Sphere { radius %<= r >% } } ] }
}""", header=JS)
    w = world_file(tmp_path, "Maybe { }\n", ["Maybe.proto"])
    (solid,) = load_world(w).world.solids
    assert solid.shapes[0].geometry.radius == 0.25


def test_errors_in_generated_text_point_at_the_template_line(tmp_path: Path) -> None:
    proto_file(tmp_path, "Gen", """[ field SFFloat r 1 ]
{
  Solid {
    children [
      Shape { geometry Sphere { radius %<= fields.r.value > 0 ? 'oops' : 1 >% } }
    ]
  }
}""", header=JS)
    w = world_file(tmp_path, "Gen { }\n", ["Gen.proto"])
    with pytest.raises(ProtoError) as exc:
        expanded(w)
    # the generated "radius oops }" reads as a node type without its '{': reported where the '}' is written
    assert str(exc.value).startswith(f"{tmp_path / 'Gen.proto'}:7:79: expected '{{' after node type oops, found '}}'")
    assert "(in the text PROTO Gen's template generated)" in str(exc.value)
    # a template computing NaN (0 / 0) or Infinity is named as such where the template writes it
    for expr, text in (("fields.r.value * NaN", "NaN"), ("fields.r.value / 0", "Infinity"), ("-1 / 0", "-Infinity")):
        proto_file(tmp_path, "Gen", f"[ field SFFloat r 1 ]\n{{\n  Solid {{ translation 0 0 %<= {expr} >% }}\n}}",
                   header=JS)
        with pytest.raises(ProtoError) as exc:
            expanded(w)
        assert str(exc.value).startswith(f"{tmp_path / 'Gen.proto'}:5:27: number '{text}' is not finite"), str(exc.value)
    # a plain text error after a template piece maps character for character
    proto_file(tmp_path, "Gen", "[ ]\n{\n  Solid { %<= '' >%\n    name 'x' }\n}", header=JS)
    with pytest.raises(ProtoError) as exc:
        expanded(w)
    assert str(exc.value).startswith(f"{tmp_path / 'Gen.proto'}:6:10: unexpected character \"'\"")


def test_console_errors_become_warnings(tmp_path: Path) -> None:
    proto_file(tmp_path, "Talk", """[ field SFFloat radius -1 ]
{
  %< if (fields.radius.value <= 0) console.error('radius must be positive'); console.log('not shown'); >%
  Group { }
}""", header=JS)
    w = world_file(tmp_path, "Talk { }\n", ["Talk.proto"])
    warnings = expanded(w).warnings
    assert [x for x in warnings if "template says" in x] == [
        f"{tmp_path / 'Talk.proto'}:3:1: PROTO Talk (instance at {w}:3): template says: radius must be positive"]


def test_no_std_os_or_require_in_the_sandbox(tmp_path: Path) -> None:
    got = probe(tmp_path, "const out = [typeof std, typeof os, typeof require, typeof process, typeof fetch, "
                          "typeof XMLHttpRequest, typeof print];")
    assert got == ["undefined"] * 7


def test_optional_commas_tabs_and_strings(tmp_path: Path) -> None:
    proto_file(tmp_path, "Commas", '[\n\tfield\tMFString\tnames\t["a, b",\t"c"]\n\tfield MFVec3f pts [ 1, 2, 3, 4 5 6 ]\n]\n'
               '{\n\tGroup {\n\t\tchildren [\n\t\t\t%< for (const n of fields.names.value) { >%\n'
               '\t\t\tSolid { name "%<= n >%", translation %<= fields.pts.value[1].x >%, 0, 0 }\n\t\t\t%< } >%\n\t\t]\n\t}\n}',
               header=JS)
    (g,) = expanded(world_file(tmp_path, "Commas { }\n", ["Commas.proto"])).nodes
    assert [(s.fields["name"], s.fields["translation"]) for s in g.fields["children"]] == [
        ("a, b", (4.0, 0.0, 0.0)), ("c", (4.0, 0.0, 0.0))]


def test_comments_prevail_over_template_statements(tmp_path: Path) -> None:
    proto_file(tmp_path, "Commented", """[ ]
{
  # %< this is not JavaScript >%
  Pose { translation %<= 1 + 1 >% 0 0 } # }
}""", header=JS)
    (p,) = expanded(world_file(tmp_path, "Commented { }\n", ["Commented.proto"])).nodes
    assert isinstance(p, Node) and p.fields["translation"] == (2.0, 0.0, 0.0)
    assert nodes_of(p, "Pose") == [p]
