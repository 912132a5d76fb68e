"""A solid a VacuumGripper lets go comes to rest on a face; a carried load is never held into the floor.

The crane: a robot without a drive whose gripper (a bounding cylinder, radius 0.05 m, 0.02 m tall)
rides a lift (a LinearMotor along +z) with its pump on at load, its cup inside the solid it holds
(vacuum.caught_at_load: held from the first step, not settled), over a floor plane at z = 0. Turned
off, the solid lands at once (ground.land_solid): a single Box or Cylinder tipped first onto the face
under it by the least turn about a horizontal axis through its centre (its yaw kept), then put on the
floor, its lowest point at 0. One span function (ground.falling_span) judges every falling solid:
one with a Plane or ElevationGrid among its bounding shapes does not fall (ground, as in Webots'
physics) and stays where it is let go; settling at load tips a solid the same way."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.server.sim.ground import falling_span, resting_pose
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.geometry import Pose
from sensorium.server.world.loader import parse_world
from sensorium.server.world.poses import axis_angle, axis_angle_matrix

STEP = 16
FLOOR = {"name": "floor", "geometry": {"type": "plane"}}
HIGH = 1.5               # the held solid's centre height


def _rot(axis, angle: float) -> np.ndarray:
    return axis_angle_matrix(axis, angle)


def _crane(cup_z: float = HIGH) -> dict:
    return {"name": "crane",
            "shapes": [{"pose": {"translation": [0.0, 0.0, cup_z]}, "geometry": {"type": "cylinder", "radius": 0.05, "height": 0.02},
                        "of_device": "cup", "seen_by": "bounding", "on_joint": "lift"}],
            "devices": [{"device": "LinearMotor", "name": "lift", "axis": [0, 0, 1], "max_velocity": 0.5, "max_force": 100.0,
                         "min_position": -1.0, "max_position": 1.0},
                        {"device": "VacuumGripper", "name": "cup", "is_on": True, "pose": {"translation": [0.0, 0.0, cup_z]},
                         "on_joint": "lift"}]}


def _solid(geometry: dict, rotation=(0.0, 0.0, 1.0, 0.0), extra: list[dict] | None = None, at=(0.0, 0.0, HIGH)) -> dict:
    solid = {"name": "load", "pose": {"translation": list(at), "rotation": list(rotation)}, "geometry": geometry, "physics": True}
    if extra:
        solid["shapes"] = extra
    return solid


def _sim(load: dict, crane: dict | None = None) -> Simulation:
    world = {"world_info": {"basic_time_step": STEP}, "solids": [FLOOR, load], "robots": [crane or _crane()]}
    return Simulation(parse_world(world), precision="exact")


def _released(sim: Simulation) -> Pose:
    g = sim.device("crane/cup")
    sim.step()
    assert g.held == "load"                                   # type: ignore[attr-defined]
    g.set_on(False)                                           # type: ignore[attr-defined]
    sim.step()
    for _ in range(200):                                      # it falls (sim/falling.py) until it rests
        if "load" not in sim.falls.falling:
            break
        sim.step()
    assert "load" not in sim.falls.falling
    return sim.scene.solid_poses["load"]


def _yaw_only(r: np.ndarray) -> float:
    """The yaw of a rotation that must be about z alone (asserted to 1e-12)."""
    assert np.allclose(r[2], [0.0, 0.0, 1.0], rtol=0, atol=1e-12) and np.allclose(r[:, 2], [0.0, 0.0, 1.0], rtol=0, atol=1e-12)
    return math.atan2(r[1, 0], r[0, 0])


BOX = {"type": "box", "size": [1.0, 1.0, 1.0]}


# ---------------------------------------------------------------------- tipping onto a face

def test_a_unit_box_turned_30_degrees_about_x_lands_flat() -> None:
    pose = _released(_sim(_solid(BOX, (1.0, 0.0, 0.0, math.radians(30.0)))))
    assert _yaw_only(pose.rotation) == pytest.approx(0.0, abs=1e-12)
    assert pose.translation[2] == pytest.approx(0.5, abs=1e-12)          # half its size: on a face
    assert pose.translation[:2].tolist() == pytest.approx([0.0, 0.0], abs=1e-15)


def test_a_tilted_box_keeps_its_yaw_about_the_up() -> None:
    """Rz(0.7)·Rx(30°): the least turn putting its -z face down leaves Rz(0.7)."""
    r = _rot((0, 0, 1), 0.7) @ _rot((1, 0, 0), math.radians(30.0))
    pose = _released(_sim(_solid(BOX, tuple(axis_angle(r)))))
    assert _yaw_only(pose.rotation) == pytest.approx(0.7, abs=1e-12)
    assert pose.translation[2] == pytest.approx(0.5, abs=1e-12)


def test_a_long_box_turned_60_degrees_about_y_lands_on_its_end() -> None:
    """0.4 x 0.2 x 0.1 m turned 60° about y: its +x axis (0.5, 0, -0.87) is the nearest straight down,
    so it stands on its +x face (0.2 x 0.1), its centre 0.2 up, rotation Ry(90°)."""
    pose = _released(_sim(_solid({"type": "box", "size": [0.4, 0.2, 0.1]}, (0.0, 1.0, 0.0, math.radians(60.0)))))
    assert np.allclose(pose.rotation, _rot((0, 1, 0), math.pi / 2), rtol=0, atol=1e-12)
    assert pose.translation[2] == pytest.approx(0.2, abs=1e-12)


@pytest.mark.parametrize(("tilt", "rotation", "height"), [
    (30.0, np.eye(3), 0.2),                                    # axis within 45° of up: on its end, half its height
    (60.0, axis_angle_matrix((1, 0, 0), math.pi / 2), 0.1),    # beyond: on its side, its radius
    (150.0, axis_angle_matrix((1, 0, 0), math.pi), 0.2),       # upside down, on its other end
])
def test_a_tilted_cylinder_lands_on_its_end_or_its_side(tilt: float, rotation: np.ndarray, height: float) -> None:
    pose = _released(_sim(_solid({"type": "cylinder", "radius": 0.1, "height": 0.4}, (1.0, 0.0, 0.0, math.radians(tilt)))))
    assert np.allclose(pose.rotation, rotation, rtol=0, atol=1e-12)
    assert pose.translation[2] == pytest.approx(height, abs=1e-12)


def test_a_sphere_keeps_its_rotation() -> None:
    pose = _released(_sim(_solid({"type": "sphere", "radius": 0.2}, (1.0, 0.0, 0.0, 0.5))))
    assert np.allclose(pose.rotation, _rot((1, 0, 0), 0.5), rtol=0, atol=1e-15)
    assert pose.translation[2] == pytest.approx(0.2, abs=1e-12)


def test_a_nue_world_tips_about_its_horizontal_axes() -> None:
    """In a NUE world the up is the world's y: a box turned 30° about x lies flat on its -y face."""
    nue = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])     # world (N, U, E) -> ENU
    solid = parse_world({"solids": [_solid(BOX, (1.0, 0.0, 0.0, math.radians(30.0)))]}).world.solids[0]
    start = Pose(_rot((1, 0, 0), math.radians(30.0)), np.array([0.0, HIGH, 0.0]))
    pose = resting_pose(solid, start, Path("."), nue)
    assert np.allclose(pose.rotation[:, 1], [0.0, 1.0, 0.0], rtol=0, atol=1e-12)    # a local axis along up
    assert np.allclose(pose.rotation, np.eye(3), rtol=0, atol=1e-12)       # its local y (0, cos 30°, sin 30°) nearest
    assert np.allclose(pose.translation, start.translation, rtol=0, atol=1e-15)     # turned about its centre


