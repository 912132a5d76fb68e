"""The Display from a C controller (the C library built with AddressSanitizer and UBSan) and from
a Webots Python controller against ``sensorium serve``, for the same robot written as YAML
(tests/worlds/display.yaml) and as .wbt (tests/worlds/display.wbt): both draw the same sequence
(lines, shapes, a blended polygon, text, images made, copied and pasted), which travels with their
step requests; ``imageSave`` writes the server's pixels as PNG files, equal to what the server's
rasteriser draws from the same commands in process (tests/test_display.py checks those pixels
against Webots' rules in closed form)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from _serve import run_controller, sensorium
from PIL import Image
from test_c_client import sanitized_controller

from sensorium.schemas import world as wm
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

REPO = Path(__file__).resolve().parents[1]
WORLDS = [REPO / "tests" / "worlds" / "display.yaml", REPO / "tests" / "worlds" / "display.wbt"]
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=1:exitcode=86", "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"}
EXPECTED = ["screen 320 240", "small 64 64", "properties 320 240", "pixels 1920", "refs 1 1 1", "done"]

RGBA_2x2 = bytes([255, 0, 0, 128, 0, 255, 0, 255, 0, 0, 255, 64, 255, 255, 255, 0])


def _bgra(rgba: bytes) -> bytes:
    out = bytearray(rgba)
    out[0::4], out[2::4] = rgba[2::4], rgba[0::4]
    return bytes(out)


def expected_images() -> tuple[np.ndarray, np.ndarray]:
    """What the controllers' sequence draws (the display, the copied image), in process: RGBA rows."""
    sim = Simulation(load_world(WORLDS[0]))
    d = sim.robots["bot"].devices["screen"]
    cmds: list[list] = []
    for x in range(320):
        for y in range(0, 240, 40):
            cmds += [["color", 0xFF0000], ["pixel", x, y]]
    cmds += [["color", 0xFF0000], ["line", 0, 0, 50, 20], ["color", 0x00FF00], ["rectangle", 60, 10, 30, 20, True],
             ["color", 0x0000FF], ["oval", 150, 100, 40, 25, False], ["oval", 250, 60, 20, 30, True],
             ["alpha", 0.5], ["opacity", 0.6], ["color", 0xFFFF00],
             ["polygon", [10, 100, 80, 30, 5], [150, 160, 230, 220, 190], True], ["opacity", 1.0], ["alpha", 1.0],
             ["rectangle", 200, 150, 60, 40, False], ["polygon", [200, 230, 215], [60, 60, 90], False],
             ["text", "Sensorium", 100, 200], ["load", 1, 2, 2, _bgra(RGBA_2x2)], ["paste", 1, 300, 220, True],
             ["copy", 2, 60, 10, 30, 20], ["paste", 2, 0, 100, False]]
    d.apply(d.check(cmds), 0)

    def rgba(words: np.ndarray) -> np.ndarray:
        b = words.astype("<u4").view(np.uint8).reshape(*words.shape, 4)
        return b[..., [2, 1, 0, 3]]
    return rgba(d.pixels), rgba(d.images[2])


@pytest.fixture(scope="module")
def c_controller(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "display_size.c")


@pytest.fixture(scope="module")
def expected() -> tuple[np.ndarray, np.ndarray]:
    return expected_images()


def test_both_world_formats_keep_the_display_size() -> None:
    for world in WORLDS:
        devices = load_world(world).world.robots[0].devices
        assert [(type(d), d.name, d.width, d.height) for d in devices] == [
            (wm.Display, "screen", 320, 240), (wm.Display, "small", 64, 64)], world


def test_a_display_size_below_one_is_one_as_in_webots(tmp_path: Path) -> None:
    p = tmp_path / "w.wbt"
    p.write_text('#VRML_SIM R2023b utf8\nRobot { name "r" children [ Display { width 0 height -3 } ] }\n')
    w = load_world(p)
    d = w.world.robots[0].devices[0]
    assert (d.width, d.height) == (1, 1)
    assert any("width" in line for line in w.warnings) and any("height" in line for line in w.warnings)


