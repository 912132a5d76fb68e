"""Property tests (Hypothesis, derandomized) of the paths sweeps 30 to 32 added, each failing case found fixed
with a regression test naming it (tests/test_props_round30*.py fuzz round 30's).

Texture urls of a PROTO's field: a world folder and a PROTO file at random places (beside the world, in a
sub-folder, in the project's protos/, in a folder beside the worlds'), one-colour images written at random
among the urls below both, a default url in the PROTO, a value the world writes for it or none, then a
Supervisor's sets of the url and simulationReset (which keeps the value set) in random order: the shape shows the image of the first of
the PROTO's folder and the world's folder that holds the url's file, the path cleaned first as Webots'
QDir::cleanPath does (``tex/../t.png`` is ``t.png``), the world's only while the path stays in it; or none,
drawn untextured.

A car's fittings: test_wbt_car.py's Hinge2 car with up to four random motorised hinges on its body (tilted,
upright or horizontal axes; nothing, a box, a sphere or a cylinder along or across the axis; a second hinge
on the first's end point), all above the wheels' axles: the same Ackermann drive as the bare car, the bicycle
model's circle (1e-9) whatever the fittings' motors are set to."""

from __future__ import annotations

import gc
import itertools
import math
import os
import shutil
from pathlib import Path

import numpy as np
import pytest
from _fuzz import example_counts
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image
from test_fuzz_core import SETTINGS
from test_supervisor import A, Live

from sensorium.server.daemon.services import Core
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

# ---------------------------------------------------------------- texture urls of a PROTO's field
#
# PLATE: a Solid "plate" whose Box's ImageTexture url IS its textureUrl field; BOSS a supervisor robot.

PLATE = """#VRML_SIM R2023b utf8
PROTO Plate [
  field SFVec3f  translation 0 0 0.5
  field SFString name "plate"
  field MFString textureUrl "{default}"
]
{{
  Solid {{
    translation IS translation
    children [ Shape {{ appearance Appearance {{ texture ImageTexture {{ url IS textureUrl }} }}
                       geometry Box {{ size 1 1 1 }} }} ]
    name IS name
  }}
}}
"""
PLATE_WORLD = """#VRML_SIM R2023b utf8
EXTERNPROTO "{proto}"
WorldInfo {{ basicTimeStep 16 }}
DEF P Plate {{ {field} }}
Robot {{ name "boss" supervisor TRUE controller "<extern>" }}
"""
WORLD_DIRS = ["w", "proj/worlds", "a/b/w"]
PROTO_PLACES = ["Plate.proto", "protos/Plate.proto", "p/q/Plate.proto", "../protos/Plate.proto", "../x/Plate.proto"]
URLS = ["t.png", "./t.png", "tex/t.png", "tex/../t.png", "tex/../../t.png", "../t.png", "u.png", "tex/u.png"]


def expected_file(url: str, proto: Path, world_dir: Path) -> Path | None:
    """The file Webots' WbUrl reads for a relative ``url`` of a PROTO's field (the path cleaned, then beside
    the PROTO, then in the world's folder), as Sensorium confines it: beside the PROTO within its project
    (the protos folder's parent), in the world's folder only while the path stays in it; None if neither."""
    beside = Path(os.path.normpath(proto.parent / url))
    if beside.is_file() and beside.is_relative_to(proto.parent.parent):
        return beside
    in_world = Path(os.path.normpath(world_dir / url))
    if in_world.is_file() and in_world.is_relative_to(world_dir):
        return in_world
    return None


