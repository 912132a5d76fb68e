"""Textures: image files → texel arrays (Pillow), the limits on them, and the sampler the scene owns.

What Webots does, and so what this does (sources: ``WbImageTexture.cpp``, ``WbAppearance.cpp``,
``WbPbrAppearance.cpp``, ``WbAbstractAppearance.cpp``, ``WbTextureTransform.cpp``,
``wren/TextureTransform.{hpp,cpp}``, ``WbShape.cpp`` ``pickColor``; docs/textures.md restates them):

* an image is read once (PNG or JPEG), converted to 8-bit RGB; alpha is never read by sensors
  (``pickColor``), only by cameras (:meth:`TextureSampler.opacity`: Webots draws a texture whose
  image uses alpha translucent, its alpha times ``1 − transparency``: phong.frag, pbr.frag);
* a lookup takes the geometry's ``(u, v)`` (:mod:`.texcoords`), applies the appearance's
  TextureTransform (X3D order: translation, then rotation and scale about ``center``; Webots'
  wren matrix ``−C·S·R·C·T`` with its flipped ``v``), wraps each coordinate (``repeatS``/``repeatT``:
  ``fmod`` into [0, 1); otherwise clamped to [0, 1]) and reads the **nearest texel**: column
  ``min(⌊u·w⌋, w − 1)``, row ``min(⌊v·h⌋, h − 1)`` counted from the image's top row, each channel
  ``byte / 255``. The ``filtering`` field only changes Webots' rendering.

Differences kept on purpose (docs/textures.md): the transform is applied in float64 (Webots:
float32), and an image whose sides are not powers of two is sampled as stored (Webots rescales it
to the next powers of two first, keeping its aspect ratio, with Qt's nearest-pixel scaling): such
an image reads the same texels except within about one texel of a texel boundary.

A world's images are read once, when the world is checked (:func:`check_textures`), and the scene
shows those very images (the file is not read again); they are bounded by the world limits
(``texture_file_bytes``, ``texture_pixels`` per image, ``texture_pixels_total`` per world): a larger
image is rejected with the limit it exceeds, never silently reduced (reduced texels would change
readings).

The sampler (:class:`TextureSampler`) is per scene: for each shape, the mapping of its geometry and
its images. Its API works on one shape's local-frame points at a time — ``uv`` (Webots'
coordinates and whether picking succeeded), ``texels`` (colours of a map at those coordinates) and
``infra_red`` (the terms an infra-red sensor reads) — so the Camera can sample the same textures.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Collection, Iterator, Mapping
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.world import texcoords as tc

__all__ = ["TextureFileError", "TextureLimitError", "resolve_texture_url", "image_header", "read_texture_file",
           "read_checked_image", "load_image", "load_alpha", "uses_alpha", "check_textures", "Checked",
           "TextureImage", "transform_uv", "TextureSampler", "TriangleLocator", "texture_urls"]

FORMATS = {"PNG": "PNG", "JPEG": "JPEG", "MPO": "JPEG"}     # Pillow's format → what Webots calls it
_FEW = 8                     # up to this many points, plain Python beats numpy's per-call cost


class TextureFileError(Exception):
    """A texture file that is missing, unreadable, not a PNG/JPEG, or over a limit."""


class TextureLimitError(TextureFileError):
    """A texture file over a limit of the world's (bytes, pixels, pixels of all textures together): Webots
    would read it; here it is refused, as a world asking for that much is."""


def resolve_texture_url(url: str, base_dir: Path, *, allow_outside: bool = False,
                        max_bytes: int | None = None, allowed: frozenset[Path] = frozenset()) -> Path:
    """A texture ``url`` → the file it names, relative to ``base_dir`` (the world's folder), which
    it may not leave unless ``allow_outside`` (as mesh urls), except the files in ``allowed`` (a
    converted .wbt's PROTO and Webots assets, read where they are). Errors quote the url as written."""
    if "\0" in url:
        raise TextureFileError("texture url contains a NUL byte")
    if not url.strip():
        raise TextureFileError("texture url is empty")
    if url.startswith("webots://"):
        raise TextureFileError(f"texture url {url!r}: webots:// urls (files of a Webots installation) are "
                               "resolved in .wbt worlds only (with --webots-home or WEBOTS_HOME); a YAML world "
                               "names files relative to itself")
    if "://" in url:
        raise TextureFileError(f"texture url {url!r}: only local files are read (no downloads)")
    base = Path(base_dir).resolve()
    try:
        path = (base / url).resolve()
    except (OSError, RuntimeError, ValueError) as exc:
        raise TextureFileError(f"texture url {url!r} cannot be resolved: {exc}") from None
    if not allow_outside and not path.is_relative_to(base) and path not in allowed:
        raise TextureFileError(f"texture url {url!r} leaves the world's folder (absolute paths and '..' are "
                               "refused; use --allow-outside-meshes to allow them)")
    try:
        if not path.is_file():
            raise TextureFileError(f"texture file {url!r} not found (urls are relative to the world file)")
        size = path.stat().st_size
    except OSError as exc:
        raise TextureFileError(f"texture file {url!r} cannot be read: {exc.strerror or exc}") from None
    if max_bytes is not None and size > max_bytes:
        raise TextureLimitError(f"texture file {url!r} is larger than the limit of {max_bytes:,} bytes "
                               "(raise the limits with --allow-large)")
    return path


def image_header(path: Path, display: str) -> tuple[str, int, int]:
    """(format, width, height) from the file's header only (nothing decoded)."""
    from PIL import Image, UnidentifiedImageError

    old = Image.MAX_IMAGE_PIXELS       # the caller checks the world's pixel limits on this header: Pillow's
    Image.MAX_IMAGE_PIXELS = None      # own bomb guard (at 179 million) would answer first, with its message
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with Image.open(path) as im:
                fmt, (w, h) = im.format, im.size
    except UnidentifiedImageError:
        raise TextureFileError(f"texture file {display!r} is not a PNG or JPEG image") from None
    except (OSError, ValueError, Image.DecompressionBombError) as exc:
        raise TextureFileError(f"texture file {display!r} cannot be read: {exc}") from None
    finally:
        Image.MAX_IMAGE_PIXELS = old
    if fmt not in FORMATS:
        raise TextureFileError(f"texture file {display!r} is a {fmt} image; Webots reads PNG and JPEG only")
    if w < 1 or h < 1:
        raise TextureFileError(f"texture file {display!r} has no pixels ({w}x{h})")
    return FORMATS[fmt], w, h


def load_image(path: Path, display: str | None = None) -> np.ndarray:
    """The image as a read-only ``(h, w, 3)`` uint8 RGB array, top row first (cached)."""
    return _decoded(path, display)[0]


def load_alpha(path: Path, display: str | None = None) -> np.ndarray | None:
    """The image's alpha channel as a read-only ``(h, w)`` uint8 array, top row first (cached with
    :func:`load_image`), or None when it has none or every pixel's alpha is 255 (its colours then
    blend as an RGB image's would: see :func:`uses_alpha` for what such an image still changes)."""
    return _decoded(path, display)[1]


def uses_alpha(path: Path, display: str | None = None) -> bool:
    """Whether the image's pixel format has alpha (an RGBA, grey-alpha or palette PNG with
    transparency, or a ``tRNS`` colour key), even if every pixel's alpha is 255: what Webots'
    ``WbImageTexture`` tests (Qt's ``alphaUsage() == UsesAlpha``, the format, not the pixels) to
    draw the shape as translucent — out of the shadow volumes (cached with :func:`load_image`)."""
    return _decoded(path, display)[2]


def _decoded(path: Path, display: str | None) -> tuple[np.ndarray, np.ndarray | None, bool]:
    path = Path(path).resolve()
    st = path.stat()
    try:
        return _decode(str(path), st.st_mtime_ns, st.st_size)
    except TextureFileError as exc:
        raise TextureFileError(str(exc).replace(str(path), display or str(path))) from None


_ALPHA_MODES = ("RGBA", "LA", "PA", "RGBa", "La")


Decoded = tuple[np.ndarray, np.ndarray | None, bool]
"""An image as read: (RGB, alpha or None, whether its pixel format has alpha)."""


def _same_image(a: Decoded, b: Decoded) -> bool:
    """Whether two reads of a file gave the same image, bit for bit (its format's alpha too)."""
    return a[2] == b[2] and np.array_equal(a[0], b[0]) and (
        a[1] is b[1] if a[1] is None or b[1] is None else np.array_equal(a[1], b[1]))


@lru_cache(maxsize=16)
def _decode(path: str, _mtime: int, _size: int) -> Decoded:
    return _decode_from(path, path)


def _decode_from(source: Any, path: str) -> Decoded:
    """The image in ``source`` (a file name or a file object) decoded; ``path`` names it in errors."""
    from PIL import Image

    old = Image.MAX_IMAGE_PIXELS       # the world limits were checked on the header; Pillow's own
    Image.MAX_IMAGE_PIXELS = None      # bomb guard would refuse what --allow-large allows
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with Image.open(source) as im:
                im.load()
                alpha = None
                has_alpha = False
                if im.mode in ("I;16", "I;16B", "I;16L", "I"):    # 16-bit grey: rounded to 8 bits
                    a = np.clip(np.asarray(im, dtype=np.int64), 0, 65535)
                    grey = ((a * 255 + 32767) // 65535).astype(np.uint8)
                    rgb = np.repeat(grey[..., None], 3, axis=2)
                else:
                    rgb = np.asarray(im.convert("RGB"), dtype=np.uint8)
                    # an alpha channel, or a palette's or colour key's transparency (PNG tRNS): what Qt
                    # reads as an image that uses alpha (WbImageTexture: the texture is then translucent)
                    if im.mode in _ALPHA_MODES or "transparency" in im.info:
                        has_alpha = True
                        alpha = np.asarray(im.convert("RGBA"), dtype=np.uint8)[..., 3]
                        alpha = None if bool((alpha == 255).all()) else np.ascontiguousarray(alpha)
    except (OSError, ValueError, SyntaxError) as exc:
        raise TextureFileError(f"texture file {path} cannot be decoded: {exc}") from None
    finally:
        Image.MAX_IMAGE_PIXELS = old
    rgb = np.ascontiguousarray(rgb)
    rgb.flags.writeable = False
    if alpha is not None:
        alpha.flags.writeable = False
    return rgb, alpha, has_alpha


# ------------------------------------------------------------------------------------ the world


def texture_urls(appearance: wm.Appearance | None) -> Iterator[tuple[str, wm.Texture]]:
    """(field name, texture) of every image an appearance names."""
    if appearance is None:
        return
    for name in ("texture", "roughness_map", "occlusion_map", "emissive_map"):
        t = getattr(appearance, name)
        if t is not None:
            yield name, t


def _appearances(world: wm.World) -> Iterator[tuple[str, Any]]:
    """(path, shape-like) of every shape of a world: solids (nested), parts, robot bodies."""
    def solid(path: str, s: wm.Solid) -> Iterator[tuple[str, Any]]:
        if s.geometry is not None:
            yield path, s
        for i, part in enumerate(s.shapes):
            yield f"{path}.shapes[{i}]", part
        for i, child in enumerate(s.children):
            yield from solid(f"{path}.children[{i}]", child)

    for i, s in enumerate(world.solids):
        yield from solid(f"solids[{i}]", s)
    for r_i, robot in enumerate(world.robots):
        if robot.body is not None:
            yield f"robots[{r_i}].body", robot.body
        for i, part in enumerate(robot.shapes):
            yield f"robots[{r_i}].shapes[{i}]", part


def _check_pixels(url: str, w: int, h: int, limits: Any, pixels_before: int) -> None:
    """An image of w×h pixels within the texture limits, alone and with the others' ``pixels_before``."""
    if w * h > limits.texture_pixels:
        raise TextureLimitError(f"texture {url!r} has {w}x{h} = {w * h:,} pixels, more than the "
                               f"limit of {limits.texture_pixels:,} (raise the limits with --allow-large)")
    if pixels_before + w * h > limits.texture_pixels_total:
        raise TextureLimitError(f"the world's textures have more than {limits.texture_pixels_total:,} "
                               "pixels together (raise the limits with --allow-large)")


def read_texture_file(file: Path, url: str, max_bytes: int) -> bytes:
    """The bytes of a texture file, at most ``max_bytes`` of them (else ``TextureFileError``): the
    one read of an image a world or a Supervisor names (:func:`read_checked_image`)."""
    try:
        with open(file, "rb") as f:
            data = f.read(max_bytes + 1)
    except OSError as exc:
        raise TextureFileError(f"texture file {url!r} cannot be read: {exc.strerror or exc}") from None
    if len(data) > max_bytes:
        raise TextureLimitError(f"texture file {url!r} is larger than the limit of {max_bytes:,} "
                               "bytes (raise the limits with --allow-large)")
    return data


def read_checked_image(url: str, base_dir: Path, limits: Any, *, allow_outside: bool = False,
                       allowed: frozenset[Path] = frozenset(), pixels_before: int = 0) -> tuple[Path, int, Decoded]:
    """A texture url checked as a world's textures are -- confined (see :func:`resolve_texture_url`), a
    PNG or JPEG no larger than ``limits.texture_file_bytes`` with at most ``limits.texture_pixels``
    pixels, ``pixels_before`` (the other images' pixels) plus its own within
    ``limits.texture_pixels_total``, and decoded -- on the file's bytes read once: (its file, its
    pixels, the image decoded from those very bytes), so a file replaced or grown after its check is
    never what is decoded (a world's textures and a Supervisor's url: what was checked is what is
    shown). Not cached: an image no shape shows is let go."""
    import io

    file = resolve_texture_url(url, base_dir, allow_outside=allow_outside, max_bytes=limits.texture_file_bytes,
                               allowed=allowed)
    data = read_texture_file(file, url, limits.texture_file_bytes)
    _, w, h = image_header(io.BytesIO(data), url)    # type: ignore[arg-type]
    _check_pixels(url, w, h, limits, pixels_before)
    return file, w * h, _decode_from(io.BytesIO(data), url)   # (the very bytes whose header was checked)


Checked = dict[str, tuple[Path, Decoded]]
"""A world's images as its check read them: url as the world names it -> (its file, its image)."""


def check_textures(world: wm.World, base_dir: Path, limits: Any, allow_outside: bool = False,
                   allowed: frozenset[Path] = frozenset(), images: Checked | None = None) -> list[tuple[str, str]]:
    """Every texture of a world: url confined (``allowed``: files outside the world's folder it may
    read, a .wbt's PROTO assets) and readable, a PNG or JPEG within the limits, decoded (so a broken
    file is found when the world is checked); the texture coordinates of inline triangles consistent.
    ``(path, message)`` per problem. Each file is read once (:func:`read_checked_image`), and
    ``images`` (when given) receives each url's file and image as read: the scene shows those
    (``TextureSampler``'s ``given``), never the file read again, so a file changed after the check is
    not what sensors see."""
    problems: list[tuple[str, str]] = []
    seen: dict[Path, Decoded] = {}
    total = 0
    for path, shape in _appearances(world):
        g = shape.geometry
        if isinstance(g, wm.Triangles) and g.tex_coords is not None:
            problems += _check_tex_coords(g, f"{path}.geometry")
        for field, tex in texture_urls(shape.appearance):
            where = f"{path}.appearance.{field}.url"
            try:
                file = resolve_texture_url(tex.url, base_dir, allow_outside=allow_outside,
                                           max_bytes=limits.texture_file_bytes, allowed=allowed)
                if file not in seen:
                    file, pixels, seen[file] = read_checked_image(tex.url, base_dir, limits, allow_outside=allow_outside,
                                                                  allowed=allowed, pixels_before=total)
                    total += pixels
                if images is not None:
                    images[tex.url] = (file, seen[file])
            except TextureFileError as exc:
                problems.append((where, str(exc)))
    for where, url in _noise_masks(world):     # a camera's noise mask: an image read as the others are
        try:
            file = resolve_texture_url(url, base_dir, allow_outside=allow_outside, max_bytes=limits.texture_file_bytes,
                                       allowed=allowed)
            if file not in seen:
                file, pixels, seen[file] = read_checked_image(url, base_dir, limits, allow_outside=allow_outside,
                                                              allowed=allowed, pixels_before=total)
                total += pixels
            if images is not None:
                images[url] = (file, seen[file])
        except TextureFileError as exc:
            problems.append((where, str(exc)))
    return problems


def _noise_masks(world: wm.World) -> Iterator[tuple[str, str]]:
    """(path, url) of every camera's noise mask (Webots' ``noiseMaskUrl``)."""
    for r_i, robot in enumerate(world.robots):
        for d_i, dev in enumerate(robot.devices):
            url = getattr(dev, "noise_mask_url", "")
            if url:
                yield f"robots[{r_i}].devices[{d_i}].noise_mask_url", url


def _check_tex_coords(g: wm.Triangles, path: str) -> list[tuple[str, str]]:
    assert g.tex_coords is not None
    n = len(g.tex_coords)
    corners = g.tex_coord_faces if g.tex_coord_faces is not None else g.faces
    if g.tex_coord_faces is not None and len(g.tex_coord_faces) != len(g.faces):
        return [(f"{path}.tex_coord_faces", f"{len(g.tex_coord_faces)} entries for {len(g.faces)} faces "
                                            "(one per face is needed)")]
    for i, face in enumerate(corners):
        if min(face) < 0 or max(face) >= n:
            key = "tex_coord_faces" if g.tex_coord_faces is not None else "faces"
            return [(f"{path}.{key}[{i}]", f"texture coordinate index outside 0..{n - 1}: {list(face)}")]
    return []


# ------------------------------------------------------------------------------------ sampling


@dataclass(frozen=True, eq=False)
class TextureImage:
    """One decoded image and how it wraps (Webots' ImageTexture)."""

    rgb: np.ndarray            # (h, w, 3) uint8, top row first
    repeat_s: bool = True
    repeat_t: bool = True
    alpha: np.ndarray | None = None     # (h, w) uint8 where the image has transparent texels (load_alpha)
    translucent: bool = False           # its pixel format has alpha, even all 255 (uses_alpha: Webots' test)

    def texel_index(self, uv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(row, column) of the nearest texel (WbImageTexture::pickColor's wrap and index)."""
        h, w = self.rgb.shape[:2]
        u, v = uv[:, 0], uv[:, 1]
        u = _wrap(u) if self.repeat_s else np.minimum(np.maximum(u, 0.0), 1.0)
        v = _wrap(v) if self.repeat_t else np.minimum(np.maximum(v, 0.0), 1.0)
        # u, v in [0, 1] here (NaN, from a failed pick, is not: the callers replace it first)
        col = np.minimum((u * w).astype(np.int64), w - 1)
        row = np.minimum((v * h).astype(np.int64), h - 1)
        return row, col

    def red(self, uv: np.ndarray) -> np.ndarray:
        """The red channel in [0, 1] at finite ``(n, 2)`` coordinates (the infra-red path). A few
        points (a line follower's sensors) are looked up in plain Python floats, the same
        arithmetic as ``texel_index`` (a numpy call costs more than a texel)."""
        if len(uv) <= _FEW:
            h, w = self.rgb.shape[:2]
            out = np.empty(len(uv))
            for k, (u, v) in enumerate(uv.tolist()):
                u = u - math.floor(u) if self.repeat_s else min(max(u, 0.0), 1.0)
                v = v - math.floor(v) if self.repeat_t else min(max(v, 0.0), 1.0)
                out[k] = int(self.rgb[min(int(v * h), h - 1), min(int(u * w), w - 1), 0]) / 255.0
            return out
        row, col = self.texel_index(uv)
        return self.rgb[row, col, 0] / 255.0

    def texels(self, uv: np.ndarray, channel: int | None = None) -> np.ndarray:
        """Texel colours ``(n, 3)`` in [0, 1] (``byte / 255``), or one channel ``(n,)``."""
        uv = np.asarray(uv, dtype=np.float64).reshape(-1, 2)
        uv = np.where(np.isnan(uv), 0.0, uv)
        row, col = self.texel_index(uv)
        px = self.rgb[row, col] if channel is None else self.rgb[row, col, channel]
        return px / 255.0

    def opacity(self, uv: np.ndarray) -> np.ndarray:
        """The texels' alpha ``(n,)`` in [0, 1] (``byte / 255``; 1 without an alpha channel), read as
        :meth:`texels` reads colours."""
        uv = np.asarray(uv, dtype=np.float64).reshape(-1, 2)
        if self.alpha is None:
            return np.ones(len(uv))
        uv = np.where(np.isnan(uv), 0.0, uv)
        row, col = self.texel_index(uv)
        return self.alpha[row, col] / 255.0


def _wrap(x: np.ndarray) -> np.ndarray:
    """Webots' repeat: C ``fmod(x, 1)``, plus 1 when negative. ``x − ⌊x⌋`` is the same number (both
    are the one rounding of the same exact sum; fmod itself is exact), up to the sign of a zero."""
    return x - np.floor(x)


def transform_uv(uv: np.ndarray, t: wm.TextureTransform | None) -> np.ndarray:
    """Webots' TextureTransform on ``(u, v)`` (v from the top): wren's ``−C·S·R·C·T`` with its
    translation and center given in X3D's upward ``t`` (hence the ``−y`` and the offsets of 1)."""
    if t is None:
        return uv
    (cx, cy), (sx, sy), (px, py) = t.center, t.scale, t.translation
    c, s = math.cos(t.rotation), math.sin(t.rotation)
    x = uv[:, 0] + px + cx
    y = uv[:, 1] - py - cy - 1.0
    xr, yr = c * x + s * y, -s * x + c * y
    return np.stack([sx * xr - cx, sy * yr + cy + 1.0], axis=1)


class TriangleLocator:
    """The triangle of a mesh a ray hit, and the hit's barycentrics, found again in float64: the
    candidate triangles are those whose (slightly enlarged) bounding box holds the hit point, in a
    uniform grid built once; among those the ray meets (Möller–Trumbore), the one whose distance is
    closest to the engine's wins. Used until the ray engine reports triangles itself."""

    def __init__(self, vertices: np.ndarray, faces: np.ndarray):
        v = np.asarray(vertices, dtype=np.float64)[np.asarray(faces, dtype=np.int64)]      # (F, 3, 3)
        self.v0, self.e1, self.e2 = v[:, 0], v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]
        lo_t, hi_t = v.min(axis=1), v.max(axis=1)
        self.lo = lo_t.min(axis=0)
        extent = hi_t.max(axis=0) - self.lo
        self.scale = float(max(extent.max(), 1e-12))
        self.pad = 1e-7 * self.scale + 1e-9
        lo_t, hi_t = lo_t - self.pad, hi_t + self.pad
        n_tri = len(v)
        # cells about the size of a typical triangle, at most ~4 per triangle (and per axis 1..1024)
        typical = float(np.median((hi_t - lo_t).max(axis=1))) if n_tri else 1.0
        cell = max(typical, self.scale / 1024.0, 1e-12)
        while True:
            dims = np.clip(np.ceil((extent + 2 * self.pad) / cell).astype(np.int64), 1, 1024)
            if int(np.prod(dims)) <= 4 * n_tri + 64:
                break
            cell *= 1.5
        self.cell, self.dims = cell, dims
        a = self._cells(lo_t)
        b = self._cells(hi_t)
        span = b - a + 1
        count = np.prod(span, axis=1)
        while int(count.sum()) > 32 * n_tri + 100_000:        # huge overlapping triangles: coarser
            self.cell *= 2.0
            self.dims = np.maximum(self.dims // 2, 1)
            a, b = self._cells(lo_t), self._cells(hi_t)
            span = b - a + 1
            count = np.prod(span, axis=1)
        tri = np.repeat(np.arange(n_tri), count)
        k = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
        sy, sz = span[tri, 1], span[tri, 2]
        ix = a[tri, 0] + k // (sy * sz)
        iy = a[tri, 1] + (k // sz) % sy
        iz = a[tri, 2] + k % sz
        key = (ix * self.dims[1] + iy) * self.dims[2] + iz
        order = np.argsort(key, kind="stable")
        self.tris = tri[order]
        self.start = np.searchsorted(key[order], np.arange(int(np.prod(self.dims)) + 1))

    def _cells(self, p: np.ndarray) -> np.ndarray:
        idx = np.floor((p - (self.lo - self.pad)) / self.cell).astype(np.int64)
        return np.clip(idx, 0, self.dims - 1)

    def locate(self, origins: np.ndarray, directions: np.ndarray, t: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(triangle or −1, b1, b2) for rays ``origins + t·directions`` (local frame)."""
        n = len(t)
        tri_out = np.full(n, -1, dtype=np.int64)
        b1_out, b2_out = np.zeros(n), np.zeros(n)
        if n == 0:
            return tri_out, b1_out, b2_out
        p = origins + t[:, None] * directions
        c = self._cells(p)
        key = (c[:, 0] * self.dims[1] + c[:, 1]) * self.dims[2] + c[:, 2]
        first, last = self.start[key], self.start[key + 1]
        count = last - first
        q = np.repeat(np.arange(n), count)
        if len(q) == 0:
            return tri_out, b1_out, b2_out
        k = np.arange(len(q)) - np.repeat(np.cumsum(count) - count, count)
        tri = self.tris[np.repeat(first, count) + k]
        d, o = directions[q], origins[q]
        e1, e2 = self.e1[tri], self.e2[tri]
        pvec = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, pvec)
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / det
            tvec = o - self.v0[tri]
            b1 = np.einsum("ij,ij->i", tvec, pvec) * inv
            qvec = np.cross(tvec, e1)
            b2 = np.einsum("ij,ij->i", d, qvec) * inv
            tt = np.einsum("ij,ij->i", e2, qvec) * inv
        eps = 1e-7
        tol = 1e-6 * (1.0 + np.abs(t[q]) + self.scale)
        good = (np.isfinite(tt) & (np.abs(det) > 0) & (b1 >= -eps) & (b2 >= -eps) & (b1 + b2 <= 1 + eps)
                & (np.abs(tt - t[q]) <= tol))
        if not good.any():
            return tri_out, b1_out, b2_out
        gi = good.nonzero()[0]
        err = np.abs(tt[gi] - t[q[gi]])
        order = np.lexsort((err, q[gi]))
        gi = gi[order]
        first_of = np.ones(len(gi), dtype=bool)
        first_of[1:] = q[gi][1:] != q[gi][:-1]
        gi = gi[first_of]
        rows = q[gi]
        tri_out[rows] = tri[gi]
        bb1, bb2 = np.clip(b1[gi], 0.0, 1.0), np.clip(b2[gi], 0.0, 1.0)
        over = bb1 + bb2 > 1.0
        s = np.where(over, bb1 + bb2, 1.0)
        b1_out[rows], b2_out[rows] = bb1 / s, bb2 / s
        return tri_out, b1_out, b2_out


UvOf = Callable[[np.ndarray, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray | None]]


@dataclass
class ShapeTexture:
    """One textured shape: its images and its transform."""

    base: TextureImage
    roughness: TextureImage | None
    occlusion: TextureImage | None
    transform: wm.TextureTransform | None


def _primitive_uv(geometry: Any, atlas: bool) -> UvOf:
    def points(o: np.ndarray, d: np.ndarray, t: np.ndarray) -> np.ndarray:
        return o + t[:, None] * d

    def ok(uv: np.ndarray) -> tuple[np.ndarray, None]:
        return uv, None                     # picking a primitive never fails

    g = geometry
    if isinstance(g, wm.Box):
        return lambda o, d, t: ok(tc.box_uv(points(o, d, t), g.size, atlas))
    if isinstance(g, wm.Plane):
        return lambda o, d, t: ok(tc.plane_uv(points(o, d, t), g.size))
    if isinstance(g, wm.Sphere):
        return lambda o, d, t: ok(tc.sphere_uv(points(o, d, t), g.radius))
    if isinstance(g, wm.Cylinder):
        return lambda o, d, t: ok(tc.cylinder_uv(points(o, d, t), g.radius, g.height, atlas))
    if isinstance(g, wm.Capsule):
        return lambda o, d, t: ok(tc.capsule_uv(points(o, d, t), g.radius, g.height, g.subdivision))
    if isinstance(g, wm.Cone):
        return lambda o, d, t: ok(tc.cone_uv(points(o, d, t), g.bottom_radius, g.height, atlas))
    if isinstance(g, wm.ElevationGrid):       # one mapping for both texture sets (Webots ignores the set)
        size = ((g.x_dimension - 1) * g.x_spacing, (g.y_dimension - 1) * g.y_spacing)
        return lambda o, d, t: ok(tc.elevation_grid_uv(points(o, d, t), size))
    raise TypeError(f"not a primitive: {g!r}")


def _mesh_uv(locator: Callable[[], TriangleLocator], corners: np.ndarray) -> UvOf:
    def uv_of(o: np.ndarray, d: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        tri, b1, b2 = locator().locate(o, d, t)
        found = tri >= 0
        uv = np.full((len(t), 2), np.nan)
        if found.any():
            uv[found] = tc.triangle_uv(corners[tri[found]], b1[found], b2[found])
        return uv, found

    return uv_of


def triangles_corner_uv(g: wm.Triangles) -> np.ndarray:
    """Corner coordinates ``(F, 3, 2)`` of inline triangles: ``(s, 1 − t)`` of their tex_coords
    (WbTriangleMesh's finalPass), else Webots' default bounding-box mapping."""
    faces = np.asarray(g.faces, dtype=np.int64)
    if g.tex_coords is None:
        return tc.default_triangle_uv(np.asarray(g.vertices, dtype=np.float64), faces)
    st = np.asarray(g.tex_coords, dtype=np.float64).reshape(-1, 2)
    idx = np.asarray(g.tex_coord_faces if g.tex_coord_faces is not None else g.faces, dtype=np.int64)
    corners = st[idx]
    corners[..., 1] = 1.0 - corners[..., 1]
    return corners


@lru_cache(maxsize=16)
def _mesh_file_uv(path: str, _mtime: int, material: int = -1, name: str = "") -> tuple[np.ndarray, np.ndarray,
                                                                                        np.ndarray]:
    """(vertices, faces, corner uv) of a mesh file as loaded for the scene (trimesh, unprocessed; a
    COLLADA file, or an OBJ file's faces of one material, through :mod:`.cad`, selected as the scene's):
    the file's first UV set with ``v`` flipped (Webots' assimp ``FlipUVs``), ``(0.5, 0.5)`` for a
    file without UVs (WbMesh)."""
    import trimesh

    from sensorium.server.world.meshes import by_cad, mesh_format

    kind = mesh_format(Path(path)) or ""
    if by_cad(kind, (material, name)):
        from sensorium.server.world.cad import read_cad

        return read_cad(path, kind).select(material, name)

    m = trimesh.load(path, force="mesh", process=False)
    vertices = np.asarray(m.vertices, dtype=np.float64)
    faces = np.asarray(m.faces, dtype=np.int64)
    uv = getattr(getattr(m, "visual", None), "uv", None)
    if uv is None or len(uv) != len(vertices):
        per_vertex = np.full((len(vertices), 2), 0.5)
    else:
        per_vertex = np.asarray(uv, dtype=np.float64).reshape(-1, 2).copy()
        per_vertex[:, 1] = 1.0 - per_vertex[:, 1]
    return vertices, faces, per_vertex[faces]


# ------------------------------------------------------------------------------------ ink (Pen)

INK_MIN_SIZE, INK_MAX_SIZE = 32, 1024      # WbPaintTexture: the paint texture of an untextured shape
INK_TEXELS_MAX = 1 << 24    # all ink layers of a world together (16 bytes each: 256 MiB); see TextureSampler


def _next_power_of_2(n: int) -> int:
    p = 1
    while p < n:
        p *= 2
    return p


def bounding_radius(geometry: Any, vertices: np.ndarray | None = None, faces: np.ndarray | None = None) -> float:
    """Webots' bounding-sphere radius of a geometry (each node's ``recomputeBoundingSphere``): half
    the diagonal of a Box or Plane, a Sphere's radius, ``|(r, h/2)|`` for a Cylinder, ``h/2 + r``
    for a Capsule, Ritter's sphere of a triangle mesh's corners (WbTriangleMeshGeometry) or of an
    ElevationGrid's points (WbElevationGrid)."""
    g = geometry
    if isinstance(g, wm.Box):
        return math.hypot(*g.size) / 2.0
    if isinstance(g, wm.Plane):
        return math.inf if g.size is None else math.hypot(*g.size) / 2.0
    if isinstance(g, wm.Sphere):
        return g.radius
    if isinstance(g, wm.Cylinder):
        return math.hypot(g.radius, g.height / 2.0)
    if isinstance(g, wm.Capsule):
        return g.height / 2.0 + g.radius
    if isinstance(g, wm.Cone):                # a disc when no taller than wide (WbCone)
        r, h = g.bottom_radius, g.height
        return r if h <= r else h / 2.0 + r * r / (2.0 * h)
    if isinstance(g, wm.ElevationGrid):       # Ritter's sphere of its points, in their order
        from sensorium.server.world.meshes import elevation_grid_mesh
        vertices = elevation_grid_mesh(g.height, g.x_dimension, g.x_spacing, g.y_dimension, g.y_spacing).vertices
        faces = np.arange(len(vertices)).reshape(-1, 1)
    assert vertices is not None and faces is not None
    pts = np.asarray(vertices, dtype=np.float64)[np.asarray(faces, dtype=np.int64)].reshape(-1, 3)
    p2 = pts[0]
    for _ in range(2):            # the farthest corner from the farthest corner of the first one
        p1 = p2
        d = ((pts - p1) ** 2).sum(axis=1)
        k = int(np.argmax(d)) if d.max() > 0 else 0
        p2, far = pts[k], float(d[k])
    centre, radius = (p1 + p2) / 2.0, math.sqrt(far) / 2.0
    for q in pts:                 # WbBoundingSphere::enclose, corner by corner
        delta = centre - q
        dist = float(np.linalg.norm(delta))
        if dist > radius:
            radius = (dist + radius) / 2.0
            centre = q + delta / dist * radius
    return radius


@lru_cache(maxsize=64)
def _disc(half: int) -> tuple[np.ndarray, np.ndarray]:
    """(row, column) offsets of a lead's texels: ``dx² ≤ half² − dy²`` (WbPaintTexture::paint)."""
    dy, dx = np.mgrid[-half:half + 1, -half:half + 1]
    inside = dx * dx <= half * half - dy * dy
    return dy[inside], dx[inside]


class InkLayer:
    """The ink pens laid on one shape (Webots' WbPaintTexture): RGB and density per texel
    (float32, as Webots keeps them), white and 0 at first.

    Its size is the shape's image size (an untextured shape: from its bounding sphere radius r,
    ``32 + 992·r/10`` texels, 1024 beyond 10 m, to the nearest power of two) times the geometry's
    factor for texture set 1 (Box 4 x 2, Cylinder 2 x 2, Cone 2 x 1, triangles without texture
    coordinates 4 x 2, else 1 x 1). A pen's lead of size L covers a disc ``⌊L·w₀/r⌋`` texels across, ``w₀`` being
    that size before the factor (``original_width``) and ``r`` the bounding radius.

    ``evaporating`` (the world's ``ink_evaporation`` > 0): each texel also keeps its ink as a double
    that :meth:`evaporate` multiplies down and writes back as the density (WbPaintTexture's
    evaporation array)."""

    def __init__(self, width: int, height: int, original_width: int, radius: float, evaporating: bool = False):
        self.rgb = np.ones((height, width, 3), dtype=np.float32)
        self.density = np.zeros((height, width), dtype=np.float32)
        self.original_width = int(original_width)
        self.radius = float(radius)
        self.evaporation: np.ndarray | None = np.zeros((height, width)) if evaporating else None
        self._live: list[int] | None = None      # [y0, y1, x0, x1): every texel that may still evaporate
        self.strokes = 0

    def lead_texels(self, lead_size: float) -> int:
        """The disc's width in texels (WbPaintTexture::paint: ``int(leadSize·w₀/r)``, at least 1;
        ``leadSize`` is a float there, the rest doubles)."""
        if not math.isfinite(self.radius) or self.radius <= 0.0:
            return 1
        return max(1, int(float(np.float32(lead_size)) * self.original_width / self.radius))

    def paint(self, u: float, v: float, lead_size: float, color, density: float) -> int:
        """One stroke at texture-set-1 coordinates (WbPaintTexture::paint): nothing outside
        [0, 1]; else a disc of texels around ``(⌊u·w⌋, ⌊v·h⌋)`` takes the ink: colour blended by
        the densities (``old/(old + new)`` of the old colour), density added and capped at 1.
        Returns the texels inked."""
        if not (0.0 <= u <= 1.0 and 0.0 <= v <= 1.0):
            return 0
        h, w = self.density.shape
        x, y = int(u * w), int(v * h)
        half = self.lead_texels(lead_size) // 2
        dy, dx = _disc(half)
        rows, cols = dy + y, dx + x
        if x - half < 0 or y - half < 0 or x + half >= w or y + half >= h:     # clipped at the edges
            keep = (rows >= 0) & (rows < h) & (cols >= 0) & (cols < w)
            rows, cols = rows[keep], cols[keep]
            if not len(rows):
                return 0
        d = np.float32(density)
        prev = self.density[rows, cols]
        total = d + prev
        with np.errstate(divide="ignore", invalid="ignore"):
            old = np.where(total < np.float32(1e-15), np.float32(0.0), prev / total).astype(np.float32)
        ink = np.asarray(color, dtype=np.float64)
        keep = (old[:, None] * self.rgb[rows, cols]).astype(np.float64)       # float * float
        new = (np.float32(1.0) - old).astype(np.float64)[:, None] * ink         # (1 - ratio) * colour (double)
        self.rgb[rows, cols] = (keep + new).astype(np.float32)
        self.density[rows, cols] = np.minimum(total, np.float32(1.0))
        if self.evaporation is not None:
            self.evaporation[rows, cols] = np.minimum(self.evaporation[rows, cols] + float(d), 1.0)
            box = [max(y - half, 0), min(y + half + 1, h), max(x - half, 0), min(x + half + 1, w)]
            live = self._live
            self._live = box if live is None else [min(live[0], box[0]), max(live[1], box[1]),
                                                   min(live[2], box[2]), max(live[3], box[3])]
        self.strokes += 1
        return int(len(rows))

    def evaporate(self, factor: float) -> bool:
        """One basic step of evaporation (WbPaintTexture::evaporateInk): every texel whose ink is
        above 0.001 is multiplied by ``factor`` and its density set to it. Returns whether any
        texel was (False: the layer is dry, and costs nothing until it is painted again)."""
        if self.evaporation is None or self._live is None:
            return False
        y0, y1, x0, x1 = self._live
        ink = self.evaporation[y0:y1, x0:x1]
        wet = ink > 0.001
        if not wet.any():
            self._live = None
            return False
        ink[wet] *= factor
        self.density[y0:y1, x0:x1][wet] = ink[wet].astype(np.float32)
        return True

    def pick(self, uv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(ink RGB as float64, density as float32) at texture-set-0 coordinates
        (WbPaintTexture::pickColor: truncated toward zero, then wrapped into the texture)."""
        h, w = self.density.shape
        uv = np.where(np.isnan(uv), 0.0, uv)
        x = np.trunc(uv[:, 0] * w).astype(np.int64) % w
        y = np.trunc(uv[:, 1] * h).astype(np.int64) % h
        return self.rgb[y, x].astype(np.float64), self.density[y, x]

    def clear(self) -> None:
        self.rgb[:] = 1.0
        self.density[:] = 0.0
        if self.evaporation is not None:
            self.evaporation[:] = 0.0
        self._live = None

    @property
    def texels(self) -> int:
        return int(self.density.size)


class TextureSampler:
    """The surface colours of a scene's shapes (indexed like ``Scene.shapes``): their images and
    the ink pens laid on them.

    ``textured[s]`` tells whether shape ``s`` has an image or ink (index −1, no hit, is False); it
    is updated in place when a shape first takes ink. All arrays given to the methods are in the
    shape's local frame (float64); ``lookups`` counts the points sampled (one per infra-red hit on
    such a shape)."""

    def __init__(self, shapes: list[tuple[Any, wm.Appearance | None]], base_dir: Path, *,
                 ink_evaporation: float = 0.0, ink_texels_max: int = INK_TEXELS_MAX,
                 given: Mapping[str, tuple[Path, Decoded]] | None = None):
        self.base_dir = Path(base_dir)
        # the world's images as its check read them (check_textures' ``images``): shown as they are
        self._given: Mapping[str, tuple[Path, Decoded]] = given or {}
        self.shapes: dict[int, ShapeTexture] = {}
        self.ink: dict[int, InkLayer] = {}
        self.ink_evaporation = float(ink_evaporation)
        self.ink_texels_max = int(ink_texels_max)
        self.ink_refused: set[int] = set()         # shapes whose ink layer would exceed ink_texels_max
        self._evaporating: list[InkLayer] = []     # layers with ink that still evaporates
        self._uv: dict[tuple[int, bool], UvOf] = {}
        self._locators: dict[int, TriangleLocator] = {}
        self._meshes: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        self._images: dict[Path, tuple[np.ndarray, np.ndarray | None, bool]] = {}
        self._kept: set[Path] = set()              # the world's own images (see _image)
        self.models: list[tuple[Any, wm.Appearance | None]] = []
        self.textured = np.zeros(1, dtype=bool)
        self.alpha = np.zeros(1, dtype=bool)
        self.has_alpha = False
        self.translucent = np.zeros(1, dtype=bool)
        self.has_translucent = False
        # a PBRAppearance's emissiveColorMap, read whether or not a base image is (cameras only)
        self.emissive: dict[int, TextureImage] = {}
        self.emissive_mapped = np.zeros(1, dtype=bool)
        self.has_emissive_map = False
        self.extend(shapes)
        self.lookups = 0

    def _image(self, t: wm.Texture | None, keep: bool = True,
               given: Mapping[str, tuple[Path, Decoded]] | None = None) -> TextureImage | None:
        """The image a texture names (read once); ``keep``: one of the world's own, kept for good (a
        reset brings them back), else (a Supervisor's) let go when no shape uses it any more.
        ``given``: url -> (file, image) already read and checked (:func:`read_checked_image`), used
        as it is: the file is not read again (a world's own image stays as loaded)."""
        if t is None:
            return None
        if given is not None and t.url in given:
            path, decoded = given[t.url]
            held = self._images.get(path)
            if held is not None and _same_image(held, decoded):
                decoded = held              # the file as it was read before: the image held (one copy)
            elif path in self._kept:        # a world's own file changed on disk since the load (a Supervisor named
                rgb, alpha, translucent = decoded    # it again): shown, the loaded image kept for a reset
                return TextureImage(rgb, t.repeat_s, t.repeat_t, alpha, translucent)
            else:
                self._images[path] = decoded
        else:
            try:
                path = (self.base_dir / t.url).resolve()
            except (OSError, RuntimeError, ValueError):
                path = None
            if path is None or path not in self._images:     # (one read before is not looked for again)
                path = resolve_texture_url(t.url, self.base_dir, allow_outside=True)
        if keep:
            self._kept.add(path)
        if path not in self._images:
            self._images[path] = (load_image(path, t.url), load_alpha(path, t.url), uses_alpha(path, t.url))
        rgb, alpha, translucent = self._images[path]
        return TextureImage(rgb, t.repeat_s, t.repeat_t, alpha, translucent)

    def extend(self, shapes: list[tuple[Any, wm.Appearance | None]]) -> None:
        """Shapes numbered after the existing ones (a Supervisor's imported solid): their images
        are read; the ink of existing shapes is kept."""
        first = len(self.models)
        self.models = [*self.models, *shapes]
        for i, (_, app) in enumerate(shapes, start=first):
            if app is not None and app.texture is not None:
                base = self._image(app.texture, given=self._given)
                assert base is not None
                self.shapes[i] = ShapeTexture(base, self._image(app.roughness_map, given=self._given),
                                              self._image(app.occlusion_map, given=self._given), app.texture_transform)
            if app is not None and app.emissive_map is not None:
                glow = self._image(app.emissive_map, given=self._given)
                assert glow is not None
                self.emissive[i] = glow
        textured = np.zeros(len(self.models) + 1, dtype=bool)
        textured[:first] = self.textured[:first]        # the trailing "no hit" entry stays False
        textured[list(self.shapes)] = True
        self.textured = textured
        # the shapes whose base image has transparent texels (cameras see through them; infra-red,
        # lidars and range finders do not read alpha, as Webots)
        alpha = np.zeros(len(self.models) + 1, dtype=bool)
        alpha[[s for s, st in self.shapes.items() if st.base.alpha is not None]] = True
        self.alpha = alpha
        self.has_alpha = bool(alpha.any())
        # the shapes whose base image's format has alpha, even 255 everywhere: Webots draws them
        # translucent, so they neither cast nor take shadows (WbImageTexture's test)
        translucent = np.zeros(len(self.models) + 1, dtype=bool)
        translucent[[s for s, st in self.shapes.items() if st.base.translucent]] = True
        self.translucent = translucent
        self.has_translucent = bool(translucent.any())
        mapped = np.zeros(len(self.models) + 1, dtype=bool)
        mapped[list(self.emissive)] = True
        self.emissive_mapped = mapped
        self.has_emissive_map = bool(mapped.any())

    def forget(self, shapes: Collection[int], count: int) -> None:
        """Shapes of a body a Supervisor removed let go: ``shapes`` (numbers kept) hold nothing any more
        (no image, no ink), and every shape from ``count`` on is gone (the next shapes added take those
        numbers again); images no shape uses any more are let go."""
        gone = set(shapes) | set(range(count, len(self.models)))
        if not gone:
            return
        layers = {id(self.ink[s]) for s in gone if s in self.ink}
        for s in gone:
            self.shapes.pop(s, None)
            self.emissive.pop(s, None)
            self.ink.pop(s, None)
            self.ink_refused.discard(s)
            self._locators.pop(s, None)
            self._meshes.pop(s, None)
            self._uv.pop((s, False), None)
            self._uv.pop((s, True), None)
        if layers:
            self._evaporating = [layer for layer in self._evaporating if id(layer) not in layers]
        shorter = count < len(self.models)
        self.models = [m if i not in gone else (None, None) for i, m in enumerate(self.models[:count])]
        for name in ("textured", "alpha", "translucent", "emissive_mapped"):
            flags = getattr(self, name)
            if shorter:           # new arrays (the scene tells their holders: shapes_version)
                flags = np.append(flags[:count], False)
                setattr(self, name, flags)
            flags[[s for s in shapes if s < count]] = False     # in place
        self.has_alpha = bool(self.alpha.any())
        self.has_translucent = bool(self.translucent.any())
        self.has_emissive_map = bool(self.emissive_mapped.any())
        self._let_go_unused()

    def set_shape(self, shape: int, appearance: wm.Appearance | None,
                  given: Mapping[str, tuple[Path, Decoded]] | None = None) -> None:
        """A Supervisor's new images for one shape (an ImageTexture's url or wrap changed, or the
        texture gone): its maps are read as :meth:`extend` reads them (the caller checked the files
        and the limits), its flags change in place (callers hold these arrays), ink stays, and an
        image no shape uses any more is let go."""
        geometry = self.models[shape][0]
        self.models[shape] = (geometry, appearance)
        if appearance is not None and appearance.texture is not None:
            base = self._image(appearance.texture, keep=False, given=given)
            assert base is not None
            self.shapes[shape] = ShapeTexture(base, self._image(appearance.roughness_map, keep=False, given=given),
                                              self._image(appearance.occlusion_map, keep=False, given=given),
                                              appearance.texture_transform)
        else:
            self.shapes.pop(shape, None)
        glow = None if appearance is None else self._image(appearance.emissive_map, keep=False, given=given)
        if glow is not None:
            self.emissive[shape] = glow
        else:
            self.emissive.pop(shape, None)
        self.emissive_mapped[shape] = glow is not None
        self.has_emissive_map = bool(self.emissive_mapped.any())
        st = self.shapes.get(shape)
        self.textured[shape] = st is not None or shape in self.ink
        self.alpha[shape] = st is not None and st.base.alpha is not None
        self.has_alpha = bool(self.alpha.any())
        self.translucent[shape] = st is not None and st.base.translucent
        self.has_translucent = bool(self.translucent.any())
        self._let_go_unused()

    def _let_go_unused(self) -> None:
        """Images no shape shows any more, but the world's own (a reset brings them back), let go."""
        used = {id(img.rgb) for st in self.shapes.values() for img in (st.base, st.roughness, st.occlusion)
                if img is not None} | {id(img.rgb) for img in self.emissive.values()}
        self._images = {p: v for p, v in self._images.items() if p in self._kept or id(v[0]) in used}

    def pixels(self, without: Collection[int] = ()) -> int:
        """The pixels of the distinct images the shapes use (but those of the shapes ``without``)."""
        seen = {id(img.rgb): img.rgb.shape[0] * img.rgb.shape[1] for k, st in self.shapes.items() if k not in without
                for img in (st.base, st.roughness, st.occlusion) if img is not None}
        seen.update({id(img.rgb): img.rgb.shape[0] * img.rgb.shape[1] for k, img in self.emissive.items()
                     if k not in without})
        return sum(seen.values())

    def __bool__(self) -> bool:
        return bool(self.shapes) or bool(self.ink) or bool(self.emissive)

    # ---- texture coordinates

    def _mesh(self, shape: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(vertices, faces, set-0 corner coordinates) of a triangle shape."""
        if shape not in self._meshes:
            g = self.models[shape][0]
            if isinstance(g, wm.Triangles):
                self._meshes[shape] = (np.asarray(g.vertices, dtype=np.float64).reshape(-1, 3),
                                       np.asarray(g.faces, dtype=np.int64), triangles_corner_uv(g))
            else:
                file = (self.base_dir / g.url).resolve()
                v, f, corners = _mesh_file_uv(str(file), file.stat().st_mtime_ns, g.material_index, g.name)
                self._meshes[shape] = (v * np.asarray(g.scale, dtype=np.float64), f, corners)
        return self._meshes[shape]

    def _uv_of(self, shape: int, atlas: bool) -> UvOf:
        key = (shape, atlas)
        if key not in self._uv:
            g = self.models[shape][0]
            if isinstance(g, wm.Triangles | wm.Mesh):
                v, f, corners = self._mesh(shape)
                if atlas and isinstance(g, wm.Triangles) and g.tex_coords is None:
                    corners = tc.default_triangle_atlas_uv(v, f)

                def locator(s: int = shape, v: np.ndarray = v, f: np.ndarray = f) -> TriangleLocator:
                    if s not in self._locators:          # built on the first lookup
                        self._locators[s] = TriangleLocator(v, f)
                    return self._locators[s]

                self._uv[key] = _mesh_uv(locator, corners)
            else:
                self._uv[key] = _primitive_uv(g, atlas)
        return self._uv[key]

    def uv(self, shape: int, origins: np.ndarray, directions: np.ndarray, t: np.ndarray, atlas: bool = False
           ) -> tuple[np.ndarray, np.ndarray]:
        """Webots' ``(u, v)`` of hits ``origins + t·directions`` on ``shape`` (before the
        TextureTransform; ``atlas``: texture set 1, where pens paint), and where picking succeeded
        (a mesh hit whose triangle is not found again fails, as Webots' picking can; its (u, v) is
        then NaN)."""
        uv, picked = self._uv_of(shape, atlas)(origins, directions, t)
        return uv, np.ones(len(uv), dtype=bool) if picked is None else picked

    def ink_uv(self, shape: int, origins: np.ndarray, directions: np.ndarray, t: np.ndarray, uv: np.ndarray
               ) -> np.ndarray:
        """Where a camera sees the ink of hits on ``shape`` (Webots' shaders sample the paint
        texture at ``penTexUv``, texture set 1: where the pen painted): ``uv`` (set 0, as given)
        where the two sets coincide, else the hits' set-1 coordinates (a Box's atlas, a Cylinder's
        or a Cone's halves, an IndexedFaceSet without texture coordinates)."""
        g = self.models[shape][0]
        if isinstance(g, wm.Box | wm.Cylinder | wm.Cone) or (isinstance(g, wm.Triangles) and g.tex_coords is None):
            return self.uv(shape, origins, directions, t, atlas=True)[0]
        return uv

    def texels(self, shape: int, uv: np.ndarray, which: str = "base", channel: int | None = None) -> np.ndarray:
        """Colours of ``shape``'s ``which`` map ("base", "roughness", "occlusion") at ``uv``
        (the TextureTransform applied, then the map's wrap, nearest texel)."""
        st = self.shapes[shape]
        img = st.base if which == "base" else st.roughness if which == "roughness" else st.occlusion
        if img is None:
            raise KeyError(f"shape {shape} has no {which} map")
        return img.texels(transform_uv(np.asarray(uv, dtype=np.float64).reshape(-1, 2), st.transform), channel)

    def emissive_texels(self, shape: int, uv: np.ndarray) -> np.ndarray:
        """Colours ``(n, 3)`` of ``shape``'s emissive map at ``uv`` (its appearance's TextureTransform
        applied, then the wrap, nearest texel, as :meth:`texels`), as stored: WREN's PBR shaders take
        them for the emissive colour without sRGB decoding."""
        appearance = self.models[shape][1]
        transform = None if appearance is None else appearance.texture_transform
        return self.emissive[shape].texels(transform_uv(np.asarray(uv, dtype=np.float64).reshape(-1, 2), transform))

    def opacity(self, shape: int, uv: np.ndarray) -> np.ndarray:
        """The alpha ``(n,)`` in [0, 1] of ``shape``'s base image at ``uv`` (the TextureTransform
        applied, then the wrap, nearest texel, as :meth:`texels`); 1 without an alpha channel."""
        st = self.shapes[shape]
        return st.base.opacity(transform_uv(np.asarray(uv, dtype=np.float64).reshape(-1, 2), st.transform))

    # ---- ink

    def ink_layer(self, shape: int) -> InkLayer | None:
        """The shape's ink layer, made on its first stroke (WbPaintTexture::paintTexture); None
        (with one warning per shape) when it would take the world's ink layers over
        ``ink_texels_max`` texels: that shape takes no ink (a bound Webots does not have)."""
        layer = self.ink.get(shape)
        if layer is None:
            if shape in self.ink_refused:
                return None
            g = self.models[shape][0]
            st = self.shapes.get(shape)
            tri = isinstance(g, wm.Triangles | wm.Mesh)
            v, f, _ = self._mesh(shape) if tri else (None, None, None)
            radius = bounding_radius(g, v, f)
            if st is not None:
                h, w = st.base.rgb.shape[:2]
            else:
                size = INK_MAX_SIZE if radius > 10.0 else INK_MIN_SIZE + (INK_MAX_SIZE - INK_MIN_SIZE) * radius / 10.0
                nxt = _next_power_of_2(int(size))
                w = h = int(nxt / 2 if abs(nxt - size) > abs(nxt / 2 - size) else nxt)
            fx, fy = ((4, 2) if isinstance(g, wm.Box) or (isinstance(g, wm.Triangles) and g.tex_coords is None)
                      else (2, 2) if isinstance(g, wm.Cylinder) else (2, 1) if isinstance(g, wm.Cone) else (1, 1))
            used = sum(layer.texels for layer in self.ink.values())
            if used + w * fx * h * fy > self.ink_texels_max:
                self.ink_refused.add(shape)
                warnings.warn(f"pen ink on shape {shape} ({type(g).__name__}) refused: its paint texture of "
                              f"{w * fx}x{h * fy} texels would take the world's ink over {self.ink_texels_max:,} "
                              "texels (textures.INK_TEXELS_MAX)", RuntimeWarning, stacklevel=2)
                return None
            layer = self.ink[shape] = InkLayer(w * fx, h * fy, w, radius, evaporating=self.ink_evaporation > 0.0)
            self.textured[shape] = True
        return layer

    def paint(self, shape: int, origin: np.ndarray, direction: np.ndarray, t: float, lead_size: float,
              color, density: float) -> int:
        """A pen's stroke where its ray hit ``shape`` (local frame): texels inked."""
        uv, ok = self.uv(shape, origin.reshape(1, 3), direction.reshape(1, 3), np.array([t]), atlas=True)
        if not ok[0]:
            return 0
        layer = self.ink_layer(shape)
        if layer is None:
            return 0
        n = layer.paint(float(uv[0, 0]), float(uv[0, 1]), lead_size, color, density)
        if n and layer.evaporation is not None and layer not in self._evaporating:
            self._evaporating.append(layer)
        return n

    def evaporate_ink(self, step_ms: float) -> None:
        """One basic step of ``step_ms`` of evaporation (WbPaintTexture::prePhysicsStep): every wet
        layer's ink times ``exp(−ink_evaporation·step_ms/1000)``; dry layers leave the list."""
        if not self._evaporating:
            return
        factor = math.exp(-self.ink_evaporation * step_ms / 1000.0)
        self._evaporating = [layer for layer in self._evaporating if layer.evaporate(factor)]

    def clear_ink(self) -> None:
        """Every ink layer white again (Webots' Pen reset clears all paint textures)."""
        for layer in self.ink.values():
            layer.clear()
        self._evaporating = []

    # ---- what infra-red sensors read

    def infra_red(self, shape: int, origins: np.ndarray, directions: np.ndarray, t: np.ndarray, red: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None, np.ndarray | None]:
        """For hits on ``shape`` whose untextured red is ``red`` (WbShape::pickColor): the red read
        (``(1 − c)·red·texel + c·ink`` with ``c`` the ink's density; a shape without appearance
        reads the ink's colour alone; the texel where picking failed is 1 and the ink ignored), the
        roughness and occlusion maps' red (None when there is no such map) and where picking
        succeeded (None: everywhere; elsewhere the roughness field and no occlusion apply)."""
        uv, picked = self._uv_of(shape, False)(origins, directions, t)
        self.lookups += len(t)
        if picked is not None:
            uv = np.where(picked[:, None], uv, 0.0)
        st = self.shapes.get(shape)
        rough = occl = None
        if st is not None:
            uvt = transform_uv(uv, st.transform)
            texel = st.base.red(uvt)
            if picked is not None:
                texel = np.where(picked, texel, 1.0)
            out = red * texel
            rough = None if st.roughness is None else st.roughness.red(uvt)
            occl = None if st.occlusion is None else st.occlusion.red(uvt)
        else:
            out = red
        layer = self.ink.get(shape)
        if layer is not None:
            ink, c = layer.pick(uv)
            if self.models[shape][1] is None:
                # a shape without any appearance reads the paint texture's colour alone, whatever its
                # density (WbShape::pickColor: neither Appearance nor PBRAppearance -> paintColor)
                out = ink[:, 0] if picked is None else np.where(picked, ink[:, 0], red)
                return out, rough, occl, picked
            if picked is not None:
                c = np.where(picked, c, np.float32(0.0))
            blended = (np.float32(1.0) - c).astype(np.float64) * red      # (1.0f - c) in float32
            if st is not None:
                blended = blended * texel
            out = blended + c.astype(np.float64) * ink[:, 0]
        return out, rough, occl, picked
