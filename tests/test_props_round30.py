"""Property tests (Hypothesis, derandomized) of round 30's new paths, each failing case found fixed with a
regression test naming it (tests/test_props_round29*.py fuzz round 29's).

Riding robots: a two-wheel carrier driven and put anywhere, its rider's place on it set through its fields or
put in the world, both saved and loaded, the world reset, in random order: the rider is always at the carrier's
pose composed with its frame on it, the frame as a model of Webots' nested node predicts it (1e-9); the
rider's and the carrier's distance sensors read the distance along their beams to a wall (closed form).

A solid's Poses set through a Supervisor: random sets of translation and rotation (degenerate ones refused in
one line, nothing changed), steps, removes, saves, loads and resets against a model of the tree: every world
position and orientation (1e-9), ids stable, and a lidar's range the nearest live box face on its beam."""

from __future__ import annotations

import gc
import math
from pathlib import Path

import numpy as np
import pytest
from _fuzz import example_counts
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

# ---------------------------------------------------------------- riding robots
#
# A two-wheel carrier TRUCK (wheels of radius 0.05 m at y = ±0.12) with a DistanceSensor "ds" 0.1 m above its
# origin along its x, carrying RIDER (no shape of its own) with a DistanceSensor "rs" at its origin along its x;
# a wall (a 0.2 m thick boundingObject, 40 m wide and high) with its near face at x = 7.9. Both sensors' lookup
# tables give the distance in metres up to 20 (20 past it, or no hit). A rider's rotation is a turn about z
# and an upward pitch (its beam never goes down), the carrier stays upright: every beam ends on the wall or
# in the air, the distance along it (7.9 - x) / dx.

WHEEL = ('HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 {y} 0 }} device [ '
         'RotationalMotor {{ name "{side}" }} ] endPoint Solid {{ translation 0 {y} 0 rotation 1 0 0 '
         '1.5707963267948966 children [ Shape {{ geometry Cylinder {{ radius 0.05 height 0.02 }} }} ] '
         'boundingObject Cylinder {{ radius 0.05 height 0.02 }} physics Physics {{ }} name "{side}" }} }}')
WALL_FACE = 7.9


def rotation_of(yaw: float, pitch: float) -> np.ndarray:
    """A turn ``yaw`` about z after a pitch ``pitch`` lifting x towards z."""
    cy, sy, cp, sp = math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch)
    return np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]]) @ np.array([[cp, 0.0, -sp], [0.0, 1.0, 0.0],
                                                                                 [sp, 0.0, cp]])


def axis_angle_of(rot: np.ndarray) -> list[float]:
    angle = math.acos(max(-1.0, min(1.0, (np.trace(rot) - 1.0) / 2.0)))
    if angle < 1e-12:
        return [0.0, 0.0, 1.0, 0.0]
    axis = np.array([rot[2, 1] - rot[1, 2], rot[0, 2] - rot[2, 0], rot[1, 0] - rot[0, 1]])
    return [*(axis / np.linalg.norm(axis)).tolist(), angle]


def beam(at: np.ndarray, rot: np.ndarray) -> float:
    """A DistanceSensor's reading at ``at`` looking along ``rot``'s x: the wall's face along it, 20 past 20 m."""
    d = rot[:, 0]
    if d[0] <= 1e-9:
        return 20.0
    t = (WALL_FACE - at[0]) / d[0]
    hit = at + t * d
    return t if t <= 20.0 and abs(hit[1]) < 20.0 and abs(hit[2]) < 20.0 else 20.0


def rider_world(folder: Path, truck: tuple[float, float, float], frame: tuple) -> Path:
    wheels = " ".join(WHEEL.format(y=y, side=side) for y, side in ((0.12, "left"), (-0.12, "right")))
    (x, y, yaw), (t, ryaw, rpitch) = truck, frame
    rider_rot = " ".join(repr(v) for v in axis_angle_of(rotation_of(ryaw, rpitch)))
    path = folder / "riders.wbt"
    path.write_text(f"""#VRML_SIM R2023b utf8
WorldInfo {{ basicTimeStep 16 }}
Robot {{ name "probe" controller "<extern>" supervisor TRUE }}
Solid {{ translation 8 0 0 name "wall" boundingObject Box {{ size 0.2 40 40 }} }}
DEF TRUCK Robot {{ translation {x!r} {y!r} 0.05 rotation 0 0 1 {yaw!r} name "truck" controller "<extern>" children [
  {wheels}
  DistanceSensor {{ translation 0 0 0.1 name "ds" lookupTable [0 0 0, 20 20 0] }}
  DEF RIDER Robot {{ translation {' '.join(repr(v) for v in t)} rotation {rider_rot} name "rider" controller "<extern>"
    children [ DistanceSensor {{ name "rs" lookupTable [0 0 0, 20 20 0] }} ] }} ]
  boundingObject Box {{ size 0.3 0.2 0.06 }} physics Physics {{ }} }}
""")
    return path