def test_the_expected_sequence_draws_what_the_rules_say(expected) -> None:
    screen, copy = expected
    assert screen.shape == (240, 320, 4) and copy.shape == (20, 30, 4)
    assert (copy == [0, 255, 0, 255]).all()                            # the green fill, copied
    assert (screen[100:120, 0:30] == [0, 255, 0, 255]).all()          # and pasted
    assert tuple(screen[0, 0]) == (255, 0, 0, 255) and tuple(screen[20, 50]) == (255, 0, 0, 255)   # line ends
    # the 2 x 2 image blended over black: each channel a·c/255, alpha capped at 255
    assert tuple(screen[220, 300]) == (128, 0, 0, 255) and tuple(screen[221, 300]) == (0, 0, 64, 255)
    assert tuple(screen[221, 301]) == (0, 0, 0, 255)                   # a transparent pixel changes nothing


def _small() -> np.ndarray:
    """The small display's map, a colour per pixel (8,192 commands: sent in several requests)."""
    ys, xs = np.mgrid[0:64, 0:64]
    return np.stack([xs << 2, ys << 2, np.full_like(xs, 0x40), np.full_like(xs, 255)], axis=-1).astype(np.uint8)


def _check(lines: list[str], err: str, out: Path, expected) -> None:
    assert lines == EXPECTED, (lines, err)
    assert "does not simulate Display" not in err and "Error" not in err, err
    for name, want in zip(("screen.png", "copy.png", "small.png"), (*expected, _small())):
        with Image.open(out / name) as im:
            assert im.mode == "RGBA"
            got = np.asarray(im)
        assert got.shape == want.shape and (got == want).all(), name


@pytest.mark.parametrize("world", WORLDS, ids=lambda p: p.suffix[1:])
def test_a_python_controller_draws_and_saves(world: Path, tmp_path: Path, expected) -> None:
    lines, err = run_controller(world, lambda url: sensorium(
        "controller", "--url", url, str(REPO / "tests" / "controllers" / "display_size.py")),
        env={"DISPLAY_OUT": str(tmp_path)})
    _check(lines, err, tmp_path, expected)


@pytest.mark.parametrize("world", WORLDS, ids=lambda p: p.suffix[1:])
def test_a_c_controller_draws_and_saves(world: Path, tmp_path: Path, c_controller: str, expected) -> None:
    lines, err = run_controller(world, lambda url: [c_controller], env={**SAN_ENV, "DISPLAY_OUT": str(tmp_path)})
    assert "Sanitizer" not in err and "runtime error" not in err, err
    _check(lines, err, tmp_path, expected)
    assert os.path.getsize(tmp_path / "screen.png") > 0


def test_python_coordinates_may_be_floats_truncated_as_webots_int_does(tmp_path: Path) -> None:
    """Webots' display_supervisor sample draws at ``width / 2`` and at a robot's scaled position
    (floats): Webots' Python Display passes each coordinate and size through ``int()``. Here too,
    so the same pixels as the integer commands (truncated toward zero: -3.6 is -3)."""
    lines, err = run_controller(WORLDS[0], lambda url: sensorium(
        "controller", "--url", url, str(REPO / "tests" / "controllers" / "display_floats.py")),
        env={"DISPLAY_OUT": str(tmp_path)})
    assert lines == ["done"] and "Error" not in err, err
    sim = Simulation(load_world(WORLDS[0]))
    d = sim.robots["bot"].devices["screen"]
    d.apply(d.check([["color", 0x505050], ["rectangle", 0, 0, 320, 240, True],
                     ["color", 0xBB2222], ["line", 160, 0, 160, 239], ["text", "x", 149, 230],
                     ["color", 0x22BB11], ["line", 0, 120, 319, 120],
                     ["opacity", 0.5], ["color", 0x2222BB], ["oval", 100, 50, 4, 4, True],
                     ["oval", -3, 200, 10, 6, False], ["opacity", 1.0],
                     ["pixel", 310, 5], ["rectangle", 200, 100, 30, 20, False],
                     ["copy", 1, 0, 0, 50, 40], ["paste", 1, 250, 180, False]]), 0)
    want = d.pixels.astype("<u4").view(np.uint8).reshape(240, 320, 4)[..., [2, 1, 0, 3]]
    with Image.open(tmp_path / "floats.png") as im:
        got = np.asarray(im)
    assert got.shape == want.shape and (got == want).all()


