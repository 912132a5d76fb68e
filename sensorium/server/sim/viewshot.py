"""Pictures of the world without a GPU: the Viewpoint's view rendered on the CPU, a Supervisor's
labels drawn over it (Webots' ``wb_supervisor_export_image`` and ``wb_supervisor_set_label``, and
``sensorium snapshot``).

The view is a planar camera at the world's ``Viewpoint`` (its ``position``, ``orientation``,
``fieldOfView``, ``near``, ``far`` and ``exposure``; a world without one has Webots' default,
``position -10 0 0``, ``orientation 0 0 1 0``): Webots' viewpoint convention is the camera's, x
forward, y left, z up, so its image is what a ``Camera`` device of that size would see there,
rendered by the camera's own code (``cameras.Camera._render``: exact rays, the same lights,
shadows, transparency, fog and background). ``fieldOfView`` spans the image's larger dimension
(Webots' ``WbViewpoint``, the VRML rule): the horizontal one of a landscape image.

Labels are Webots' overlay of the 3D view: text whose top-left corner is at ``(x·W, y·H)`` in
its colour, ``transparency`` mixing it with the picture (``display._over``, WbDisplay's integer
blend), one per id, drawn in increasing id order. The glyphs are the Display's (``display.text_lines``:
Pillow's small bitmap font, Webots' TrueType fonts are not here), each glyph pixel scaled to a
square of ``max(1, round(size·H / line height))`` pixels, so ``size`` (a fraction of the height,
Webots' unit) sets the text's height to the nearest whole multiple of the font's.

A Supervisor's movie (:class:`Movie`) is the same picture rendered at Webots' frame times
(:func:`movie_frame_step`) while it records, the frames kept until the recording controller takes
them (its client pipes them into ffmpeg); a simulation without one renders nothing.

The work is bounded: an image has at most :data:`MAX_PIXELS` pixels, a label's text
:data:`MAX_TEXT` characters, a simulation :data:`MAX_LABELS` labels, and a label's glyph squares
are cut to the image before they are filled (a label costs at most about the image's pixels).
"""

from __future__ import annotations

import math
import re
from collections import Counter
from dataclasses import dataclass
from typing import Any

import numpy as np

from sensorium.server.devices import imaging, shading
from sensorium.server.sim import display
from sensorium.server.sim.cameras import Camera, MountedRays
from sensorium.server.sim.sensors import Device
from sensorium.server.world.geometry import Pose

__all__ = ["EXPORT_SIZE", "MAX_PIXELS", "MAX_SIDE", "MAX_LABELS", "MAX_TEXT", "MAX_LABEL_ID", "Label", "Labels",
           "Viewpoint", "placed_viewpoint", "viewpoint_of", "framing_position", "render", "draw_labels", "picture", "parse_size", "FORMATS",
           "image_format", "encode", "snapshot", "Movie", "movie_frame_step"]

EXPORT_SIZE = (640, 480)
"""The size of a Supervisor's ``exportImage`` (Webots': its 3D window's, which a server has not)."""
MAX_SIDE = 4096
MAX_PIXELS = 1 << 22
MAX_STEPS = 1_000_000          # basic steps `sensorium snapshot` runs first, at most
MAX_LABELS = 256
MAX_TEXT = 1024
MAX_LABEL_ID = 65534          # Webots: ids 0..65534, 65535 is its movie caption's


@dataclass(frozen=True, slots=True)
class Viewpoint:
    """A Viewpoint's fields as the view uses them."""

    position: tuple[float, float, float] = (-10.0, 0.0, 0.0)
    orientation: tuple[float, float, float, float] = (0.0, 0.0, 1.0, 0.0)
    field_of_view: float = 0.785398
    near: float = 0.05
    far: float = 0.0
    exposure: float = 1.0

    def pose(self) -> Pose:
        ax = self.orientation
        return Pose.from_axis_angle(ax[:3], ax[3], self.position)


def placed_viewpoint(sim: Any) -> bool:
    """Whether the world's Viewpoint has a position or orientation written (a world without one
    gets Webots' default node, empty, as Webots adds it; :func:`viewpoint_of` then looks from
    (-10, 0, 0) along +x)."""
    layout = getattr(sim, "top_level", None)
    return any(s.type == "Viewpoint" and ("position" in s.fields or "orientation" in s.fields)
               for s in (layout.scenery if layout is not None else ()))


