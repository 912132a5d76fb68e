"""Webots' Display functions (``wb_display_*``) on Sensorium; :mod:`sensorium.client.wb` re-exports them.

As in Webots' libController, drawing costs no round trip: every call is checked here (Webots'
error lines), buffered per Display and sent with the next step request (its ``displays`` entry),
where the server draws it before the world advances (README "The Display"). An image reference
(``wb_display_image_new``/``copy``/``load``) is a number this client gives out, as libController
does. ``wb_display_image_save`` sends the buffered commands at once and gets the pixels back (the
``draw`` service; Webots flushes the same way) and writes the file here: ``.png`` (RGBA) or
``.jpg``/``.jpeg`` (RGB, quality 100 without chroma subsampling, as libController writes it; through
Pillow), overwriting a file of that name as Webots does. ``wb_display_image_load`` reads a ``.png``,
``.jpg`` or ``.jpeg`` file through Pillow (Webots reads it in the controller too), PNG or JPEG by its
content, as the C library does."""

from __future__ import annotations

import sys
from dataclasses import dataclass
from typing import Any

from sensorium.client import images
from sensorium.client.connection import ErrorCode, SensoriumError
from sensorium.client.wb_robot import DeviceState, c_string, current, integer, real

DISPLAY = "Display"
WB_IMAGE_RGB = 3
WB_IMAGE_RGBA = 4
WB_IMAGE_ARGB = 5
WB_IMAGE_BGRA = 6
WB_IMAGE_ABGR = 7

__all__ = ["DISPLAY", "ImageRef", "WB_IMAGE_RGB", "WB_IMAGE_RGBA", "WB_IMAGE_ARGB", "WB_IMAGE_BGRA", "WB_IMAGE_ABGR",
           "wb_display_get_width", "wb_display_get_height", "wb_display_set_color", "wb_display_set_alpha",
           "wb_display_set_opacity", "wb_display_set_font", "wb_display_attach_camera", "wb_display_detach_camera",
           "wb_display_draw_pixel", "wb_display_draw_line", "wb_display_draw_rectangle", "wb_display_draw_oval",
           "wb_display_draw_polygon", "wb_display_draw_text", "wb_display_fill_rectangle", "wb_display_fill_oval",
           "wb_display_fill_polygon", "wb_display_image_new", "wb_display_image_copy", "wb_display_image_paste",
           "wb_display_image_load", "wb_display_image_save", "wb_display_image_delete"]


# What one request carries (the server's 4,096 commands per display; PROTOCOL's 1 MiB and 100,000
# values per request): a Display's list goes ahead with the "draw" service, in order, when the next
# command would pass these.
FLUSH_COMMANDS = 4096
FLUSH_ITEMS = 40_000
FLUSH_BYTES = 512 * 1024
MAX_IMAGE_PIXELS = 1 << 22     # the server's bound on one kept image
BAND_BYTES = FLUSH_BYTES       # a larger image goes in bands of whole rows, each at most this (one request)
IMAGE_TYPES = (".png", ".jpg", ".jpeg")    # the names libController reads and writes (any case)


@dataclass(frozen=True)
class ImageRef:
    """Webots' ``WbImageRef``: an image a Display keeps (``id`` >= 1), of the Display ``tag``."""

    id: int
    tag: int


def _err(func: str, what: str) -> None:
    print(f"Error: {func}(): {what}", file=sys.stderr)


def _display(tag: int, func: str) -> DeviceState | None:
    """The Display of ``tag`` (SensoriumError for another device); None when the server lists it
    only (one warning), or the controller's steps are over."""
    r = current()
    dev = r.device(tag, DISPLAY, func, listed=True)
    if not dev.simulated:
        r.warn_unsimulated(dev, func)
        return None
    return None if r.terminated else dev


def _size(command: list[Any]) -> tuple[int, int]:
    """About how many values and bytes a command adds to a request."""
    items, size = len(command), 8 * len(command)
    for v in command:
        if isinstance(v, list):
            items += len(v)
            size += 5 * len(v)
        elif isinstance(v, (bytes, str)):
            size += len(v)
    return items, size


def _add(dev: DeviceState, command: list[Any]) -> None:
    """Append a command to ``dev``'s list, sending the list ahead first if it would grow too large."""
    items, size = _size(command)
    pending = dev.drawing_size
    if dev.drawing and (len(dev.drawing) >= FLUSH_COMMANDS or pending[0] + items > FLUSH_ITEMS
                        or pending[1] + size > FLUSH_BYTES):
        commands, dev.drawing = dev.drawing, []
        current().rpc(dev, "draw", {"commands": commands})
        pending[0] = pending[1] = 0
    if not dev.drawing:
        pending[0] = pending[1] = 0
    dev.drawing.append(command)
    pending[0] += items
    pending[1] += size