def test_a_box_settling_at_load_tips_onto_a_face() -> None:
    """Webots' physics lets a box loaded on a corner fall onto a face: so does settling at load."""
    world = {"solids": [FLOOR, _solid(BOX, (1.0, 0.0, 0.0, math.radians(30.0)), at=(0.3, 0.2, 2.0))]}
    sim = Simulation(parse_world(world, source="w.yaml"), precision="exact")
    pose = sim.scene.solid_poses["load"]
    assert _yaw_only(pose.rotation) == pytest.approx(0.0, abs=1e-12)
    assert pose.translation.tolist() == pytest.approx([0.3, 0.2, 0.5], abs=1e-12)
    assert [n for n in sim.loaded.warnings if "settled" in n] == [
        "w.yaml: solid 'load' settled on the ground at load, as Webots' physics drops it: tipped onto a face, "
        "its origin's z from 2.0000 to 0.5000 m"]


# ---------------------------------------------------------------------- one span for every falling solid

@pytest.mark.parametrize("geometry", [BOX, {"type": "cylinder", "radius": 0.1, "height": 0.4}])
def test_a_released_box_or_cylinder_rests_with_its_falling_span_on_the_floor(geometry: dict) -> None:
    sim = _sim(_solid(geometry))
    pose = _released(sim)
    span = falling_span(sim.world.solids[1], sim.loaded.base_dir, None, pose)
    assert span is not None and span[0] == pytest.approx(0.0, abs=1e-12)
    assert pose.translation[2] == pytest.approx(span[1] / 2.0, abs=1e-12)   # upright: its centre halfway up


