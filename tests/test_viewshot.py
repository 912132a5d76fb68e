"""Pictures of the world without a GPU (server/sim/viewshot.py): the Viewpoint's view, a
Supervisor's labels over it, ``exportImage``/``setLabel`` through the services and from the Python
and C clients, and ``sensorium snapshot``.

tests/worlds/viewshot.wbt: the Viewpoint at (0, 0, 0.5) looks along +x (fieldOfView Φ = 0.785398),
a red box (0.5 m) at (5, 0, 0.5) and a green one at (5, 1.2, 0.5), lit head-on by one directional
light (direction +x, intensity 1, no ambient term, no shadows), a black sky. A front face (x = 4.75,
normal −x) therefore has the radiance ``albedo · 1`` and the byte ``⌊255·(1 − e⁻¹)^(1/2.2) + ½⌋``
in its colour's channel; the boxes' sides (normals ±y, ±z) get no light; the sky is 0. A pixel
(row r, column j) of a W × H picture looks along ``(1, (1 − 2u)·t, (1 − 2v)·t·H/W)`` with
``u = (j + ½)/W``, ``v = (r + ½)/H``, ``t = tan(Φ/2)`` (the pinhole; Φ across the wider side)."""

from __future__ import annotations

import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from sensorium.schemas.wire import ErrorCode
from sensorium.server.sim import display, viewshot
from sensorium.server.sim.simulation import Simulation

REPO = Path(__file__).resolve().parents[1]
WORLD = REPO / "tests" / "worlds" / "viewshot.wbt"
FOV = 0.785398
FACE = math.floor(255.0 * (1.0 - math.exp(-1.0)) ** (1.0 / 2.2) + 0.5)     # 207


@pytest.fixture(scope="module")
def sim() -> Simulation:
    return Simulation.from_file(WORLD)


def lateral(j: int, w: int, depth: float) -> float:
    """Where column j's ray meets the plane at ``depth`` ahead: its y (left of the view is +y)."""
    u = (j + 0.5) / w
    return (1.0 - 2.0 * u) * math.tan(FOV / 2.0) * depth


def vertical(r: int, w: int, h: int, depth: float) -> float:
    v = (r + 0.5) / h
    return (1.0 - 2.0 * v) * math.tan(FOV / 2.0) * h / w * depth