def _queue(tag: int, func: str, *command: Any) -> None:
    dev = _display(tag, func)
    if dev is not None:
        _add(dev, list(command))


def _int(v: Any, func: str, name: str) -> int:
    i = integer(v)
    if i is None:
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): '{name}' must be an integer, got {v!r}")
    return i


def _next_id(dev: DeviceState) -> int:
    dev.image_ids += 1
    return dev.image_ids


def wb_display_get_width(tag: int) -> int:
    return int(current().device(tag, DISPLAY, "wb_display_get_width", listed=True).desc.get("width", 0))


def wb_display_get_height(tag: int) -> int:
    return int(current().device(tag, DISPLAY, "wb_display_get_height", listed=True).desc.get("height", 0))


def wb_display_set_color(tag: int, color: int) -> None:
    func = "wb_display_set_color"
    c = _int(color, func, "color")
    if not 0 <= c <= 0xFFFFFF:
        return _err(func, "'color' argument out of bounds.")
    _queue(tag, func, "color", c)


def _unit(tag: int, func: str, name: str, value: Any) -> None:
    v = real(value)
    if v is None:
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): '{name}' must be a number, got {value!r}")
    if not 0.0 <= v <= 1.0:
        return _err(func, f"'{name}' argument out of bounds.")
    _queue(tag, func, name, v)


def wb_display_set_alpha(tag: int, alpha: float) -> None:
    _unit(tag, "wb_display_set_alpha", "alpha", alpha)


def wb_display_set_opacity(tag: int, opacity: float) -> None:
    _unit(tag, "wb_display_set_opacity", "opacity", opacity)


def wb_display_set_font(tag: int, font: str, size: int, anti_aliasing: bool) -> None:
    font = c_string(font)
    func = "wb_display_set_font"
    n = _int(size, func, "size")
    if n <= 0:
        return _err(func, "'size' argument is negative or null.")
    _queue(tag, func, "font", str(font), n, bool(anti_aliasing))


def wb_display_attach_camera(tag: int, camera_tag: int) -> None:
    func = "wb_display_attach_camera"
    dev = _display(tag, func)
    cam = current().device(camera_tag, "Camera", func)
    if dev is None:
        return
    if dev.camera.get("attached"):
        return _err(func, "a camera is already attached to the display.")
    dev.camera["attached"] = cam.name
    _add(dev, ["attach", cam.name])


def wb_display_detach_camera(tag: int) -> None:
    func = "wb_display_detach_camera"
    dev = _display(tag, func)
    if dev is None:
        return
    if not dev.camera.get("attached"):
        return _err(func, "no camera to detach.")
    dev.camera["attached"] = None
    _add(dev, ["detach"])


def wb_display_draw_pixel(tag: int, x: int, y: int) -> None:
    func = "wb_display_draw_pixel"
    _queue(tag, func, "pixel", _int(x, func, "x"), _int(y, func, "y"))


def wb_display_draw_line(tag: int, x1: int, y1: int, x2: int, y2: int) -> None:
    func = "wb_display_draw_line"
    _queue(tag, func, "line", *(_int(v, func, n) for v, n in ((x1, "x1"), (y1, "y1"), (x2, "x2"), (y2, "y2"))))


def _box(tag: int, func: str, op: str, names: tuple[str, str, str, str], values: tuple, fill: bool) -> None:
    a, b, c, d = (_int(v, func, n) for v, n in zip(values, names))
    for v, n in ((c, names[2]), (d, names[3])):
        if v <= 0:
            return _err(func, f"'{n}' argument is negative or null.")
    _queue(tag, func, op, a, b, c, d, fill)


def wb_display_draw_rectangle(tag: int, x: int, y: int, width: int, height: int) -> None:
    _box(tag, "wb_display_draw_rectangle", "rectangle", ("x", "y", "width", "height"), (x, y, width, height), False)


def wb_display_fill_rectangle(tag: int, x: int, y: int, width: int, height: int) -> None:
    _box(tag, "wb_display_fill_rectangle", "rectangle", ("x", "y", "width", "height"), (x, y, width, height), True)


def wb_display_draw_oval(tag: int, cx: int, cy: int, a: int, b: int) -> None:
    _box(tag, "wb_display_draw_oval", "oval", ("cx", "cy", "horizontal_radius", "vertical_radius"), (cx, cy, a, b),
         False)


def wb_display_fill_oval(tag: int, cx: int, cy: int, a: int, b: int) -> None:
    _box(tag, "wb_display_fill_oval", "oval", ("cx", "cy", "horizontal_radius", "vertical_radius"), (cx, cy, a, b),
         True)