def _png_cases(folder: Path) -> dict[str, np.ndarray]:
    """PNG files of every colour type and depth a controller's image may have, written by Pillow
    (zlib's fixed and dynamic blocks; level 0: stored blocks), each 37 x 23 with every filter's
    work to undo (a gradient, noise): name -> the RGBA rows the display must show."""
    rng = np.random.default_rng(7)
    ys, xs = np.mgrid[0:23, 0:37]
    rgba = np.stack([xs * 6, ys * 11, (xs * ys) % 256, 255 - xs * 3], axis=-1).astype(np.uint8)
    rgba[5:9, 10:20] = rng.integers(0, 256, (4, 10, 4), dtype=np.uint8)
    grey = rgba[..., 0]
    want: dict[str, np.ndarray] = {}

    def keep(name: str, im: Image.Image, rows: np.ndarray, **kw) -> None:
        im.save(folder / name, **kw)
        want[name] = rows

    keep("rgba.png", Image.fromarray(rgba, "RGBA"), rgba)
    keep("stored.png", Image.fromarray(rgba, "RGBA"), rgba, compress_level=0)
    opaque = rgba.copy()
    opaque[..., 3] = 255
    keep("rgb.png", Image.fromarray(rgba[..., :3], "RGB"), opaque)
    g = np.stack([grey, grey, grey, np.full_like(grey, 255)], axis=-1)
    keep("grey.png", Image.fromarray(grey, "L"), g)
    keep("grey_alpha.png", Image.fromarray(np.stack([grey, rgba[..., 3]], axis=-1), "LA"),
         np.stack([grey, grey, grey, rgba[..., 3]], axis=-1))
    bits = (grey > 100).astype(np.uint8) * 255
    keep("one_bit.png", Image.fromarray(bits, "L").convert("1"),
         np.stack([bits, bits, bits, np.full_like(bits, 255)], axis=-1))
    wide = grey.astype(np.uint16) * 256 + 3                       # 16-bit: the high byte is shown
    keep("grey16.png", Image.fromarray(wide), g)
    index = (xs + ys) % 5
    colours = np.array([[255, 0, 0], [0, 255, 0], [0, 0, 255], [9, 99, 199], [250, 250, 0]], dtype=np.uint8)
    pal = Image.fromarray(index.astype(np.uint8), "P")
    pal.putpalette(colours.reshape(-1).tolist())
    alpha = np.array([255, 128, 0, 255, 64], dtype=np.uint8)
    keep("palette.png", pal, np.concatenate([colours[index], alpha[index][..., None]], axis=-1),
         transparency=alpha.tobytes())
    return want


@pytest.fixture(scope="module")
def load_controller(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "display_load.c")


