"""The built-in stand-ins for Webots' CircleArena and SolidPipe (no Webots installation): what each
kind of ray sees, against closed forms from the PROTOs' published geometry. The pipe's rendered
ring (an IndexedFaceSet of n quads per side, its inner circle of radius r - su with
su = r·cos(π/n) - (r - thickness), vertices from -π/2) is what lidars see; PipeBoundingObject's n
boxes (inner faces at r - thickness, normals at (i + ½)·2π/n) are what generic and sonar distance
sensors and kinematic contact see; the arena's floor is a polygon for visual rays and a Plane for the
others. Our own worlds; before the stand-ins, such a world lost the arena (or was refused)."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, load_world
from sensorium.server.world.poses import pose_from_model

RAW = "https://raw.githubusercontent.com/cyberbotics/webots/R2023b/projects/objects"
ARENA = f'EXTERNPROTO "{RAW}/floors/protos/CircleArena.proto"\n'
PIPE = f'EXTERNPROTO "{RAW}/solids/protos/SolidPipe.proto"\n'
HEADER = "#VRML_SIM R2023b utf8\n"


def _world(tmp_path: Path, body: str, declared: str = ARENA, name: str = "w.wbt") -> Path:
    p = tmp_path / name
    p.write_text(HEADER + declared + "WorldInfo { basicTimeStep 16 }\n" + body)
    return p


def _load(path: Path, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_world(path, **kw)


def _ray_polygon(o: np.ndarray, u: np.ndarray, vertices: np.ndarray) -> float:
    """The distance along the unit ray o + t·u (2-D) to the nearest edge of the closed polyline
    ``vertices`` (k, 2) (the last vertex joined to none: the rings repeat their first one last)."""
    best = math.inf
    for a, b in zip(vertices[:-1], vertices[1:]):
        e = b - a
        den = u[0] * e[1] - u[1] * e[0]
        if den == 0.0:
            continue
        w = a - o
        t = (w[0] * e[1] - w[1] * e[0]) / den
        s = (w[0] * u[1] - w[1] * u[0]) / den
        if t > 0.0 and -1e-12 <= s <= 1.0 + 1e-12:
            best = min(best, t)
    return best


def _ray_boxes(o: np.ndarray, u: np.ndarray, boxes: list[tuple[np.ndarray, float, float, float]]) -> float:
    """The distance along the unit ray o + t·u (2-D) to the nearest of the rectangles (centre, turn,
    half size along their x, half size along their y), by slabs in each one's frame."""
    best = math.inf
    for c, turn, hx, hy in boxes:
        ax, ay = np.array([math.cos(turn), math.sin(turn)]), np.array([-math.sin(turn), math.cos(turn)])
        lo, hi = -math.inf, math.inf
        for axis, h in ((ax, hx), (ay, hy)):
            p, d = float(axis @ (o - c)), float(axis @ u)
            if d == 0.0:
                if abs(p) > h:
                    lo, hi = math.inf, -math.inf
                continue
            t1, t2 = sorted(((-h - p) / d, (h - p) / d))
            lo, hi = max(lo, t1), min(hi, t2)
        if lo <= hi and lo > 0.0:
            best = min(best, lo)
    return best


def _ring(radius: float, n: int, shift: float, centre=(0.0, 0.0), turn: float = 0.0) -> np.ndarray:
    k = np.arange(n + 1)
    a = shift + k * 2.0 * math.pi / n + turn
    return np.stack([centre[0] + radius * np.cos(a), centre[1] + radius * np.sin(a)], axis=1)


def _pipe_geometry(radius: float, thickness: float, n: int, centre=(0.0, 0.0), turn: float = 0.0):
    """(inner ring, outer ring, boxes) of a SolidPipe in the plane, from the published formulas."""
    alpha = math.pi / n
    inner = radius - thickness
    gap = abs(radius * math.cos(alpha) - inner)
    c = np.array(centre)
    boxes = []
    for i in range(n):
        gamma = (2 * i + 1) * alpha + (n % 2) * math.pi / n + turn
        mid = inner + gap / 2
        boxes.append((c + mid * np.array([math.cos(gamma), math.sin(gamma)]), gamma + math.pi / 2,
                      radius * math.sin(alpha), gap / 2))
    return (_ring(radius - gap, n, -math.pi / 2, centre, turn), _ring(radius, n, -math.pi / 2, centre, turn), boxes)


