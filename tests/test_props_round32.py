"""Property tests (Hypothesis, derandomized) of the paths added with round 31's sweeps: pre-R2022a worlds,
the battery topic's energy and the client's C-string cut.

Worlds before R2022a: a random R2021b world of ours (Cylinders, Capsules, Cones and Planes each in a
Transform holding only it, at random translations and rotations, one in a boundingObject; a robot with a
Lidar, a Camera, an Emitter and a Pen at random poses, each with a pose child) loads as the R2023b world a user
writes by hand with README "Worlds before R2022a"'s turns applied: each Transform's rotation times Rx(-pi/2),
a Lidar's and a Camera's times Rx(-pi/2)·Rz(pi/2), an Emitter's times Rx(-pi/2)·Rz(-pi/2), a Pen's times
Rx(-pi/2), a device's pose child's rotation and translation by the inverse turn. The shapes' and devices' poses agree to 1e-12 and
the lidar's ranges to a float32 rounding; the same text read as an R2023b world is untouched (every pose as
written).

The battery topic: random batteries, consumptions and sensor periods: each sample's energy is the sensor's
very value and max(0, E0 - P·t). The C-string cut: random text with NULs gives its longest NUL-free prefix."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import msgpack
import numpy as np
import pytest
from _fuzz import example_counts
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS

from sensorium.client.wb_robot import c_string
from sensorium.server.daemon.services import Core
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world, parse_world

# ---------------------------------------------------------------- worlds before R2022a


def rotation_matrix(axis: tuple[float, float, float], angle: float) -> np.ndarray:
    """Rodrigues' formula for a unit ``axis``."""
    x, y, z = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    k = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * (k @ k)


def axis_angle(m: np.ndarray) -> tuple[float, float, float, float]:
    """An axis and angle of the rotation ``m`` (by its quaternion: stable near 0 and pi)."""
    w = math.sqrt(max(0.0, 1 + m[0, 0] + m[1, 1] + m[2, 2])) / 2
    x = math.copysign(math.sqrt(max(0.0, 1 + m[0, 0] - m[1, 1] - m[2, 2])) / 2, m[2, 1] - m[1, 2])
    y = math.copysign(math.sqrt(max(0.0, 1 - m[0, 0] + m[1, 1] - m[2, 2])) / 2, m[0, 2] - m[2, 0])
    z = math.copysign(math.sqrt(max(0.0, 1 - m[0, 0] - m[1, 1] + m[2, 2])) / 2, m[1, 0] - m[0, 1])
    s = math.sqrt(x * x + y * y + z * z)
    if s < 1e-300:
        return (0.0, 0.0, 1.0, 0.0)
    return (x / s, y / s, z / s, 2 * math.atan2(s, w))


RX = rotation_matrix((1, 0, 0), -math.pi / 2)
RZ_PLUS = rotation_matrix((0, 0, 1), math.pi / 2)
RZ_MINUS = rotation_matrix((0, 0, 1), -math.pi / 2)
TURNS = {"Lidar": RX @ RZ_PLUS, "Camera": RX @ RZ_PLUS, "Emitter": RX @ RZ_MINUS, "Pen": RX}
GEOMETRY = {"Cylinder": "Cylinder {{ radius {a} height {b} }}", "Capsule": "Capsule {{ radius {a} height {b} }}",
            "Cone": "Cone {{ bottomRadius {a} height {b} }}", "Plane": "Plane {{ size {a} {b} }}"}

def milli(lo: float, hi: float) -> st.SearchStrategy[float]:
    """Values in thousandths (the loader refuses magnitudes below 1e-30, which a float draw finds)."""
    return st.integers(round(lo * 1000), round(hi * 1000)).map(lambda k: k / 1000)


unit = milli(-1, 1).filter(lambda v: v != 0)
axes = st.tuples(unit, unit, unit)
angles = milli(-math.pi, math.pi)
places = st.tuples(*[milli(-1.5, 1.5)] * 3)
geometry = st.tuples(st.sampled_from(sorted(GEOMETRY)), milli(0.05, 0.5), milli(0.1, 1.0), places, axes, angles)
device = st.tuples(places, axes, angles, places, axes, angles)


def _f(v: float) -> str:
    return repr(float(v))


def _rot(axis, angle) -> str:
    return " ".join(_f(c) for c in (*axis, angle))


def _written(m: np.ndarray) -> str:
    return _rot(axis_angle(m)[:3], axis_angle(m)[3])


