"""Saving images as Webots' ``save_image`` functions do: PNG written here (zlib only, the client
stays light), JPEG through Pillow when it is installed, a range finder's Radiance HDR (``.hdr``)
written here. Returns Webots' 0 / -1."""

from __future__ import annotations

import array
import math
import struct
import sys
import zlib


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)


def png_bytes(rgb: bytes, width: int, height: int) -> bytes:
    """An 8-bit RGB PNG of ``rgb`` (``height`` rows of ``width`` × 3 bytes, top row first)."""
    row = 3 * width
    raw = b"".join(b"\0" + rgb[y * row:(y + 1) * row] for y in range(height))
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", header) + _chunk(b"IDAT", zlib.compress(raw, 6)) + _chunk(b"IEND", b"")


def png_rgba_bytes(bgra: bytes, width: int, height: int) -> bytes:
    """An 8-bit RGBA PNG of ``bgra`` (``height`` rows of ``width`` × 4 bytes B, G, R, A, top row first)."""
    rgba = bytearray(len(bgra))
    rgba[0::4], rgba[1::4], rgba[2::4], rgba[3::4] = bgra[2::4], bgra[1::4], bgra[0::4], bgra[3::4]
    row = 4 * width
    raw = b"".join(b"\0" + bytes(rgba[y * row:(y + 1) * row]) for y in range(height))
    header = struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", header) + _chunk(b"IDAT", zlib.compress(raw, 6)) + _chunk(b"IEND", b"")


def bgra_to_rgb(bgra: bytes) -> bytes:
    out = bytearray(len(bgra) // 4 * 3)
    out[0::3] = bgra[2::4]
    out[1::3] = bgra[1::4]
    out[2::3] = bgra[0::4]
    return bytes(out)


def hdr_bytes(grey: list[float], width: int, height: int) -> bytes:
    """A Radiance picture (``#?RADIANCE``, 32-bit RGBE, flat scanlines, top row first) of ``grey``:
    each value in r, g and b, as the grey HDR Webots' range finder writes. A value ``v`` is stored as
    the mantissa byte ``int(m·256)`` thrice and the exponent byte ``e + 128`` (``v = m·2^e``,
    ``frexp``) after its rounding to float32 (Webots' float image); 0 (and anything below 1e-32) as
    four zeros, the format's rule."""
    out = bytearray(4 * len(grey))
    for i, v in enumerate(array.array("f", grey)):
        if v >= 1e-32:
            m, e = math.frexp(v)
            c = int(m * 256.0)
            out[4 * i:4 * i + 4] = bytes((c, c, c, e + 128))
    return f"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {height} +X {width}\n".encode() + bytes(out)


def check_save(func: str, filename: str, quality: int) -> bool:
    """Webots' argument checks of every ``save_image``: a filename, a quality in 1..100."""
    if not filename:
        print(f"Error: {func}() called with NULL or empty 'filename' argument.", file=sys.stderr)
        return False
    if isinstance(quality, bool) or not isinstance(quality, int) or not 1 <= quality <= 100:
        print(f"Error: {func}() called with invalid 'quality' argument.", file=sys.stderr)
        return False
    return True


def write_file(func: str, filename: str, data: bytes) -> int:
    try:
        with open(filename, "wb") as f:
            f.write(data)
    except OSError as exc:
        print(f"Error: {func}(): cannot write {filename!r}: {exc.strerror or exc}", file=sys.stderr)
        return -1
    return 0


def install(func: str, tmp: str, filename: str) -> bool:
    """``tmp``, written in full, renamed onto ``filename`` (no reader ever sees half a file); on failure
    Webots' kind of line, ``tmp`` removed and False."""
    import os

    try:
        os.replace(tmp, filename)
    except OSError as exc:
        print(f"Error: {func}(): cannot write {filename!r}: {exc.strerror or exc}", file=sys.stderr)
        try:
            os.unlink(tmp)
        except OSError:
            pass
        return False
    return True


def save_rgb(func: str, filename: str, quality: int, rgb: bytes, width: int, height: int) -> int:
    """Webots' checks and formats: ``.png``, ``.jpg``/``.jpeg`` (quality 1..100); -1 with Webots'
    message on a bad argument, an unknown extension or a file that cannot be written."""
    if not check_save(func, filename, quality):
        return -1
    lower = str(filename).lower()
    try:
        if lower.endswith(".png"):
            data = png_bytes(rgb, width, height)
        elif lower.endswith((".jpg", ".jpeg")):
            try:
                from PIL import Image
            except ImportError:
                print(f"Error: {func}(): JPEG needs Pillow here (pip install pillow); save a .png instead.",
                      file=sys.stderr)
                return -1
            import io
            buf = io.BytesIO()
            Image.frombytes("RGB", (width, height), rgb).save(buf, format="JPEG", quality=quality)
            data = buf.getvalue()
        else:
            print(f"Error: {func}(): unsupported image format of {filename!r} (use .png, .jpg or .jpeg).",
                  file=sys.stderr)
            return -1
    except OSError as exc:
        print(f"Error: {func}(): cannot write {filename!r}: {exc.strerror or exc}", file=sys.stderr)
        return -1
    return write_file(func, filename, data)