def _sensors(angles: list[float], kind: str, z: float) -> str:
    return "".join(f'DistanceSensor {{ translation 0 0 {z} rotation 0 0 1 {a!r} name "{kind}{i}" type "{kind}" '
                   f'lookupTable [ 0 0 0, 4 4000 0 ] }}\n' for i, a in enumerate(angles))


ANGLES = [0.0, math.pi / 48, 0.3, 1.234, 2.0, math.pi - 0.01, -2.5, -1.0]


def test_what_lidars_and_bounding_rays_see_from_the_arenas_centre(tmp_path: Path) -> None:
    """A robot at the centre of a default CircleArena (radius 1, wall 0.01 thick and 0.1 high, 48
    segments): each of a 360-beam lidar's beams reads the distance to the wall's rendered inner
    polygon (vertices at 1.01 - su, su = 1.01·cos(π/48) - 1), and generic and sonar distance
    sensors the distance to the nearest bounding box's inner face (1 / cos of the angle to its
    normal): the two differ by about 1.7e-5 m, each matched to 1e-9 (the lidar's float32 to 2e-7)."""
    body = ("CircleArena { }\nRobot { name \"bot\" controller \"<extern>\" children [\n"
            "  Lidar { translation 0 0 0.05 name \"lidar\" horizontalResolution 360 fieldOfView 6.283185307179586 "
            "numberOfLayers 1 maxRange 5 }\n" + _sensors(ANGLES, "generic", 0.05) + _sensors(ANGLES, "sonar", 0.05)
            + "] }\n")
    loaded = _load(_world(tmp_path, body))
    assert [s.name for s in loaded.world.solids] == ["circle arena"]
    sim = Simulation(loaded, precision="exact")
    lidar = sim.device("bot/lidar")
    lidar.enable(16)
    for kind in ("generic", "sonar"):
        for i in range(len(ANGLES)):
            sim.device(f"bot/{kind}{i}").enable(16)
    sim.step()
    inner_ring, _, boxes = _pipe_geometry(1.01, 0.01, 48)
    o = np.zeros(2)
    theta = math.pi - (np.arange(360) + 0.5) * 2 * math.pi / 360     # the fixed lidar's column azimuths
    want = np.array([_ray_polygon(o, np.array([math.cos(t), math.sin(t)]), inner_ring) for t in theta])
    got = np.asarray(lidar.range_image, dtype=np.float64)[0]
    assert np.abs(got - want).max() < 2e-7
    # the ring's inner polygon, not the boxes: about 1.7e-5 m further out
    boxes_along = np.array([_ray_boxes(o, np.array([math.cos(t), math.sin(t)]), boxes) for t in theta])
    assert (want - boxes_along).min() > 1.5e-5
    for i, a in enumerate(ANGLES):
        u = np.array([math.cos(a), math.sin(a)])
        d = _ray_boxes(o, u, boxes)
        assert 1.0 <= d < 1.0 / math.cos(math.pi / 48) + 1e-12
        nearest = min(abs(math.remainder(a - (2 * k + 1) * math.pi / 48, 2 * math.pi)) for k in range(48))
        assert d == pytest.approx(1.0 / math.cos(nearest), abs=1e-12)    # the inner face's closed form
        for kind in ("generic", "sonar"):
            assert sim.device(f"bot/{kind}{i}").value == pytest.approx(1000.0 * d, abs=1e-6), (kind, a)


def _driver(tmp_path: Path, heading: float, arena: str) -> Simulation:
    """A two-wheel robot at the centre of ``arena``, its 0.1 x 0.04 box body ahead and behind 0.05 of
    its origin (narrow enough that its front corners stay off the next boxes), turned to ``heading``."""
    def wheel(side: str, y: float) -> str:
        return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 {y} 0.02 }}\n'
                f'  device [ RotationalMotor {{ name "{side} wheel motor" maxVelocity 20 }} ]\n'
                f'  endPoint Solid {{ translation 0 {y} 0.02 rotation 1 0 0 1.5707963267948966 name "{side} wheel"\n'
                f'    children [ Shape {{ geometry Cylinder {{ radius 0.02 height 0.01 }} }} ]\n'
                f'    boundingObject Cylinder {{ radius 0.02 height 0.01 }} physics Physics {{ }} }} }}\n')

    body = (f'{arena}\nRobot {{ rotation 0 0 1 {heading!r} name "bot" controller "<extern>"\n'
            f'  children [\n{wheel("left", 0.025)}{wheel("right", -0.025)} ]\n'
            '  boundingObject Pose { translation 0 0 0.03 children [ Box { size 0.1 0.04 0.04 } ] }\n'
            '  physics Physics { } }\n')
    return Simulation(_load(_world(tmp_path, body, name=f"drive{abs(hash((heading, arena)))}.wbt")), precision="exact")


