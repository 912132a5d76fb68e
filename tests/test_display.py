"""The Display drawn on the server (sensorium/server/sim/display.py), in process: each primitive
gives the pixels WbDisplay's rule gives, computed here from the rule (Bresenham's incremental loop,
the midpoint oval, the scanline polygon, the "over" blend in integers); images copy, paste, load;
bad commands are refused with one line naming the command; the topic carries the image."""

from __future__ import annotations

import numpy as np
import pytest

from sensorium.server.sim import display as dmod
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world

BLACK = 0xFF000000


def world(devices: list[dict]) -> Simulation:
    data = {"world_info": {"basic_time_step": 16},
            "robots": [{"name": "bot", "devices": devices}]}
    return Simulation(parse_world(data))


@pytest.fixture
def disp():
    sim = world([{"device": "Display", "name": "screen", "width": 20, "height": 12}])
    return sim.robots["bot"].devices["screen"]


def draw(d, *commands):
    d.apply(d.check([list(c) for c in commands]), 0)


def painted(d, colour=0xFFFFFFFF) -> set[tuple[int, int]]:
    ys, xs = np.nonzero(d.pixels == colour)
    return {(int(x), int(y)) for x, y in zip(xs, ys)}


def bresenham(x0, y0, x1, y1):
    """WbDisplay::drawLine's loop, step by step (the rule the vectorised form must match)."""
    out = [(x0, y0)]
    dy, dx = y1 - y0, x1 - x0
    sy, sx = (-1, -dy) if dy < 0 else (1, dy), (-1, -dx) if dx < 0 else (1, dx)
    stepy, dy = sy
    stepx, dx = sx
    dy, dx = dy << 1, dx << 1
    if dx > dy:
        f = dy - (dx >> 1)
        while x0 != x1:
            if f >= 0:
                y0 += stepy
                f -= dx
            x0 += stepx
            f += dy
            out.append((x0, y0))
    else:
        f = dx - (dy >> 1)
        while y0 != y1:
            if f >= 0:
                x0 += stepx
                f -= dy
            y0 += stepy
            f += dx
            out.append((x0, y0))
    return out


def test_a_new_display_is_opaque_black(disp) -> None:
    assert disp.pixels.shape == (12, 20) and (disp.pixels == BLACK).all()
    assert (disp.color, disp.alpha, disp.opacity) == (0xFFFFFF, 255, 255)


@pytest.mark.parametrize("line", [(0, 0, 19, 11), (3, 9, 17, 2), (5, 0, 8, 11), (19, 4, 0, 7), (2, 2, 9, 9),
                                  (4, 4, 4, 4), (-5, -3, 30, 14)])
def test_lines_are_bresenhams(disp, line) -> None:
    draw(disp, ["line", *line])
    want = {(x, y) for x, y in bresenham(*line) if 0 <= x < 20 and 0 <= y < 12}
    assert painted(disp) == want
    assert (disp.pixels[disp.pixels != 0xFFFFFFFF] == BLACK).all()


def test_every_line_of_a_fan_matches_the_loop() -> None:
    for x1 in range(-6, 7):
        for y1 in range(-6, 7):
            xs, ys = dmod.line_pixels(0, 0, x1, y1)
            assert list(zip(xs.tolist(), ys.tolist())) == bresenham(0, 0, x1, y1), (x1, y1)


def test_a_clipped_line_is_the_visible_part_of_the_whole_line() -> None:
    """Only the steps on a 20 x 12 display are computed, and they are the whole line's steps there."""
    rng = np.random.default_rng(5)
    for x0, y0, x1, y1 in rng.integers(-200, 200, size=(400, 4)).tolist():
        xs, ys = dmod.line_pixels(x0, y0, x1, y1)
        whole = [(x, y) for x, y in zip(xs.tolist(), ys.tolist()) if 0 <= x < 20 and 0 <= y < 12]
        cx, cy = dmod.line_pixels(x0, y0, x1, y1, 20, 12)
        clipped = [(x, y) for x, y in zip(cx.tolist(), cy.tolist()) if 0 <= x < 20 and 0 <= y < 12]
        assert clipped == whole, (x0, y0, x1, y1)
        assert len(cx) <= 20                # steps off the display are not computed


