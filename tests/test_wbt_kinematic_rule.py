"""A .wbt robot without Physics moves by Webots' own kinematic rule (``WbKinematicDifferentialWheels``), the
drive's ``step_rule: mid_heading``: its axle the sum of its wheels' cylinders' 3-D distances from its origin,
each basic step a straight segment along the mid-step heading. One with Physics keeps the exact arc; one
whose wheels make no pair Webots accepts keeps it too. Our own worlds (an e-puck-like robot); closed forms:
one step, and a circle of N steps, the vertices of a regular N-gon."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from _wheeled_wbt import H0, STEP, X0, Y0, R, T, Y, heading, robot_world, wheel

from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.sim.summary import drive_line
from sensorium.server.world.loader import WorldError, load_world, parse_world

AXLE = 2.0 * math.hypot(Y, R)             # Webots' axle: the wheels' cylinders (at height R) from the origin


def write(tmp_path: Path, physics: bool = False, right_y: float = -Y) -> Path:
    return robot_world(tmp_path / "kinematic.wbt",
                       wheel("left wheel motor", 0.0, Y) + wheel("right wheel motor", 0.0, right_y), physics)


def run(sim: Simulation, wl: float, wr: float, steps: int) -> None:
    r = sim.robot("bot")
    for name, w in (("left wheel motor", wl), ("right wheel motor", wr)):
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(w)
    sim.run(steps)


def test_without_physics_the_drive_takes_webots_axle_and_mid_heading_rule(tmp_path: Path) -> None:
    w = load_world(write(tmp_path))
    dd = w.world.robots[0].differential_drive
    assert dd is not None and dd.step_rule == "mid_heading"
    assert dd.axle_length == pytest.approx(AXLE, abs=1e-15)       # 0.0656, not the 0.052 between the wheels
    assert (dd.wheel_radius, dd.left_motor, dd.right_motor) == (R, "left wheel motor", "right wheel motor")
    assert dd.axle_center == (0.0, 0.0)
    assert f"axle {AXLE:g} m, each step straight along the mid-step heading" in drive_line(w.world.robots[0])

    # one step: (v cos(h + d), v sin(h + d)) with d = (wr - wl) t r / (2 axle), v = (wl + wr) r t / 2; heading h + 2d
    wl, wr = 1.0, 3.0
    sim = Simulation(w)
    for name in ("left wheel motor sensor", "right wheel motor sensor"):
        sim.robot("bot").device(name).enable(STEP)
    run(sim, wl, wr, 1)
    d = (wr - wl) * T * R / (2.0 * AXLE)
    v = 0.5 * (wl + wr) * R * T
    pose = sim.robot("bot").pose
    assert pose.translation[:2] == pytest.approx([X0 + v * math.cos(H0 + d), Y0 + v * math.sin(H0 + d)], abs=1e-16)
    assert heading(pose.rotation) == pytest.approx(H0 + 2.0 * d, abs=1e-15)
    # the wheels' encoders read what the wheels turned, as under the arc
    run(sim, wl, wr, 9)
    assert sim.robot("bot").device("left wheel motor sensor").value == pytest.approx(wl * 10 * T, abs=1e-12)
    assert sim.robot("bot").device("right wheel motor sensor").value == pytest.approx(wr * 10 * T, abs=1e-12)


def test_a_circle_of_n_steps_is_a_regular_polygon(tmp_path: Path) -> None:
    """Each step a chord s = v·t turning 2d: the robot's places are the vertices of the regular N-gon
    inscribed in the circle of radius s / (2 sin d) about (x0, y0) + R·(−sin h, cos h); the exact arc's
    radius s / (2d) would be 7.6 µm less here. After N steps (2dN = 2π) it is back where it started."""
    n = 96
    d = math.pi / n
    wl = 1.0
    wr = wl + 2.0 * AXLE * d / (T * R)
    s = 0.5 * (wl + wr) * R * T
    radius = s / (2.0 * math.sin(d))
    assert radius - s / (2.0 * d) > 7e-6                      # the arc's circle is another one
    centre = np.array([X0 - radius * math.sin(H0), Y0 + radius * math.cos(H0)])
    sim = Simulation(load_world(write(tmp_path)))
    run(sim, wl, wr, 0)
    for k in range(1, n + 1):
        sim.run(1)
        pose = sim.robot("bot").pose
        assert math.dist(pose.translation[:2], centre) == pytest.approx(radius, abs=1e-13), k
        assert math.remainder(heading(pose.rotation) - (H0 + 2.0 * d * k), 2.0 * math.pi) == pytest.approx(0.0, abs=1e-12)
    assert pose.translation[:2] == pytest.approx([X0, Y0], abs=1e-13)


def test_with_physics_or_without_a_webots_pair_the_exact_arc(tmp_path: Path) -> None:
    """A robot with Physics keeps the arc and the wheels' separation; so does one without Physics whose
    wheels are not equally far from its origin (Webots finds no pair and would not move it at all)."""
    for folder, physics, right_y, axle in (("physics", True, -Y, 2.0 * Y), ("unequal", False, -0.027, Y + 0.027)):
        (tmp_path / folder).mkdir()
        w = load_world(write(tmp_path / folder, physics, right_y))
        dd = w.world.robots[0].differential_drive
        assert dd is not None and dd.step_rule == "arc"
        assert dd.axle_length == pytest.approx(axle, abs=1e-15)
        sim = Simulation(w)
        run(sim, 1.0, 3.0, 1)
        om = R * 2.0 / axle
        v = 2.0 * R
        pose = sim.robot("bot").pose
        cy = dd.axle_center[1]       # (the second robot's wheels' centre is 0.5 mm right of its origin)
        if cy == 0.0:
            x = X0 + v / om * (math.sin(H0 + om * T) - math.sin(H0))
            y = Y0 - v / om * (math.cos(H0 + om * T) - math.cos(H0))
            assert pose.translation[:2] == pytest.approx([x, y], abs=1e-15)
        assert heading(pose.rotation) == pytest.approx(H0 + om * T, abs=1e-15)


def test_batched_copies_step_the_rule_as_the_simulation(tmp_path: Path) -> None:
    from sensorium.gym.views import CopySim

    w = load_world(write(tmp_path))
    b = BatchedSimulation(w, 2)
    b.reset(np.arange(2), [1, 2])
    views = [CopySim(b, c) for c in range(2)]
    single = Simulation(w)
    for speeds in ((1.0, 3.0), (-2.0, 5.0), (4.0, 4.0)):
        for s in (single, *views):
            for name, om in zip(("left wheel motor", "right wheel motor"), speeds):
                s.robot("bot").motor(name).set_position(math.inf)
                s.robot("bot").motor(name).set_velocity(om)
        for _ in range(20):
            single.step()
            b.step()
            p = single.robot("bot").pose
            for c in range(2):
                assert b.pos[c, 0].tobytes() == p.translation.tobytes()
                assert b.rot[c, 0].tobytes() == p.rotation.tobytes()
    assert math.dist(p.translation[:2], (X0, Y0)) > 0.05


def test_mid_heading_turns_about_the_origin_only() -> None:
    with pytest.raises(WorldError, match=r"axle_center must be \(0, 0\)"):
        parse_world({"robots": [{"name": "r", "differential_drive": {"step_rule": "mid_heading",
                                                                     "axle_center": [0.01, 0.0]}}]})