def test_a_c_controller_loads_png_images_as_webots_display_sample_does(tmp_path: Path, load_controller: str) -> None:
    """Webots' display sample (C) loads its emoticons with wb_display_image_load: the C library reads
    PNG files itself (every colour type and depth Pillow writes; a JPEG is refused with one line, a
    damaged or missing file is Webots' "unreadable" line with the reason, and NULL), so the pasted
    pixels are the file's."""
    exe = load_controller
    src, out = tmp_path / "in", tmp_path / "out"
    src.mkdir()
    out.mkdir()
    want = _png_cases(src)
    good = (src / "rgba.png").read_bytes()
    (src / "damaged.png").write_bytes(good[:60] + bytes(40) + good[100:])
    (src / "photo.jpg").write_bytes(b"\xff\xd8\xff\xe0 not decoded")
    names = [*want, "damaged.png", "photo.jpg", "missing.png"]
    lines, err = run_controller(WORLDS[0], lambda url: [exe, *names],
                                env={**SAN_ENV, "DISPLAY_IN": str(src), "DISPLAY_OUT": str(out)})
    assert "Sanitizer" not in err and "runtime error" not in err, err
    assert lines == [*(f"loaded {n}" for n in want), "unreadable damaged.png", "unreadable photo.jpg",
                     "unreadable missing.png", "done"], err
    for name, rows in want.items():
        with Image.open(out / f"{name}.png") as im:
            got = np.asarray(im)[:23, :37]
        assert (got == rows).all(), name
    errors = err.strip().splitlines()
    assert len(errors) == 3 and all(e.startswith("Error: wb_display_image_load(): ") for e in errors), err
    assert f'the "{src / "damaged.png"}" image is unreadable' in errors[0]
    assert 'photo.jpg" image is unreadable (Premature end of JPEG file)' in errors[1]
    assert "missing.png\" image is unreadable (cannot be opened)" in errors[2]