def legacy_worlds(shapes: list, devices: dict, bound: int) -> tuple[str, str]:
    """The R2021b text and the R2023b text a user writes by hand with the turns applied."""
    old, new = [], []
    for i, (kind, a, b, place, axis, angle) in enumerate(shapes):
        geo = GEOMETRY[kind].format(a=_f(a), b=_f(b))
        turned = _written(rotation_matrix(axis, angle) @ RX)
        pos = " ".join(map(_f, place))
        for out, rot in ((old, _rot(axis, angle)), (new, turned)):
            body = f"Transform {{ translation {pos} rotation {rot} children [ Shape {{ geometry {geo} }} ] }}"
            bo = f"boundingObject Transform {{ translation {pos} rotation {rot} children [ {geo} ] }}" if i == bound else ""
            out.append(f'Solid {{ name "s{i}" children [ {body} ] {bo} }}')
    olds, news = [], []
    for kind, (place, axis, angle, cplace, caxis, cangle) in devices.items():
        extra = ' horizontalResolution 32 numberOfLayers 4 fieldOfView 6.2 verticalFieldOfView 0.5 maxRange 8' \
            if kind == "Lidar" else ""
        pos, cpos = " ".join(map(_f, place)), " ".join(map(_f, cplace))
        inner = rotation_matrix(caxis, cangle)
        back = " ".join(map(_f, TURNS[kind].T @ np.asarray(cplace)))
        for out, rot, ct, crot in ((olds, _rot(axis, angle), cpos, _rot(caxis, cangle)),
                                   (news, _written(rotation_matrix(axis, angle) @ TURNS[kind]), back,
                                    _written(TURNS[kind].T @ inner))):
            child = f'DistanceSensor {{ name "{kind.lower()} child" translation {ct} rotation {crot} }}'
            out.append(f'{kind} {{ name "{kind.lower()}" translation {pos} rotation {rot}{extra} children [ {child} ] }}')
    robot = 'Robot {{ name "r" controller "<extern>" children [ {} ] }}'
    head = 'WorldInfo { coordinateSystem "NUE" basicTimeStep 16 }\n'
    return ("#VRML_SIM R2021b utf8\n" + head + "\n".join(old) + "\n" + robot.format(" ".join(olds)) + "\n",
            "#VRML_SIM R2023b utf8\n" + head + "\n".join(new) + "\n" + robot.format(" ".join(news)) + "\n")


def _pose(p) -> tuple[np.ndarray, np.ndarray]:
    r = np.eye(3) if p.rotation is None else rotation_matrix(p.rotation[:3], p.rotation[3])
    return np.asarray(p.translation), r


def _poses(loaded) -> list:
    w = loaded.world
    out = [(s.name, _pose(s.pose)) for s in w.solids]
    out += [(f"{s.name}:{i}", _pose(part.pose)) for s in w.solids for i, part in enumerate(s.shapes)]
    out += [(d.name, _pose(d.pose)) for d in w.robots[0].devices]
    return sorted(out, key=lambda x: x[0])


def _ranges(loaded) -> np.ndarray:
    sim = Simulation(loaded)
    lidar = sim.device("r/lidar")
    lidar.enable(16)
    sim.step()
    return np.asarray(lidar.range_image, dtype=np.float32).copy()


