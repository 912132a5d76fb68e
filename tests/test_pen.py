"""The Pen (issue 21): ink laid where the pen points, at the start of each basic step, read by
infra-red sensors as Webots reads it - closed-form readings over strokes on untextured and
textured floors, density blending, lead size, maxDistance, a box face (painted on texture set 1,
read on set 0 as Webots does), evaporation, reset; the services, topics and .wbt conversion.

Over ink of density ``c`` and red ``k`` on a surface of red ``r`` (colour × texel), an infra-red
ray of length ``d`` reads ``lookup(d / (0.2 + 0.8·((1 − c)·r + c·k)))``; every sensor here has the
table ``[[0, 0], [1, 1000]]`` (value = 1000 × that distance) and looks down from 1 cm."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from sensorium.schemas import messages as msgs
from sensorium.schemas import world as wm
from sensorium.schemas.wire import pack, unpack
from sensorium.server.daemon.services import Core
from sensorium.server.sim.pen import ink_channel
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world, parse_world

DOWN = [0.0, 1.0, 0.0, math.pi / 2]          # a distance sensor's +x turned to -z
TABLE = [[0.0, 0.0, 0.0], [1.0, 1000.0, 0.0]]
PRECISIONS = ["fast", "exact"]


def reading(red: float, d: float = 0.01) -> float:
    """What a sensor of TABLE reads over red ``red`` at ``d`` (Webots' D + (D/F − D)·1)."""
    f = 0.2 + 0.8 * red
    return 1000.0 * (d + (d / f - d))


def ir(name: str, x: float, y: float, z: float = 0.01) -> dict:
    return {"device": "DistanceSensor", "name": name, "type": "infra-red", "lookup_table": TABLE,
            "pose": {"translation": [x, y, z], "rotation": DOWN}}


def pen(name: str = "pen", x: float = 0.0, y: float = 0.0, z: float = 0.05, **fields) -> dict:
    return {"device": "Pen", "name": name, "pose": {"translation": [x, y, z]}, **fields}


def make(devices: list, *, floor: dict | None = None, solids: list | None = None, at=(0.0, 0.0),
         precision: str = "exact", base_dir: Path | None = None, step: int = 16, evaporation: float = 0.0,
         drive: bool = False) -> Simulation:
    floor = floor or {"name": "floor", "geometry": {"type": "plane", "size": [1.0, 1.0]}}
    robot = {"name": "r", "pose": {"translation": [at[0], at[1], 0.0]}, "devices": devices}
    if drive:
        robot["differential_drive"] = {"wheel_radius": 0.02, "axle_length": 0.05, "max_wheel_speed": 100}
    data = {"world_info": {"basic_time_step": step, "ink_evaporation": evaporation, "contact": False},
            "solids": [floor, *(solids or [])], "robots": [robot]}
    sim = Simulation(parse_world(data, base_dir=base_dir), precision)
    for d in sim.all_devices():
        if d.kind == "DistanceSensor":
            d.enable(step)
    return sim


def values(sim: Simulation) -> dict[str, float]:
    return {d.name: d.value for d in sim.all_devices() if d.kind == "DistanceSensor"}


def tol(precision: str) -> float:
    return 1e-12 if precision == "exact" else 2e-4      # FAST: float32 ray distances


# a 1 m x 1 m untextured plane: bounding radius 0.707 m -> 32 + 992 x 0.0707 = 102 -> a 128 x 128
# paint texture, texels of 7.8125 mm; texel (column c, row r) has its centre at
# x = (c + 0.5)/128 - 0.5, y = 0.5 - (r + 0.5)/128 (u = x + 0.5, v = 0.5 - y)
def texel_centre(col: int, row: int, n: int = 128, side: float = 1.0) -> tuple[float, float]:
    return ((col + 0.5) / n - 0.5) * side, (0.5 - (row + 0.5) / n) * side


# an appearance (white): ink blends with it by density; a shape without any appearance reads the
# ink's colour alone (test_a_shape_without_appearance_reads_the_ink_colour_alone)
WHITE_FLOOR = {"name": "floor", "geometry": {"type": "plane", "size": [1.0, 1.0]}, "appearance": {"base_color": [1, 1, 1]}}


# ------------------------------------------------------------------ a stroke, then a reading

@pytest.mark.parametrize("precision", PRECISIONS)
def test_a_stroke_on_an_untextured_floor_then_infra_red_reads_it(precision: str) -> None:
    x, y = texel_centre(70, 60)
    floor = {"name": "floor", "geometry": {"type": "plane", "size": [1.0, 1.0]},
             "appearance": {"base_color": [0.8, 0.3, 0.3]}}
    sim = make([pen(ink_color=[0.25, 0.5, 1.0], ink_density=0.5), ir("over", 0.0, 0.0),
                ir("beside", 2 / 128, 0.0)], floor=floor, at=(x, y), precision=precision)
    sim.step()
    v = values(sim)
    # the pen inked before the sensors measured (the same step): (1 - 0.5)·0.8 + 0.5·0.25
    assert v["over"] == pytest.approx(reading(0.5 * 0.8 + 0.5 * 0.25), rel=tol(precision))
    assert v["beside"] == pytest.approx(reading(0.8), rel=tol(precision))      # two texels away: no ink
    layer = sim.scene.textures.ink[0]
    assert layer.density.shape == (128, 128)
    assert layer.density[60, 70] == np.float32(0.5) and np.count_nonzero(layer.density) == 1
    assert sim.counters["rays_pen"] == 1 and sim.counters["ink_strokes"] == 1
    sim.step()                                   # a second stroke on the same texel: density 1
    assert values(sim)["over"] == pytest.approx(reading(0.25), rel=tol(precision))


@pytest.mark.parametrize("precision", PRECISIONS)
def test_a_stroke_on_a_textured_floor_then_infra_red_reads_it(tmp_path: Path, precision: str) -> None:
    # a 64 x 64 image: red 200 on its left half, 40 on its right; a 1 m plane -> texels of 1/64 m
    img = np.zeros((64, 64, 3), dtype=np.uint8)
    img[:, :32] = (200, 90, 10)
    img[:, 32:] = (40, 90, 10)
    Image.fromarray(img).save(tmp_path / "floor.png")
    floor = {"name": "floor", "geometry": {"type": "plane", "size": [1.0, 1.0]}, "appearance": {"texture": "floor.png"}}
    x, y = texel_centre(20, 30, 64)
    sim = make([pen(ink_color=[0.0, 0.0, 0.0], ink_density=0.75), ir("over", 0.0, 0.0),
                ir("beside", 3 / 64, 0.0), ir("right", 20 / 64, 0.0)],
               floor=floor, at=(x, y), precision=precision, base_dir=tmp_path)
    sim.step()
    v = values(sim)
    d = float(np.float32(0.75))
    assert sim.scene.textures.ink[0].density.shape == (64, 64)        # the image's size (a Plane: 1 x 1)
    assert v["over"] == pytest.approx(reading((1 - d) * 200 / 255), rel=tol(precision))
    assert v["beside"] == pytest.approx(reading(200 / 255), rel=tol(precision))
    assert v["right"] == pytest.approx(reading(40 / 255), rel=tol(precision))


def test_the_pen_inks_where_the_step_starts_and_sensors_read_where_it_ends() -> None:
    """Webots paints in prePhysicsStep (before the robot moves) and measures after: a robot
    driving at v lays its k-th stroke at x0 + (k-1)·v·dt."""
    sim = make([pen()], at=(-0.2, 0.0), drive=True)
    for m in sim.robot("r").motors.values():
        m.set_position(math.inf)
        m.set_velocity(5.0)                   # 0.1 m/s with 2 cm wheels: 1.6 mm per 16 ms step
    p = sim.device("r/pen")
    xs = []
    for _ in range(4):
        sim.step()
        xs.append(float(p.stroke[0]))
    assert xs == pytest.approx([-0.2 + k * 0.0016 for k in range(4)], abs=1e-12)
    assert p.stroke[2] == pytest.approx(0.0, abs=1e-12) and p.measurements == 4 and p.measured_at_ms == 64
    assert sim.robot("r").pose.translation[0] == pytest.approx(-0.2 + 4 * 0.0016, abs=1e-12)


# ------------------------------------------------------------------ density blending

def test_density_blends_colours_and_caps_at_one() -> None:
    """WbPaintTexture::paint: the colour keeps old/(old + new) of itself, the density adds up to 1.
    Colours set with set_ink_color are Webots' float32 byte/255."""
    x, y = texel_centre(70, 60)
    sim = make([pen(write=False), ir("over", 0.0, 0.0)], at=(x, y), floor=WHITE_FLOOR)
    p = sim.device("r/pen")
    c1 = (ink_channel(0x33), ink_channel(0x66), ink_channel(0x99))
    assert c1[0] == float(np.float32(51) / np.float32(255)) and c1[0] != 0.2      # Webots' r / 255.0f
    p.set_write(True)
    p.set_ink_color(0x336699, 0.25)
    sim.step()
    assert values(sim)["over"] == pytest.approx(reading(0.75 + 0.25 * c1[0]), rel=1e-6)
    p.set_ink_color(0xFF0000, 0.5)
    sim.step()
    mix = (0.25 * c1[0] + 0.5 * 1.0) / 0.75              # density 0.75
    assert values(sim)["over"] == pytest.approx(reading(0.25 + 0.75 * mix), rel=1e-6)
    p.set_ink_color(0x000000, 0.75)                      # 0.75 + 0.75 > 1: capped, old ratio 0.5
    sim.step()
    layer = sim.scene.textures.ink[0]
    assert layer.density[60, 70] == 1.0
    assert layer.rgb[60, 70].tolist() == pytest.approx([0.5 * mix, 0.5 * (0.25 * c1[1]) / 0.75,
                                                       0.5 * (0.25 * c1[2]) / 0.75], abs=1e-6)
    assert values(sim)["over"] == pytest.approx(reading(0.5 * mix), rel=1e-6)
    # a density outside [0, 1] is clamped (Webots), bits above 0xFFFFFF ignored
    p.set_ink_color(0x1FF0000, 7.0)
    assert p.ink_density == 1.0 and p.ink_color == (1.0, 0.0, 0.0)
    p.set_ink_color(0x00FF00, -3.0)
    assert p.ink_density == 0.0
    with pytest.raises(ValueError, match="finite"):
        p.set_ink_color(0, math.nan)


@pytest.mark.parametrize("precision", PRECISIONS)
def test_a_shape_without_appearance_reads_the_ink_colour_alone(precision: str) -> None:
    """WbShape::pickColor: a shape with neither Appearance nor PBRAppearance reads its paint
    texture's colour, whatever the density (white where never inked); with an appearance the ink
    blends by density. Ink 0x336699 at density 0.25 on both."""
    bare = {"name": "bare", "geometry": {"type": "plane", "size": [1.0, 1.0]}}
    white = {**WHITE_FLOOR, "name": "white", "pose": {"translation": [2.0, 0.0, 0.0]}}
    x, y = texel_centre(70, 60)
    sim = make([pen("p0", x, y, write=False), pen("p1", 2.0 + x, y, write=False), ir("bare", x, y),
                ir("white", 2.0 + x, y), ir("beside", x + 2 / 128, y)], floor=bare, solids=[white], precision=precision)
    for name in ("p0", "p1"):
        sim.device(f"r/{name}").set_ink_color(0x336699, 0.25)
        sim.device(f"r/{name}").set_write(True)
    sim.step()
    c = ink_channel(0x33)
    v = values(sim)
    assert v["bare"] == pytest.approx(reading(c), rel=tol(precision))
    assert v["white"] == pytest.approx(reading(0.75 + 0.25 * c), rel=tol(precision))
    assert v["beside"] == pytest.approx(reading(1.0), rel=tol(precision))       # never inked: white


# ------------------------------------------------------------------ lead size

def disc(half: int) -> int:
    return sum(1 for dx, dy in itertools.product(range(-half, half + 1), repeat=2) if dx * dx + dy * dy <= half * half)


@pytest.mark.parametrize("lead, width", [(0.002, 1), (0.01, 1), (0.06, 5), (0.1, 9), (0.15, 13)])
def test_lead_size_is_a_disc_of_texels(lead: float, width: int) -> None:
    """A 2 m plane: radius 1.414 m -> 32 + 992 x 0.1414 = 172 -> 128 texels of 1.5625 cm; a lead
    of L m is int(L x 128 / 1.414) texels across (at least 1), a disc of radius width // 2."""
    assert max(1, int(float(np.float32(lead)) * 128 / math.sqrt(2.0))) == width
    half = width // 2
    x, y = texel_centre(64, 64, 128, 2.0)
    floor = {"name": "floor", "geometry": {"type": "plane", "size": [2.0, 2.0]}}
    step = 2.0 / 128
    sim = make([pen(lead_size=lead, ink_density=1.0), ir("edge", half * step, 0.0), ir("out", (half + 1) * step, 0.0),
                ir("corner", (half - 1) * step if half else 0.0, (half - 1) * step if half > 1 else 0.0)],
               floor=floor, at=(x, y))
    sim.step()
    layer = sim.scene.textures.ink[0]
    assert layer.density.shape == (128, 128)
    assert np.count_nonzero(layer.density) == disc(half)
    v = values(sim)
    assert v["edge"] == pytest.approx(reading(0.0), rel=1e-12)       # black ink on the disc's rim
    assert v["out"] == pytest.approx(reading(1.0), rel=1e-12)        # one texel further: the floor
    inside = (half - 1) ** 2 * 2 <= half * half if half > 1 else True
    assert v["corner"] == pytest.approx(reading(0.0 if inside else 1.0), rel=1e-12)


# ------------------------------------------------------------------ maxDistance

@pytest.mark.parametrize("precision", PRECISIONS)
@pytest.mark.parametrize("max_distance, inks", [(0.0, True), (-1.0, True), (0.2, False), (0.3, True), (0.25, False)])
def test_max_distance(precision: str, max_distance: float, inks: bool) -> None:
    """The pen 0.25 m above the floor inks it only if the floor is strictly nearer than maxDistance
    (Webots' findIntersectingShape); 0 or less is unlimited."""
    sim = make([pen(z=0.25, max_distance=max_distance)], precision=precision)
    sim.step()
    assert sim.counters["rays_pen"] == 1
    assert sim.counters["ink_strokes"] == int(inks) and sim.device("r/pen").measurements == int(inks)


def test_a_pen_far_away_with_no_limit_and_a_pen_that_does_not_write() -> None:
    sim = make([pen(z=50.0), pen("off", write=False)])
    sim.run(3)
    assert sim.counters["rays_pen"] == 3 and sim.counters["ink_strokes"] == 3
    assert sim.device("r/off").measurements == 0
    sim.device("r/pen").set_write(False)
    sim.run(3)
    assert sim.counters["rays_pen"] == 3                              # nobody writes: no ray at all


# ------------------------------------------------------------------ a box face

@pytest.mark.parametrize("precision", PRECISIONS)
def test_ink_on_a_box_face_is_read_where_webots_reads_it(precision: str) -> None:
    """A 0.4 x 0.4 x 0.2 box (bounding radius 0.3 m -> 64 texels -> a 256 x 128 paint texture,
    Webots' 4 x 2 atlas). The pen paints its top face's centre at texture set 1: (0.25·0.5 + 0.5,
    0.5·0.5) -> texel (160, 32). Infra-red sensors read the paint texture at texture set 0 (u, v) =
    (a, 1 − b) of the face point (a, b), as Webots' WbShape::pickColor does: the ink is seen from
    a = 0.627, b = 0.746 (texel (160, 32)), not from the centre (texel (128, 64))."""
    box = {"name": "box", "pose": {"translation": [0.0, 0.0, 0.1]}, "geometry": {"type": "box", "size": [0.4, 0.4, 0.2]}}
    xa, yb = 0.4 * (0.627 - 0.5), 0.4 * (0.746 - 0.5)
    sim = make([pen(z=0.5, ink_density=1.0), ir("centre", 0.0, 0.0, 0.21), ir("set0", xa, yb, 0.21)],
               solids=[box], precision=precision)
    sim.step()
    layer = sim.scene.textures.ink[1]            # shape 0 is the floor, 1 the box
    assert layer.density.shape == (128, 256)
    assert layer.density[32, 160] == 1.0 and np.count_nonzero(layer.density) == 1
    v = values(sim)
    assert v["set0"] == pytest.approx(reading(0.0), rel=tol(precision))
    assert v["centre"] == pytest.approx(reading(1.0), rel=tol(precision))


@pytest.mark.parametrize("precision", PRECISIONS)
def test_a_camera_sees_ink_on_a_box_face_where_the_pen_painted_it(precision: str) -> None:
    """Webots' shaders sample the paint texture at texture set 1 (``penTexUv``), the coordinates
    the pen painted at: a camera above the box of the test above sees the black stroke on the top
    face's centre, in the middle of its image (it used to read set 0, as infra-red does, and
    showed the stroke up and to the right of the middle, at a = 0.627, b = 0.746)."""
    box = {"name": "box", "pose": {"translation": [0.0, 0.0, 0.1]}, "geometry": {"type": "box", "size": [0.4, 0.4, 0.2]},
           "appearance": {"base_color": [1, 1, 1]}}
    down = [-1.0, 1.0, 1.0, 2.0 * math.pi / 3.0]     # +x to world -z, the image's top to world +y
    cam = {"device": "Camera", "name": "cam", "width": 33, "height": 33, "field_of_view": 0.5,
           "pose": {"translation": [0.0, 0.0, 1.0], "rotation": down}}
    data = {"world_info": {"contact": False}, "solids": [box],
            "lights": [{"type": "DirectionalLight", "direction": [0, 0, -1]}],
            "robots": [{"name": "r", "devices": [pen(z=0.5, ink_density=1.0, lead_size=0.03), cam]}]}
    sim = Simulation(parse_world(data), precision)
    sim.device("r/cam").enable(16)
    sim.step()
    assert np.count_nonzero(sim.scene.textures.ink[0].density) == 29       # a disc 7 texels across
    red = sim.device("r/cam").image[:, :, 2]
    rows, cols = np.nonzero(red < 100)
    assert red[16, 16] == 0 and len(rows) > 4
    assert abs(rows.mean() - 16) < 1.0 and abs(cols.mean() - 16) < 1.0
    assert red[2, 2] > 200                              # the rest of the face is white and lit


# ------------------------------------------------------------------ evaporation and reset

def test_ink_evaporates_as_webots_inkEvaporation_and_reset_clears_it() -> None:  # noqa: N802
    """Density d painted, then × exp(−e·dt) every basic step (the painting step included), read as
    (1 − D)·1 + D·0 under black ink."""
    x, y = texel_centre(70, 60)
    e, dt = 2.0, 16
    sim = make([pen(ink_density=0.5), ir("over", 0.0, 0.0)], at=(x, y), evaporation=e, step=dt, floor=WHITE_FLOOR)
    p = sim.device("r/pen")
    sim.step()
    p.set_write(False)
    factor = math.exp(-e * dt / 1000.0)
    for n in range(1, 6):
        density = float(np.float32(0.5 * factor ** n))
        assert sim.scene.textures.ink[0].density[60, 70] == pytest.approx(density, rel=1e-6)
        assert values(sim)["over"] == pytest.approx(reading(1.0 - density), rel=1e-6)
        sim.step()
    sim.reset()
    sim.step()
    assert values(sim)["over"] == pytest.approx(reading(1.0), rel=1e-12)
    assert not sim.scene.textures.ink[0].density.any()


def test_a_paint_texture_over_the_budget_is_refused_with_a_warning() -> None:
    from sensorium.server.world import textures

    sim = make([pen()])
    assert sim.scene.textures is None            # an untextured world: the sampler comes with the first stroke
    sim.step()
    sampler = sim.scene.textures
    assert sampler.ink[0].texels == 128 * 128
    sampler.ink.clear()
    sampler.ink_texels_max = 128 * 128 - 1
    with pytest.warns(RuntimeWarning, match="refused"):
        sim.step()
    assert 0 in sampler.ink_refused and sim.counters["ink_strokes"] == 1
    sim.step()                                   # refused once, silently after
    assert textures.INK_TEXELS_MAX == 1 << 24


# ------------------------------------------------------------------ services, topics, world files

_ids = itertools.count(1)


def call(core: Core, service: str, args: dict | None = None) -> dict:
    [reply] = core.handle([b"peer", pack({"id": next(_ids), "service": service, "args": args or {}})], 0.0)
    return unpack(reply[-1])


def test_services_attach_description_and_topics() -> None:
    x, y = texel_centre(70, 60)
    sim = make([pen(write=False, lead_size=0.004, max_distance=0.1), ir("over", 0.0, 0.0)], at=(x, y),
               floor=WHITE_FLOOR)
    core = Core(sim)
    assert {"/r/pen/write", "/r/pen/set_ink_color"} <= set(core.routes)
    types = {t.name: t.type for t in core.topics.topics}
    assert types["/r/pen/stroke"] == msgs.POINT_STAMPED and types["/r/pen/ink"] == msgs.COLOR_RGBA
    recorded: list[tuple[str, dict]] = []
    core.topics.set_recorder(lambda topic, t, env, body, ns, seq: recorded.append((topic, unpack(body))),
                             ["/r/pen/"])
    assert call(core, "/r/pen/write", {"value": True})["error"]["code"] == 6        # NOT_ATTACHED
    attached = call(core, "attach", {"robot": "r"})["result"]
    desc = next(d for d in attached["devices"] if d["name"] == "pen")
    assert desc == {"name": "pen", "type": "Pen", "model": "", "index": 0, "simulated": True, "write": False,
                    "ink_color": [0.0, 0.0, 0.0], "ink_density": 0.5, "lead_size": 0.004, "max_distance": 0.1}
    sim.step()
    assert sim.counters["ink_strokes"] == 0 and not recorded
    assert call(core, "/r/over/enable", {"value": 16})["result"] == {"success": True}
    assert call(core, "/r/pen/set_ink_color", {"color": 0x8000FF, "density": 2.5})["result"] == {"success": True}
    assert call(core, "/r/pen/write", {"value": True})["result"] == {"success": True}
    sim.step()
    core.topics.publish(sim.time_ms)
    red = ink_channel(0x80)
    assert values(sim)["over"] == pytest.approx(reading(red), rel=1e-12)          # density 2.5 -> 1
    assert recorded == [("/r/pen/stroke", {"header": {"stamp": {"sec": 0, "nanosec": 32_000_000}, "frame_id": "world"},
                                           "point": {"x": x, "y": y, "z": pytest.approx(0.0, abs=1e-12)}}),
                        ("/r/pen/ink", {"r": red, "g": 0.0, "b": 1.0, "a": 1.0})]
    sim.step()
    core.topics.publish(sim.time_ms)
    assert len(recorded) == 4                     # one stroke and its ink per basic step
    bad = [({"color": 0x1000000, "density": 0.5}, "color"), ({"color": 1, "density": math.nan}, "density"),
           ({"color": 1}, "density"), ({"value": 1}, "")]
    for args, what in bad:
        err = call(core, "/r/pen/set_ink_color", args)["error"]
        assert err["code"] == 5 and what in err["message"], err                      # INVALID_ARGUMENT
    assert call(core, "/r/pen/write", {"value": 1})["error"]["code"] == 5             # strict: not a bool
    listed = {s["name"]: s for s in call(core, "get_services")["result"]["services"]}
    assert listed["/r/pen/set_ink_color"]["args"] == {"color": "int", "density": "float"}


def test_world_file_fields_are_checked_and_sanitised() -> None:
    w = parse_world({"robots": [{"name": "r", "devices": [pen(ink_density=1.5)]}]})
    assert w.world.robots[0].devices[0].ink_density == 1.0
    assert any("devices[0].ink_density: 1.5 outside [0, 1], clamped to 1.0" in m for m in w.warnings)
    for bad, field in [({"ink_color": [0, 0, 2]}, "ink_color"), ({"lead_size": -0.1}, "lead_size"),
                       ({"write": "sometimes"}, "write")]:
        with pytest.raises(Exception, match=field):
            wm.World.model_validate({"robots": [{"name": "r", "devices": [pen(**bad)]}]})
    with pytest.raises(Exception, match="ink_evaporation"):
        wm.WorldInfo(ink_evaporation=-1.0)


def test_a_wbt_pen_and_ink_evaporation_convert(tmp_path: Path) -> None:
    p = tmp_path / "pen.wbt"
    p.write_text("""#VRML_SIM R2023b utf8
WorldInfo { basicTimeStep 16 inkEvaporation 0.5 }
Solid { children [ Shape { geometry Plane { size 1 1 } } ] }
Robot {
  translation 0.1 0.2 0
  name "r"
  children [
    Pen { translation 0 0 0.05 name "marker" inkColor 1 0 0 inkDensity 0.8 leadSize 0.01 maxDistance 0.2 write FALSE
      children [ Pose { translation 0 0 0.011 children [ Shape { geometry Cylinder { height 0.02 radius 0.004 } } ] } ] }
    Pen { }
  ]
}
""")
    loaded = load_world(p)
    assert loaded.world.world_info.ink_evaporation == 0.5
    a, b = loaded.world.robots[0].devices
    assert isinstance(a, wm.Pen) and a.name == "marker" and a.ink_color == (1.0, 0.0, 0.0)
    assert (a.ink_density, a.lead_size, a.max_distance, a.write) == (0.8, 0.01, 0.2, False)
    assert a.pose.translation == (0.0, 0.0, 0.05)
    assert (b.name, b.ink_color, b.ink_density, b.lead_size, b.max_distance, b.write) == \
        ("pen", (0.0, 0.0, 0.0), 0.5, 0.002, 0.0, True)
    assert len(loaded.world.robots[0].shapes) == 1                  # the pen's shape is part of the body
    sim = Simulation(loaded)
    sim.device("r/pen").set_write(False)
    sim.device("r/marker").set_write(True)
    sim.step()
    # the marker's tip is the bottom of its own cylinder; its ray goes down to the floor
    assert sim.counters["ink_strokes"] == 1
    assert sim.device("r/marker").stroke.tolist() == pytest.approx([0.1, 0.2, 0.0], abs=1e-12)


def test_a_recording_holds_every_stroke_and_exports_to_ros2(tmp_path: Path) -> None:
    """``serve --record`` records the pen's topics like any other: one stroke (where) and one ink
    (which) per basic step that inked; the ROS 2 export carries them as PointStamped and ColorRGBA."""
    from rosbags.highlevel import AnyReader

    from sensorium.server.recording.export import export_ros2
    from sensorium.server.recording.reader import Recording
    from sensorium.server.recording.writer import McapRecorder

    sim = make([pen(ink_color=[1.0, 0.5, 0.0], ink_density=0.25)], at=(-0.2, 0.1), drive=True)
    for m in sim.robot("r").motors.values():
        m.set_position(math.inf)
        m.set_velocity(5.0)
    core = Core(sim)
    path = tmp_path / "pen.mcap"
    points = []
    with McapRecorder(path, b"", "pen.yaml", {}, ["/r/pen/"], foxglove=False) as rec:
        core.topics.set_recorder(rec)
        for k in range(5):
            if k == 3:
                sim.device("r/pen").set_write(False)      # no stroke, no message
            sim.step()
            core.topics.publish(sim.time_ms)
            if k < 3:
                points.append(sim.device("r/pen").stroke.tolist())
    got = [(m.topic, m.stamp_ns, m.decode()) for m in Recording(path).messages()]
    assert [t for t, _, _ in got] == ["/r/pen/stroke", "/r/pen/ink"] * 3
    assert [ns for _, ns, _ in got] == [16_000_000, 16_000_000, 32_000_000, 32_000_000, 48_000_000, 48_000_000]
    strokes = [body["point"] for t, _, body in got if t == "/r/pen/stroke"]
    assert [[p["x"], p["y"], p["z"]] for p in strokes] == points
    assert points[1][0] - points[0][0] == pytest.approx(0.0016, abs=1e-12)        # 0.1 m/s x 16 ms
    assert got[1][2] == {"r": 1.0, "g": 0.5, "b": 0.0, "a": 0.25}
    out = tmp_path / "pen_ros2.mcap"
    report = export_ros2(path, out, distro="jazzy")
    assert report.messages == 6 and not report.skipped
    with AnyReader([out]) as reader:
        msgs_ = [(c.topic, c.msgtype, reader.deserialize(raw, c.msgtype)) for c, _, raw in reader.messages()]
    assert msgs_[0][1] == "geometry_msgs/msg/PointStamped" and msgs_[0][2].header.frame_id == "world"
    assert msgs_[0][2].point.x == points[0][0] and msgs_[1][1] == "std_msgs/msg/ColorRGBA"
    assert msgs_[1][2].a == pytest.approx(0.25)