def textures_follow_webots_lookup(root: Path, world_rel: str, proto_rel: str, files: list[tuple[bool, str]],
                                  default: str, written: str | None, ops: list[str | None]) -> None:
    shutil.rmtree(root, ignore_errors=True)
    world_dir = (root / world_rel)
    world_dir.mkdir(parents=True)
    world_dir = world_dir.resolve()
    proto = Path(os.path.normpath(world_dir / proto_rel))
    proto.parent.mkdir(parents=True, exist_ok=True)
    proto.write_text(PLATE.format(default=default))
    colours: dict[Path, tuple[int, int, int]] = {}
    for k, (beside, url) in enumerate(files):       # a colour per file: the image tells which one is shown
        path = Path(os.path.normpath((proto.parent if beside else world_dir) / url))
        if path not in colours and path.is_relative_to(root):
            colours[path] = (10 + 20 * k, 250 - 15 * k, 5 * k)
            path.parent.mkdir(parents=True, exist_ok=True)
            Image.new("RGB", (2, 2), colours[path]).save(path)
    world = world_dir / "plate.wbt"
    world.write_text(PLATE_WORLD.format(proto=proto_rel, field=f'textureUrl "{written}"' if written else ""))

    sim = Simulation(load_world(world), "exact")
    lv = Live(sim)
    n = itertools.count()
    lv.core = Core(sim, new_token=lambda: f"s{next(n)}", log=lambda line: None)
    lv.ok(A, "attach", {"robot": "boss"})
    node = lv.ok(A, "/boss/robot/get_from_def", {"name": "P"})["node"]

    def shown() -> tuple[int, int, int] | None:
        (shape,) = sim.scene.solid_shapes("plate")
        texture = sim.scene.shape_model(shape).appearance.texture
        if texture is None:
            return None
        file = Path(os.path.normpath(world_dir / texture.url))
        image = Image.open(file).convert("RGB")
        return image.getpixel((0, 0))

    def want(url: str) -> tuple[int, int, int] | None:
        file = expected_file(url, proto, world_dir)
        return None if file is None else colours[file]

    url = written or default
    assert shown() == want(url), (url, "at load")
    for op in ops:
        if op is None:      # the url set stays (README: Webots' reset resets no field)
            lv.ok(A, "/boss/robot/simulation_reset")
        else:
            lv.ok(A, "/boss/robot/set_field", {"node": node, "field": "textureUrl", "value": op, "index": 0})
            url = op
        sim.step()
        assert shown() == want(url), (url, op)


file_places = st.lists(st.tuples(st.booleans(), st.sampled_from(URLS)), max_size=8)
url_ops = st.lists(st.one_of(st.none(), st.sampled_from(URLS)), max_size=4)


@pytest.mark.parametrize("examples", example_counts(300, 10))
def test_a_proto_fields_texture_is_read_beside_the_proto_then_in_the_worlds_folder(tmp_path, examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(st.sampled_from(WORLD_DIRS), st.sampled_from(PROTO_PLACES), file_places, st.sampled_from(URLS),
           st.one_of(st.none(), st.sampled_from(URLS)), url_ops)
    def run(world_rel: str, proto_rel: str, files: list, default: str, written: str | None, ops: list) -> None:
        try:
            textures_follow_webots_lookup(tmp_path / "case", world_rel, proto_rel, files, default, written, ops)
        finally:
            gc.collect()          # each Simulation's Embree device freed

    run()


def test_regression_a_cleaned_url_names_the_file_beside_the_proto_without_its_folder(tmp_path) -> None:
    """``tex/../t.png`` written for a PROTO's field names the t.png beside the PROTO (Webots cleans the path
    before it looks), where the folder tex missing there made it look in the world's folder only."""
    textures_follow_webots_lookup(tmp_path / "case", "w", "protos/Plate.proto",
                                  [(True, "t.png"), (False, "t.png"), (False, "tex/u.png")],
                                  "u.png", "tex/../t.png", ["tex/../t.png", None])


# ---------------------------------------------------------------- a car's fittings
#
# test_wbt_car.py's Hinge2Joint car (wheelbase L, track T, tyres R, its body box up to z 0.9) with random
# fittings on its body: motorised hinges about a tilted, vertical or horizontal axis, holding nothing, a box, a
# sphere, a cylinder along or across the axis, or another such hinge (a mirror's yaw then pitch), all above
# the wheels' axles. The car is the same Ackermann drive as without them and drives the bicycle model's
# circle (closed form, 1e-9) whatever the fittings' motors are set to; each fitting turns as a joint.

FITTING_AXES = {"tilted": "0.6 0 0.8", "vertical": "0 0 1", "along": "1 0 0", "across": "0 1 0",
                "leaning": "0.2 0.1 1"}
FITTING_PARTS = {"nothing": "", "box": "Box { size 0.3 0.05 0.02 }", "sphere": "Sphere { radius 0.1 }",
                 "upright cylinder": "Cylinder { radius 0.2 height 0.03 }",
                 "cylinder on y": "Cylinder { radius 0.2 height 0.03 }", "cylinder on x": "Cylinder { radius 0.2 height 0.03 }"}
PART_TURNS = {"cylinder on y": "rotation 1 0 0 1.5707963267948966", "cylinder on x": "rotation 0 1 0 1.5707963267948966"}


def fitting_text(k: int, spec: tuple, inner: str = "") -> str:
    axis, part, x, y, z = spec
    shape = (f'Pose {{ {PART_TURNS.get(part, "")} children [ Shape {{ geometry {FITTING_PARTS[part]} }} ] }}'
             if FITTING_PARTS[part] else "")
    return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis {FITTING_AXES[axis]} anchor {x} {y} {z} }} '
            f'device [ RotationalMotor {{ name "fitting {k}" maxVelocity 10 }} ] '
            f'endPoint Solid {{ translation {x} {y} {z} children [ {shape} {inner} ] name "fitting {k}" }} }}\n')