def plain(v: float) -> float:
    return v if abs(v) >= 1e-4 else 0.0            # the loader refuses magnitudes under 1e-30: no draws there


def span(low: float, high: float) -> st.SearchStrategy[float]:
    return st.floats(low, high).map(plain)


offset = span(-0.5, 0.5)
turn = span(-0.6, 0.6)
frames = st.tuples(st.tuples(offset, offset, span(0.1, 0.5)), turn, span(0.0, 0.3))   # above the box
places = st.tuples(span(-2.0, 2.0), span(-2.0, 2.0), turn)
rider_ops = st.lists(st.one_of(
    st.tuples(st.just("drive"), st.floats(-8.0, 8.0), st.floats(-8.0, 8.0), st.integers(1, 6)),
    st.tuples(st.just("truck"), places),
    st.tuples(st.just("field"), frames, st.booleans(), st.booleans()),
    st.tuples(st.just("world"), places, st.floats(0.15, 0.5)),
    st.tuples(st.just("save"), st.sampled_from(["TRUCK", "RIDER"]), st.sampled_from(["a", "b"])),
    st.tuples(st.just("load"), st.sampled_from(["TRUCK", "RIDER"]), st.sampled_from(["a", "b", "__init__"])),
    st.tuples(st.just("reset"))), min_size=1, max_size=10)


def riders_follow_the_model(folder: Path, truck: tuple, frame: tuple, ops: list[tuple]) -> None:
    from test_supervisor import A, Live

    lv = Live(Simulation(load_world(rider_world(folder, truck, frame))))
    lv.ok(A, "attach", {"robot": "probe"})
    sim = lv.sim

    def call(item: str, args: dict | None = None):
        return lv.ok(A, f"/probe/robot/{item}", args)

    ids = {name: call("get_from_def", {"name": name})["node"] for name in ("TRUCK", "RIDER")}
    carrier, rider = sim.robot("truck"), sim.robot("rider")
    for name in ("truck/ds", "rider/rs"):
        sim.device(name).enable(16)
    # the model: the rider's frame on its carrier (rotation, translation), as loaded and as saved
    loaded = (rotation_of(frame[1], frame[2]), np.array(frame[0]))
    now = loaded
    saved: dict[tuple[str, str], tuple] = {}      # (DEF, name): the rider's frame (a TRUCK's: with its pose)

    def check(what) -> None:
        sim.step()
        c_rot, c_at = carrier.pose.rotation, carrier.pose.translation
        rot, at = c_rot @ now[0], c_at + c_rot @ now[1]
        assert rider.pose.translation == pytest.approx(at, abs=1e-9), what
        assert rider.pose.rotation == pytest.approx(rot, abs=1e-9), what
        got = call("get_field", {"node": ids["RIDER"], "field": "translation"})["value"]
        assert got == pytest.approx(now[1].tolist(), abs=1e-9), what
        assert sim.device("rider/rs").value == pytest.approx(beam(at, rot), abs=1e-6), what
        assert sim.device("truck/ds").value == pytest.approx(beam(c_at + c_rot[:, 2] * 0.1, c_rot), abs=1e-6), what

    check("start")
    for op in ops:
        kind = op[0]
        if kind == "drive":
            for side, speed in zip(("left", "right"), op[1:3]):
                carrier.motor(side).set_position(math.inf)
                carrier.motor(side).set_velocity(speed)
            for _ in range(op[3] - 1):
                sim.step()
        elif kind == "truck":
            x, y, yaw = op[1]
            call("set_field", {"node": ids["TRUCK"], "field": "translation", "value": [x, y, 0.05]})
            call("set_field", {"node": ids["TRUCK"], "field": "rotation", "value": [0.0, 0.0, 1.0, yaw]})
        elif kind == "field":                 # translation, rotation or both, in the carrier's frame
            (t, ryaw, rpitch), set_t, set_r = op[1:]
            rot = rotation_of(ryaw, rpitch)
            if set_t or not set_r:
                call("set_field", {"node": ids["RIDER"], "field": "translation", "value": list(t)})
                now = (now[0], np.array(t))
            if set_r:
                call("set_field", {"node": ids["RIDER"], "field": "rotation", "value": axis_angle_of(rot)})
                now = (rot, now[1])
        elif kind == "world":                 # put in the world: it stays there, fixed on its carrier
            (x, y, yaw), z = op[1:]
            rot = rotation_of(yaw, 0.0)
            rider.set_pose(translation=[x, y, z], rotation=axis_angle_of(rot))
            c_rot, c_at = carrier.pose.rotation, carrier.pose.translation
            now = (c_rot.T @ rot, c_rot.T @ (np.array([x, y, z]) - c_at))
        elif kind == "save":
            call("save_node_state", {"node": ids[op[1]], "state": op[2]})
            saved[op[1:]] = now
        elif kind == "load":
            if op[2] != "__init__" and op[1:] not in saved:
                continue
            call("load_node_state", {"node": ids[op[1]], "state": op[2]})
            # a node's state covers every field below it (WbNode::save): a carrier's, its rider's place on it
            now = loaded if op[2] == "__init__" else saved[op[1:]]
        elif kind == "reset":
            call("simulation_reset")
            now = loaded
            for name in ("truck/ds", "rider/rs"):
                sim.device(name).enable(16)
        check(op)