def _jpeg_cases(folder: Path) -> tuple[list[str], list[str]]:
    """JPEG files Pillow writes (4:2:0 at quality 75, Pillow's default; 4:4:4; greyscale;
    progressive 4:2:2; CMYK), a PNG under a .jpg name (the content decides, as in Webots), and three
    files a controller cannot load: a JPEG cut in the middle of its scan, one whose markers are
    damaged, and a BMP (not a type Webots reads): (loadable names, refused names)."""
    ys, xs = np.mgrid[0:23, 0:37]
    rgb = np.stack([xs * 6, ys * 11, (xs * ys) % 256], axis=-1).astype(np.uint8)
    rgb[5:9, 10:20] = np.random.default_rng(3).integers(0, 256, (4, 10, 3), dtype=np.uint8)
    im = Image.fromarray(rgb, "RGB")
    im.save(folder / "colour.jpg")
    im.save(folder / "fine.jpeg", quality=95, subsampling=0)
    im.convert("L").save(folder / "grey.JPG")
    im.save(folder / "progressive.jpg", progressive=True, subsampling=1)
    im.convert("CMYK").save(folder / "cmyk.jpg")                  # Adobe's inverted inks
    im.save(folder / "png_inside.jpg", format="PNG")
    whole = (folder / "colour.jpg").read_bytes()
    (folder / "truncated.jpg").write_bytes(whole[:len(whole) * 2 // 3])
    huffman = whole.index(b"\xff\xc4") + 5                        # a Huffman table's 16 code counts
    (folder / "damaged.jpg").write_bytes(whole[:huffman] + b"\xff" * 16 + whole[huffman + 16:])
    im.save(folder / "image.bmp")
    return ["colour.jpg", "fine.jpeg", "grey.JPG", "progressive.jpg", "cmyk.jpg", "png_inside.jpg"], \
        ["truncated.jpg", "damaged.jpg", "image.bmp"]


def _python_loads(src: Path, out: Path, names: list[str]) -> list[str]:
    """The Python client's wb_display_image_load of each file, pasted at (0, 0) on "screen" and saved
    as out/<name>.png and out/<name>.jpg, against a server in this process: "loaded NAME" or
    "unreadable NAME"."""
    from _inproc import inproc_server

    from sensorium.client import wb
    lines = []
    with inproc_server(heartbeat_ms=5000, world=WORLDS[0]) as (_core, transport):
        wb.wb_robot_init(f"{transport.rpc_endpoint}/bot")
        try:
            tag = wb.wb_robot_get_device("screen")
            for name in names:
                ref = wb.wb_display_image_load(tag, str(src / name))
                if ref is None:
                    lines.append(f"unreadable {name}")
                    continue
                wb.wb_display_image_paste(tag, ref, 0, 0, False)
                wb.wb_display_image_save(tag, None, str(out / f"{name}.png"))
                wb.wb_display_image_save(tag, None, str(out / f"{name}.jpg"))
                wb.wb_display_image_delete(tag, ref)
                lines.append(f"loaded {name}")
        finally:
            wb.wb_robot_cleanup()
    return lines


def test_c_and_python_controllers_load_jpeg_images_alike(tmp_path: Path, load_controller: str, capsys) -> None:
    """wb_display_image_load of JPEG files from C (libjpeg) and from Python (Pillow, whose JPEG
    decoder is libjpeg-turbo too): the pasted pixels are the same, byte for byte, and those Pillow
    decodes from the file; a JPEG that ends early or whose markers are damaged, and a file of
    another type, are one "unreadable" line each (with the reason) and NULL/None in both clients.
    wb_display_image_save to a .jpg writes the display as a JPEG (RGB, quality 100, 4:4:4, as
    libController writes it) that Pillow reads back at the display's size."""
    from PIL import JpegImagePlugin
    src, c_out, py_out = tmp_path / "in", tmp_path / "c", tmp_path / "py"
    for d in (src, c_out, py_out):
        d.mkdir()
    good, bad = _jpeg_cases(src)
    lines, err = run_controller(WORLDS[0], lambda url: [load_controller, *good, *bad],
                                env={**SAN_ENV, "DISPLAY_IN": str(src), "DISPLAY_OUT": str(c_out)})
    assert "Sanitizer" not in err and "runtime error" not in err, err
    expected_lines = [*(f"loaded {n}" for n in good), *(f"unreadable {n}" for n in bad)]
    assert lines == [*expected_lines, "done"], err
    capsys.readouterr()
    assert _python_loads(src, py_out, [*good, *bad]) == expected_lines
    py_err = capsys.readouterr().err
    for name in good:
        with Image.open(c_out / f"{name}.png") as a, Image.open(py_out / f"{name}.png") as b, \
                Image.open(src / name) as f:
            c_px, py_px, file_px = (np.asarray(x.convert("RGBA"))[:23, :37] for x in (a, b, f))
        assert (c_px == py_px).all() and (c_px == file_px).all(), name
        assert (c_px[..., 3] == 255).all()
    for errors in (err.strip().splitlines(), [e for e in py_err.splitlines() if e.startswith("Error")]):
        assert len(errors) == 3, errors
        for line, name in zip(errors, bad):
            assert line.startswith(f'Error: wb_display_image_load(): the "{src / name}" image is unreadable ('), line
        assert errors[2].endswith("(unsupported image type: a .png, .jpg or .jpeg file is read).")
    assert "(Premature end of JPEG file)" in err.splitlines()[0] and "(Bogus Huffman table" in err.splitlines()[1], err

    for out in (c_out, py_out):
        with Image.open(out / "colour.jpg.png") as im:
            shown = np.asarray(im.convert("RGB")).astype(int)
        with Image.open(out / "colour.jpg.jpg") as im:
            assert (im.format, im.mode, im.size) == ("JPEG", "RGB", (320, 240))
            assert JpegImagePlugin.get_sampling(im) == 0               # 4:4:4
            saved = np.asarray(im).astype(int)
        assert np.abs(saved - shown).max() <= 2, out                   # quality 100: a unit or two of rounding


BIG = 2048
WINDOWS = [(0, 0), (1000, 700), (BIG - 320, BIG - 240)]      # the parts of the image each saved display shows


def _gradient(w: int, h: int) -> np.ndarray:
    """RGBA rows telling each pixel's place: r = x mod 256, g = y mod 256, b = the 256-pixel block
    (x // 256 · 16 + y // 256), alpha 255 - (x + y) mod 128."""
    ys, xs = np.mgrid[0:h, 0:w]
    return np.stack([xs % 256, ys % 256, (xs // 256 * 16 + ys // 256) % 256, 255 - (xs + ys) % 128],
                    axis=-1).astype(np.uint8)


def _python_big(src: Path, out: Path, name: str) -> str:
    """tests/c/display_big.c's sequence from the Python client, against a server in this process."""
    from _inproc import inproc_server

    from sensorium.client import wb
    with inproc_server(heartbeat_ms=5000, world=WORLDS[0]) as (_core, transport):
        wb.wb_robot_init(f"{transport.rpc_endpoint}/bot")
        try:
            tag = wb.wb_robot_get_device("screen")
            wb.wb_robot_step(16)
            ref = wb.wb_display_image_load(tag, str(src / name))
            for x, y in WINDOWS if ref is not None else []:
                wb.wb_display_image_paste(tag, ref, -x, -y, False)
                wb.wb_display_image_save(tag, None, str(out / f"{x}_{y}.png"))
            if ref is not None:
                wb.wb_display_image_delete(tag, ref)
            wb.wb_robot_step(16)
        finally:
            wb.wb_robot_cleanup()
    return f"{'unreadable' if ref is None else 'loaded'} {name}"


@pytest.fixture(scope="module")
def big_controller(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "display_big.c")


@pytest.mark.slow
def test_a_2048_square_image_loads_in_bands_from_c_and_python_alike(tmp_path: Path, big_controller: str,
                                                                   capsys) -> None:
    """A 2048 x 2048 PNG (16 MiB of pixels, 16 times what one request carries) is loaded by
    wb_display_image_load in both clients, sent in bands of rows and kept whole by the server: pasted
    at three offsets on the 320 x 240 screen, each saved display is the image's part there, pixel for
    pixel (the gradient's closed form), the same in C and Python. An image one pixel row wider than
    the Display's 4,194,304 pixels is one "unreadable" line and NULL/None in both."""
    src, c_out, py_out = tmp_path / "in", tmp_path / "c", tmp_path / "py"
    for d in (src, c_out, py_out):
        d.mkdir()
    Image.fromarray(_gradient(BIG, BIG), "RGBA").save(src / "ground.png", compress_level=1)
    Image.fromarray(_gradient(BIG + 1, BIG)[..., :3], "RGB").save(src / "over.png", compress_level=1)
    args = [str(v) for xy in WINDOWS for v in xy]
    lines, err = run_controller(WORLDS[0], lambda url: [big_controller, "ground.png", *args],
                                env={**SAN_ENV, "DISPLAY_IN": str(src), "DISPLAY_OUT": str(c_out)})
    assert "Sanitizer" not in err and "runtime error" not in err, err
    assert lines == ["loaded ground.png", "done"], err
    assert not err.strip(), err
    capsys.readouterr()
    assert _python_big(src, py_out, "ground.png") == "loaded ground.png"
    assert "Error" not in capsys.readouterr().err
    for x, y in WINDOWS:
        want = _gradient(x + 320, y + 240)[y:, x:]
        with Image.open(c_out / f"{x}_{y}.png") as a, Image.open(py_out / f"{x}_{y}.png") as b:
            c_px, py_px = np.asarray(a.convert("RGBA")), np.asarray(b.convert("RGBA"))
        assert (c_px == want).all() and (py_px == want).all(), (x, y)
    assert (_gradient(BIG, BIG)[BIG - 1, BIG - 1] == [255, 255, 119, 129]).all()      # the closed form's corner

    lines, err = run_controller(WORLDS[0], lambda url: [big_controller, "over.png", "0", "0"],
                                env={**SAN_ENV, "DISPLAY_IN": str(src), "DISPLAY_OUT": str(c_out)})
    assert lines == ["unreadable over.png", "done"], err
    refused = (f'Error: wb_display_image_load(): the "{src / "over.png"}" image is unreadable (2049 x 2048 pixels, '
               "more than one image may hold (4194304)).")
    assert err.strip().splitlines() == [refused], err
    assert _python_big(src, py_out, "over.png") == "unreadable over.png"
    assert [e for e in capsys.readouterr().err.splitlines() if e.startswith("Error")] == [refused]