fitting_specs = st.tuples(st.sampled_from(sorted(FITTING_AXES)), st.sampled_from(sorted(FITTING_PARTS)),
                          st.sampled_from([0.4, 1.3, 2.2, 3.0]), st.sampled_from([-0.5, 0.0, 0.4]),
                          st.sampled_from([0.8, 1.0, 1.5]))


def a_car_with_fittings_drives_as_without(folder: Path, fittings: list[tuple[tuple, tuple | None]],
                                          turns: list[float], delta: float, speed: float) -> None:
    from test_wbt_car import HINGE2_CAR, L, R, T, car, hinge2_front

    from sensorium.client.webots.vehicle.driver import ackermann_angles

    texts, k = [], 0
    for outer, inner in fittings:
        inner_text = ""
        if inner is not None:          # a second hinge on the first's end point, in its frame
            ax, part, x, y, z = inner
            inner_text = fitting_text(k + 1, (ax, part, 0.1 * x, 0.1 * y, 0.1 * z))
        texts.append(fitting_text(k, outer, inner_text))
        k += 2
    folder.mkdir(parents=True, exist_ok=True)
    bare = folder / "bare.wbt"
    bare.write_text("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n" + HINGE2_CAR)
    fitted = folder / "fitted.wbt"
    fitted.write_text("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n"
                      + car(hinge2_front("right", -T / 2) + hinge2_front("left", T / 2) + "".join(texts)))
    w = load_world(fitted)
    assert w.world.robots[0].ackermann_drive == load_world(bare).world.robots[0].ackermann_drive, w.warnings
    sim = Simulation(w)
    r = sim.robot("car")
    motors = sorted(m for m in r.motors if m.startswith("fitting"))
    assert len(motors) == sum(1 + (inner is not None) for _, inner in fittings)
    for name, turn in zip(motors, turns):
        r.motor(name).set_position(turn)
    right, left = ackermann_angles(delta, L, T)
    r.motor("right_steer").set_position(right)
    r.motor("left_steer").set_position(left)
    sim.run(10)
    start = np.asarray(r.pose.translation, dtype=np.float64)
    assert start == pytest.approx([0.0, 0.0, 0.0], abs=1e-12)
    for name in ("right_rear_wheel", "left_rear_wheel"):
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(speed)
    n = 100
    sim.run(n)
    # the bicycle model's circle about the rear axle's centre, turning right for a positive delta (the
    # car's positive_steers "right"), radius L / tan(delta)
    radius = L / math.tan(delta)
    phi = R * speed * n * 0.016 / radius
    p = r.pose.translation
    assert (p[0], p[1]) == pytest.approx((radius * math.sin(phi), -radius + radius * math.cos(phi)), abs=1e-9)
    for name, turn in zip(motors, turns):         # each fitting where its motor put it
        assert r.motors[name].position == pytest.approx(turn, abs=1e-12)