def test_regression_a_carriers_load_state_puts_its_rider_back_where_it_was_saved_on_it(tmp_path) -> None:
    """Found by the property above: saveState of the carrier, its rider's translation set, loadState of the
    carrier left the rider where it was set (a carrier's state kept only its own pose and joints); Webots'
    state of a node covers the fields below it. The rider written at (0, 0, 0.25) on a carrier at the origin:
    back there after the load, and at (0, 0, 0.25) again after loading the carrier's "__init__"."""
    from test_supervisor import A, Live

    lv = Live(Simulation(load_world(rider_world(tmp_path, (0.0, 0.0, 0.0), ((0.0, 0.0, 0.25), 0.0, 0.0)))))
    lv.ok(A, "attach", {"robot": "probe"})

    def call(item: str, args: dict | None = None):
        return lv.ok(A, f"/probe/robot/{item}", args)

    truck, rider = (call("get_from_def", {"name": n})["node"] for n in ("TRUCK", "RIDER"))
    field = {"node": rider, "field": "translation"}
    call("save_node_state", {"node": truck, "state": "a"})
    call("set_field", {**field, "value": [0.0, 0.0, 0.5]})
    lv.sim.step()
    assert lv.sim.robot("rider").pose.translation == pytest.approx([0.0, 0.0, 0.55], abs=1e-12)
    call("load_node_state", {"node": truck, "state": "a"})
    lv.sim.step()
    assert call("get_field", field)["value"] == pytest.approx([0.0, 0.0, 0.25], abs=1e-15)
    assert lv.sim.robot("rider").pose.translation == pytest.approx([0.0, 0.0, 0.3], abs=1e-12)
    call("set_field", {**field, "value": [0.1, 0.0, 0.5]})
    call("load_node_state", {"node": truck, "state": "__init__"})
    lv.sim.step()
    assert lv.sim.robot("rider").pose.translation == pytest.approx([0.0, 0.0, 0.3], abs=1e-12)


@pytest.mark.parametrize("examples", example_counts(200, 8))
def test_a_rider_is_where_its_carrier_and_its_frame_on_it_put_it(tmp_path, examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(places, frames, rider_ops)
    def run(truck: tuple, frame: tuple, ops: list[tuple]) -> None:
        try:
            riders_follow_the_model(tmp_path, truck, frame, ops)
        finally:
            gc.collect()          # each Simulation's Embree device freed (a process holds about 1,000)

    run()