def viewpoint_of(sim: Any) -> Viewpoint:
    """The world's Viewpoint (its written fields, Webots' defaults for the others); a value that
    makes no view is one line naming it (ValueError)."""
    layout = getattr(sim, "top_level", None)
    fields: dict = {}
    for s in (layout.scenery if layout is not None else ()):
        if s.type == "Viewpoint":
            fields = dict(s.fields)
            break
    d = Viewpoint()

    def numbers(name: str, n: int, default: tuple) -> tuple:
        v = fields.get(name, default)
        try:
            out = tuple(float(c) for c in v)
        except (TypeError, ValueError):
            out = ()
        if len(out) != n or not all(math.isfinite(c) for c in out):
            raise ValueError(f"Viewpoint {name} must be {n} finite numbers, got {v!r}")
        return out

    def number(name: str, default: float) -> float:
        v = fields.get(name, default)
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
            raise ValueError(f"Viewpoint {name} must be a finite number, got {v!r}")
        return float(v)

    vp = Viewpoint(numbers("position", 3, d.position), numbers("orientation", 4, d.orientation),
                   number("fieldOfView", d.field_of_view), number("near", d.near), number("far", d.far),
                   number("exposure", d.exposure))
    if not 0.0 < vp.field_of_view < math.pi:
        raise ValueError(f"Viewpoint fieldOfView must be in (0, pi) for a picture, got {vp.field_of_view}")
    if vp.near < 0.0 or vp.far < 0.0 or vp.exposure < 0.0:
        raise ValueError("Viewpoint near, far and exposure must be >= 0")
    return vp


def framing_position(vp: Viewpoint, centre: np.ndarray, radius: float) -> tuple[float, float, float]:
    """Where Webots' ``moveViewpoint`` puts the Viewpoint to frame a bounding sphere (WbViewpoint's
    ``moveViewpointToObject``): its orientation kept, backed off from ``centre`` along its view
    direction (+x of its frame) by ``d = 1.05 r / (sin(fov/2) * min(a, 1/a))``, at least
    ``near + 1.05 r``. Webots' ``a`` is its 3D view's aspect; headless, the exportImage picture's
    (``EXPORT_SIZE``)."""
    w, h = EXPORT_SIZE
    aspect = w / h
    r = 1.05 * radius
    d = max(r / (math.sin(vp.field_of_view / 2.0) * min(aspect, 1.0 / aspect)), vp.near + r)
    forward = vp.pose().apply_dirs(np.array([[1.0, 0.0, 0.0]]))[0]
    p = np.asarray(centre, dtype=np.float64) - d * forward
    return (float(p[0]), float(p[1]), float(p[2]))


class _Eye:
    """What ``Camera._render`` reads of a camera, for a camera that is no device: no robot, no
    shapes of its own, the scene's lights and background."""

    own_shapes: frozenset[int] = frozenset()
    hidden_shapes = Device.hidden_shapes      # the Viewpoint's: those a Supervisor hid from it
    _rays: Any = None          # (its rays are render()'s; its shadow buffers made per picture)
    _shadow_out: Any = None
    _render = Camera._render
    _shadows = Camera._shadows
    _light_arrays = Camera._light_arrays

    def __init__(self, scene: Any, limits: tuple[Any, Any], hidden: dict[int, frozenset[int]]):
        self.hidden = hidden
        self._scene = scene
        self._background = scene.background
        self._limits = limits
        self._lights: Any = None


def geometry(vp: Viewpoint, width: int, height: int) -> imaging.ImageGeometry:
    """The planar image: ``fieldOfView`` across the larger side (a portrait image's vertical one)."""
    fov = vp.field_of_view
    if width < height:
        fov = 2.0 * math.atan(math.tan(fov / 2.0) * width / height)
    return imaging.ImageGeometry(width, height, fov, "planar")