def _polygon(tag: int, func: str, x: Any, y: Any, size: Any, fill: bool) -> None:
    if x is None or y is None:
        return _err(func, "'x' or 'y' argument is NULL.")
    xs, ys = list(x), list(y)
    n = min(len(xs), len(ys)) if size is None else _int(size, func, "size")
    if n < 1 or n > len(xs) or n > len(ys):
        return _err(func, f"'size' {n} does not fit the {len(xs)} x and {len(ys)} y coordinates.")
    _queue(tag, func, "polygon", [_int(v, func, "x") for v in xs[:n]], [_int(v, func, "y") for v in ys[:n]], fill)


def wb_display_draw_polygon(tag: int, x: Any, y: Any, size: int | None = None) -> None:
    _polygon(tag, "wb_display_draw_polygon", x, y, size, False)


def wb_display_fill_polygon(tag: int, x: Any, y: Any, size: int | None = None) -> None:
    _polygon(tag, "wb_display_fill_polygon", x, y, size, True)


def wb_display_draw_text(tag: int, text: str, x: int, y: int) -> None:
    text = c_string(text)
    func = "wb_display_draw_text"
    if not text:
        return _err(func, "'text' argument is NULL or empty.")
    _queue(tag, func, "text", str(text), _int(x, func, "x"), _int(y, func, "y"))


def _to_bgra(data: bytes, fmt: int, n: int) -> bytes | None:
    """Pixels in ``fmt`` as 0xAARRGGBB words (bytes B, G, R, A): WbDisplay::imageLoad's conversions."""
    channels = 3 if fmt == WB_IMAGE_RGB else 4
    if len(data) < channels * n:
        return None
    src = data[:channels * n]
    out = bytearray(4 * n)
    if fmt == WB_IMAGE_RGB:
        out[0::4], out[1::4], out[2::4], out[3::4] = src[2::3], src[1::3], src[0::3], b"\xff" * n
    elif fmt == WB_IMAGE_RGBA:
        out[0::4], out[1::4], out[2::4], out[3::4] = src[2::4], src[1::4], src[0::4], src[3::4]
    elif fmt == WB_IMAGE_ARGB:
        out[0::4], out[1::4], out[2::4], out[3::4] = src[3::4], src[2::4], src[1::4], src[0::4]
    elif fmt == WB_IMAGE_BGRA:
        out[:] = src
    else:                                           # ABGR
        out[0::4], out[1::4], out[2::4], out[3::4] = src[1::4], src[2::4], src[3::4], src[0::4]
    return bytes(out)


def wb_display_image_new(tag: int, width: Any, height: Any, data: Any, format: int = WB_IMAGE_RGB) -> ImageRef | None:
    func = "wb_display_image_new"
    if data is None:
        _err(func, "'data' argument is NULL.")
        return None
    w, h, fmt = _int(width, func, "width"), _int(height, func, "height"), _int(format, func, "format")
    if w < 1 or h < 1:
        _err(func, "'width' or 'height' argument is invalid.")
        return None
    if fmt not in (WB_IMAGE_RGB, WB_IMAGE_RGBA, WB_IMAGE_ARGB, WB_IMAGE_BGRA, WB_IMAGE_ABGR):
        _err(func, "'format' argument is invalid.")
        return None
    if w * h > MAX_IMAGE_PIXELS:
        _err(func, f"a {w} x {h} image is {w * h} pixels, more than a Display keeps ({MAX_IMAGE_PIXELS}).")
        return None
    if 4 * w > BAND_BYTES:
        _err(func, f"a row of {w} pixels is {4 * w} bytes, more than one request carries ({BAND_BYTES}).")
        return None
    raw = data.tobytes() if hasattr(data, "tobytes") else bytes(data)
    bgra = _to_bgra(raw, fmt, w * h)
    if bgra is None:
        _err(func, f"'data' holds {len(raw)} bytes, fewer than {w} x {h} pixels of {3 if fmt == 3 else 4} bytes.")
        return None
    dev = _display(tag, func)
    if dev is None:
        return None
    ref = ImageRef(_next_id(dev), tag)
    if 4 * w * h <= BAND_BYTES:
        _add(dev, ["load", ref.id, w, h, bgra])
        return ref
    band = BAND_BYTES // (4 * w)                    # rows per request; the server keeps the image at its last row
    for y in range(0, h, band):
        _add(dev, ["rows", ref.id, w, h, y, bgra[4 * w * y:4 * w * min(h, y + band)]])
    return ref