def _drive_out(sim: Simulation, steps: int) -> np.ndarray:
    d = sim.robot("bot").drive
    for motors in (d.lefts, d.rights):
        for m in motors:
            m.set_position(math.inf)
            m.set_velocity(15.0)
    for _ in range(steps):
        sim.step()
    return np.asarray(sim.robot("bot").pose.translation, dtype=np.float64)


def test_kinematic_contact_stops_a_robot_at_the_walls_boxes(tmp_path: Path) -> None:
    """Driving out along a box's normal (π/48), the robot's front face stops on that box's inner
    face: its origin 1 - 0.05 from the centre (not at the rendered ring, 1.7e-5 further), and it
    stays there; a wall of radius 0.6 stops it at 0.55."""
    for arena, stop in (("CircleArena { }", 0.95), ("CircleArena { radius 0.6 wallHeight 0.2 }", 0.55)):
        heading = math.pi / 48
        sim = _driver(tmp_path, heading, arena)
        at = _drive_out(sim, 400)            # 0.3 m/s for 6.4 s: it would be far outside without the wall
        assert at[:2] == pytest.approx(stop * np.array([math.cos(heading), math.sin(heading)]), abs=1e-9)
        again = _drive_out(sim, 20)
        assert np.array_equal(again, at)


def test_the_floor_is_a_polygon_to_visual_rays_and_a_plane_to_the_others(tmp_path: Path) -> None:
    """Looking straight down from 0.05 m up: inside the arena a lidar and a generic sensor both read
    the floor; outside the wall (1.2 m out at 45°) but inside the bounding Plane's 2 x 2 m square, the
    lidar sees nothing (the floor polygon ends at 1.005 m, under the wall) while the generic sensor
    still reads the Plane."""
    down = "rotation 0 1 0 1.5707963267948966"
    body = ('CircleArena { }\nRobot { translation %r %r 0 name "bot" controller "<extern>" children [\n'
            f'  Lidar {{ translation 0 0 0.05 {down} name "lidar" horizontalResolution 1 fieldOfView 0.01 '
            'numberOfLayers 1 maxRange 5 }\n'
            f'  DistanceSensor {{ translation 0 0 0.05 {down} name "generic" type "generic" '
            'lookupTable [ 0 0 0, 4 4000 0 ] } ] }\n')
    out = 1.2 * math.cos(math.pi / 4)
    for (x, y), floor in (((0.5, 0.2), True), ((out, out), False)):
        sim = Simulation(_load(_world(tmp_path, body % (x, y), name=f"{floor}.wbt")), precision="exact")
        lidar, generic = sim.device("bot/lidar"), sim.device("bot/generic")
        lidar.enable(16)
        generic.enable(16)
        sim.step()
        seen = float(np.asarray(lidar.range_image)[0, 0])
        assert seen == pytest.approx(0.05, abs=1e-7) if floor else math.isinf(seen)
        assert generic.value == pytest.approx(50.0, abs=1e-9)           # the Plane 0.05 below


def _pipe_solid(world: wm.World, name: str = "pipe") -> wm.Solid:
    for s in world.solids:
        if s.name == name:
            return s
        for c in s.children:
            if c.name == name:
                return c
    raise AssertionError(name)