@pytest.mark.parametrize("ground", [
    {"type": "plane", "size": [0.5, 0.5]},
    {"type": "elevation_grid", "height": [0.0, 0.0, 0.0, 0.0], "x_dimension": 2, "x_spacing": 0.5,
     "y_dimension": 2, "y_spacing": 0.5},
])
def test_a_solid_holding_a_plane_or_terrain_does_not_fall(ground: dict) -> None:
    """A Plane or ElevationGrid among a solid's bounding shapes is ground, static in Webots' physics:
    the solid neither settles at load nor lands when let go (falling_span is None for it)."""
    extra = [{"pose": {"translation": [0.0, 0.0, -0.5]}, "geometry": ground}]
    sim = _sim(_solid({"type": "box", "size": [0.2, 0.2, 0.2]}, extra=extra))
    assert falling_span(sim.world.solids[1], sim.loaded.base_dir, None) is None
    pose = _released(sim)
    assert pose.translation.tolist() == [0.0, 0.0, HIGH] and np.array_equal(pose.rotation, np.eye(3))


# ---------------------------------------------------------------------- a carried load and the floor

def test_a_load_lowered_into_the_floor_lies_on_it_and_rises_again_with_the_cup() -> None:
    """A 0.1 m cube held with its centre at 0.3: the lift lowered by 0.3 m would put half of it under
    the floor; the kinematic arm goes on, the cube lies on the floor (its centre at 0.05) and, lifted
    again, it is where the cup holds it (the offset kept)."""
    sim = _sim(_solid({"type": "box", "size": [0.1, 0.1, 0.1]}, at=(0.0, 0.0, 0.3)), _crane(0.3))
    g, lift = sim.device("crane/cup"), sim.robot("crane").motors["lift"]
    sim.step()
    assert g.held == "load"                                   # type: ignore[attr-defined]
    lift.set_position(-0.3)
    for _ in range(100):
        sim.step()
        assert sim.scene.solid_poses["load"].translation[2] >= 0.05 - 1e-12
    assert float(lift.position) == pytest.approx(-0.3, abs=1e-12)
    assert sim.scene.solid_poses["load"].translation.tolist() == pytest.approx([0.0, 0.0, 0.05], abs=1e-12)
    lift.set_position(0.0)
    for _ in range(100):
        sim.step()
    assert sim.scene.solid_poses["load"].translation.tolist() == pytest.approx([0.0, 0.0, 0.3], abs=1e-12)
    assert g.held == "load"                                   # type: ignore[attr-defined]
