"""Property tests (Hypothesis, derandomized) of round 29's new paths, each failing case found fixed with a
regression test naming it (tests/test_props_round29.py fuzzes whole worlds' numbers; this file the paths).

Batched free wheels (batched_steered.py, packets.c ``sp_constrained_twists``): random steered drives (two to
five wheels at random places, collinear or not, random radii and headings, any number of them free but one
driven, steered or not) in two or three copies, each copy steered and rolled at its own random commands:
the world is refused in one line, or every copy's pose, free wheels' rolled angles and driven wheels' angles
are its Simulation's bits at every step, with the C pass and with numpy's, every pose finite.

GPS degrees text: the Python client, the C library and the C++ class write Webots' text (its rule computed
apart) for any double: NaN, ±inf, −0, subnormals, ±180, values a hair off whole seconds, past int's range.

Display screens: a camera looking straight down at a Display's screen sees its random drawing by the texel
closed form, whichever of its maps the screen's ImageTextures are (fixed: a url-less emissiveColorMap).

A solid's Poses, Transforms and Groups as Supervisor nodes: random trees and random operation sequences against
a model of the tree and of Webots' getFromDef (copies imported from exportString included); the lidar's range
after each operation the nearest live box face on its beam.

A tracked robot with Physics on random Track bounding objects rests on their closed-form lowest point."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from _fuzz import example_counts
from _packets import use_packets
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS
from test_sweep18 import clib  # noqa: F401 - a fixture: our libController, built once

from sensorium.server.sim.batched import BatchedError, BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, load_world, parse_world

# ---------------------------------------------------------------- batched free wheels

def _plain(v: float) -> float:
    return v if abs(v) >= 1e-4 else 0.0            # the loader refuses magnitudes under 1e-30: no draws there


coordinate = st.sampled_from([0.0, 0.25, -0.25, 0.5]) | st.floats(-0.6, 0.6).map(_plain)


@st.composite
def steered_robots(draw) -> dict:
    """A steered drive of two to five wheels: places random (or all on the x axis: collinear), radii,
    headings and steering signs random; wheel 0 always driven, the others driven or free, each steered
    or not."""
    count = draw(st.integers(2, 5))
    collinear = draw(st.booleans())
    wheels, devices = [], []
    for i in range(count):
        place = [draw(coordinate), 0.0 if collinear else draw(coordinate)]
        wheel: dict = {"position": place, "radius": draw(st.sampled_from([0.03, 0.05]) | st.floats(0.01, 0.2))}
        if i == 0 or draw(st.booleans()):
            wheel["motor"] = f"w{i}"
        if draw(st.booleans()):
            wheel["steer"] = f"s{i}"
            sign = draw(st.sampled_from([1, -1]))
            wheel["steer_sign"] = sign
            devices.append({"device": "RotationalMotor", "name": f"s{i}", "axis": [0.0, 0.0, float(sign)],
                            "anchor": [place[0], place[1], 0.0], "max_velocity": 100.0})
        if draw(st.booleans()):
            wheel["heading"] = draw(st.sampled_from([0.0, math.pi / 2, math.pi]) | st.floats(-3.0, 3.0).map(_plain))
        wheels.append(wheel)
    return {"name": "bot", "pose": {"translation": [0.0, 0.0, 0.1]},
            "body": {"geometry": {"type": "box", "size": [0.3, 0.3, 0.1]}},
            "steered_drive": {"max_wheel_speed": 20.0, "wheels": wheels}, "devices": devices}


def command_of(robot: dict, rng: np.random.Generator) -> tuple[list[float], dict[str, float]]:
    """Random rolling speeds (the motored wheels in order) and steering targets (sometimes all zero)."""
    wheels = robot["steered_drive"]["wheels"]
    speeds = [float(rng.choice([0.0, rng.uniform(-15.0, 15.0)])) for w in wheels if "motor" in w]
    zero = rng.random() < 0.3
    angles = {w["steer"]: 0.0 if zero else float(rng.uniform(-1.6, 1.6)) for w in wheels if "steer" in w}
    return speeds, angles


def batched_as_single(robot: dict, copies: int, seed: int, contact: bool, steps: int = 40) -> None:
    """The robot in ``copies`` batched copies against as many Simulations, commanded alike (random per
    copy, new commands every 10 steps; with ``contact``, inside four walls 0.3 m off that it meets): loads
    with a WorldError line (or BatchedError's) or is the same bits every step."""
    try:
        walls = [{"name": f"wall{k}", "pose": {"translation": [0.3 * x, 0.3 * y, 0.25]},
                  "geometry": {"type": "box", "size": [0.1 if x else 1.2, 0.1 if y else 1.2, 0.5]}}
                 for k, (x, y) in enumerate(((1, 0), (-1, 0), (0, 1), (0, -1)))] if contact else []
        loaded = parse_world({"world_info": {"basic_time_step": 16, "contact": contact}, "solids": walls,
                              "robots": [robot]})
    except WorldError as e:                     # one line per refused value, each naming the source
        assert str(e) and all(line.startswith("<memory>: ") for line in str(e).splitlines()), str(e)
        return
    try:
        batched = BatchedSimulation(loaded, copies)
    except BatchedError as e:
        assert "\n" not in str(e) and str(e), str(e)
        return
    singles = [Simulation(loaded) for _ in range(copies)]
    wheels = robot["steered_drive"]["wheels"]
    motors = [w["motor"] for w in wheels if "motor" in w]
    rng = np.random.default_rng(seed)
    k = batched.steered.of[0]
    for t in range(steps):
        if t % 10 == 0:
            for c, s in enumerate(singles):
                speeds, angles = command_of(robot, rng)
                batched.steered.command(0, np.array([speeds]), copies=[c])
                for name, omega in zip(motors, speeds):
                    m = s.robot("bot").motor(name)
                    m.set_position(math.inf)
                    m.set_velocity(omega)
                for name, angle in angles.items():
                    s.robot("bot").motor(name).command(angle, 3.0, None, None)
                    batched.joints.command(0, name, position=angle, velocity=3.0, copies=[c])
        for s in singles:
            s.step()
        batched.step()
        for c, s in enumerate(singles):
            pose, got = s.robot("bot").pose, batched.pose(c, 0)
            assert np.isfinite(pose.translation).all() and np.isfinite(pose.rotation).all(), (t, c)
            assert got.translation.tobytes() == pose.translation.tobytes(), (t, c, got.translation, pose.translation)
            assert got.rotation.tobytes() == pose.rotation.tobytes(), (t, c)
            drive = s.robot("bot").drive
            for i, turned in drive.free_turned.items():
                assert np.float64(batched.steered.free_turned[c, k, i]).tobytes() == np.float64(turned).tobytes(), \
                    (t, c, i)
            for name in motors:
                col = batched.steered.column(0, name)
                assert batched.steered.angle[c, col[0], col[1]] == s.robot("bot").motor(name).position, (t, c, name)


@pytest.fixture(params=["helper", "math"])
def native(request, monkeypatch):
    """The batched simulation with the packets helper's C pass or numpy's (``SENSORIUM_PACKETS=0``)."""
    use_packets(request.param == "helper", monkeypatch)
    return request.param


@pytest.mark.parametrize("examples", example_counts(120, 4))
def test_random_steered_drives_with_free_wheels_run_in_copies_as_simulation_bit_for_bit(native, examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(steered_robots(), st.integers(2, 3), st.integers(0, 2**31), st.booleans())
    def check(robot: dict, copies: int, seed: int, contact: bool) -> None:
        batched_as_single(robot, copies, seed, contact)

    check()


# ---------------------------------------------------------------- GPS degrees text
#
# Webots' libController writes "%d° %d′ %d″" of three C (int) conversions: D of the degrees, M of
# (degrees − D)·60 and S of ((degrees − D)·60 − M)·60, each truncated toward zero in float64 (x86-64's
# INT_MIN for NaN, infinities and values past int's range). The reference below computes the rule with
# numpy's float64 and trunc, apart from the clients' code; the Python client, the C library (through ctypes,
# the caller freeing the string) and the C++ class's static method must write its text for every double.

INT_MIN = -(1 << 31)


def dms_reference(value: float) -> str:
    def c_int(x: np.float64) -> int:
        if not np.isfinite(x) or not (-2.0 ** 31 - 1.0 < x < 2.0 ** 31):
            return INT_MIN
        return int(np.trunc(x))

    d = np.float64(value)
    with np.errstate(over="ignore", invalid="ignore"):          # past int's range: inf and NaN, INT_MIN
        degrees = c_int(d)
        part = (d - np.float64(degrees)) * np.float64(60.0)
        minutes = c_int(part)
        seconds = c_int((part - np.float64(minutes)) * np.float64(60.0))
    return f"{degrees}\u00b0 {minutes}\u2032 {seconds}\u2033"


@st.composite
def near_a_whole_second(draw) -> float:
    """A coordinate a hair away from D° M′ S″ (60″ and 60′ included, either sign): where truncation
    and float64 rounding decide the text."""
    whole = draw(st.integers(0, 180)) + draw(st.integers(0, 60)) / 60.0 + draw(st.integers(0, 60)) / 3600.0
    hair = draw(st.sampled_from([0.0, 1e-15, -1e-15, 1e-12, -1e-12, 1e-9, -1e-9]))
    sign = draw(st.sampled_from([1.0, -1.0]))
    return sign * (whole + hair)


degree_values = (st.floats() | near_a_whole_second()
                 | st.sampled_from([0.0, -0.0, 180.0, -180.0, 90.0, -90.0, 5e-324, -5e-324, -1e-300,
                                    2147483647.5, -2147483648.5, 2147483648.0, -2147483649.0, 1e300, -1e300,
                                    math.inf, -math.inf, math.nan, 40.66999864942021, -73.94])
                 | st.floats(-180.0, 180.0))


@pytest.mark.parametrize("examples", example_counts(4000, 4))
def test_the_python_client_writes_webots_degrees_text_for_every_double(examples: int) -> None:
    from sensorium.client import wb

    @settings(SETTINGS, max_examples=examples)
    @given(degree_values)
    def check(value: float) -> None:
        assert wb.wb_gps_convert_to_degrees_minutes_seconds(value) == dms_reference(value), value

    check()


def test_regression_the_degrees_text_of_values_at_the_edges() -> None:
    """The reference's own closed forms: −0 is 0, a tiny negative 0 everywhere, −1.5° is −1° −30′ 0″ and
    180° 180° 0′ 0″; int's end: 2147483647.5° keeps its degrees, 2147483648° is INT_MIN."""
    assert dms_reference(-0.0) == "0\u00b0 0\u2032 0\u2033"
    assert dms_reference(-1e-300) == "0\u00b0 0\u2032 0\u2033"
    assert dms_reference(-1.5) == "-1\u00b0 -30\u2032 0\u2033"
    assert dms_reference(-180.0) == "-180\u00b0 0\u2032 0\u2033"
    assert dms_reference(2147483647.5).startswith("2147483647\u00b0 30\u2032 0\u2033")
    assert dms_reference(2147483648.0).startswith("-2147483648\u00b0 ")


DMS_CPP = r"""
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <webots/GPS.hpp>
#include <webots/gps.h>
int main() {
  char line[128];
  while (std::fgets(line, sizeof line, stdin)) {
    const double value = std::strtod(line, nullptr);     /* C99's hexadecimal floats: every bit kept */
    const char *text = wb_gps_convert_to_degrees_minutes_seconds(value);
    std::cout << text << '|' << webots::GPS::convertToDegreesMinutesSeconds(value) << '\n';
    std::free((void *)text);
  }
  return 0;
}
"""


@pytest.mark.slow
def test_the_c_library_and_the_cpp_class_write_webots_degrees_text_for_every_double(tmp_path, clib) -> None:  # noqa: F811
    """Built against our libController: for 3000 doubles drawn as above (printed in C's hexadecimal, every
    bit kept) the C function's text and webots::GPS::convertToDegreesMinutesSeconds' are the reference's."""
    import subprocess

    from test_sweep18 import REPO

    if __import__("shutil").which("c++") is None:
        pytest.skip("needs a C++ compiler")
    build, libs = clib
    values: list[float] = []

    @settings(SETTINGS, max_examples=3000)
    @given(degree_values)
    def collect(value: float) -> None:
        values.append(value)

    collect()
    source = tmp_path / "dms.cpp"
    source.write_text(DMS_CPP)
    made = subprocess.run(["c++", f"-I{REPO / 'sensorium' / 'client' / 'c' / 'include'}", str(source), "-o",
                           str(tmp_path / "dms"), str(build / "libController.a"), *libs, "-lm"],
                          capture_output=True, text=True, timeout=300)
    assert made.returncode == 0, made.stderr
    ran = subprocess.run([str(tmp_path / "dms")], input="".join(f"{float(v).hex()}\n" for v in values),
                         capture_output=True, text=True, timeout=60)
    assert ran.returncode == 0, ran.stderr
    lines = ran.stdout.splitlines()
    assert len(lines) == len(values)
    for value, line in zip(values, lines):
        want = dms_reference(value)
        assert line == f"{want}|{want}", value


# ---------------------------------------------------------------- Display screens
#
# A Display (``Dw`` x ``Dh``) whose first child is a 1 m Plane on the floor, its appearance a PBRAppearance
# with black base and an ImageTexture as emissiveColorMap (no url, a url, or beside a url-less baseColorMap),
# no lights: what a camera sees of the plane is the display's image through the emissive path alone. The
# camera (W x W pixels, W a multiple of both sizes) 1 m above it looks straight down with tan(fov/2) = 1/2,
# its image up the world's +x and right its −y: pixel (j, i) sees the floor point x = (W/2 − j − ½)/W,
# y = (W/2 − i − ½)/W, the texel (⌊(x + ½)·Dw⌋, ⌊(½ − y)·Dh⌋) (column, row: the Plane's texture lies with
# its top row at +y), never within 1/2W of a texel's edge. Random drawing (colours, opacity, lines,
# rectangles, ovals, pixels, coordinates past the display's edges and far out) then: each channel of the
# camera is one non-decreasing function of the texel's channel (the tone mapping's, the same for every
# pixel), black for black, at every step a drawing changed the image.

SCREEN_WBT = """#VRML_SIM R2025a utf8
WorldInfo {{ basicTimeStep 16 }}
Robot {{
  children [
    Display {{
      children [
        Shape {{
          appearance PBRAppearance {{ baseColor 0 0 0 {maps} roughness 1 metalness 0 }}
          geometry Plane {{ }}
        }}
      ]
      name "screen"
      width {dw}
      height {dh}
    }}
  ]
  name "board"
  controller "<extern>"
}}
Robot {{
  translation 0 0 1
  rotation 0 1 0 1.5707963267948966
  children [ Camera {{ name "camera" width {w} height {w} fieldOfView {fov!r} }} ]
  name "eye"
  controller "<extern>"
}}
"""
SCREEN_MAPS = {"emissive": 'emissiveColorMap ImageTexture { filtering 0 }',
               "emissive url": 'emissiveColorMap ImageTexture { url "grey.png" filtering 0 }',
               "base and emissive": 'baseColorMap ImageTexture { } emissiveColorMap ImageTexture { filtering 0 }'}


def screen_world(folder, dw: int, dh: int, maps: str) -> tuple[object, int]:
    """The world above in ``folder`` (and its grey.png); its camera's width."""
    from PIL import Image

    w = math.lcm(dw, dh)
    w *= max(1, -(-16 // w))
    Image.fromarray(np.full((4, 4, 3), 77, np.uint8)).save(folder / "grey.png")
    path = folder / "screen.wbt"
    path.write_text(SCREEN_WBT.format(maps=SCREEN_MAPS[maps], dw=dw, dh=dh, w=w, fov=2 * math.atan(0.5)))
    return path, w


def seen_texels(dw: int, dh: int, w: int) -> tuple[np.ndarray, np.ndarray]:
    """Each camera pixel's texel (row, column arrays of w x w), by the closed form above."""
    j, i = np.meshgrid(np.arange(w), np.arange(w), indexing="ij")
    x, y = (w / 2 - j - 0.5) / w, (w / 2 - i - 0.5) / w
    return np.floor((0.5 - y) * dh).astype(int), np.floor((x + 0.5) * dw).astype(int)


def one_increasing_function(texel: np.ndarray, seen: np.ndarray) -> None:
    """``seen`` (n,) is f(``texel``) (n,) for one non-decreasing f with f(0) = 0 (the tone mapping is
    increasing, but its 8-bit output may give two near texel values one value: 64 and 65 both 129)."""
    pairs = np.unique(np.stack([texel, seen], axis=1), axis=0)
    values, counts = np.unique(pairs[:, 0], return_counts=True)
    assert (counts == 1).all(), f"texel values seen as two: {pairs[np.isin(pairs[:, 0], values[counts > 1])]}"
    assert (np.diff(pairs[:, 1].astype(int)) >= 0).all(), pairs
    if pairs[0, 0] == 0:
        assert pairs[0, 1] == 0, pairs


coord = st.integers(-6, 18) | st.sampled_from([-65536, 65536, -(2**31), 2**31 - 1])


def display_command(draw) -> list:
    op = draw(st.sampled_from(["color", "opacity", "pixel", "line", "rectangle", "oval"]))
    if op == "color":
        return ["color", draw(st.integers(0, 0xFFFFFF))]
    if op == "opacity":
        return ["opacity", draw(st.sampled_from([1.0, 1.0, 0.5, 0.25]))]
    if op == "pixel":
        return ["pixel", draw(coord), draw(coord)]
    if op == "line":
        return ["line", draw(coord), draw(coord), draw(coord), draw(coord)]
    small = st.integers(-6, 18)
    return [op, draw(small), draw(small), draw(st.integers(1, 20)), draw(st.integers(1, 20)), draw(st.booleans())]


@st.composite
def drawings(draw) -> list[list[list]]:
    return [[display_command(draw) for _ in range(draw(st.integers(1, 8)))] for _ in range(draw(st.integers(1, 4)))]


def a_camera_sees_the_screen_as_drawn(folder, dw: int, dh: int, maps: str, steps: list[list[list]]) -> None:
    path, w = screen_world(folder, dw, dh, maps)
    sim = Simulation(load_world(path), "exact")
    cam, display = sim.device("eye/camera"), sim.device("board/screen")
    cam.enable(16)
    rows, cols = seen_texels(dw, dh, w)
    for commands in [[]] + steps:
        display.apply(display.check(commands), sim.time_ms)
        sim.step()
        texels = np.asarray(display.pixels, dtype=np.uint32)[rows, cols]
        assert ((texels >> 24) == 0xFF).all()           # (opaque: no alpha drawn)
        image = np.asarray(cam.image)[..., :3].astype(np.uint8)     # B, G, R
        for k, shift in enumerate((0, 8, 16)):
            one_increasing_function(((texels >> shift) & 0xFF).ravel().astype(np.uint8), image[..., k].ravel())


@pytest.mark.parametrize("examples", example_counts(80, 4))
def test_a_camera_sees_a_display_s_random_drawing_on_its_screen_by_the_texel_closed_form(tmp_path, examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(st.integers(1, 10), st.integers(1, 10), st.sampled_from(sorted(SCREEN_MAPS)), drawings())
    def check(dw: int, dh: int, maps: str, steps: list[list[list]]) -> None:
        a_camera_sees_the_screen_as_drawn(tmp_path, dw, dh, maps, steps)

    check()


@pytest.mark.parametrize("maps", sorted(SCREEN_MAPS))
def test_regression_a_screen_whose_emissive_color_map_has_no_url_shows_the_image(tmp_path, maps: str) -> None:
    """Found by the property above: a screen whose PBRAppearance's ImageTexture without url is its
    emissiveColorMap stayed black (the image went to the base map, which its black base colour and no
    light show as black; WbDisplay replaces the emissiveColorMap's texture, and both maps when both are
    ImageTextures). A 4 x 2 display of eight colours, the camera's pixels by the closed form."""
    colours = [0x102030, 0xF0E0D0, 0x00FF00, 0x808080, 0xFF0000, 0x0000FF, 0x404000, 0xFFFFFF]
    a_camera_sees_the_screen_as_drawn(tmp_path, 4, 2, maps, [[c for k, colour in enumerate(colours) for c in (
        ["color", colour], ["pixel", k % 4, k // 4])]])
    from sensorium.server.world.loader import load_world

    sim = Simulation(load_world(tmp_path / "screen.wbt"), "exact")
    assert sim.world.robots[0].devices[0].screen_maps == (
        ["emissive_map"] if maps != "base and emissive" else ["texture", "emissive_map"])
    cam = sim.device("eye/camera")
    cam.enable(16)
    sim.device("board/screen").apply(sim.device("board/screen").check([["color", 0xFFFFFF],
                                                                       ["rectangle", 0, 0, 4, 2, True]]), 0)
    sim.step()
    assert (np.asarray(cam.image)[..., :3] > 150).all()          # white everywhere (black before the fix)


# ---------------------------------------------------------------- Poses, Transforms and Groups as nodes
#
# A top-level solid ROOT at (2, 0, 0) holding a random tree of Poses (translations on a 0.1 m grid, quarter
# turns about z), Transforms (scale 1), Groups and Box shapes (sizes 0.12, 0.26, 0.34: their faces never at
# y = 0 or z = 0 exactly), every node DEF'd N0, N1, ... A supervisor at the origin with a one-beam lidar
# along +x runs a random sequence of getFromDef (plain, dotted through the DEF'd ancestors, dotted past a
# level: NULL), children, world positions, remove(), exportString of a node then importMFNodeFromString of
# it inside a new solid, and simulationReset, against a model of the tree: ids stable, removed ones NULL
# (also after the reset, which takes the imported solids away), children in file order, positions the
# composed poses (1e-12), and after every operation the lidar's range the nearest box face on its beam
# (float32's 1e-6), inf for none.

QUARTERS = [np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
            np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
            np.array([[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]]),
            np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])]
ROOT_AT = np.array([2.0, 0.0, 0.0])
grid = st.integers(-4, 4).map(lambda k: k / 10.0)


@st.composite
def pose_trees(draw, depth: int = 0) -> list[dict]:
    """Children lists: each a dict type, translation, quarter (turns about z), size (Box), children."""
    out = []
    for _ in range(draw(st.integers(0 if depth else 1, 3))):
        kind = draw(st.sampled_from(["Pose", "Transform", "Group", "Shape"] if depth < 3 else ["Shape"]))
        node: dict = {"type": kind, "children": []}
        if kind in ("Pose", "Transform"):
            node["translation"] = [draw(grid), draw(grid), draw(grid)]
            node["quarter"] = draw(st.integers(0, 3))
        if kind == "Shape":
            node["size"] = [draw(st.sampled_from([0.12, 0.26, 0.34])) for _ in range(3)]
        else:
            node["children"] = draw(pose_trees(depth + 1))
        out.append(node)
    return out


def number_nodes(children: list[dict], parent: dict | None, out: list[dict]) -> None:
    for node in children:
        node["def"], node["parent"] = f"N{len(out)}", parent
        out.append(node)
        number_nodes(node["children"], node, out)


def vrml(node: dict, indent: str) -> str:
    inner = indent + "  "
    if node["type"] == "Shape":
        size = " ".join(repr(v) for v in node["size"])
        return f"{indent}DEF {node['def']} Shape {{ geometry Box {{ size {size} }} }}\n"
    head = f"{indent}DEF {node['def']} {node['type']} {{\n"
    if node["type"] != "Group":
        t = " ".join(repr(v) for v in node["translation"])
        head += f"{inner}translation {t}\n{inner}rotation 0 0 1 {node['quarter'] * math.pi / 2!r}\n"
    return head + f"{inner}children [\n" + "".join(vrml(c, inner + "  ") for c in node["children"]) + f"{inner}]\n{indent}}}\n"


def tree_world(children: list[dict]) -> str:
    return ("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 8 }\n"
            'DEF PROBE Robot { name "probe" supervisor TRUE controller "<extern>" children [ Lidar { name "lidar" '
            "horizontalResolution 1 fieldOfView 0.1 numberOfLayers 1 minRange 0.05 maxRange 10 } ] }\n"
            "DEF ROOT Solid {\n  translation 2 0 0\n  name \"root\"\n  children [\n"
            + "".join(vrml(c, "    ") for c in children) + "  ]\n}\n")


def world_frame(node: dict | None) -> tuple[np.ndarray, np.ndarray]:
    """(rotation, translation) of a node's frame in the world (a Group's: its parent's)."""
    if node is None:
        return np.eye(3), ROOT_AT.copy()
    rot, at = world_frame(node["parent"])
    if node["type"] in ("Pose", "Transform"):
        return rot @ QUARTERS[node["quarter"]], at + rot @ np.array(node["translation"])
    return rot, at


def alive(node: dict) -> bool:
    while node is not None:
        if node.get("removed"):
            return False
        node = node["parent"]
    return True


def copied(node: dict, parent: dict | None) -> dict:
    """A live subtree's copy (an imported exportString), its nodes marked ``copy``."""
    out = {"def": node["def"], "type": node["type"], "parent": parent, "copy": True}
    out["children"] = [copied(c, out) for c in node["children"] if not c.get("removed")]
    return out


def resolve(scene: list[dict], dotted: str) -> dict | None:
    """Webots' getFromDef in the model: the first live node of the path's first DEF in the scene tree's
    order (depth first, children in order), then each further name a live direct child of the last."""
    first, *rest = dotted.split(".")

    def search(nodes: list[dict]) -> dict | None:
        for n in nodes:
            if n.get("removed"):
                continue
            if n["def"] == first:
                return n
            hit = search(n["children"])
            if hit is not None:
                return hit
        return None

    at = search(scene)
    for name in rest:
        if at is None:
            return None
        at = next((c for c in at["children"] if c["def"] == name and not c.get("removed")), None)
    return at


def beam_range(nodes: list[dict]) -> float:
    """The nearest face x of a live box across the lidar's beam (y = z = 0, x > 0), inf for none."""
    best = math.inf
    for node in nodes:
        if node["type"] != "Shape" or not alive(node):
            continue
        rot, centre = world_frame(node["parent"])
        half = np.abs(rot) @ (np.array(node["size"]) / 2.0)
        if abs(centre[1]) < half[1] and abs(centre[2]) < half[2]:
            best = min(best, float(centre[0] - half[0]))
    return best


operations = st.lists(st.tuples(st.sampled_from(["find", "dotted", "skip", "children", "position", "remove",
                                                 "copy", "reset"]), st.integers(0, 1000)), min_size=1, max_size=8)


def supervisor_ops_follow_the_model(children: list[dict], ops: list[tuple[str, int]], folder) -> None:
    from test_supervisor import A, Live

    nodes: list[dict] = []
    number_nodes(children, None, nodes)
    path = folder / "tree.wbt"
    path.write_text(tree_world(children))
    lv = Live(Simulation(load_world(path)))
    lv.ok(A, "attach", {"robot": "probe"})

    def call(item: str, args: dict | None = None):
        return lv.ok(A, f"/probe/robot/{item}", args)

    def find(name: str) -> int:
        return call("get_from_def", {"name": name})["node"]

    def reading() -> float:
        lv.step(A, "probe")
        return float(np.asarray(lv.sim.robot("probe").device("lidar").range_image).reshape(-1)[0])

    lv.sim.robot("probe").device("lidar").enable(8)
    root = find("ROOT")
    ids = {n["def"]: find(n["def"]) for n in nodes}
    assert 0 not in ids.values() and len(set(ids.values())) == len(ids)
    copies = 0

    def check_range(what) -> None:
        want, got = beam_range(nodes), reading()
        assert got == want if math.isinf(want) else got == pytest.approx(want, abs=1e-6), (what, got, want)

    scene = [{"def": "ROOT", "type": "Solid", "children": children}]     # the root's solids: ROOT, then copies

    def expect(got: int, want: dict | None, what) -> None:
        if want is None:
            assert got == 0, what
        elif want.get("copy"):              # a copy's node: an id of its own
            assert got not in (0, *ids.values()), what
        else:
            assert got == ids[want["def"]], what

    check_range("start")
    for op, k in ops:
        node = nodes[k % len(nodes)]
        name = node["def"]
        if op == "find":
            expect(find(name), resolve(scene, name), (op, name))
        elif op == "dotted":                 # from a DEF'd ancestor (ROOT or any) down to it, level by level
            chain = [node]
            while chain[-1]["parent"] is not None:
                chain.append(chain[-1]["parent"])
            chain.append({"def": "ROOT"})
            start = k % len(chain)
            dotted = ".".join(n["def"] for n in reversed(chain[:start + 1]))
            expect(find(dotted), resolve(scene, dotted), (op, dotted))
        elif op == "skip":                   # a dotted path past a level names nothing
            if node["parent"] is not None:
                assert find(f"ROOT.{name}") == 0, (op, name)
        elif op == "children" and node["type"] != "Shape" and alive(node):
            want = [ids[c["def"]] for c in node["children"] if not c.get("removed")]
            assert call("get_field", {"node": ids[name], "field": "children"})["value"] == want, (op, name)
        elif op == "position" and node["type"] in ("Pose", "Transform") and alive(node):
            got = call("get_node_pose", {"node": ids[name]})
            rot, at = world_frame(node)
            assert got["position"] == pytest.approx(at.tolist(), abs=1e-12), (op, name)
            assert got["orientation"] == pytest.approx(rot.reshape(-1).tolist(), abs=1e-12), (op, name)
        elif op == "remove" and alive(node):
            call("remove_node", {"node": ids[name]})
            node["removed"] = True
            expect(find(name), resolve(scene, name), (op, name))
            check_range(("remove", name))
        elif op == "copy" and alive(node):   # its text imported inside a new solid far off the beam
            text = call("node_export_string", {"node": ids[name]})["value"]
            copies += 1
            call("import_node_from_string", {"node": 0, "field": "children", "position": -1, "node_string":
                                             f"DEF C{copies} Solid {{ translation 0 {4 + copies} 0 name \"c{copies}\" "
                                             f"children [ {text} ] }}"})
            scene.append({"def": f"C{copies}", "type": "Solid", "children": [copied(node, None)]})
            copy = find(f"C{copies}.{name}")
            assert copy not in (0, *ids.values()), (op, name)
            again = call("node_export_string", {"node": copy})["value"]
            assert again == text, (op, name)
            if node["type"] != "Shape":
                live_children = [c for c in node["children"] if not c.get("removed")]
                assert len(call("get_field", {"node": copy, "field": "children"})["value"]) == len(live_children)
            check_range(("copy", name))
        elif op == "reset":
            call("simulation_reset")
            del scene[1:]                    # the imported solids go (README: as in Webots); removed nodes stay
            lv.sim.robot("probe").device("lidar").enable(8)
            check_range("reset")
    assert call("get_field", {"node": root, "field": "children"})["value"] == [
        ids[c["def"]] for c in children if not c.get("removed")]
    exported = call("node_export_string", {"node": root})["value"]      # the live nodes, in file order
    assert re.findall(r"DEF (N\d+) ", exported) == [n["def"] for n in nodes if alive(n)]


@pytest.mark.parametrize("examples", example_counts(400, 8))
def test_supervisor_operations_on_a_solid_s_poses_follow_a_model_of_the_tree(tmp_path, examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(pose_trees(), operations)
    def check(children: list[dict], ops: list[tuple[str, int]]) -> None:
        supervisor_ops_follow_the_model(children, ops, tmp_path)

    check()


# ---------------------------------------------------------------- a tracked robot's rest on its Tracks
#
# A robot with Physics on two Tracks (test_wbt_tracks' belts at y = ±0.15, each its own random height),
# each Track's boundingObject one to three Boxes, Spheres, Cylinders and Capsules, each in a Pose (a random
# translation and rotation) in a Transform (a translation and a uniform scale 0.5, 1 or 2) and maybe a Shape
# and a Group: dropped onto the floor it rests with its origin over the lowest point of them all, the closed
# form of each geometry's lowest point along z (a Box's corner: Σ|R₂ⱼ|·hⱼ below its centre; a Cylinder's rim:
# |R₂₁|·h/2 + r·√(1 − R₂₁²); a Capsule's cap: |R₂₁|·h/2 + r), to 1e-12.

def axis_angle(axis, angle: float) -> np.ndarray:
    a = np.asarray(axis, dtype=np.float64)
    x, y, z = a / np.linalg.norm(a)
    c, s, t = math.cos(angle), math.sin(angle), 1.0 - math.cos(angle)
    return np.array([[t * x * x + c, t * x * y - s * z, t * x * z + s * y],
                     [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
                     [t * x * z - s * y, t * y * z + s * x, t * z * z + c]])


length = st.sampled_from([0.02, 0.05, 0.1]) | st.floats(0.01, 0.3)
offset = st.floats(-0.1, 0.1).map(_plain)


@st.composite
def bound_pieces(draw) -> dict:
    kind = draw(st.sampled_from(["Box", "Sphere", "Cylinder", "Capsule"]))
    sizes = {"Box": {"size": [draw(length), draw(length), draw(length)]}, "Sphere": {"radius": draw(length)},
             "Cylinder": {"radius": draw(length), "height": draw(length)},
             "Capsule": {"radius": draw(length), "height": draw(length)}}[kind]
    axis = [draw(st.sampled_from([0.0, 1.0, -0.5]) | st.floats(-1.0, 1.0).map(_plain)) for _ in range(3)]
    if max(abs(v) for v in axis) < 0.1:
        axis = [0.0, 0.0, 1.0]
    return {"kind": kind, **sizes, "axis": axis, "angle": draw(st.floats(-3.2, 3.2).map(_plain)),
            "pose": [draw(offset), draw(offset), draw(st.floats(-0.2, -0.05))],
            "move": [draw(offset), draw(offset), draw(offset)], "scale": draw(st.sampled_from([0.5, 1.0, 2.0])),
            "shape": draw(st.booleans()), "group": draw(st.booleans())}


def piece_vrml(p: dict) -> str:
    fields = " ".join(f"{k} {' '.join(repr(v) for v in p[k]) if isinstance(p[k], list) else repr(p[k])}"
                      for k in ("size", "radius", "height") if k in p)
    geometry = f"{p['kind']} {{ {fields} }}"
    if p["shape"]:
        geometry = f"Shape {{ geometry {geometry} }}"
    axis = " ".join(repr(v) for v in p["axis"])
    text = (f"Transform {{ translation {' '.join(repr(v) for v in p['move'])} scale {p['scale']!r} {p['scale']!r} "
            f"{p['scale']!r} children [ Pose {{ translation {' '.join(repr(v) for v in p['pose'])} rotation {axis} "
            f"{p['angle']!r} children [ {geometry} ] }} ] }}")
    return f"Group {{ children [ {text} ] }}" if p["group"] else text


def piece_lowest(p: dict, track_z: float) -> float:
    r = axis_angle(p["axis"], p["angle"])
    if p["kind"] == "Box":
        below = float(np.abs(r[2]) @ (np.array(p["size"]) / 2.0))
    elif p["kind"] == "Sphere":
        below = p["radius"]
    else:
        a = abs(float(r[2, 2]))      # a Cylinder's and a Capsule's axis: their z (Webots R2022a+)
        rim = p["radius"] if p["kind"] == "Capsule" else p["radius"] * math.sqrt(max(0.0, 1.0 - a * a))
        below = a * p["height"] / 2.0 + rim
    return track_z + p["move"][2] + p["scale"] * (p["pose"][2] - below)


def tracked_world(folder, tracks: list[tuple[float, list[dict]]], heading: float = 0.0, backwards: bool = False):
    text = []
    turned = " rotation 0 0 1 3.141592653589793" if backwards else ""     # (a turn about up: the same bottom)
    for (z, pieces), side, y in zip(tracks, ("left", "right"), (0.15, -0.15)):
        bounds = pieces[0] if len(pieces) == 1 else {"group": False, "raw": pieces}
        bo = piece_vrml(bounds) if "raw" not in bounds else \
            "Group { children [ " + " ".join(piece_vrml(p) for p in pieces) + " ] }"
        text.append(f'Track {{ translation 0 {y} {z!r}{turned} name "{side} track" boundingObject {bo} children [\n'
                    '  TrackWheel { position -0.1 0 radius 0.05 }\n  TrackWheel { position 0.1 0 radius 0.05 }\n'
                    f'] device [ LinearMotor {{ name "{side} motor" }} ] }}\n')
    path = folder / "tracked.wbt"
    path.write_text('#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 10 }\n'
                    f'Robot {{ name "tank" translation 0 0 2 rotation 0 0 1 {heading!r} children [\n'
                    '  DEF BODY Shape { geometry Box { size 0.2 0.2 0.04 } }\n' + "".join(text)
                    + '] boundingObject USE BODY physics Physics { } }\n'
                    'Solid { name "floor" children [ DEF F Shape { geometry Plane { size 10 10 } } ] '
                    "boundingObject USE F }\n")
    return path


@pytest.mark.parametrize("examples", example_counts(200, 4))
def test_a_tracked_robot_rests_on_the_lowest_point_of_its_tracks_bounding_objects(tmp_path, examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(st.lists(st.tuples(st.floats(-0.05, 0.05).map(_plain), st.lists(bound_pieces(), min_size=1, max_size=3)),
                    min_size=2, max_size=2), st.floats(-3.2, 3.2).map(_plain), st.booleans())
    def check(tracks: list[tuple[float, list[dict]]], heading: float, backwards: bool) -> None:
        w = load_world(tracked_world(tmp_path, tracks, heading, backwards))
        bottom = min(piece_lowest(p, z) for z, pieces in tracks for p in pieces)
        assert w.world.robots[0].differential_drive.wheel_bottom == pytest.approx(bottom, abs=1e-12)
        sim = Simulation(w)
        sim.step()
        assert sim.robot("tank").pose.translation == pytest.approx([0.0, 0.0, -bottom], abs=1e-12)

    check()


# ---------------------------------------------------------------- a bumper touching its robot's own parts
#
# A robot (selfCollision TRUE or FALSE) with a bumper box of random size at (0.1, 0, 0.05) on its body, a
# slider "a" (along x) on the body whose end point "first" (a random box) starts on the bumper, and a slider
# "b" (along y) on "first" whose end point "second" (a random box) starts 0.3 m beside it. Both sliders
# driven to random positions: once there, the bumper reads 1 exactly when selfCollision is TRUE and
# second's box overlaps the bumper's (axis-aligned boxes: |Δ| < (s₁ + s₂)/2 on every axis), never for
# "first", consecutive to the body (cases within 1e-3 of touching left out).

def bumper_world(folder, flag: str, stop: list[float], first: list[float], second: list[float]):
    def box(size: list[float]) -> str:
        return f"boundingObject Box {{ size {' '.join(repr(v) for v in size)} }}"

    path = folder / "own_stop.wbt"
    path.write_text("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 32 }\n"
                    f'Robot {{ name "r" selfCollision {flag} children [\n'
                    f'  TouchSensor {{ translation 0.1 0 0.05 name "stop" {box(stop)} }}\n'
                    '  SliderJoint { jointParameters JointParameters { axis 1 0 0 } device [ LinearMotor { name "a" '
                    'minPosition -1 maxPosition 1 } ]\n'
                    f'    endPoint Solid {{ translation 0.1 0 0.05 name "first" {box(first)} children [\n'
                    '      SliderJoint { jointParameters JointParameters { axis 0 1 0 } device [ LinearMotor { name "b" '
                    'minPosition -1 maxPosition 1 } ]\n'
                    f'        endPoint Solid {{ translation 0 0.3 0 name "second" {box(second)} }} }} ] }} }} ] }}\n')
    return path


box_size = st.lists(st.sampled_from([0.02, 0.05, 0.1]) | st.floats(0.01, 0.2), min_size=3, max_size=3)
slide_a = st.floats(-0.15, 0.15).map(_plain)
slide_b = st.floats(-0.45, -0.15).map(_plain) | st.floats(-0.6, 0.2).map(_plain)   # mostly near over the bumper


@pytest.mark.parametrize("examples", example_counts(120, 4))
def test_a_bumper_reads_the_overlap_of_its_robots_own_non_consecutive_part(tmp_path, examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(st.sampled_from(["TRUE", "FALSE"]), box_size, box_size, box_size, slide_a, slide_b)
    def check(flag: str, stop: list[float], first: list[float], second: list[float], a: float, b: float) -> None:
        gap = np.abs(np.array([a, 0.3 + b, 0.0])) - (np.array(stop) + np.array(second)) / 2.0
        closest = float(gap.max())                # < 0: overlapping; > 0: apart
        if abs(closest) < 1e-3:
            return
        sim = Simulation(load_world(bumper_world(tmp_path, flag, stop, first, second)), "exact")
        sensor = sim.device("r/stop")
        sensor.enable(32)
        robot = sim.robot("r")
        robot.motor("a").set_position(a)
        robot.motor("b").set_position(b)
        for _ in range(400):                      # until both sliders are there (10 m/s at most)
            sim.step()
            if robot.motor("a").position == a and robot.motor("b").position == b:
                break
        sim.step()
        assert (robot.motor("a").position, robot.motor("b").position) == (a, b)
        assert sensor.value == (1.0 if flag == "TRUE" and closest < 0.0 else 0.0), (closest, flag)

    check()