def wb_display_image_load(tag: int, filename: str) -> ImageRef | None:
    filename = c_string(filename)
    func = "wb_display_image_load"
    if not filename:
        _err(func, "'filename' argument is NULL or empty.")
        return None
    try:
        from PIL import Image
    except ImportError:
        _err(func, f"reading {filename!r} needs Pillow here (pip install pillow).")
        return None
    if not str(filename).lower().endswith(IMAGE_TYPES):
        _err(func, f"the \"{filename}\" image is unreadable (unsupported image type: a .png, .jpg or .jpeg file is read).")
        return None
    try:
        with Image.open(filename, formats=["PNG", "JPEG"]) as im:
            w, h = im.size
            if w * h > MAX_IMAGE_PIXELS:
                _err(func, f"the \"{filename}\" image is unreadable ({w} x {h} pixels, more than one image may hold "
                           f"({MAX_IMAGE_PIXELS})).")
                return None
            rgba = im.convert("RGBA")
            w, h = rgba.size
            data = rgba.tobytes()
    except FileNotFoundError:
        _err(func, f"the \"{filename}\" image is unreadable (cannot be opened).")
        return None
    except (OSError, ValueError, SyntaxError) as exc:
        _err(func, f"the \"{filename}\" image is unreadable ({exc}).")
        return None
    return wb_display_image_new(tag, w, h, data, WB_IMAGE_RGBA)


def _ref(tag: int, ref: Any, func: str, what: str = "invalid WbImageRef argument.") -> int | None:
    if not isinstance(ref, ImageRef) or ref.id <= 0:
        _err(func, what)
        return None
    if ref.tag != tag:
        _err(func, "invalid WbImageRef created by a different Display device.")
        return None
    return ref.id


def wb_display_image_copy(tag: int, x: int, y: int, width: int, height: int) -> ImageRef | None:
    func = "wb_display_image_copy"
    a, b, w, h = (_int(v, func, n) for v, n in ((x, "x"), (y, "y"), (width, "width"), (height, "height")))
    if w < 1 or h < 1:
        _err(func, "'width' or 'height' argument is invalid.")
        return None
    dev = _display(tag, func)
    if dev is None:
        return None
    ref = ImageRef(_next_id(dev), tag)
    _add(dev, ["copy", ref.id, a, b, w, h])
    return ref


def wb_display_image_paste(tag: int, ref: Any, x: int, y: int, blend: bool = False) -> None:
    func = "wb_display_image_paste"
    iid = _ref(tag, ref, func)
    if iid is not None:
        _queue(tag, func, "paste", iid, _int(x, func, "x"), _int(y, func, "y"), bool(blend))


def wb_display_image_delete(tag: int, ref: Any) -> None:
    func = "wb_display_image_delete"
    iid = _ref(tag, ref, func, "invalid WbImageRef.")
    if iid is not None:
        _queue(tag, func, "delete", iid)


def wb_display_image_save(tag: int, ref: Any, filename: str) -> None:
    """Write the display as shown (``ref`` None) or a kept image to ``filename`` (.png or .jpg)."""
    filename = c_string(filename)
    func = "wb_display_image_save"
    if not filename:
        return _err(func, "'filename' argument is NULL or empty.")
    iid = 0
    if ref is not None:
        got = _ref(tag, ref, func, "invalid WbImageRef.")
        if got is None:
            return None
        iid = got
    lower = str(filename).lower()
    if not lower.endswith((".png", ".jpg", ".jpeg")):
        return _err(func, 'unsupported file format. Supported file formats are ".jpg" and ".png".')
    dev = _display(tag, func)
    if dev is None:
        return None
    commands, dev.drawing = dev.drawing, []
    reply = current().rpc(dev, "draw", {"commands": commands, "save": iid})
    data = reply.get("data")
    if data is None:
        return _err(func, f"image {iid} of Display '{dev.name}' holds no pixels (a copy outside the display, "
                          f"or deleted): {str(filename)!r} is not written.")
    w, h = int(reply["width"]), int(reply["height"])
    if lower.endswith(".png"):
        images.write_file(func, str(filename), images.png_rgba_bytes(bytes(data), w, h))
    else:
        _save_jpeg(func, str(filename), images.bgra_to_rgb(bytes(data)), w, h)
    return None


def _save_jpeg(func: str, filename: str, rgb: bytes, width: int, height: int) -> None:
    """libController's display JPEG: quality 100, the alpha dropped, no chroma subsampling (4:4:4)."""
    try:
        from PIL import Image
    except ImportError:
        return _err(func, "JPEG needs Pillow here (pip install pillow); save a .png instead.")
    import io
    buf = io.BytesIO()
    Image.frombytes("RGB", (width, height), rgb).save(buf, format="JPEG", quality=100, subsampling=0)
    images.write_file(func, filename, buf.getvalue())
    return None