@pytest.mark.parametrize("examples", example_counts(200, 10))
def test_a_cars_fittings_leave_its_ackermann_drive_as_it_is(tmp_path, examples: int) -> None:
    cases = itertools.count()

    @settings(SETTINGS, max_examples=examples)
    @given(st.lists(st.tuples(fitting_specs, st.one_of(st.none(), fitting_specs)), max_size=4),
           st.lists(st.sampled_from([-1.2, -0.3, 0.0, 0.5, 1.4]), min_size=8, max_size=8),   # (a motor's own tolerance not asked)
           st.sampled_from([-0.3, -0.1, 0.05, 0.2, 0.4]), st.sampled_from([5.0, 20.0, 40.0]))
    def run(fittings: list, turns: list[float], delta: float, speed: float) -> None:
        try:
            a_car_with_fittings_drives_as_without(tmp_path / f"car{next(cases)}", fittings, turns, delta, speed)
        finally:
            gc.collect()

    run()


@pytest.mark.parametrize("fittings", [
    # a roller high on the body (its bottom 0.9 m above the wheels'): its line said the Hinge2 car's steering
    # joints, whose end points are free wheels, "hold no wheel", and the car had no drive
    [(("across", "cylinder on y", 0.4, -0.5, 1.0), None)],
    # a roller above the axles but within a wheel's diameter of the ground: a wheel, and no pair with the rest
    [(("along", "cylinder on x", 0.4, -0.5, 0.8), None)],
    # an upright hinge turning a round part on the roof (a beacon), alone or on a fitting: a third steering joint
    [(("leaning", "upright cylinder", 1.3, 0.4, 1.0), None)],
    [(("across", "box", 0.4, -0.5, 0.8), ("leaning", "cylinder on x", 0.4, -0.5, 0.8))],
], ids=["lifted roller", "low roller", "beacon", "beacon on a fitting"])
def test_regression_a_cars_fittings_found_by_the_property(tmp_path, fittings: list) -> None:
    a_car_with_fittings_drives_as_without(tmp_path, fittings, [0.3] * 8, -0.3, 5.0)


# ---------------------------------------------------------------- a rider inside a Pose of its carrier
#
# Round 30's two-wheel TRUCK with RIDER inside a Pose of its children (turned about z, moved): the rider's
# translation and rotation fields are in that Pose's frame, as Webots gives a nested node's fields in its
# parent's; read as written, set there (its world pose the truck's composed with the Pose's and the value set,
# 1e-9) while the truck drives, and given back as written by simulationReset.

def rider_in_pose_world(folder: Path, pose: tuple, local: tuple) -> Path:
    from test_props_round30 import WHEEL

    wheels = " ".join(WHEEL.format(y=y, side=side) for y, side in ((0.12, "left"), (-0.12, "right")))
    (px, py, pz, pyaw), (lx, ly, lz, lyaw) = pose, local
    path = folder / "pose_rider.wbt"
    path.write_text(f"""#VRML_SIM R2023b utf8
WorldInfo {{ basicTimeStep 16 }}
Robot {{ name "boss" controller "<extern>" supervisor TRUE }}
DEF TRUCK Robot {{ translation 0 0 0.05 name "truck" controller "<extern>" children [
  {wheels}
  Pose {{ translation {px!r} {py!r} {pz!r} rotation 0 0 1 {pyaw!r} children [
    DEF RIDER Robot {{ translation {lx!r} {ly!r} {lz!r} rotation 0 0 1 {lyaw!r} name "rider" controller "<extern>"
      children [ DistanceSensor {{ name "rs" }} ] }} ] }} ]
  boundingObject Box {{ size 0.3 0.2 0.06 }} physics Physics {{ }} }}
""")
    return path