def test_defaults_names_models_and_the_boxes_as_published(tmp_path: Path) -> None:
    """A default CircleArena: the Solid "circle arena" (model "circle arena") holding the Solid
    "pipe" (model "pipe") 0.05 up; the floor polygon's 49 vertices at 1.005 from angle 0 and its
    Plane 2 x 2; the ring's 4 x 49 vertices; 48 boxes 2·1.01·sin(π/48) x (1.01·cos(π/48) - 1) x
    0.1 at 1 + that/2 from the centre, turned (i + ½)·π/24 + π/2, their z jitter wbrandom's: the
    first box's z is (-1 + 2·12820163/(2^24 - 1))·1e-4 (the generator's first number from seed 0),
    each within ±1e-4. The Supervisor lists it as a Solid of PROTO CircleArena."""
    w = _load(_world(tmp_path, "DEF ARENA CircleArena { }\n")).world
    (arena,) = w.solids
    assert (arena.name, arena.model) == ("circle arena", "circle arena")
    (pipe,) = arena.children
    assert pipe.name == "pipe"      # (a nested solid's model is not kept: recognition reports top-level ones)
    assert tuple(pipe.pose.translation) == (0.0, 0.0, 0.05)
    floor, plane = arena.shapes
    assert (floor.seen_by, plane.seen_by) == ("visual", "bounding")
    assert plane.geometry == wm.Plane(type="plane", size=(2.0, 2.0))
    v = np.asarray(floor.geometry.vertices)
    assert v.shape == (49, 3) and np.allclose(np.hypot(v[:, 0], v[:, 1]), 1.005, atol=1e-15)
    assert np.allclose(np.arctan2(v[:48, 1], v[:48, 0]) % (2 * math.pi), np.arange(48) * math.pi / 24, atol=1e-12)
    ring, *boxes = pipe.shapes
    assert ring.seen_by == "visual" and np.asarray(ring.geometry.vertices).shape == (196, 3)
    assert len(boxes) == 48 and all(b.seen_by == "bounding" for b in boxes)
    gap = 1.01 * math.cos(math.pi / 48) - 1.0
    for i, b in enumerate(boxes):
        assert b.geometry.size == pytest.approx((2 * 1.01 * math.sin(math.pi / 48), gap, 0.1), abs=1e-15)
        gamma = (2 * i + 1) * math.pi / 48
        t = np.asarray(b.pose.translation)
        assert t[:2] == pytest.approx((1.0 + gap / 2) * np.array([math.cos(gamma), math.sin(gamma)]), abs=1e-15)
        assert abs(t[2]) <= 1e-4
        # turned about z by gamma + π/2: its x along the tangent, its z up
        m = pose_from_model(b.pose).rotation
        assert m[:, 0] == pytest.approx([-math.sin(gamma), math.cos(gamma), 0.0], abs=1e-14)
        assert m[:, 2] == pytest.approx([0.0, 0.0, 1.0], abs=1e-14)
    assert boxes[0].pose.translation[2] == (-1.0 + 12820163.0 * 2.0 / 16777215.0) * 0.0001
    top = [n for n in w.top_nodes if n.def_name == "ARENA"]
    assert [(n.type, n.proto) for n in top] == [("Solid", "CircleArena")]


def test_resets_warn_at_the_fields_line_as_the_template_does(tmp_path: Path) -> None:
    """Values the PROTO's template replaces are replaced the same way, each with its message at the
    field's line: radius -1 -> 1, wallThickness 0 -> 0.01, wallHeight -2 -> 0.1, subdivision 8 -> 8
    (the arena asks for more than 8), and the wall then too thin for 8 segments (the template's
    SolidPipe says so and takes the gap's absolute value); subdivision 9 is kept, quietly."""
    p = _world(tmp_path, "CircleArena {\n  radius -1\n  wallThickness 0\n  wallHeight -2\n  subdivision 8\n}\n")
    loaded = _load(p)
    said = [x for x in loaded.warnings if "CircleArena." in x]
    assert said == [
        f"{p}:8:3: CircleArena.subdivision 8: 'subdivision' must be greater than 8. Using 8 instead. (as Webots' "
        "CircleArena does)",
        f"{p}:5:3: CircleArena.radius -1: 'radius' must be strictly positive. Value reset to 1. (as Webots' "
        "CircleArena does)",
        f"{p}:6:3: CircleArena.wallThickness 0: 'wallThickness' must be strictly positive. Value reset to 0.01. "
        "(as Webots' CircleArena does)",
        f"{p}:7:3: CircleArena.wallHeight -2: 'wallHeight' must be strictly positive. Value reset to 0.1. (as "
        "Webots' CircleArena does)",
        f"{p}:6:3: CircleArena.wallThickness 0: Either 'thickness' or 'subdivision' are too small for the box "
        "subdivision algorithm. (as the SolidPipe of Webots' CircleArena does: the ring and boxes are made with the "
        "gap's absolute value)"]
    (arena,) = loaded.world.solids
    (pipe,) = arena.children
    ring, *boxes = pipe.shapes
    assert len(boxes) == 8 and arena.shapes[1].geometry.size == (2.0, 2.0)
    assert tuple(pipe.pose.translation) == (0.0, 0.0, 0.05)
    gap = abs(1.01 * math.cos(math.pi / 8) - 1.0)          # 0.0669...: thicker than the wall, as in Webots
    assert boxes[0].geometry.size == pytest.approx((2 * 1.01 * math.sin(math.pi / 8), gap, 0.1), abs=1e-15)
    inner = np.asarray(ring.geometry.vertices)[9:18]
    assert np.allclose(np.hypot(inner[:, 0], inner[:, 1]), 1.01 - gap, atol=1e-15)
    loaded = _load(_world(tmp_path, "CircleArena { subdivision 9 wallThickness 0.2 }\n", name="nine.wbt"))
    assert not [x for x in loaded.warnings if "CircleArena." in x]
    assert len(loaded.world.solids[0].children[0].shapes) == 1 + 9