def _load(path: Path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_world(path)


def check_legacy_world(tmp: Path, shapes: list, devices: dict, bound: int) -> None:
    old, new = legacy_worlds(shapes, devices, bound)
    (tmp / "old.wbt").write_text(old)
    (tmp / "new.wbt").write_text(new)
    (tmp / "same.wbt").write_text(old.replace("R2021b", "R2023b"))
    converted, by_hand, untouched = _load(tmp / "old.wbt"), _load(tmp / "new.wbt"), _load(tmp / "same.wbt")
    a, b = _poses(converted), _poses(by_hand)
    assert [n for n, _ in a] == [n for n, _ in b]
    for (name, (ta, ra)), (_, (tb, rb)) in zip(a, b, strict=True):
        # 1e-11: two axis-angle round trips of a near-identity turn differ by up to 1.1e-12 (found at 1,500 examples)
        assert np.abs(ta - tb).max() <= 1e-12 and np.abs(ra - rb).max() <= 1e-11, name
    # the R2023b reading of the R2021b text: every rotation as written
    for kind, (place, axis, angle, *_) in devices.items():
        (d,) = [d for d in untouched.world.robots[0].devices if d.name == kind.lower()]
        assert np.abs(_pose(d.pose)[1] - rotation_matrix(axis, angle)).max() <= 1e-12
        assert tuple(d.pose.translation) == tuple(place)
    for i, (*_, place, axis, angle) in enumerate(shapes):
        (solid,) = [s for s in untouched.world.solids if s.name == f"s{i}"]
        for part in solid.shapes:
            assert np.abs(_pose(part.pose)[1] - rotation_matrix(axis, angle)).max() <= 1e-12
            assert tuple(part.pose.translation) == tuple(place)
    if "Lidar" in devices:
        ra, rb = _ranges(converted), _ranges(by_hand)
        close = np.isclose(ra, rb, rtol=4e-7, atol=0) | (ra == rb)
        # a beam grazing an edge may fall either side of it by the 1e-16 the two rotations differ: a few at most
        assert (~close).sum() <= 2, (ra[~close], rb[~close])


@pytest.mark.parametrize("examples", example_counts(200, 10))
def test_an_r2021b_world_loads_as_the_r2023b_world_written_with_the_documented_turns(tmp_path, examples) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(shapes=st.lists(geometry, min_size=1, max_size=4),
           devices=st.dictionaries(st.sampled_from(sorted(TURNS)), device, min_size=1),
           bound=st.integers(0, 3))
    def prop(shapes, devices, bound) -> None:
        check_legacy_world(tmp_path, shapes, devices, bound)

    prop()


# ---------------------------------------------------------------- the battery topic's energy
#
# A robot with a random battery [energy, maximum, 0] and cpuConsumption, its controller's battery sensor at a
# random period: at each sample the topic's energy is the very number the sensor reads, its percentage that
# over the maximum, and both the closed form max(0, E0 - P·t) (no motors, no charger).

DT = 16


def _attached(e0: float, emax: float, power: float):
    from test_battery_topic import Controller

    world = {"world_info": {"basic_time_step": DT},
             "robots": [{"name": "r", "battery": [e0, emax, 0.0], "cpu_consumption": power}]}
    core = Core(Simulation(parse_world(world)), new_token=lambda: "s0", log=lambda *_: None)
    ctl = Controller(core)
    ctl.call("attach", {"robot": "r"})
    core.subscription(b"\x01/r/battery\0")
    return ctl


@pytest.mark.parametrize("examples", example_counts(100, 10))
def test_the_battery_topics_energy_is_the_battery_sensors_value(examples) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(e0=milli(0, 2), extra=milli(0, 50), power=milli(0, 40), every=st.integers(1, 4), steps=st.integers(1, 12))
    def prop(e0, extra, power, every, steps) -> None:
        drain = power * DT / 1000
        # the step in which the battery empties (Webots refreshes the sensor then, its schedule from there)
        empties = math.ceil(e0 / drain) if e0 > 0 and drain > 0 else None
        assume(empties is None or abs(e0 / drain - round(e0 / drain)) > 1e-6)    # not on a step's edge
        emax = e0 + extra
        ctl = _attached(e0, emax, power)
        ctl.call("/r/robot/battery_sensor_enable", {"value": every * DT})
        last = 0
        for n in range(1, steps + 1):
            ctl.step()
            sent = [msgpack.unpackb(f[2]) for f in ctl.published if f[0][:-1] == b"/r/battery"]
            ctl.published.clear()
            value = ctl.call("/r/robot/battery_sensor_get_value")["value"]
            if n - last < every and n != empties:
                assert sent == [], n
                continue
            last = n
            (body,) = sent
            assert body["energy"] == value
            assert body["percentage"] == value / emax if emax > 0 else math.isnan(body["percentage"])
            assert value == pytest.approx(max(0.0, e0 - drain * n), abs=1e-9)

    prop()


# ---------------------------------------------------------------- the client's C-string cut


@settings(SETTINGS, max_examples=300)
@given(text=st.text(alphabet=st.sampled_from("a\0é\x01 \U0001f600"), max_size=12))
def test_a_c_string_is_the_text_before_its_first_nul(text: str) -> None:
    """Closed form: the longest prefix holding no NUL (the whole text when there is none)."""
    cut = c_string(text)
    assert "\0" not in cut and text.startswith(cut)
    assert cut == text or text[len(cut)] == "\0"
    assert c_string(text.encode()) == text.encode() and c_string(None) is None   # not a str: unchanged


# ---------------------------------------------------------------- the Viewpoint's follow
#
# A Viewpoint following a top-level solid or a robot, moved by a Supervisor's translation sets, with
# moveViewpoint calls (the one outside set of its position: the field is read only to a Supervisor) and resets
# between random steps. Closed form (Webots' Tracking Shot,
# WbViewpoint::updateFollowUp at once): after each step the view is where it stood before the step (as
# written, or as moveViewpoint put it) plus the followed node's displacement since the step before (its world-file
# place at load and after a reset); a reset puts the written position back.

FOLLOW = """#VRML_SIM R2023b utf8
WorldInfo {{ basicTimeStep 16 }}
Viewpoint {{ orientation 0 0 1 0 position {view} follow "{follow}" }}
DEF CRATE Solid {{ translation 1 2 0.5 name "crate" children [ Shape {{ geometry Box {{ size 0.2 0.2 0.2 }} }} ] }}
DEF MOVER Robot {{ translation -1 0.5 0 name "mover" controller "<extern>" }}
DEF OTHER Solid {{ translation 3 -2 0.1 name "other" children [ Shape {{ geometry Sphere {{ radius 0.1 }} }} ] }}
DEF BOSS Robot {{ name "boss" supervisor TRUE controller "<extern>" }}
"""
FOLLOWED_AT = {"crate": (1.0, 2.0, 0.5), "mover": (-1.0, 0.5, 0.0)}


def _boss(lv, item: str, args: dict | None = None):
    from test_supervisor import A

    return lv.ok(A, f"/boss/robot/{item}", args)


follow_ops = st.one_of(
    st.tuples(st.just("move"), places),
    st.tuples(st.sampled_from(["moveViewpoint", "reset"]), st.sampled_from(["CRATE", "OTHER", "MOVER"])),
    st.tuples(st.just("step"), st.integers(1, 3)))


@pytest.mark.parametrize("examples", example_counts(100, 10))
def test_the_viewpoint_moves_by_the_followed_nodes_displacement(tmp_path, examples) -> None:
    from test_supervisor import A, Live

    @settings(SETTINGS, max_examples=examples)
    @given(follow=st.sampled_from(sorted(FOLLOWED_AT)), view=places, ops=st.lists(follow_ops, max_size=10))
    def prop(follow, view, ops) -> None:
        path = tmp_path / "follow.wbt"
        path.write_text(FOLLOW.format(view=" ".join(map(_f, view)), follow=follow))
        lv = Live(Simulation(load_world(path)))
        lv.ok(A, "attach", {"robot": "boss"})
        ids = {name: _boss(lv, "get_from_def", {"name": name})["node"] for name in ("CRATE", "MOVER", "OTHER")}
        followed = ids[follow.upper()]
        viewpoint = next(n for n in lv.sim.top_level.scenery if n.type == "Viewpoint")

        def position() -> np.ndarray:
            return np.asarray(viewpoint.fields["position"], dtype=float)

        def at() -> np.ndarray:
            return np.asarray(_boss(lv, "get_field", {"node": followed, "field": "translation"})["value"])

        before = np.asarray(FOLLOWED_AT[follow])
        for op, arg in ops:
            if op == "move":
                _boss(lv, "set_field", {"node": followed, "field": "translation", "value": list(arg)})
            elif op == "moveViewpoint":
                _boss(lv, "move_viewpoint", {"node": ids[arg]})
            elif op == "reset":
                _boss(lv, "simulation_reset")
                assert np.array_equal(position(), view)
                before = np.asarray(FOLLOWED_AT[follow])
            else:
                for _ in range(arg):
                    stood = position()
                    lv.step(A, "boss")
                    now = at()
                    assert np.abs(position() - (stood + (now - before))).max() <= 1e-12, (op, stood, now, before)
                    before = now

    prop()


# ---------------------------------------------------------------- a nested Transform's scale
#
# test_supervisor_transform_scale.py's world: a Supervisor sets ST's scale (inside the top-level solid BOX) to
# random values in turn (zero and negative components among them): each reads back as set (a zero as 1), the lidar and camera see bit for bit what the world file
# written with it gives, the lidar's middle beam the box's face at x = 2 - 0.1·|sx| (float32), a reset the
# loaded 1 1 2 again.


@pytest.mark.parametrize("examples", example_counts(40, 4))
def test_a_nested_transforms_scale_set_reads_as_its_world_file(tmp_path, examples) -> None:
    import test_supervisor_transform_scale as ts

    component = milli(0.05, 3) | milli(-3, -0.05) | st.just(0.0)
    scales = st.tuples(component, component, component)
    loaded = ts.seen(ts._live(tmp_path))

    @settings(SETTINGS, max_examples=examples)
    @given(values=st.lists(scales, min_size=1, max_size=3))
    def prop(values) -> None:
        lv = ts._live(tmp_path)
        st_node = ts.node(lv, "ST")
        for value in values:
            ts.call(lv, "set_field", {"node": st_node, "field": "scale", "value": list(value)})
            assert ts.get(lv, st_node, "scale") == [v or 1.0 for v in value]      # a zero reset to 1, as Webots
            got = ts.seen(lv)
            assert got == ts.seen(ts._live(tmp_path, " ".join(map(_f, value))))
            assert ts.middle(got[0]) == np.float32(2.0 - 0.1 * abs(value[0] or 1.0))
        ts.call(lv, "simulation_reset")
        assert ts.get(lv, st_node, "scale") == [1.0, 1.0, 2.0] and ts.seen(lv) == loaded

    prop()
