"""The Display (Webots' WbDisplay): an image a controller draws on, rasterised here, published as
``/<robot>/<display>/image`` (``sensor_msgs/Image``, bgra8) whenever it changed.

The image is Webots' own: one 32-bit word per pixel, 0xAARRGGBB (the bytes B, G, R, A in memory,
so "bgra8" on the wire), black and opaque (0xFF000000) at the start. What changes it follows
WbDisplay's rules, pixel for pixel where they are simple:

* a drawn pixel is blended "over" the old one, channel by channel with integer division:
  ``new = ((255 - opacity) · old + opacity · source) / 255``, the source being the colour for r, g
  and b and the alpha for a; with opacity 255 the pixel simply becomes (alpha, colour) (a pixel a
  primitive draws twice is blended twice, as WbDisplay does);
* lines are Bresenham's (the pixel of step k along the major axis is at
  ``floor((2·|minor|·k + |major|) / (2·|major|))`` on the minor one, which is what WbDisplay's
  incremental loop computes); a filled rectangle is clipped as WbDisplay clips it (a negative x or
  y moves to 0 without shortening the width or height); an unfilled one is its frame, with
  WbDisplay's quirks at the edges; ovals are WbDisplay's midpoint loop; polygons its scanline fill
  (C integer division), outlines its nodes and horizontal edges;
* text: Webots' TrueType fonts are not here; glyphs come from Pillow's small built-in bitmap font
  (the pixels differ from Webots'; position and colour rules are the same: top-left at (x, y),
  ``\\n`` starts a new line);
* images: ``copy`` keeps a clipped region (blended over the attached camera's image when one is
  attached), ``load`` keeps a client's pixels (``rows``: an image larger than one request, in bands
  of whole rows sent in order, kept only once its last row came), ``paste`` puts one back (``blend``: "over" by the
  image's alpha, alpha channels added and capped at 255), ``delete`` forgets it; id 0 is the
  display itself (``save``).
* ``attach`` a camera of the same robot: the display's pixels still black and opaque become
  transparent (WbDisplay's rule), and the image published is the display over the camera's latest
  image, as Webots shows it: Webots draws the camera's texture as the background of the display's
  overlay, stretched to the display's size and sampled without interpolation (nearest texel), so a
  camera of another size is scaled here the same way, display pixel x showing camera column
  ``floor((x + 1/2) · camera width / display width)`` (rows alike).

Commands come from the controller (the step request's ``displays``, or the ``draw`` service when
``imageSave`` needs the pixels back); a request's commands are all checked before any is drawn,
and the work one request may ask for is bounded (:data:`MAX_COMMANDS`, :data:`MAX_WORK`, ...).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from sensorium.server.sim.sensors import Device

MAX_COMMANDS = 4096             # per display, per request
MAX_POLYGON = 1024              # vertices of one polygon
MAX_TEXT = 1024                 # characters of one text
MAX_COORD = 1 << 16             # |coordinate| and radii
C_INT = (-(1 << 31), (1 << 31) - 1)   # a C int: the points of pixels, lines and texts (drawn clipped)
MAX_IMAGE_PIXELS = 1 << 22      # one stored image (copy, load)
MAX_IMAGES = 256                # images a display keeps
MAX_WORK = 1 << 20              # loop iterations one request may cost (oval rows, polygon rows, glyphs)

BLACK = 0xFF000000

_FONT: Any = None


def _font() -> Any:
    global _FONT
    if _FONT is None:
        from PIL import ImageFont
        loader = getattr(ImageFont, "load_default_imagefont", None)
        _FONT = loader() if loader is not None else ImageFont.load_default()
    return _FONT


def line_height() -> int:
    """The pixels from one text line's top to the next one's (the font's "Ag" height + 2)."""
    return int(_font().getbbox("Ag")[3]) + 2


def text_lines(text: str) -> list[tuple[np.ndarray, np.ndarray]]:
    """The glyph pixels of each non-empty line of ``text`` (``\\n`` starts a new one), as column and
    row offsets (int64) from the text's top-left corner; the Display's text and a Supervisor's
    labels (``sim/viewshot.py``) are both drawn from them."""
    from PIL import Image, ImageDraw
    font = _font()
    step = line_height()
    out = []
    for k, line in enumerate(text.split("\n")):
        if not line:
            continue
        right, bottom = font.getbbox(line)[2:]
        if right <= 0 or bottom <= 0:
            continue
        glyphs = Image.new("1", (right, bottom), 0)
        ImageDraw.Draw(glyphs).text((0, 0), line, font=font, fill=1)
        gy, gx = np.nonzero(np.asarray(glyphs, dtype=np.uint8))
        out.append((gx.astype(np.int64), k * step + gy.astype(np.int64)))
    return out


def _cdiv(a: int, b: int) -> int:
    """C's integer division (truncation toward zero)."""
    q = abs(a) // abs(b)
    return q if (a >= 0) == (b >= 0) else -q


def _int(v: Any, what: str) -> int:
    if isinstance(v, bool) or not isinstance(v, int):
        raise ValueError(f"{what} must be an integer, got {v!r}")
    if not -MAX_COORD <= v <= MAX_COORD:
        raise ValueError(f"{what} {v} is out of [-{MAX_COORD}, {MAX_COORD}]")
    return v


def _point(v: Any, what: str) -> int:
    """A pixel's, a line end's or a text's coordinate: any C int (a controller's (int)(x * inf) is
    INT_MIN), as WbDisplay takes it; only what falls on the display is drawn."""
    if isinstance(v, bool) or not isinstance(v, int):
        raise ValueError(f"{what} must be an integer, got {v!r}")
    if not C_INT[0] <= v <= C_INT[1]:
        raise ValueError(f"{what} {v} is out of a C int's range [{C_INT[0]}, {C_INT[1]}]")
    return v


def _unit(v: Any, what: str) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0.0 <= float(v) <= 1.0:
        raise ValueError(f"{what} must be a number in [0, 1], got {v!r}")
    return float(v)


def _flag(v: Any, what: str) -> bool:
    if not isinstance(v, bool):
        raise ValueError(f"{what} must be true or false, got {v!r}")
    return v


def _image_id(v: Any) -> int:
    if isinstance(v, bool) or not isinstance(v, int) or not 1 <= v < 1 << 31:
        raise ValueError(f"image id must be an integer >= 1, got {v!r}")
    return v


_ARITY = {"color": 1, "alpha": 1, "opacity": 1, "font": 3, "pixel": 2, "line": 4, "rectangle": 5, "oval": 5,
          "polygon": 3, "text": 3, "copy": 5, "paste": 4, "load": 4, "rows": 5, "delete": 1, "attach": 1, "detach": 0}


def _check_image_size(w: Any, h: Any) -> None:
    """A ``load``'s or ``rows``' width and height: integers, 1 to MAX_IMAGE_PIXELS pixels in all."""
    if any(isinstance(v, bool) or not isinstance(v, int) for v in (w, h)) or w < 1 or h < 1 \
            or w * h > MAX_IMAGE_PIXELS:
        raise ValueError(f"an image is 1 to {MAX_IMAGE_PIXELS} pixels, got {w!r} x {h!r}")

def line_pixels(x0: int, y0: int, x1: int, y1: int, width: int | None = None,
                height: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The pixels of WbDisplay's Bresenham line from (x0, y0) to (x1, y1), in order; with ``width``
    and ``height`` only the steps whose major coordinate falls on the display (the others' pixels are
    off it), so a line to INT_MIN costs what its visible part does. Exact integer arithmetic (WbDisplay's
    doubled deltas overflow a C int beyond 2^30, where it draws no defined line)."""
    dx, dy = abs(x1 - x0), abs(y1 - y0)
    sx, sy = (1 if x1 >= x0 else -1), (1 if y1 >= y0 else -1)
    major, n, start, step = (dx, width, x0, sx) if dx > dy else (dy, height, y0, sy)
    lo, hi = 0, major
    if n is not None:                    # the k with 0 <= start + step * k < n
        a, b = (-start, n - 1 - start) if step > 0 else (start - n + 1, start)
        lo, hi = max(lo, a), min(hi, b)
        if lo > hi:
            empty = np.zeros(0, dtype=np.int64)
            return empty, empty
    if 2 * major * (hi + 1) < 1 << 62:  # int64 holds every product
        k = np.arange(lo, hi + 1, dtype=np.int64)
        if dx > dy:
            return x0 + sx * k, y0 + sy * ((2 * dy * k + dx) // (2 * dx))
        minor = (2 * dx * k + dy) // (2 * dy) if dy else np.zeros(len(k), dtype=np.int64)
        return x0 + sx * minor, y0 + sy * k
    # a line beyond 2^30 or so: Python's integers for the few visible steps
    ks = range(lo, hi + 1)
    if dx > dy:
        return (np.array([x0 + sx * k for k in ks], dtype=np.int64),
                np.array([y0 + sy * ((2 * dy * k + dx) // (2 * dx)) for k in ks], dtype=np.int64))
    return (np.array([x0 + sx * ((2 * dx * k + dy) // (2 * dy)) for k in ks], dtype=np.int64),
            np.array([y0 + sy * k for k in ks], dtype=np.int64))


class Display(Device):
    """One display: its image (``pixels``, uint32 0xAARRGGBB, rows top first), the drawing state
    (``color``, ``alpha``, ``opacity`` as WbDisplay keeps them), the stored images and the attached
    camera. ``measurements`` counts the changes the topic publishes."""

    captures = True                 # the step asks ``due`` after the cameras captured (simulation.py)

    def __post_init__(self) -> None:
        super().__post_init__()
        c = self.config
        self.width, self.height = int(c.width), int(c.height)
        self.pixels = np.full((self.height, self.width), BLACK, dtype=np.uint32)
        self.color, self.alpha, self.opacity = 0xFFFFFF, 0xFF, 0xFF
        self.images: dict[int, np.ndarray] = {}
        self.loading: dict[int, tuple[np.ndarray, int]] = {}  # images still coming in bands: rows, next row
        self.camera: Any = None
        self._cameras: dict[str, Any] = {}
        self._camera_seen = -1
        self._camera_rows: np.ndarray | None = None   # the camera's row and column each display pixel shows
        self._camera_cols: np.ndarray | None = None   # (None: the camera is of the display's size)
        self._changed_at = -1       # measurements when the image last changed (image_data)

    def bind(self, robot: Any) -> None:
        self._cameras = {n: d for n, d in robot.devices.items() if d.kind == "Camera"}

    def describe(self) -> dict:
        return {"width": self.width, "height": self.height}

    def readings(self) -> dict:
        return {"image": self.pixels}

    def step_reading(self) -> dict:
        return {}

    # -- the step: a new camera image under an attached camera is a new display image
    def due(self, now_ms: int) -> bool:
        cam = self.camera
        return cam is not None and cam.measurements != self._camera_seen and cam._image_at == cam.measurements

    def capture(self, now_ms: int, counters: Any) -> None:
        self._camera_seen = self.camera.measurements
        self._mark(now_ms)

    # -- what a topic publishes
    def composed(self) -> np.ndarray:
        """The image as shown: the display over the attached camera's latest image (opaque)."""
        cam = self.camera
        if cam is None:
            return self.pixels
        bgra = cam.image.view(np.uint32).reshape(cam.image.shape[:2])
        if self._camera_rows is not None:
            bgra = bgra[self._camera_rows[:, None], self._camera_cols[None, :]]
        return _over_camera(self.pixels, bgra)

    def image_data(self, reading: str) -> tuple[int, int, str, bytes] | None:
        return self.height, self.width, "bgra8", np.ascontiguousarray(self.composed()).astype("<u4").tobytes()

    # -- commands
    def check(self, commands: Any) -> list[tuple]:
        """The commands of one request, checked (ValueError naming the first bad one), as tuples."""
        if not isinstance(commands, list):
            raise ValueError("commands must be a list")
        if len(commands) > MAX_COMMANDS:
            raise ValueError(f"{len(commands)} commands, at most {MAX_COMMANDS} per display and request")
        out: list[tuple] = []
        work = 0
        stored = set(self.images) | set(self.loading)
        loading = {iid: (rows.shape[1], rows.shape[0], y) for iid, (rows, y) in self.loading.items()}
        for i, cmd in enumerate(commands):
            try:
                t, cost = self._check_one(cmd, stored, loading)
            except ValueError as exc:
                op = cmd[0] if isinstance(cmd, list) and cmd and isinstance(cmd[0], str) else "?"
                raise ValueError(f"command {i} ({op}): {exc}") from None
            work += cost
            if work > MAX_WORK:
                raise ValueError(f"command {i}: the request asks for more than {MAX_WORK} drawing steps "
                                 "(ovals, polygons and text cost one per row or glyph): send it over several steps")
            out.append(t)
        return out

    def _check_one(self, cmd: Any, stored: set[int], loading: dict[int, tuple[int, int, int]]) -> tuple[tuple, int]:
        if not isinstance(cmd, list) or not cmd or not isinstance(cmd[0], str) or cmd[0] not in _ARITY:
            raise ValueError(f"not a display command: {str(cmd)[:60]} (commands: {', '.join(_ARITY)})")
        op, args = cmd[0], cmd[1:]
        if len(args) != _ARITY[op]:
            raise ValueError(f"takes {_ARITY[op]} arguments, got {len(args)}")
        if op == "color":
            c = args[0]
            if isinstance(c, bool) or not isinstance(c, int) or not 0 <= c <= 0xFFFFFF:
                raise ValueError(f"color must be an integer 0xRRGGBB, got {c!r}")
            return (op, c), 0
        if op in ("alpha", "opacity"):
            return (op, int(_unit(args[0], op) * 255)), 0
        if op == "font":
            name, size, aa = args
            if not isinstance(name, str) or len(name) > 256 or isinstance(size, bool) or not isinstance(size, int) \
                    or size <= 0:
                raise ValueError("font takes a name and a size > 0")
            return (op,), 0
        if op == "pixel":
            return (op, _point(args[0], "x"), _point(args[1], "y")), 0
        if op == "line":
            return (op, *(_point(v, n) for v, n in zip(args, ("x1", "y1", "x2", "y2")))), 0
        if op in ("rectangle", "oval"):
            names = ("x", "y", "width", "height") if op == "rectangle" else ("cx", "cy", "a", "b")
            a, b, c, d = (_int(v, n) for v, n in zip(args[:4], names))
            if c <= 0 or d <= 0:
                raise ValueError(f"{names[2]} and {names[3]} must be > 0")
            return (op, a, b, c, d, _flag(args[4], "fill")), (c + d + 2 if op == "oval" else 1)
        if op == "polygon":
            xs, ys = args[0], args[1]
            if not isinstance(xs, list) or not isinstance(ys, list) or len(xs) != len(ys) or not xs:
                raise ValueError("polygon takes two lists of coordinates of the same length")
            if len(xs) > MAX_POLYGON:
                raise ValueError(f"{len(xs)} vertices, at most {MAX_POLYGON}")
            px = [_int(v, "x") for v in xs]
            py = [_int(v, "y") for v in ys]
            rows = max(0, min(self.height - 1, max(py)) - max(0, min(py)) + 1)
            return (op, px, py, _flag(args[2], "fill")), 1 + rows
        if op == "text":
            text = args[0]
            if not isinstance(text, str) or not text:
                raise ValueError("text must be a non-empty string")
            if len(text) > MAX_TEXT:
                raise ValueError(f"{len(text)} characters, at most {MAX_TEXT}")
            return (op, text, _point(args[1], "x"), _point(args[2], "y")), 1 + len(text)
        if op == "copy":
            iid = _image_id(args[0])
            x, y, w, h = (_int(v, n) for v, n in zip(args[1:], ("x", "y", "width", "height")))
            if w < 1 or h < 1:
                raise ValueError("width and height must be >= 1")
            self._room(stored, iid)
            return (op, iid, x, y, w, h), 1
        if op == "paste":
            iid = _image_id(args[0])
            return (op, iid, _int(args[1], "x"), _int(args[2], "y"), _flag(args[3], "blend")), 1
        if op == "load":
            iid, w, h, data = args
            iid = _image_id(iid)
            _check_image_size(w, h)
            if not isinstance(data, bytes) or len(data) != 4 * w * h:
                raise ValueError(f"data must be {4 * w * h} bytes (BGRA, {w} x {h}), got "
                                 f"{len(data) if isinstance(data, bytes) else type(data).__name__}")
            self._room(stored, iid)
            return (op, iid, w, h, data), 1
        if op == "rows":
            return self._check_rows(args, stored, loading), 1
        if op == "delete":
            iid = _image_id(args[0])
            stored.discard(iid)
            loading.pop(iid, None)
            return (op, iid), 0
        if op == "attach":
            name = args[0]
            cam = self._cameras.get(name) if isinstance(name, str) else None
            if cam is None:
                raise ValueError(f"{name!r} is no camera of robot {self.robot_name!r}")
            return (op, name), 0
        return (op,), 0

    def _check_rows(self, args: list, stored: set[int], loading: dict[int, tuple[int, int, int]]) -> tuple:
        """``rows`` id width height y data: the band of whole rows from row ``y`` of an image of
        width x height, the bands in order (the first at row 0, each where the last one ended)."""
        iid, w, h, y, data = args
        iid = _image_id(iid)
        _check_image_size(w, h)
        if isinstance(y, bool) or not isinstance(y, int) or not 0 <= y < h:
            raise ValueError(f"y must be a row of the image, 0 to {h - 1}, got {y!r}")
        if not isinstance(data, bytes) or not data or len(data) % (4 * w):
            raise ValueError(f"data must be whole rows of {w} BGRA pixels ({4 * w} bytes each), got "
                             f"{len(data) if isinstance(data, bytes) else type(data).__name__}")
        n = len(data) // (4 * w)
        if y == 0:
            self._room(stored, iid)
        else:
            if iid not in loading:
                raise ValueError(f"y {y}: image {iid} has no band before (the first band is row 0)")
            lw, lh, expect = loading[iid]
            if (w, h) != (lw, lh):
                raise ValueError(f"width x height {w} x {h} differs from the image's first band ({lw} x {lh})")
            if y != expect:
                raise ValueError(f"y {y} is out of order: image {iid}'s next band starts at row {expect}")
        if y + n > h:
            raise ValueError(f"data holds {n} rows from row {y}, past the image's height {h}")
        if y + n == h:
            loading.pop(iid, None)
        else:
            loading[iid] = (w, h, y + n)
        return ("rows", iid, w, h, y, data)

    @staticmethod
    def _room(stored: set[int], iid: int) -> None:
        stored.add(iid)
        if len(stored) > MAX_IMAGES:
            raise ValueError(f"a display keeps at most {MAX_IMAGES} images (delete some)")

    def apply(self, commands: list[tuple], now_ms: int) -> None:
        """Draw checked commands (:meth:`check`) in order; a change is a new measurement."""
        changed = False
        for cmd in commands:
            changed |= bool(getattr(self, "_op_" + cmd[0])(*cmd[1:]))
        if changed:
            self._mark(now_ms)

    def save_image(self, iid: int) -> np.ndarray | None:
        """The pixels ``wb_display_image_save`` writes: id 0 the display as shown, else a stored image."""
        if iid == 0:
            return self.composed().copy()
        img = self.images.get(iid)
        return None if img is None else img.copy()

    def reset(self) -> None:
        """WbDisplay's setup: black, white colour, opaque, no stored image, no camera."""
        self.pixels[:] = BLACK
        self.color, self.alpha, self.opacity = 0xFFFFFF, 0xFF, 0xFF
        self.images.clear()
        self.loading.clear()
        self.camera = None

    # -- the rasteriser (WbDisplay's rules)
    def _blend(self, xs: np.ndarray, ys: np.ndarray) -> bool:
        """Draw the given pixels (those on the display; repeated ones blended as often)."""
        keep = (xs >= 0) & (xs < self.width) & (ys >= 0) & (ys < self.height)
        if not keep.any():
            return False
        idx = ys[keep] * self.width + xs[keep]
        flat = self.pixels.reshape(-1)
        if self.opacity == 0xFF:
            flat[idx] = (self.alpha << 24) | self.color
            return True
        uniq, counts = np.unique(idx, return_counts=True)
        for k in range(1, int(counts.max()) + 1):
            sel = uniq[counts >= k]
            flat[sel] = _over(flat[sel], self.color, self.alpha, self.opacity)
        return True

    def _op_color(self, c: int) -> bool:
        self.color = c
        return False

    def _op_alpha(self, a: int) -> bool:
        self.alpha = a
        return False

    def _op_opacity(self, o: int) -> bool:
        self.opacity = o
        return False

    def _op_font(self) -> bool:
        return False

    def _op_pixel(self, x: int, y: int) -> bool:
        return self._blend(np.array([x]), np.array([y]))

    def _op_line(self, x0: int, y0: int, x1: int, y1: int) -> bool:
        if max(x0, x1) < 0 or max(y0, y1) < 0 or min(x0, x1) >= self.width or min(y0, y1) >= self.height:
            return False
        return self._blend(*line_pixels(x0, y0, x1, y1, self.width, self.height))

    def _op_rectangle(self, x: int, y: int, w: int, h: int, fill: bool) -> bool:
        W, H = self.width, self.height
        if fill:
            x, y = max(x, 0), max(y, 0)          # WbDisplay: the corner moves, the size stays
            w, h = min(w, W - x), min(h, H - y)
            if w <= 0 or h <= 0:
                return False
            if self.opacity == 0xFF:
                self.pixels[y:y + h, x:x + w] = 0 if self.alpha == 0 else (self.alpha << 24) | self.color
                return True
            block = self.pixels[y:y + h, x:x + w]
            block[:] = _over(block, self.color, self.alpha, self.opacity)
            return True
        nw, nh = x + w - 1, y + h - 1
        if self.opacity != 0xFF:
            cols = np.arange(max(0, x), min(nw + 1, W))
            rows = np.arange(max(0, y + 1), min(nh, H))
            xs = [cols, cols, np.full(len(rows), x), np.full(len(rows), nw)]
            ys = [np.full(len(cols), y), np.full(len(cols), nh), rows, rows]
            return self._blend(np.concatenate(xs), np.concatenate(ys))
        colour = (self.alpha << 24) | self.color
        drawn = False
        h_start = 0 if x < 0 else (-1 if x >= W else x)
        h_end = -1 if nw <= 0 else (W - 1 if nw >= W else nw)
        if h_start >= 0 and h_end >= 0:
            if 0 <= y < H:
                self.pixels[y, h_start:h_end + 1] = colour
                drawn = True
            if 0 < nh < H:
                self.pixels[nh, h_start:h_end + 1] = colour
                drawn = True
        v_start = 0 if y < 0 else (-1 if y >= H else y)
        v_end = -1 if nh < 0 else (H - 1 if nh >= H else nh)
        if v_start >= 0 and v_end >= 0:
            if 0 <= x < W:
                self.pixels[v_start:v_end + 1, x] = colour
                drawn = True
            if 0 <= nw < W:
                self.pixels[v_start:v_end + 1, nw] = colour
                drawn = True
        return drawn

    def _op_oval(self, cx: int, cy: int, a: int, b: int, fill: bool) -> bool:
        if cx + a < 0 or cx - a >= self.width or cy + b < 0 or cy - b >= self.height:
            return False
        xs: list[int] = []
        ys: list[int] = []
        lines: list[tuple[int, int, int, int]] = []
        mx1, my1, mx2, my2 = cx - a, cy, cx + a, cy
        aq, bq = a * a, b * b
        dx, dy = aq << 1, bq << 1
        r = a * bq
        rx, ry = r << 1, 0
        x = a
        old_my2 = -2
        if fill:
            lines.append((cx - a, cy, cx + a, cy))
        else:
            xs += [cx + a, cx - a]
            ys += [cy, cy]
        while x > 0:
            if r > 0:
                my1 += 1
                my2 -= 1
                ry += dx
                r -= ry
            if r <= 0:
                x -= 1
                mx1 += 1
                mx2 -= 1
                rx -= dy
                r += rx
            if fill:
                if old_my2 != my2:
                    lines.append((mx1, my1, mx2, my1))
                    lines.append((mx1, my2, mx2, my2))
                old_my2 = my2
            else:
                xs += [mx1, mx1]
                ys += [my1, my2]
                if x != 0:
                    xs += [mx2, mx2]
                    ys += [my1, my2]
        drawn = False
        if lines:                                # each row a horizontal line, as WbDisplay draws them
            span = np.array(lines, dtype=np.int64)
            lengths = span[:, 2] - span[:, 0] + 1
            first = np.repeat(np.cumsum(lengths) - lengths, lengths)
            row_x = np.repeat(span[:, 0], lengths) + np.arange(int(lengths.sum())) - first
            drawn |= self._blend(row_x, np.repeat(span[:, 1], lengths))
        if xs:
            drawn |= self._blend(np.array(xs, dtype=np.int64), np.array(ys, dtype=np.int64))
        return drawn

    def _op_polygon(self, px: list[int], py: list[int], fill: bool) -> bool:
        if min(px) >= self.width or min(py) >= self.height or max(px) < 0 or max(py) < 0:
            return False
        n = len(px)
        drawn = False
        edges: list[tuple[int, int, int]] = []
        for row in range(max(0, min(py)), min(self.height - 1, max(py)) + 1):
            nodes: list[int] = []
            j = n - 1
            for i in range(n):
                if (py[i] < row <= py[j]) or (py[j] < row <= py[i]):
                    nodes.append(px[i] + _cdiv((row - py[i]) * (px[j] - px[i]), py[j] - py[i]))
                elif py[i] == row and py[j] == row:
                    edges.append((row, min(px[i], px[j]), max(px[i], px[j])))
                j = i
            nodes.sort()
            for i in range(2, len(nodes), 2):    # WbDisplay's merge of adjacent pairs
                if nodes[i - 1] == nodes[i]:
                    nodes[i] += 1
            for i in range(0, len(nodes) - 1, 2):
                if fill:
                    drawn |= self._op_rectangle(nodes[i], row, nodes[i + 1] - nodes[i] + 1, 1, True)
                else:
                    pts = [nodes[i]] if nodes[i] == nodes[i + 1] else [nodes[i], nodes[i + 1]]
                    drawn |= self._blend(np.array(pts), np.full(len(pts), row))
        for row, left, right in edges:
            cols = np.arange(left, right + 1)
            drawn |= self._blend(cols, np.full(len(cols), row))
        return drawn

    def _op_text(self, text: str, x: int, y: int) -> bool:
        if x >= self.width or y >= self.height:
            return False
        drawn = False
        for gx, gy in text_lines(text):
            drawn |= self._blend(x + gx, y + gy)
        return drawn

    def _op_copy(self, iid: int, x: int, y: int, w: int, h: int) -> bool:
        cx, cy = max(0, x), max(0, y)
        w = min(self.width - cx, w - (cx - x))
        h = min(self.height - cy, h - (cy - y))
        if cx >= self.width or cy >= self.height or w < 1 or h < 1:
            return False                         # WbDisplay keeps nothing (a later paste does nothing)
        src = self.composed() if self.camera is not None else self.pixels
        self.images[iid] = src[cy:cy + h, cx:cx + w].copy()
        return False

    def _op_load(self, iid: int, w: int, h: int, data: bytes) -> bool:
        self.images[iid] = np.frombuffer(data, dtype="<u4").astype(np.uint32).reshape(h, w)
        return False

    def _op_rows(self, iid: int, w: int, h: int, y: int, data: bytes) -> bool:
        # the image is assembled aside and kept (a paste may show it) once its last row came
        rows = np.empty((h, w), dtype=np.uint32) if y == 0 else self.loading[iid][0]
        n = len(data) // (4 * w)
        rows[y:y + n] = np.frombuffer(data, dtype="<u4").reshape(n, w)
        if y + n == h:
            self.loading.pop(iid, None)
            self.images[iid] = rows
        else:
            self.loading[iid] = (rows, y + n)
        return False

    def _op_delete(self, iid: int) -> bool:
        self.loading.pop(iid, None)
        self.images.pop(iid, None)
        return False

    def _op_paste(self, iid: int, x: int, y: int, blend: bool) -> bool:
        img = self.images.get(iid)
        if img is None or x >= self.width or y >= self.height:
            return False
        ih, iw = img.shape
        cx, cy = max(0, x), max(0, y)
        w = min(self.width - cx, iw - (cx - x))
        h = min(self.height - cy, ih - (cy - y))
        if w < 1 or h < 1:
            return False
        src = img[cy - y:cy - y + h, cx - x:cx - x + w]
        dst = self.pixels[cy:cy + h, cx:cx + w]
        if not blend:
            dst[:] = src
            return True
        new_a = (src >> 24) & 0xFF
        alpha = np.minimum(0xFF, new_a + ((dst >> 24) & 0xFF))
        out = alpha << 24
        for shift in (16, 8, 0):
            out |= (((0xFF - new_a) * ((dst >> shift) & 0xFF) + new_a * ((src >> shift) & 0xFF)) // 0xFF) << shift
        dst[:] = out
        return True

    def _op_attach(self, name: str) -> bool:
        cam = self._cameras[name]
        if cam is self.camera:
            return False
        self.camera = cam
        self._camera_seen = -1
        ch, cw = cam.image.shape[:2]
        if (cw, ch) == (self.width, self.height):
            self._camera_rows = self._camera_cols = None
        else:
            self._camera_rows = nearest_texels(ch, self.height)
            self._camera_cols = nearest_texels(cw, self.width)
        self.pixels[self.pixels == BLACK] = 0     # WbDisplay: untouched black becomes transparent
        return True

    def _op_detach(self) -> bool:
        if self.camera is None:
            return False
        self.camera = None
        return True


def nearest_texels(texels: int, pixels: int) -> np.ndarray:
    """The texel each of ``pixels`` shows when a texture of ``texels`` is stretched over them and
    sampled at the pixel's centre without interpolation: ``floor((i + 1/2) · texels / pixels)``, in
    integers (a centre exactly on a texel boundary takes the texel after it)."""
    i = np.arange(pixels, dtype=np.int64)
    return ((2 * i + 1) * texels) // (2 * pixels)


def _over(old: np.ndarray, color: int, alpha: int, opacity: int) -> np.ndarray:
    """WbDisplay's pixel "over" operation on 0xAARRGGBB words (integer arithmetic)."""
    old = old.astype(np.uint32)
    keep = 0xFF - opacity
    out = ((keep * ((old >> 24) & 0xFF) + opacity * alpha) // 0xFF) << 24
    for shift in (16, 8, 0):
        out |= ((keep * ((old >> shift) & 0xFF) + opacity * ((color >> shift) & 0xFF)) // 0xFF) << shift
    return out.astype(np.uint32)


def _over_camera(display: np.ndarray, camera: np.ndarray) -> np.ndarray:
    """The display over the camera image by the display's alpha; the result is opaque (WbDisplay's
    image copy with an attached camera)."""
    a = (display >> 24) & 0xFF
    out = np.full(display.shape, 0xFF000000, dtype=np.uint32)
    for shift in (16, 8, 0):
        out |= (((0xFF - a) * ((camera >> shift) & 0xFF) + a * ((display >> shift) & 0xFF)) // 0xFF) << shift
    return out


def screen_image(pixels: np.ndarray) -> tuple[np.ndarray, np.ndarray | None, bool]:
    """A display's pixels (0xAARRGGBB) as a decoded texture image (world/textures.Decoded): RGB rows top
    first, its alpha when a pixel is not opaque (a camera sees through it), else None."""
    p = np.asarray(pixels, dtype=np.uint32)
    rgb = np.stack([(p >> 16) & 0xFF, (p >> 8) & 0xFF, p & 0xFF], axis=-1).astype(np.uint8)
    a = (p >> 24).astype(np.uint8)
    alpha = a if (a != 0xFF).any() else None
    return rgb, alpha, alpha is not None