INT_MIN = -(1 << 31)


def test_a_line_to_int_min_draws_its_visible_part(disp) -> None:
    """A controller drawing a beam of infinite range ((int)(x * inf) is INT_MIN in C, as Webots'
    hokuyo sample does) gets the visible part of the line, as WbDisplay draws it, not a refusal:
    from (10, 6) towards (INT_MIN, INT_MIN) is nearly the diagonal, leaving the display at its corner;
    towards (INT_MIN, 6) the row to the left edge."""
    draw(disp, ["line", 10, 6, INT_MIN, INT_MIN])
    d = -INT_MIN + 10                       # the line's x extent; its y extent is -INT_MIN + 6
    want = {(10 - k, 6 - (2 * (d - 4) * k + d) // (2 * d)) for k in range(11)}
    assert painted(disp) == {(x, y) for x, y in want if y >= 0} and (10, 6) in want and (4, 0) in want
    draw(disp, ["color", 0x00FF00], ["line", 10, 6, INT_MIN, 6], ["line", 3, 2, (1 << 31) - 1, 2])
    assert painted(disp, 0xFF00FF00) == {(x, 6) for x in range(11)} | {(x, 2) for x in range(3, 20)}


def test_rectangles_fill_and_frame(disp) -> None:
    draw(disp, ["color", 0xFF0000], ["rectangle", 2, 3, 5, 4, True])
    assert painted(disp, 0xFFFF0000) == {(x, y) for x in range(2, 7) for y in range(3, 7)}
    draw(disp, ["color", 0x00FF00], ["rectangle", 10, 1, 4, 3, False])
    frame = {(x, y) for x in range(10, 14) for y in (1, 3)} | {(x, y) for x in (10, 13) for y in range(1, 4)}
    assert painted(disp, 0xFF00FF00) == frame
    # WbDisplay's clipping of a fill: a negative corner moves to 0, the size stays
    draw(disp, ["color", 0x0000FF], ["rectangle", -3, -2, 4, 3, True])
    assert painted(disp, 0xFF0000FF) == {(x, y) for x in range(4) for y in range(3)}


def midpoint_oval(cx, cy, a, b):
    """WbDisplay::drawOval's unfilled loop, as a set of pixels."""
    pts = {(cx + a, cy), (cx - a, cy)}
    mx1, my1, mx2, my2 = cx - a, cy, cx + a, cy
    aq, bq = a * a, b * b
    dx, dy, r = 2 * aq, 2 * bq, a * bq
    rx, ry, x = 2 * r, 0, a
    while x > 0:
        if r > 0:
            my1, my2, ry = my1 + 1, my2 - 1, ry + dx
            r -= ry
        if r <= 0:
            x, mx1, mx2, rx = x - 1, mx1 + 1, mx2 - 1, rx - dy
            r += rx
        pts |= {(mx1, my1), (mx1, my2)}
        if x != 0:
            pts |= {(mx2, my1), (mx2, my2)}
    return pts


def test_an_oval_outline_is_the_midpoint_loop_and_a_filled_one_spans_it(disp) -> None:
    draw(disp, ["oval", 9, 6, 6, 4, False])
    want = midpoint_oval(9, 6, 6, 4)
    assert painted(disp) == want
    # symmetric and on the axes' ends
    assert {(15, 6), (3, 6), (9, 2), (9, 10)} <= want
    assert all((18 - x, y) in want and (x, 12 - y) in want for x, y in want)
    draw(disp, ["rectangle", 0, 0, 20, 12, True])
    draw(disp, ["color", 0], ["oval", 9, 6, 6, 4, True])
    filled = painted(disp, BLACK)
    for y in range(12):                       # each row of the fill spans the outline's extremes
        row = sorted(x for x, yy in want if yy == y)
        assert {x for x, yy in filled if yy == y} == (set(range(row[0], row[-1] + 1)) if row else set())


def test_a_polygon_fills_its_scanlines(disp) -> None:
    # a right triangle: a row takes the edges crossing it (y0 < y <= y1, so not the apex's row 0)
    # and rows y = 1..8 span x = 0 .. y (C division is exact here); the bottom edge is horizontal
    draw(disp, ["polygon", [0, 0, 8], [0, 8, 8], True])
    assert painted(disp) == {(x, y) for y in range(1, 9) for x in range(0, y + 1)}
    draw(disp, ["color", 0xFF0000], ["polygon", [12, 18, 18, 12], [2, 2, 6, 6], False])
    # outline: each scanline's two nodes, and the horizontal edges
    want = {(12, y) for y in range(3, 7)} | {(18, y) for y in range(3, 7)} | {(x, y) for x in range(12, 19)
                                                                               for y in (2, 6)}
    assert painted(disp, 0xFFFF0000) == want


def test_alpha_and_opacity_blend_in_integers(disp) -> None:
    draw(disp, ["color", 0x204080], ["alpha", 0.5], ["opacity", 0.4], ["pixel", 1, 1])
    op, a = int(0.4 * 255), int(0.5 * 255)          # the bytes Webots sends (truncated)
    keep = 255 - op
    want = ((keep * 255 + op * a) // 255) << 24 | ((op * 0x20) // 255) << 16 | ((op * 0x40) // 255) << 8 \
        | (op * 0x80) // 255
    assert int(disp.pixels[1, 1]) == want
    draw(disp, ["pixel", 1, 1])                      # drawn again: blended again, over the new value
    old = want
    again = 0
    for shift, src in ((24, a), (16, 0x20), (8, 0x40), (0, 0x80)):
        again |= ((keep * ((old >> shift) & 255) + op * src) // 255) << shift
    assert int(disp.pixels[1, 1]) == again
    # opacity 1 and alpha 0 in a fill: the pixels become fully transparent black (WbDisplay's clear)
    draw(disp, ["opacity", 1.0], ["alpha", 0.0], ["rectangle", 0, 0, 3, 3, True])
    assert (disp.pixels[0:3, 0:3] == 0).all()


def test_images_copy_paste_blend_load_and_delete(disp) -> None:
    draw(disp, ["color", 0x112233], ["rectangle", 0, 0, 3, 2, True], ["copy", 1, 0, 0, 3, 2])
    assert disp.images[1].shape == (2, 3) and (disp.images[1] == 0xFF112233).all()
    draw(disp, ["paste", 1, 10, 5, False])
    assert painted(disp, 0xFF112233) == {(x, y) for x in range(3) for y in range(2)} | \
        {(x, y) for x in range(10, 13) for y in range(5, 7)}
    # a half-transparent image pasted with blend over opaque white
    px = bytes([0x10, 0x20, 0x30, 0x80])            # B, G, R, A
    draw(disp, ["color", 0xFFFFFF], ["rectangle", 15, 0, 5, 5, True], ["load", 2, 1, 1, px], ["paste", 2, 16, 1, True])
    a = 0x80
    want = 0xFF << 24 | (((255 - a) * 255 + a * 0x30) // 255) << 16 | (((255 - a) * 255 + a * 0x20) // 255) << 8 \
        | ((255 - a) * 255 + a * 0x10) // 255
    assert int(disp.pixels[1, 16]) == want
    # pasted partly off the display: clipped
    draw(disp, ["paste", 1, 18, 11, False])
    assert int(disp.pixels[11, 18]) == 0xFF112233 and int(disp.pixels[11, 19]) == 0xFF112233
    draw(disp, ["delete", 1])
    assert 1 not in disp.images
    before = disp.pixels.copy()
    draw(disp, ["paste", 1, 0, 0, False])          # a deleted image pastes nothing (WbDisplay)
    assert (disp.pixels == before).all()


def _words(w: int, h: int) -> np.ndarray:
    """A gradient image, 0xAARRGGBB words: r = x, g = y, b = x + y, alpha 255 - x (mod 256)."""
    ys, xs = np.mgrid[0:h, 0:w].astype(np.uint32)
    return ((255 - xs) % 256) << 24 | (xs % 256) << 16 | (ys % 256) << 8 | ((xs + ys) % 256)


def _band(rows: np.ndarray) -> bytes:
    return rows.astype("<u4").tobytes()


def test_an_image_sent_in_bands_of_rows_is_kept_at_its_last_band_as_one_load_keeps_it(disp) -> None:
    """``rows``: an image larger than one request comes in bands of whole rows, in order; it is kept
    (a paste shows it) only once its last row came, and is then the image one ``load`` keeps."""
    img = _words(7, 10)
    draw(disp, ["load", 1, 7, 10, _band(img)])
    draw(disp, ["rows", 2, 7, 10, 0, _band(img[:4])], ["rows", 2, 7, 10, 4, _band(img[4:5])])
    assert 2 not in disp.images
    draw(disp, ["paste", 2, 0, 0, False])               # a partial upload is never shown
    assert (disp.pixels == BLACK).all()
    draw(disp, ["rows", 2, 7, 10, 5, _band(img[5:])], ["paste", 2, 1, 2, False])
    assert disp.images[2].dtype == disp.images[1].dtype and (disp.images[2] == disp.images[1]).all()
    assert (disp.pixels[2:12, 1:8] == img).all() and disp.loading == {}
    # a band left half way is forgotten by delete and by a reset; a new first band starts over
    draw(disp, ["rows", 3, 7, 10, 0, _band(img[:3])], ["delete", 3])
    assert 3 not in disp.loading and 3 not in disp.images
    with pytest.raises(ValueError, match=r"command 0 \(rows\): y 3: image 3 has no band before"):
        disp.check([["rows", 3, 7, 10, 3, _band(img[3:])]])
    draw(disp, ["rows", 4, 7, 10, 0, _band(img[:3])])
    disp.reset()
    assert disp.loading == {} and disp.images == {}


@pytest.mark.parametrize("commands, message", [
    ([["rows", 5, 7, 10, 0, _band(_words(7, 3))], ["rows", 5, 7, 10, 4, _band(_words(7, 2))]],
     "command 1 (rows): y 4 is out of order: image 5's next band starts at row 3"),
    ([["rows", 5, 7, 10, 0, _band(_words(7, 3))], ["rows", 5, 8, 10, 3, _band(_words(8, 2))]],
     "command 1 (rows): width x height 8 x 10 differs from the image's first band (7 x 10)"),
    ([["rows", 5, 7, 10, 0, _band(_words(7, 8))], ["rows", 5, 7, 10, 8, _band(_words(7, 3))]],
     "command 1 (rows): data holds 3 rows from row 8, past the image's height 10"),
    ([["rows", 5, 7, 10, 0, b"\0" * 30]], "command 0 (rows): data must be whole rows of 7 BGRA pixels (28 bytes each), got 30"),
    ([["rows", 5, 2049, 2048, 0, b"\0" * 4 * 2049]], "command 0 (rows): an image is 1 to 4194304 pixels, got 2049 x 2048"),
    ([["rows", 5, 7, 10, 10, _band(_words(7, 1))]], "command 0 (rows): y must be a row of the image, 0 to 9, got 10"),
])
def test_bad_bands_are_refused_with_the_command_and_field(disp, commands, message) -> None:
    with pytest.raises(ValueError) as exc:
        disp.check(commands)
    assert str(exc.value) == message
    assert disp.loading == {} and disp.images == {}


def test_text_is_drawn_in_the_colour_at_its_corner(disp) -> None:
    draw(disp, ["color", 0x00FF00], ["text", "Hi", 1, 1])
    got = painted(disp, 0xFF00FF00)
    assert got and min(x for x, _ in got) >= 1 and min(y for _, y in got) >= 1
    assert max(y for _, y in got) < 1 + 12


@pytest.mark.parametrize("command, message", [
    (["line", 1, 2, 3], "command 0 (line): takes 4 arguments, got 3"),
    (["oval", 1, 2, 0, 3, True], "command 0 (oval): a and b must be > 0"),
    (["color", 0x1000000], "command 0 (color): color must be an integer 0xRRGGBB"),
    (["alpha", 2.0], "command 0 (alpha): alpha must be a number in [0, 1]"),
    (["pixel", 1 << 31, 0], "command 0 (pixel): x 2147483648 is out of a C int's range"),
    (["rectangle", 1 << 20, 0, 2, 2, True], "command 0 (rectangle): x 1048576 is out of"),
    (["polygon", [0] * 2000, [0] * 2000, True], "command 0 (polygon): 2000 vertices, at most 1024"),
    (["text", "x" * 2000, 0, 0], "command 0 (text): 2000 characters, at most 1024"),
    (["load", 3, 2, 2, b"1234"], "command 0 (load): data must be 16 bytes"),
    (["attach", "nothing"], "command 0 (attach): 'nothing' is no camera of robot 'bot'"),
    (["spray", 1], "command 0 (spray): not a display command"),
])
def test_bad_commands_are_refused_before_anything_is_drawn(disp, command, message) -> None:
    with pytest.raises(ValueError) as exc:
        disp.check([command])
    assert str(exc.value).startswith(message), str(exc.value)


def test_a_request_is_checked_whole_and_bounded(disp) -> None:
    with pytest.raises(ValueError, match="at most 4096 per display"):
        disp.check([["pixel", 0, 0]] * 4097)
    with pytest.raises(ValueError, match="more than 1048576 drawing steps"):
        disp.check([["oval", 0, 0, 60000, 60000, True]] * 10)
    with pytest.raises(ValueError, match=r"command 1 \(line\)"):
        disp.check([["pixel", 0, 0], ["line", 0]])
    assert (disp.pixels == BLACK).all()


def test_an_attached_camera_is_under_the_display() -> None:
    sim = world([{"device": "Camera", "name": "cam", "width": 4, "height": 3},
                 {"device": "Display", "name": "screen", "width": 4, "height": 3}])
    d, cam = sim.robots["bot"].devices["screen"], sim.robots["bot"].devices["cam"]
    draw(d, ["pixel", 0, 0], ["attach", "cam"])
    assert int(d.pixels[0, 0]) == 0xFFFFFFFF and int(d.pixels[1, 1]) == 0     # untouched black: transparent
    cam.enable(16)
    sim.step()
    sim.step()
    bgra = cam.image.view(np.uint32).reshape(3, 4)
    shown = d.composed()
    assert int(shown[0, 0]) == 0xFFFFFFFF and int(shown[1, 1]) == int(bgra[1, 1]) | 0xFF000000
    assert d.measurements >= 2                      # the camera's new image is a new display image


def _camera_words(h: int, w: int) -> np.ndarray:
    """A camera image (BGRA bytes) whose every pixel is its own: 0xFF000000 | row << 8 | column."""
    ys, xs = np.mgrid[0:h, 0:w]
    return (0xFF000000 | (ys << 8) | xs).astype("<u4").view(np.uint8).reshape(h, w, 4)


@pytest.mark.parametrize("camera, display, rows, cols", [
    ((12, 9), (4, 3), [1, 4, 7], [1, 4, 7, 10]),            # three times the display: each pixel's middle texel
    ((2, 2), (4, 4), [0, 0, 1, 1], [0, 0, 1, 1]),            # half the display: each texel twice
    ((5, 3), (4, 6), [0, 0, 1, 1, 2, 2], [0, 1, 3, 4]),      # 5/4 across, 1/2 down
])
def test_a_camera_of_another_size_is_stretched_to_the_display_nearest_texel(camera, display, rows, cols) -> None:
    """Webots draws an attached camera's texture as the background of the display's overlay,
    stretched to the display's size without interpolation: display pixel (x, y) shows the camera
    texel under its centre, column floor((x + 1/2)·cw/dw), row floor((y + 1/2)·ch/dh)."""
    (cw, ch), (dw, dh) = camera, display
    sim = world([{"device": "Camera", "name": "cam", "width": cw, "height": ch},
                 {"device": "Display", "name": "screen", "width": dw, "height": dh}])
    d, cam = sim.robots["bot"].devices["screen"], sim.robots["bot"].devices["cam"]
    draw(d, ["color", 0x0000FF], ["pixel", 1, 1], ["attach", "cam"])
    cam.image = _camera_words(ch, cw)
    shown = d.composed()
    assert shown.shape == (dh, dw)
    want = np.array([[0xFF000000 | (r << 8) | c for c in cols] for r in rows], dtype=np.uint32)
    want[1, 1] = 0xFF0000FF                              # the display's own opaque pixel stays on top
    assert (shown == want).all(), shown
    assert (dmod.nearest_texels(ch, dh) == rows).all() and (dmod.nearest_texels(cw, dw) == cols).all()
    draw(d, ["copy", 1, 0, 0, dw, dh])
    assert (d.images[1] == want).all()                   # a copy (and imageSave) takes what is shown
    cam.enable(16)                                       # and a rendered image goes through the same sampling
    sim.step()
    sim.step()
    rendered = cam.image.view(np.uint32).reshape(ch, cw)
    got = d.composed()
    assert int(got[0, 0]) == int(rendered[rows[0], cols[0]]) | 0xFF000000
    assert int(got[dh - 1, dw - 1]) == int(rendered[rows[-1], cols[-1]]) | 0xFF000000


def test_the_image_topic_carries_each_change_once() -> None:
    import msgpack

    from sensorium.server.daemon.topics import Topics
    sim = world([{"device": "Display", "name": "screen", "width": 5, "height": 4}])
    d = sim.robots["bot"].devices["screen"]
    topics = Topics(sim)
    assert [t.type for t in topics.topics if t.name == "/bot/screen/image"] == ["sensor_msgs/msg/Image"]
    got: list[tuple[str, dict]] = []
    topics.set_recorder(lambda name, typ, env, body, ns, seq: got.append((name, msgpack.unpackb(body))),
                        topics=["/bot/screen/image"])
    sim.step()
    topics.publish(sim.time_ms)
    assert got == []                                  # nothing drawn yet: nothing new to show
    draw(d, ["color", 0x123456], ["line", 0, 0, 4, 3])
    sim.step()
    topics.publish(sim.time_ms)
    sim.step()
    topics.publish(sim.time_ms)                       # unchanged: not again
    assert len(got) == 1
    msg = got[0][1]
    assert (msg["width"], msg["height"], msg["encoding"], msg["step"]) == (5, 4, "bgra8", 20)
    words = np.frombuffer(msg["data"], dtype="<u4").reshape(4, 5)
    line = {(int(x), int(y)) for x, y in zip(*dmod.line_pixels(0, 0, 4, 3))}
    assert all(int(words[y, x]) == (0xFF123456 if (x, y) in line else BLACK) for y in range(4) for x in range(5))
    assert msg["header"]["frame_id"] == "bot/screen"


def test_a_python_controller_loads_pastes_and_saves_over_the_wire(tmp_path, capsys) -> None:
    """imageLoad of a PNG (Pillow), pasted with blend, saved as PNG: the server's pixels, over a
    real server in this process; a format Webots does not write writes nothing; a bad request is
    one line naming the display and the command."""
    import yaml
    from _inproc import inproc_server
    from PIL import Image

    from sensorium.client import wb
    from sensorium.client.connection import SensoriumError
    path = tmp_path / "w.yaml"
    path.write_text(yaml.safe_dump({"world_info": {"basic_time_step": 16}, "robots": [
        {"name": "bot", "devices": [{"device": "Display", "name": "screen", "width": 6, "height": 4}]}]}))
    src = np.zeros((2, 3, 4), dtype=np.uint8)
    src[0, 0] = (255, 0, 0, 255)
    src[0, 1] = (0, 0, 255, 51)                       # a fifth opaque
    src[1, 2] = (10, 20, 30, 255)
    Image.fromarray(src, "RGBA").save(tmp_path / "in.png")
    with inproc_server(heartbeat_ms=5000, world=path) as (core, transport):
        wb.wb_robot_init(f"{transport.rpc_endpoint}/bot")
        try:
            tag = wb.wb_robot_get_device("screen")
            ref = wb.wb_display_image_load(tag, str(tmp_path / "in.png"))
            wb.wb_display_set_color(tag, 0xFFFFFF)
            wb.wb_display_fill_rectangle(tag, 0, 0, 6, 4)
            wb.wb_display_image_paste(tag, ref, 2, 1, True)
            out = tmp_path / "out.png"
            out.write_bytes(b"old")                   # Webots overwrites a file of that name: so does this
            wb.wb_display_image_save(tag, None, str(out))
            wb.wb_display_image_save(tag, ref, str(tmp_path / "ref.png"))
            wb.wb_display_image_save(tag, None, str(tmp_path / "out.bmp"))
            assert "unsupported file format" in capsys.readouterr().err
            assert not (tmp_path / "out.bmp").exists()
            wb.wb_display_draw_polygon(tag, list(range(2000)), [0] * 2000)
            with pytest.raises(SensoriumError) as exc:
                wb.wb_robot_step(16)
            assert "step: displays: bot/screen: command 0 (polygon): 2000 vertices, at most 1024" in str(exc.value)
        finally:
            wb.wb_robot_cleanup()
    with Image.open(out) as im:
        got = np.asarray(im.convert("RGBA")).astype(int)
    with Image.open(tmp_path / "ref.png") as im:
        assert (np.asarray(im) == src).all()          # the loaded image as kept
    white = np.array([255, 255, 255, 255])
    assert (got[0] == white).all() and (got[:, 0:2] == white).all()
    assert tuple(got[1, 2]) == (255, 0, 0, 255) and tuple(got[2, 4]) == (10, 20, 30, 255)
    a = 51                                            # blue at alpha 51 over white, alpha capped at 255
    assert tuple(got[1, 3]) == ((255 - a) * 255 // 255, (255 - a) * 255 // 255, ((255 - a) * 255 + a * 255) // 255,
                                255)
    assert tuple(got[2, 2]) == (255, 255, 255, 255)   # a transparent pixel leaves white


def test_a_reset_makes_the_display_black_again_and_a_batched_world_ignores_it() -> None:
    from sensorium.server.sim.batched import BatchedSimulation
    devices = [{"device": "Display", "name": "screen", "width": 4, "height": 4},
               {"device": "LightSensor", "name": "ls"}]
    sim = world(devices)
    d = sim.robots["bot"].devices["screen"]
    draw(d, ["color", 0x00FF00], ["alpha", 0.5], ["rectangle", 0, 0, 2, 2, True], ["copy", 1, 0, 0, 2, 2])
    before = d.measurements
    sim.reset()
    assert (d.pixels == BLACK).all() and d.images == {} and (d.color, d.alpha, d.opacity) == (0xFFFFFF, 255, 255)
    assert d.measurements == before + 1               # the black image is published
    data = {"world_info": {"basic_time_step": 16}, "robots": [{"name": "bot", "devices": devices}]}
    bs = BatchedSimulation(parse_world(data), 2)
    bs.step()                                         # builds and steps; the display draws nothing here


def test_a_python_controller_drawing_more_than_a_request_carries_keeps_its_order(tmp_path, capsys) -> None:
    """A full 160 x 120 map drawn pixel by pixel with a colour each (38,400 commands, beyond the
    4,096 a request may carry per display): the client sends its list ahead in order, and the
    image is the map. An image over the Display's 4,194,304 pixels, or one row of it over what a
    request carries, is one error line each, not a failed step."""
    import yaml
    from _inproc import inproc_server

    from sensorium.client import wb
    path = tmp_path / "w.yaml"
    path.write_text(yaml.safe_dump({"world_info": {"basic_time_step": 16}, "robots": [
        {"name": "bot", "devices": [{"device": "Display", "name": "map", "width": 160, "height": 120}]}]}))
    with inproc_server(heartbeat_ms=5000, world=path) as (core, transport):
        wb.wb_robot_init(f"{transport.rpc_endpoint}/bot")
        try:
            capsys.readouterr()
            tag = wb.wb_robot_get_device("map")
            for y in range(120):
                for x in range(160):
                    wb.wb_display_set_color(tag, (x << 16) | (y << 8) | ((x + y) & 0xFF))
                    wb.wb_display_draw_pixel(tag, x, y)
            assert wb.wb_display_image_new(tag, 2049, 2048, bytes(3 * 2049 * 2048), wb.WB_IMAGE_RGB) is None
            assert wb.wb_display_image_new(tag, 300_000, 1, bytes(3 * 300_000), wb.WB_IMAGE_RGB) is None
            assert wb.wb_robot_step(16) == 0
            pixels = core.sim.robots["bot"].devices["map"].pixels
            assert capsys.readouterr().err.splitlines() == [
                "Error: wb_display_image_new(): a 2049 x 2048 image is 4196352 pixels, more than a Display keeps "
                "(4194304).",
                "Error: wb_display_image_new(): a row of 300000 pixels is 1200000 bytes, more than one request "
                "carries (524288)."]
        finally:
            wb.wb_robot_cleanup()
    ys, xs = np.mgrid[0:120, 0:160]
    assert (pixels == (0xFF000000 | (xs << 16) | (ys << 8) | ((xs + ys) & 0xFF)).astype(np.uint32)).all()


def test_a_half_opaque_filled_oval_blends_each_pixel_as_often_as_webots_draws_it(disp) -> None:
    # WbDisplay's fill: the middle row, then two rows per step of the loop whenever my2 changed;
    # how often each pixel is drawn is counted here from the loop itself
    cx, cy, a, b = 9, 6, 5, 3
    counts: dict[tuple[int, int], int] = {}

    def row(x0, x1, y):
        for x in range(x0, x1 + 1):
            counts[(x, y)] = counts.get((x, y), 0) + 1
    row(cx - a, cx + a, cy)
    mx1, my1, mx2, my2 = cx - a, cy, cx + a, cy
    dx, dy, r = 2 * a * a, 2 * b * b, a * b * b
    rx, ry, x, old = 2 * r, 0, a, -2
    while x > 0:
        if r > 0:
            my1, my2, ry = my1 + 1, my2 - 1, ry + dx
            r -= ry
        if r <= 0:
            x, mx1, mx2, rx = x - 1, mx1 + 1, mx2 - 1, rx - dy
            r += rx
        if old != my2:
            row(mx1, mx2, my1)
            row(mx1, mx2, my2)
        old = my2
    draw(disp, ["opacity", 0.5], ["oval", cx, cy, a, b, True])
    op = int(0.5 * 255)

    def blended(times):
        v = 0                                             # a channel of black (the colour is white)
        for _ in range(times):
            v = ((255 - op) * v + op * 255) // 255
        return v
    for (px, py), n in counts.items():
        c = blended(n)
        assert int(disp.pixels[py, px]) == (0xFF << 24 | c << 16 | c << 8 | c), (px, py, n)
    untouched = disp.pixels[[y for y in range(12) for x in range(20) if (x, y) not in counts],
                            [x for y in range(12) for x in range(20) if (x, y) not in counts]]
    assert (untouched == BLACK).all()