def test_solid_pipe_resets_follow_its_template(tmp_path: Path) -> None:
    """SolidPipe's own rules: subdivision under 8 -> 8 (8 itself is kept), height and radius reset to
    their defaults, a thickness not under the radius as written -> half the radius used."""
    p = _world(tmp_path, "SolidPipe { radius -1 thickness 0.7 height 0 subdivision 3 }\n", declared=PIPE)
    loaded = _load(p)
    said = [x.split(": ", 1)[1] for x in loaded.warnings if "SolidPipe." in x]
    assert said == ["SolidPipe.subdivision 3: 'subdivision' must be greater or equal to 8. Using 8 instead. (as "
                    "Webots' SolidPipe does)",
                    "SolidPipe.height 0: 'height' must be strictly positive. Value reset to 2. (as Webots' SolidPipe does)",
                    "SolidPipe.radius -1: 'radius' must be strictly positive. Value reset to 1. (as Webots' SolidPipe "
                    "does)",
                    "SolidPipe.thickness 0.7: 'thickness' must be smaller than 'radius'. Value reset to 0.5. (as "
                    "Webots' SolidPipe does)"]
    (pipe,) = loaded.world.solids
    ring, *boxes = pipe.shapes
    assert len(boxes) == 8 and (pipe.name, pipe.model) == ("pipe", "pipe")
    assert boxes[0].geometry.size == pytest.approx((2 * math.sin(math.pi / 8), math.cos(math.pi / 8) - 0.5, 2.0))
    loaded = _load(_world(tmp_path, "SolidPipe { subdivision 8 thickness 0 }\n", declared=PIPE, name="eight.wbt"))
    said = [x.split(": ", 1)[1] for x in loaded.warnings if "SolidPipe." in x]
    assert said == ["SolidPipe.thickness 0: 'thickness' must be greater than 0. Value reset to 0.5. (as Webots' "
                    "SolidPipe does)"]
    assert len(loaded.world.solids[0].shapes) == 1 + 8
    with pytest.raises(WorldError, match=r"w\.wbt: line 4, column 13: SolidPipe\.subdivision: 300,000 segments: more than 200,000"):
        _load(_world(tmp_path, "SolidPipe { subdivision 300000 }\n", declared=PIPE))