def render(sim: Any, width: int, height: int) -> np.ndarray:
    """The world seen from its Viewpoint now: RGB uint8 (height, width, 3), row 0 at the top."""
    width, height = parse_size_values(width, height)
    if hasattr(sim, "show_screens"):      # displays drawn on while no device looked show now
        sim.show_screens()
    vp = viewpoint_of(sim)
    g = geometry(vp, width, height)
    dirs = imaging.pixel_directions(g)[0]
    factors = imaging.depth_factors(g, dirs)
    limits = imaging.clip_limits(g, factors, vp.near, vp.far if vp.far > 0.0 else math.inf)
    eye = _Eye(sim.scene, limits, getattr(sim, "viewpoint_hidden", {}))
    L = eye._render(vp.pose(), MountedRays(dirs), Counter())
    v = shading.tone_map(L, vp.exposure).reshape(height, width, 3)
    return shading.to_bytes(v)


# ------------------------------------------------------------------------------ labels

@dataclass(frozen=True, slots=True)
class Label:
    text: str
    x: float
    y: float
    size: float
    color: int            # 0xRRGGBB
    transparency: float
    font: str


def _unit(v: Any, what: str) -> float:
    if isinstance(v, bool) or not isinstance(v, int | float) or not 0.0 <= float(v) <= 1.0:
        raise ValueError(f"label {what} must be a number in [0, 1], got {v!r}")
    return float(v)


class Labels:
    """A Supervisor's labels by id (Webots' ``supervisor_label`` list): setting an id again
    replaces its label; they stay until the simulation ends."""

    def __init__(self) -> None:
        self._by_id: dict[int, Label] = {}

    def set(self, id: Any, text: Any, x: Any, y: Any, size: Any, color: Any, transparency: Any, font: Any) -> None:
        if isinstance(id, bool) or not isinstance(id, int) or not 0 <= id <= MAX_LABEL_ID:
            raise ValueError(f"label id must be an integer in 0..{MAX_LABEL_ID}, got {id!r}")
        if not isinstance(text, str) or len(text) > MAX_TEXT:
            raise ValueError(f"label {id} text must be a string of at most {MAX_TEXT} characters")
        bad = next((c for c in text if not (32 <= ord(c) <= 127 or c == "\n")), None)
        if bad is not None:
            raise ValueError(f"label {id} text has {bad!r}: only characters 32..127 (and newlines) are displayed")
        if isinstance(color, bool) or not isinstance(color, int) or not 0 <= color <= 0xFFFFFF:
            raise ValueError(f"label {id} color must be an integer 0xRRGGBB, got {color!r}")
        if not isinstance(font, str) or len(font) > 256:
            raise ValueError(f"label {id} font must be a string of at most 256 characters")
        label = Label(text, _unit(x, "x"), _unit(y, "y"), _unit(size, "size"), int(color),
                      _unit(transparency, "transparency"), font)
        if id not in self._by_id and len(self._by_id) >= MAX_LABELS:
            raise ValueError(f"at most {MAX_LABELS} labels are kept; set an existing id again to change one")
        self._by_id[id] = label

    def items(self) -> list[tuple[int, Label]]:
        return sorted(self._by_id.items())

    def __len__(self) -> int:
        return len(self._by_id)


def label_scale(size: float, height: int) -> int:
    """The side of the square each glyph pixel becomes: ``size·H`` over the font's line height."""
    return max(1, int(math.floor(size * height / display.line_height() + 0.5)))