def test_the_view_is_the_pinhole_camera_of_the_viewpoint_in_closed_form(sim: Simulation) -> None:
    W, H = 640, 480
    img = viewshot.render(sim, W, H)
    assert img.shape == (H, W, 3) and img.dtype == np.uint8
    assert img[H // 2, W // 2].tolist() == [FACE, 0, 0]        # the red box straight ahead
    assert img[0, 0].tolist() == [0, 0, 0]                      # the black sky
    depth, row = 4.75, H // 2                                   # the front faces' plane; a row through both boxes
    for j in range(W):
        y = lateral(j, W, depth)
        red, green = abs(y) < 0.25, 0.95 < y < 1.45
        if min(abs(abs(y) - 0.25), abs(y - 0.95), abs(y - 1.45)) < 1e-6:
            continue                                            # a ray on an edge: either answer
        want = [FACE, 0, 0] if red else [0, FACE, 0] if green else [0, 0, 0]
        assert img[row, j].tolist() == want, (j, y)
    for r in range(H):                                          # the red box's column: its face's height
        z = vertical(r, W, H, depth)
        if abs(abs(z) - 0.25) > 1e-6:
            assert img[r, W // 2].tolist() == ([FACE, 0, 0] if abs(z) < 0.25 else [0, 0, 0]), (r, z)
    # the green face's centre (4.75, 1.2, 0.5) projects to u = ½ − 1.2/(4.75·t)/2: that pixel is green
    u = 0.5 - 1.2 / (4.75 * math.tan(FOV / 2.0)) / 2.0
    assert img[row, int(u * W)].tolist() == [0, FACE, 0]


def test_a_portrait_picture_spans_the_field_of_view_vertically(sim: Simulation) -> None:
    """Webots' viewpoint: fieldOfView across the larger side, so a 240 × 480 picture's rows span
    Φ and its columns 2·atan(t·W/H)."""
    W, H = 240, 480
    img = viewshot.render(sim, W, H)
    t = math.tan(FOV / 2.0)
    for r in range(H):
        z = (1.0 - 2.0 * (r + 0.5) / H) * t * 4.75
        if abs(abs(z) - 0.25) > 1e-6:
            assert img[r, W // 2].tolist() == ([FACE, 0, 0] if abs(z) < 0.25 else [0, 0, 0]), r
    for j in range(W):
        y = (1.0 - 2.0 * (j + 0.5) / W) * t * W / H * 4.75     # the green box's edge y = 0.95 is in view too
        if min(abs(abs(y) - 0.25), abs(y - 0.95)) > 1e-6:
            want = [FACE, 0, 0] if abs(y) < 0.25 else [0, FACE, 0] if y > 0.95 else [0, 0, 0]
            assert img[H // 2, j].tolist() == want, j


def _label_box(img: np.ndarray, color: tuple[int, int, int]) -> tuple[int, int, int, int, int]:
    ys, xs = np.nonzero((img == np.array(color, dtype=np.uint8)).all(axis=-1))
    return int(xs.min()), int(ys.min()), int(xs.max()), int(ys.max()), len(xs)


def test_a_label_is_drawn_at_x_w_y_h_in_its_colour_at_its_size(sim: Simulation) -> None:
    W, H = 640, 480
    base = viewshot.render(sim, W, H)
    labels = viewshot.Labels()
    labels.set(4, "Hi", 0.25, 0.1, 0.1, 0x0000FF, 0.0, "Arial")
    out = viewshot.draw_labels(base, labels)
    k = viewshot.label_scale(0.1, H)                 # each glyph pixel a k x k square
    assert k == max(1, math.floor(0.1 * H / display.line_height() + 0.5))
    [(gx, gy)] = display.text_lines("Hi")
    x0, y0 = math.floor(0.25 * W), math.floor(0.1 * H)
    assert _label_box(out, (0, 0, 255)) == (x0 + k * int(gx.min()), y0 + k * int(gy.min()),
                                             x0 + k * int(gx.max()) + k - 1, y0 + k * int(gy.max()) + k - 1,
                                             k * k * len(gx))
    changed = (out != base).any(axis=-1)
    assert changed.sum() == k * k * len(gx)          # nothing else touched
    # half transparent over the black sky: WbDisplay's integer blend, opacity 255 - int(0.5 * 255) = 128
    labels.set(4, "Hi", 0.25, 0.1, 0.1, 0x0000FF, 0.5, "Arial")
    half = viewshot.draw_labels(base, labels)
    assert half[changed].tolist() == [[0, 0, (128 * 255) // 255]] * int(changed.sum())
    # the same id again replaces the label; a label past the right edge draws nothing
    labels.set(4, "Hi", 1.0, 0.1, 0.1, 0x0000FF, 0.0, "Arial")
    assert (viewshot.draw_labels(base, labels) == base).all()


def test_label_and_picture_bounds_are_one_line_each() -> None:
    labels = viewshot.Labels()
    bad = [((65535, "t", 0.1, 0.1, 0.1, 0, 0.0, "Arial"), "label id must be an integer in 0..65534"),
           ((1 << 40, "t", 0.1, 0.1, 0.1, 0, 0.0, "Arial"), "label id"),
           ((1, "t", math.nan, 0.1, 0.1, 0, 0.0, "Arial"), "label x must be a number in [0, 1]"),
           ((1, "t", 0.1, 1.5, 0.1, 0, 0.0, "Arial"), "label y"),
           ((1, "x" * 1025, 0.1, 0.1, 0.1, 0, 0.0, "Arial"), "at most 1024 characters"),
           ((1, "tab\t", 0.1, 0.1, 0.1, 0, 0.0, "Arial"), "only characters 32..127"),
           ((1, "t", 0.1, 0.1, 0.1, 1 << 24, 0.0, "Arial"), "0xRRGGBB")]
    for args, words in bad:
        with pytest.raises(ValueError, match=re.escape(words)) as exc:
            labels.set(*args)
        assert "\n" not in str(exc.value)
    assert len(labels) == 0
    for i in range(viewshot.MAX_LABELS):
        labels.set(i, "t", 0.0, 0.0, 0.0, 0, 0.0, "Arial")
    with pytest.raises(ValueError, match="at most 256 labels"):
        labels.set(viewshot.MAX_LABELS, "t", 0.0, 0.0, 0.0, 0, 0.0, "Arial")
    labels.set(0, "again", 0.0, 0.0, 0.0, 0, 0.0, "Arial")       # an existing id still changes
    for size in ("0x10", "5000x10", "3000x3000", "640*480", "abc"):
        with pytest.raises(ValueError):
            viewshot.parse_size(size)
    assert viewshot.parse_size("320X240") == (320, 240)


# ---------------------------------------------------------------------- the services

def _live():
    from test_supervisor import A, Live
    lv = Live(Simulation.from_file(WORLD))
    lv.ok(A, "attach", {"robot": "boss"})
    return lv, A


def test_export_image_sends_the_pictures_pixels_with_the_labels_and_set_label_checks_its_arguments() -> None:
    lv, A = _live()
    assert lv.ok(A, "/boss/robot/set_label", {"id": 9, "text": "Sensorium", "x": 0.05, "y": 0.05, "size": 0.1,
                                              "color": 0x0000FF, "transparency": 0.0, "font": "Arial"}) == {"success": True}
    got = lv.ok(A, "/boss/robot/export_image")
    W, H = viewshot.EXPORT_SIZE
    assert (got["width"], got["height"]) == (640, 480) == (W, H)
    img = np.frombuffer(got["data"], dtype=np.uint8).reshape(H, W, 3)
    labels = viewshot.Labels()
    labels.set(9, "Sensorium", 0.05, 0.05, 0.1, 0x0000FF, 0.0, "Arial")
    assert (img == viewshot.draw_labels(viewshot.render(lv.sim, W, H), labels)).all()
    assert img[H // 2, W // 2].tolist() == [FACE, 0, 0] and _label_box(img, (0, 0, 255))[4] > 0
    good = {"id": 1, "text": "t", "x": 0.1, "y": 0.1, "size": 0.1, "color": 0, "transparency": 0.0, "font": "Arial"}
    for change in ({"id": 65535}, {"id": 1 << 40}, {"x": math.nan}, {"y": -0.1}, {"size": 2.0}, {"color": -1},
                   {"text": "x" * 1025}, {"text": "\x01"}):
        msg = lv.err(A, "/boss/robot/set_label", {**good, **change}, ErrorCode.INVALID_ARGUMENT)
        assert "\n" not in msg


# ---------------------------------------------------------------------- the clients

def _serve_and_run(argv, out: Path, env: dict[str, str] | None = None) -> tuple[list[str], str]:
    from _serve import Proc, serve
    with serve(WORLD, "--mode", "fast") as server:
        url = server.url("boss")
        proc = Proc(argv(url), env={**(env or {}), "VIEWSHOT_OUT": str(out), "SENSORIUM_CONTROLLER_URL": url})
        try:
            code = proc.wait(120)
        finally:
            proc.stop()
        assert code == 0, proc.stderr()
        return proc.stdout().splitlines(), proc.stderr()


REFUSED = ["Error: wb_supervisor_set_label() called with an 'id' outside of [0,65534] (70000).",
           "Error: wb_supervisor_set_label() called with x parameter outside of [0,1] range.",
           "Error: wb_supervisor_set_label() called with a 'color' that is no 0xRRGGBB value (-1).",
           "(the server's refusal of a tab)",
           "Error: wb_supervisor_export_image() called with NULL or empty 'filename' argument.",
           "Error: wb_supervisor_export_image(): unsupported image format of '{out}/view.bmp' (use .png, .jpg or "
           ".jpeg).",
           "Error: wb_supervisor_export_image(): 'quality' argument (0) must be between 1 and 100."]


def _expected_picture() -> np.ndarray:
    """The controllers' sequence in process: label 7, then label 2 replaced by "half"."""
    s = Simulation.from_file(WORLD)
    s.step()
    labels = viewshot.Labels()
    labels.set(7, "Sensorium", 0.05, 0.05, 0.1, 0x0000FF, 0.0, "Arial")
    labels.set(2, "half", 0.6, 0.85, 0.05, 0xFFFFFF, 0.5, "Impact")
    return viewshot.picture(s, *viewshot.EXPORT_SIZE, labels)


def _check_files(out: Path, lines: list[str], err: str) -> np.ndarray:
    assert lines == ["done"], err
    errors = [line for line in err.splitlines() if line.startswith("Error")]
    want = [line.replace("{out}", str(out)) for line in REFUSED]
    # the server's refusal: each client's usual line for it (C names the error code), the server's words
    server = "set_label: label 3 text has '\\t': only characters 32..127 (and newlines) are displayed"
    assert errors[3].startswith("Error: wb_supervisor_set_label(): ") and server in errors[3], err
    assert errors[:3] + errors[4:] == want[:3] + want[4:], err
    assert "not served" not in err
    assert sorted(p.name for p in out.iterdir()) == ["view.jpg", "view.png"]     # no temporary left behind
    with Image.open(out / "view.png") as im:
        assert (im.format, im.mode, im.size) == ("PNG", "RGB", (640, 480))
        png = np.asarray(im)
    with Image.open(out / "view.jpg") as im:
        assert (im.format, im.size) == ("JPEG", (640, 480))
        jpg = np.asarray(im.convert("RGB")).astype(int)
    assert (png == _expected_picture()).all()
    assert abs(jpg[240, 320] - np.array([FACE, 0, 0])).max() <= 12        # lossy, but the red box
    return png


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX paths")
def test_the_python_and_c_clients_write_the_same_png_and_a_jpeg(tmp_path: Path, tmp_path_factory) -> None:
    from _serve import sensorium
    from test_c_client import SAN_ENV, sanitized_controller
    py_out, c_out = tmp_path / "py", tmp_path / "c"
    py_out.mkdir()
    c_out.mkdir()
    lines, err = _serve_and_run(lambda url: sensorium("controller", "--url", url,
                                                      str(REPO / "tests" / "controllers" / "viewshot.py")), py_out)
    py_png = _check_files(py_out, lines, err)
    exe = sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "viewshot.c")
    lines, err = _serve_and_run(lambda url: [exe], c_out, SAN_ENV)
    assert "Sanitizer" not in err and "runtime error" not in err, err
    c_png = _check_files(c_out, lines, err)
    assert (py_png == c_png).all()


# ---------------------------------------------------------------------- sensorium snapshot

def _snapshot(*args: str) -> subprocess.CompletedProcess:
    from _serve import sensorium
    return subprocess.run(sensorium("snapshot", *args), capture_output=True, text=True, timeout=300, cwd=str(REPO))


def test_snapshot_writes_png_or_jpeg_by_extension_and_never_overwrites_unasked(tmp_path: Path) -> None:
    png, jpg = tmp_path / "a.png", tmp_path / "a.JPG"
    done = _snapshot(str(WORLD), str(png), "--size", "320x240")
    assert done.returncode == 0, done.stderr
    with Image.open(png) as im:
        assert (im.format, im.size) == ("PNG", (320, 240))
        got = np.asarray(im)
    assert (got == viewshot.render(Simulation.from_file(WORLD), 320, 240)).all()
    done = _snapshot(str(WORLD), str(jpg), "--size", "320x240", "--quality", "80")
    assert done.returncode == 0, done.stderr
    with Image.open(jpg) as im:
        assert im.format == "JPEG"
    png.write_bytes(b"the user's file")
    done = _snapshot(str(WORLD), str(png))
    assert done.returncode == 1 and png.read_bytes() == b"the user's file"
    assert done.stderr.strip().splitlines() == [f"snapshot: {png}: exists; not overwriting it (use --force)"]
    done = _snapshot(str(WORLD), str(png), "--force", "--steps", "2")
    assert done.returncode == 0, done.stderr
    with Image.open(png) as im:
        assert im.size == (640, 480)


@pytest.mark.parametrize(("args", "line"), [
    (["x.bmp"], "snapshot: {tmp}/x.bmp: the picture must end in .png, .jpg or .jpeg"),
    (["x.png", "--size", "99999x2"], "snapshot: image width must be an integer in 1..4096, got 99999"),
    (["x.png", "--size", "big"], "snapshot: size must be WIDTHxHEIGHT (e.g. 640x480), got 'big'"),
    (["x.jpg", "--quality", "0"], "snapshot: --quality must be in 1..100, got 0"),
    (["x.png", "--steps", "-1"], "snapshot: --steps must be in 0..1000000, got -1"),
])
def test_snapshot_bad_input_is_one_line_and_exit_1(tmp_path: Path, args: list[str], line: str) -> None:
    done = _snapshot(str(WORLD), str(tmp_path / args[0]), *args[1:])
    assert done.returncode == 1
    assert done.stderr.strip().splitlines() == [line.replace("{tmp}", str(tmp_path))]
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(("args", "line"), [
    # found by the hardening pass: each was a traceback, a message naming Python's int() or a check
    # made only after the world was loaded
    (["{tmp}/" + "a" * 300 + ".png"], "snapshot: {tmp}/" + "a" * 300 + ".png: File name too long"),
    (["{tmp}/d.png"], "snapshot: {tmp}/d.png: is a directory; give the picture's file name"),
    (["{tmp}/d.png", "--force"], "snapshot: {tmp}/d.png: is a directory; give the picture's file name"),
    (["{tmp}/x.png", "--size", "\u00b2x2"], "snapshot: size must be WIDTHxHEIGHT (e.g. 640x480), got '\u00b2x2'"),
    (["{tmp}/x.png", "--size", "1" * 5000 + "x2"], "snapshot: size must be WIDTHxHEIGHT (e.g. 640x480), got '"
                                                    + "1" * 5000 + "x2'"),
    (["{tmp}/x.png", "--steps", "1000001"], "snapshot: --steps must be in 0..1000000, got 1000001"),
    (["{tmp}/x", "--size", "1x1"], "snapshot: {tmp}/x: the picture must end in .png, .jpg or .jpeg"),
])
def test_snapshot_odd_paths_sizes_and_steps_are_one_line(tmp_path: Path, capsys, args: list[str], line: str) -> None:
    from sensorium.cli import main

    (tmp_path / "d.png").mkdir()
    assert main(["snapshot", str(WORLD), *(a.replace("{tmp}", str(tmp_path)) for a in args)]) == 1
    assert capsys.readouterr().err.splitlines() == [line.replace("{tmp}", str(tmp_path))]
    assert [p.name for p in tmp_path.iterdir()] == ["d.png"]


def test_a_viewpoint_that_makes_no_picture_is_one_line(tmp_path: Path) -> None:
    world = tmp_path / "w.yaml"
    world.write_text("top_nodes:\n  - type: Viewpoint\n    fields: {fieldOfView: 3.5}\n")
    done = _snapshot(str(world), str(tmp_path / "x.png"))
    assert done.returncode == 1
    assert done.stderr.strip().splitlines()[-1] == (
        f"snapshot: {world}: Viewpoint fieldOfView must be in (0, pi) for a picture, got 3.5")
    assert not (tmp_path / "x.png").exists()


BUNDLED = sorted(p.name for p in (REPO / "sensorium" / "worlds").iterdir() if p.suffix in (".yaml", ".wbt"))


@pytest.mark.parametrize("name", BUNDLED)
def test_each_bundled_world_is_pictured_from_a_viewpoint_that_looks_down_at_it(name: str) -> None:
    """A bundled world's Viewpoint looks down at the world: its optical axis (the pose's x) meets
    the ground z = 0 within 1 m of the box the solids' and robots' positions span, and the middle
    third of a picture is (nearly) all geometry, not sky. Webots' default Viewpoint ((-10, 0, 0) looking along +x),
    which the worlds without one had, showed a black picture with a speck or a wall edge-on."""
    sim = Simulation.from_file(REPO / "sensorium" / "worlds" / name)
    pose = viewshot.viewpoint_of(sim).pose()
    rot = pose.rotation
    eye, axis = np.asarray(pose.translation, float), rot[:, 0]
    assert axis[2] < 0.0, f"{name}: the Viewpoint looks up or level ({axis})"
    ground = eye + axis * (-eye[2] / axis[2])
    xy = np.array([s.pose.translation[:2] for s in sim.world.solids]
                  + [r.pose.translation[:2] for r in sim.world.robots])
    lo, hi = xy.min(axis=0) - 1.0, xy.max(axis=0) + 1.0
    assert np.all(lo <= ground[:2]) and np.all(ground[:2] <= hi), (name, ground, lo, hi)
    rgb = viewshot.render(sim, 48, 36)
    sky = viewshot.shading.to_bytes(viewshot.shading.tone_map(sim.scene.background.reshape(1, 3), 1.0))[0]
    middle = rgb[12:24, 16:32].reshape(-1, 3)
    assert np.mean(np.all(middle == sky, axis=1)) < 0.05, f"{name}: sky in the middle of the picture"


def test_snapshot_of_a_world_without_a_viewpoint_says_so_in_one_line(tmp_path: Path) -> None:
    """Webots' default Viewpoint stands at ground level 10 m away: a world without one of its own
    (most hand-written YAML worlds) gave a black picture and no hint why."""
    world = tmp_path / "w.yaml"
    world.write_text("solids:\n  - {name: floor, geometry: {type: plane, size: [2.0, 2.0]}}\n")
    done = _snapshot(str(world), str(tmp_path / "x.png"))
    assert done.returncode == 0, done.stderr
    assert done.stderr.strip().splitlines() == [
        f"snapshot: {world}: no Viewpoint placed: Webots' default one, at (-10, 0, 0) looking along +x at ground level, "
        "which may show little; list one in the world (README 'World files')"]
    assert (tmp_path / "x.png").exists()
    done = _snapshot(str(WORLD), str(tmp_path / "y.png"))          # a world with its own: no such line
    assert done.returncode == 0 and "Viewpoint" not in done.stderr, done.stderr