def test_a_solid_pipe_placed_and_turned(tmp_path: Path) -> None:
    """A SolidPipe of radius 0.4, 0.05 thick, 0.6 high and 13 segments at (1, 2, 0.5) turned 0.3
    about z, seen from a robot at (2.3, 1.7): for rays through and past the pipe, a lidar reads the
    outer ring polygon (turned, from -π/2 + 0.3) and generic sensors the boxes' outer faces (13 is
    odd: the boxes sit at (i + 1)·2π/13 + 0.3); a pipe without its bounding object is seen by the
    lidar only."""
    pipe = "SolidPipe { translation 1 2 0.5 rotation 0 0 1 0.3 radius 0.4 thickness 0.05 height 0.6 subdivision 13 %s}\n"
    o = np.array([2.3, 1.7])
    aims = [math.atan2(2.0 - o[1], 1.0 - o[0]) + d for d in (0.0, 0.05, -0.12, 0.2, -0.26)]
    lidar = ('Lidar { translation 0 0 0.5 name "lidar" horizontalResolution 512 fieldOfView 6.283185307179586 '
             'numberOfLayers 1 maxRange 5 }\n')
    robot = (f'Robot {{ translation {float(o[0])!r} {float(o[1])!r} 0 name "bot" controller "<extern>" children [\n{lidar}'
             + _sensors(aims, "generic", 0.5) + "] }\n")
    _, outer_ring, boxes = _pipe_geometry(0.4, 0.05, 13, centre=(1.0, 2.0), turn=0.3)
    theta = math.pi - (np.arange(512) + 0.5) * 2 * math.pi / 512
    for extra, bounded in (("", True), ("enableBoundingObject FALSE ", False)):
        sim = Simulation(_load(_world(tmp_path, pipe % extra + robot, declared=PIPE, name=f"p{bounded}.wbt")),
                         precision="exact")
        for d in sim.all_devices():
            d.enable(16)
        sim.step()
        want = np.array([_ray_polygon(o, np.array([math.cos(t), math.sin(t)]), outer_ring) for t in theta])
        got = np.asarray(sim.device("bot/lidar").range_image, dtype=np.float64)[0]
        assert np.isfinite(want).sum() > 40 and np.array_equal(np.isinf(got), np.isinf(want))
        assert np.abs(got[np.isfinite(want)] - want[np.isfinite(want)]).max() < 2e-7
        for i, a in enumerate(aims):
            d = _ray_boxes(o, np.array([math.cos(a), math.sin(a)]), boxes)
            assert math.isfinite(d)
            value = sim.device(f"bot/generic{i}").value
            if bounded:
                assert value == pytest.approx(1000.0 * d, abs=1e-6), a
            else:
                assert value == 4000.0      # nothing within its 4 m table: its last value


def test_loaded_by_name_and_the_real_proto_preferred_when_installed(tmp_path: Path, monkeypatch) -> None:
    """A world before R2022b names CircleArena without EXTERNPROTO: the stand-in too; with an
    installation holding a CircleArena (our own one-line PROTO here), that file is used instead."""
    monkeypatch.delenv("WEBOTS_HOME", raising=False)
    old = _load(_world(tmp_path, "CircleArena { radius 2 }\nSolidPipe { name \"p\" }\n", declared="", name="old.wbt"))
    assert [s.name for s in old.world.solids] == ["circle arena", "p"] and old.losses == ()   # no "lost unknown node"
    w = _world(tmp_path, "CircleArena { radius 2 }\n", name="new.wbt")
    loaded = _load(w)
    assert [x for x in loaded.warnings if "PROTO files not found" in x] == [
        f"{w}:2:1: PROTO files not found: Sensorium's built-in stand-ins used for CircleArena (give --webots-home or "
        "WEBOTS_HOME to use Webots' own)"]
    home = tmp_path / "webots"
    folder = home / "projects" / "objects" / "floors" / "protos"
    folder.mkdir(parents=True)
    (folder / "CircleArena.proto").write_text(
        '#VRML_SIM R2023b utf8\nPROTO CircleArena [ field SFFloat radius 1 ] { Solid { name "real arena" } }\n')
    loaded = _load(w, webots_home=home)
    assert [s.name for s in loaded.world.solids] == ["real arena"]
    assert not [x for x in loaded.warnings if "CircleArena" in x]


def test_a_stand_ins_unknown_field_is_one_warning_at_its_line(tmp_path: Path) -> None:
    """A field outside a stand-in's PROTO interface (a typo Webots skips with an error) is said at its
    line, with the close field it likely meant; the stand-in is built from its other fields."""
    from sensorium.server.world.loader import load_world

    p = tmp_path / "w.wbt"
    p.write_text("#VRML_SIM R2023b utf8\nWorldInfo { }\nRectangleArena {\n  floorsize 3 3\n  wallHeight 0.2\n"
                 "  banana 1\n}\nCircleArena { radius 2 wallheight 0.3 }\nTexturedBackgroundLight { luminosity 1 }\n")
    w = load_world(p)
    typos = [x for x in w.warnings if "not a field of PROTO" in x]
    assert typos == [f"{p}:4:3: RectangleArena.floorsize: not a field of PROTO RectangleArena, ignored "
                     "(did you mean floorSize?)",
                     f"{p}:6:3: RectangleArena.banana: not a field of PROTO RectangleArena, ignored",
                     f"{p}:8:24: CircleArena.wallheight: not a field of PROTO CircleArena, ignored "
                     "(did you mean wallHeight?)"]