def draw_labels(rgb: np.ndarray, labels: Labels) -> np.ndarray:
    """The labels over an RGB image (a new array)."""
    h, w = rgb.shape[:2]
    words = (np.uint32(0xFF000000) | (rgb[..., 0].astype(np.uint32) << 16) | (rgb[..., 1].astype(np.uint32) << 8)
             | rgb[..., 2].astype(np.uint32)).reshape(-1)
    for _, lab in labels.items():
        k = label_scale(lab.size, h)
        x0, y0 = int(math.floor(lab.x * w)), int(math.floor(lab.y * h))
        if x0 >= w or y0 >= h:
            continue
        # the glyph pixels on the image, in glyph units, each then grown to its k x k square and the
        # squares cut to the image: about the label's part of the picture in work, whatever k
        nx, ny = -(-(w - x0) // k), -(-(h - y0) // k)
        small = np.zeros((ny, nx), dtype=bool)
        for gx, gy in display.text_lines(lab.text):
            on = (gx < nx) & (gy < ny)
            small[gy[on], gx[on]] = True
        if not small.any():
            continue
        mask2d = np.zeros((h, w), dtype=bool)
        mask2d[y0:, x0:] = small.repeat(k, axis=0).repeat(k, axis=1)[: h - y0, : w - x0]
        mask = mask2d.reshape(-1)
        if mask.any():
            opacity = 0xFF - int(lab.transparency * 0xFF)      # libController's transparency byte
            words[mask] = display._over(words[mask], lab.color, 0xFF, opacity)
    out = np.empty_like(rgb)
    words = words.reshape(h, w)
    out[..., 0], out[..., 1], out[..., 2] = (words >> 16) & 0xFF, (words >> 8) & 0xFF, words & 0xFF
    return out


def picture(sim: Any, width: int, height: int, labels: Labels | None = None) -> np.ndarray:
    """The Viewpoint's view with the labels over it: RGB uint8 (height, width, 3)."""
    rgb = render(sim, width, height)
    return draw_labels(rgb, labels) if labels is not None and len(labels) else rgb


def parse_size_values(width: Any, height: Any) -> tuple[int, int]:
    for v, what in ((width, "width"), (height, "height")):
        if isinstance(v, bool) or not isinstance(v, int) or not 1 <= v <= MAX_SIDE:
            raise ValueError(f"image {what} must be an integer in 1..{MAX_SIDE}, got {v!r}")
    if width * height > MAX_PIXELS:
        raise ValueError(f"image {width}x{height} has more than {MAX_PIXELS} pixels")
    return int(width), int(height)


def parse_size(text: str) -> tuple[int, int]:
    """``"WxH"`` → (W, H), bounded as :func:`render` bounds them."""
    parts = str(text).lower().split("x")
    if len(parts) != 2 or not all(re.fullmatch(r"[0-9]{1,12}", p.strip()) for p in parts):
        raise ValueError(f"size must be WIDTHxHEIGHT (e.g. 640x480), got {text!r}")
    return parse_size_values(int(parts[0]), int(parts[1]))


# ------------------------------------------------------------------------------ files (sensorium snapshot)

FORMATS = {".png": "PNG", ".jpg": "JPEG", ".jpeg": "JPEG"}


def image_format(name: str) -> str:
    """"PNG" or "JPEG" by a file name's extension (Webots' ``exportImage`` rule); another is one line."""
    import os

    ext = os.path.splitext(str(name))[1].lower()
    if ext not in FORMATS:
        raise ValueError(f"{name}: the picture must end in .png, .jpg or .jpeg")
    return FORMATS[ext]


def encode(rgb: np.ndarray, fmt: str, quality: int = 95) -> bytes:
    """An RGB image (H, W, 3) uint8 as PNG or JPEG (``quality`` 1..100) bytes (Pillow)."""
    import io

    from PIL import Image
    if isinstance(quality, bool) or not isinstance(quality, int) or not 1 <= quality <= 100:
        raise ValueError(f"JPEG quality must be an integer in 1..100, got {quality!r}")
    buf = io.BytesIO()
    image = Image.fromarray(np.ascontiguousarray(rgb), "RGB")
    if fmt == "JPEG":
        image.save(buf, format="JPEG", quality=quality)
    else:
        image.save(buf, format="PNG")
    return buf.getvalue()


def snapshot(sim: Any, width: int, height: int, steps: int = 0) -> np.ndarray:
    """``sensorium snapshot``: ``steps`` basic steps of ``sim`` (its robots with no controller),
    then the Viewpoint's view."""
    if isinstance(steps, bool) or not isinstance(steps, int) or not 0 <= steps <= MAX_STEPS:
        raise ValueError(f"steps must be an integer in 0..{MAX_STEPS}, got {steps!r}")
    width, height = parse_size_values(width, height)
    viewpoint_of(sim)                 # a Viewpoint that makes no picture: said before any step
    for _ in range(steps):
        sim.step()
    return picture(sim, width, height)


# ------------------------------------------------------------------------------ movies

MOVIE_FRAME_MS = 40               # Webots' aim between two frames at acceleration 1 (25 fps)
MOVIE_MAX_ACCELERATION = 10_000
MOVIE_MAX_FRAMES = 1 << 20        # a movie's frames, at most (about 11.6 h at 25 fps)
MOVIE_QUEUE_BYTES = 128 << 20     # frames waiting for the recording controller, at most
MOVIE_REPLY_BYTES = 32 << 20      # frames handed over in one reply, at most (one frame always)
CAPTION_ID = 65535                # Webots' movie caption label


def movie_frame_step(basic_ms: int, acceleration: int) -> int:
    """The simulated ms between two movie frames (Webots' WbVideoRecorder rule): a whole number
    of basic steps near ``acceleration`` × 40 ms, the lower whole number unless it is 0 or the
    upper one's step lies nearer 40 ms."""
    refresh = acceleration * MOVIE_FRAME_MS / basic_ms
    low, high = math.floor(refresh) * basic_ms, math.ceil(refresh) * basic_ms
    if low == 0 or abs(low - MOVIE_FRAME_MS) > abs(high - MOVIE_FRAME_MS):
        return int(high)
    return int(low)


class Movie:
    """A Supervisor's movie on the server: the Viewpoint's picture (labels and caption over it)
    rendered at every ``step_ms`` of simulated time after its start, kept until the recording
    controller takes them (:meth:`take`). A simulation without a movie renders nothing."""

    def __init__(self, robot: str, start_ms: int, basic_ms: int, width: Any, height: Any, acceleration: Any,
                 caption: Any) -> None:
        width, height = parse_size_values(width, height)
        if width % 2 or height % 2:
            raise ValueError(f"movie size {width}x{height}: width and height must be even (H.264, 4:2:0 colour)")
        if (isinstance(acceleration, bool) or not isinstance(acceleration, int)
                or not 1 <= acceleration <= MOVIE_MAX_ACCELERATION):
            raise ValueError(f"movie acceleration must be an integer in 1..{MOVIE_MAX_ACCELERATION}, "
                             f"got {acceleration!r}")
        self.robot = robot
        self.width, self.height = width, height
        self.step_ms = movie_frame_step(basic_ms, acceleration)
        self.next_ms = start_ms + self.step_ms
        self.frames = 0                     # taken so far
        self.full = False                   # MOVIE_MAX_FRAMES reached: no more frames taken
        self.failed = ""                    # why the server stopped taking frames
        self.queue: list[bytes] = []
        self.queued = 0
        self.caption: Label | None = None
        if caption:
            # Webots' caption: the acceleration ("4x") in white at the top right, 0.2 of the height
            self.caption = Label(f"{acceleration}x", 1.0 - 0.227 * height / width, 0.025, 0.2, 0xFFFFFF, 0.0, "Arial")

    def after_step(self, sim: Any, labels: Labels | None) -> None:
        """Called after every basic step: the frame when its time has come."""
        now = sim.time_ms
        if now < self.next_ms or self.failed:
            return
        self.next_ms += self.step_ms        # (start and step are whole basic steps)
        if self.frames >= MOVIE_MAX_FRAMES:
            self.full = True
            return
        size = self.width * self.height * 3
        if self.queued + size > MOVIE_QUEUE_BYTES:
            self.failed = (f"the movie's frames not yet taken by the recording controller passed "
                           f"{MOVIE_QUEUE_BYTES >> 20} MiB: step it more often, or record a smaller movie")
            return
        over = Labels()
        if labels is not None:
            over._by_id.update(labels._by_id)
        if self.caption is not None:
            over._by_id[CAPTION_ID] = self.caption
        try:
            rgb = picture(sim, self.width, self.height, over)
        except ValueError as exc:            # a Viewpoint a Supervisor made unusable
            self.failed = str(exc)
            return
        except Exception as exc:  # noqa: BLE001 - a rendering bug ends the movie, never the world's step
            self.failed = f"the frame at {now} ms could not be rendered: {type(exc).__name__}: {exc}"
            return
        self.queue.append(rgb.tobytes())
        self.queued += size
        self.frames += 1

    def take(self) -> tuple[list[bytes], bool]:
        """The frames waiting (at most MOVIE_REPLY_BYTES of them, one at least) and whether more wait."""
        out, n = [], 0
        while self.queue and (not out or n + len(self.queue[0]) <= MOVIE_REPLY_BYTES):
            frame = self.queue.pop(0)
            out.append(frame)
            n += len(frame)
        self.queued -= n
        return out, bool(self.queue)