def frame_of(x: float, y: float, z: float, yaw: float) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = [[math.cos(yaw), -math.sin(yaw), 0.0], [math.sin(yaw), math.cos(yaw), 0.0], [0.0, 0.0, 1.0]]
    m[:3, 3] = (x, y, z)
    return m


def a_rider_in_a_pose_reads_and_sets_its_fields_there(folder: Path, pose: tuple, local: tuple, put: tuple,
                                                      speeds: tuple[float, float]) -> None:
    sim = Simulation(load_world(rider_in_pose_world(folder, pose, local)), "exact")
    lv = Live(sim)
    lv.ok(A, "attach", {"robot": "boss"})
    node = lv.ok(A, "/boss/robot/get_from_def", {"name": "RIDER"})["node"]

    def field(name: str) -> list[float]:
        return lv.ok(A, "/boss/robot/get_field", {"node": node, "field": name})["value"]

    def where(value: tuple) -> np.ndarray:
        truck = sim.robot("truck").pose
        t = np.eye(4)
        t[:3, :3], t[:3, 3] = np.asarray(truck.rotation), np.asarray(truck.translation)
        return t @ frame_of(*pose) @ frame_of(*value)

    def check(value: tuple) -> None:
        want, got = where(value), sim.robot("rider").pose
        assert np.asarray(got.translation) == pytest.approx(want[:3, 3], abs=1e-9)
        assert np.asarray(got.rotation) == pytest.approx(want[:3, :3], abs=1e-9)
        assert field("translation") == pytest.approx(list(value[:3]), abs=1e-9)
        axis_angle = field("rotation")
        assert frame_of(0, 0, 0, axis_angle[3] * axis_angle[2])[:3, :3] == pytest.approx(frame_of(*value)[:3, :3], abs=1e-9)

    truck = sim.robot("truck")
    for side, speed in zip(("left", "right"), speeds):
        truck.motor(side).set_position(math.inf)
        truck.motor(side).set_velocity(speed)
    sim.run(5)
    check(local)
    lv.ok(A, "/boss/robot/set_field", {"node": node, "field": "translation", "value": list(put[:3])})
    lv.ok(A, "/boss/robot/set_field", {"node": node, "field": "rotation", "value": [0.0, 0.0, 1.0, put[3]]})
    sim.run(5)
    check(put)
    lv.ok(A, "/boss/robot/simulation_reset")
    sim.run(1)
    check(local)


small = st.sampled_from([-0.2, 0.0, 0.05, 0.3])
turn = st.sampled_from([-2.0, 0.0, 0.4, 1.5707963267948966, 3.0])
frames4 = st.tuples(small, small, st.sampled_from([0.1, 0.25]), turn)


@pytest.mark.parametrize("examples", example_counts(100, 10))
def test_a_rider_inside_a_pose_of_its_carrier_has_its_fields_in_that_pose(tmp_path, examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(frames4, frames4, frames4, st.tuples(st.sampled_from([0.0, 2.0, 5.0]), st.sampled_from([-1.0, 3.0])))
    def run(pose: tuple, local: tuple, put: tuple, speeds: tuple) -> None:
        try:
            a_rider_in_a_pose_reads_and_sets_its_fields_there(tmp_path, pose, local, put, speeds)
        finally:
            gc.collect()

    run()


def test_regression_a_rider_inside_a_pose_reads_and_sets_its_fields_in_the_poses_frame(tmp_path) -> None:
    """Its fields read its frame in the carrier's (the Pose composed with them) and a set was taken there."""
    a_rider_in_a_pose_reads_and_sets_its_fields_there(tmp_path, (0.1, 0.0, 0.2, 0.5), (0.1, 0.05, 0.1, 0.3),
                                                      (0.0, -0.1, 0.3, -0.4), (2.0, 5.0))
