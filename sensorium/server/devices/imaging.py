"""Image geometry of Webots' cameras and range finders — pure math, device frame FLU, float64.

An image is ``width`` × ``height`` pixels, row 0 at the top, column 0 at the left (Webots' scan
lines). Pixel ``(r, j)`` is sampled at image coordinates ``u = (j + ox)/W``, ``v = (r + oy)/H``
with ``(ox, oy) = (½, ½)`` (its centre) or, with anti-aliasing, the four points of a 2×2 grid
(``¼``, ``¾``). Φ = ``fieldOfView`` (horizontal).

Projections (Webots' ``WbWrenCamera`` and its ``merge_spherical.frag``)
    * ``planar`` — a pinhole camera with square pixels: the ray through ``(u, v)`` is
      ``(1, (1 − 2u)·tan(Φ/2), (1 − 2v)·tan(Φ/2)·H/W)``, so the vertical field of view is
      ``2·atan(tan(Φ/2)·H/W)`` (``computeFieldOfViewY``; Webots' reference formula).
    * ``cylindrical`` — equal angles: azimuth ``(½ − u)·Φ``, elevation ``(½ − v)·Φ·H/W``,
      direction ``(cos e cos a, cos e sin a, sin e)``.
    * ``spherical`` — Webots' fisheye: with ``(dx, dy) = (u − ½, v − ½)`` (each in its own axis'
      unit, as the shader has them) the ray makes the angle ``ψ = |(dx, dy)|·Φ`` with +x, in the
      direction ``(−dx, −dy)`` of the image plane: ``(cos ψ, −sin ψ·dx/ρ, −sin ψ·dy/ρ)``. A
      non-square spherical image therefore spans Φ vertically as well (the shader's choice).

Lens distortion (Webots' ``Lens`` node, its ``lens_distortion.frag``)
    Webots renders the pinhole image, then gives each output pixel the colour (or range) the
    rendered image has at a *source* coordinate: with ``(x, y) = (u − cx, v − cy)`` (image units,
    each axis its own: x in widths, y in heights; v down, as the rows), ``r = x² + y²``,
    ``d1 = k1·r + k2·r²`` and ``d2 = 1/(1 + 4·k1·r + 6·k2·r² + 8·p1·y + 8·p2·x)``, the source is
    ``us = u − d2·(d1·x + 2·p1·x·y + p2·(r + 2x²))``, ``vs = v − d2·(d1·y + 2·p2·x·y + p1·(r + 2y²))``
    (one Newton-like step inverting Brown's model, the shader's own approximation). Webots samples
    its rendered texels there bilinearly, clamped to the edge: a source outside the image reads its
    edge pixel. Here the output sample's ray is the pinhole ray through ``(us, vs)``, each clamped to
    the span of the image's own samples (the edge pixel's centre without anti-aliasing, Webots'
    clamp exactly) — an exact ray where Webots interpolates between rendered pixels. With zero
    coefficients ``(us, vs) = (u, v)`` exactly: the rays of no lens, bit for bit.

    A spherical or cylindrical image is Webots' merge of cube-face sub-cameras (``WbWrenCamera``:
    front, and left/right, up/down, back as the field of view needs them), and the lens pass runs
    on each sub-camera's own planar image before the merge reads it. So here a sample's nominal ray
    (the projection above) picks its face (the largest component of the direction, the merge
    shader's rule), its face-image coordinates are that face's pinhole coordinates ``(s, t)`` (the
    same convention as ``(u, v)``: ``s = ½(1 − a/tx)``, ``t = ½(1 − b/ty)`` with ``(a, b)`` the ray's
    tangents along the face image's left and up axes), the lens moves them to ``(ss, ts)`` in that
    face's image units about that face's ``center``, clamped to the face image's edges, and the ray
    is the face's pinhole ray through them. ``(tx, ty)``, every sub-camera's half-extents
    (:func:`sub_camera_extents`), are ``WbWrenCamera::setFieldOfView``'s: the horizontal field
    ``min(Φ, π/2)``, the aspect ``W/H`` (times ``(π/2)/Φ`` when Φ > π/2), the vertical field
    ``2·atan(tan(fx/2)/aspect)``, at most π/2 (then the aspect 1). A sample the lens does not move
    keeps its nominal ray bit for bit. A range finder then holds what Webots' merge computes: the
    face's planar depth of the distorted ray's hit over the nominal ray's cosine with the face's
    axis — the distance along the distorted ray times :func:`depth_factors`' ratio.

Range values (``range_image``)
    ``planar``: the depth along +x (the distance to the plane x = 0 of the device, Webots' reference
    page), i.e. ``t·cos`` of the ray with +x; the other projections: the distance ``t`` along the
    ray (the merge shader's depth/cosine). Then Webots' steps, as for the lidar: no hit,
    ``v < minRange`` or ``v >= maxRange`` → ``+inf``; with ``motionBlur`` (Webots' motion blur pass,
    before the noise): ``B ← v·(1 − w) + B·w``, ``w = 0.005^(period/motionBlur)``, where both ``v``
    and the last image's ``B`` are finite, else ``B ← v`` (the pass lets an infinite value, new or
    last, through as the new one: the first image is itself); Gaussian noise σ = ``noise·maxRange``
    (reference manual) on each finite value; ``resolution`` rounding ``floor(v/res + ½)·res``; the
    bounds again (noise or rounding can push a value out, never in); float32.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .lookup import RESOLUTION_OFF, quantize_lidar
from .noise import gaussian

__all__ = ["PROJECTIONS", "ImageGeometry", "Lens", "SAMPLES_CENTRE", "SAMPLES_2X2", "lens_source", "pixel_directions",
           "FACES", "sub_camera_extents", "face_of",
           "depth_factors", "clip_limits", "range_values", "pinhole_intrinsics"]

PROJECTIONS = ("planar", "cylindrical", "spherical")
SAMPLES_CENTRE = ((0.5, 0.5),)
"""One sample per pixel: its centre."""
SAMPLES_2X2 = ((0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75))
"""Anti-aliasing: a 2×2 grid of samples per pixel (supersampling)."""


@dataclass(frozen=True, slots=True)
class ImageGeometry:
    """What decides the pixels' rays (Webots' fields)."""

    width: int
    height: int
    field_of_view: float
    projection: str = "planar"

    def __post_init__(self) -> None:
        if int(self.width) < 1 or int(self.height) < 1:
            raise ValueError(f"image size must be at least 1 x 1, got {self.width} x {self.height}")
        if self.projection not in PROJECTIONS:
            raise ValueError(f"projection must be one of {', '.join(PROJECTIONS)}, got {self.projection!r}")
        if not 0.0 < float(self.field_of_view) <= 2.0 * math.pi:
            raise ValueError(f"field_of_view must be in (0, 2 pi], got {self.field_of_view}")
        if self.projection == "planar" and float(self.field_of_view) >= math.pi:
            raise ValueError(f"a planar projection needs field_of_view < pi, got {self.field_of_view}")

    @property
    def planar(self) -> bool:
        return self.projection == "planar"

    @property
    def vertical_field_of_view(self) -> float:
        """The image's vertical extent (rad): planar ``2·atan(tan(Φ/2)·H/W)``, cylindrical ``Φ·H/W``,
        spherical ``Φ`` (see the module docstring)."""
        fov, w, h = float(self.field_of_view), int(self.width), int(self.height)
        if self.projection == "planar":
            return 2.0 * math.atan(math.tan(fov / 2.0) * h / w)
        if self.projection == "cylindrical":
            return fov * h / w
        return fov


@dataclass(frozen=True, slots=True)
class Lens:
    """Webots' Lens node: the distortion's ``center`` (image units, (½, ½) the image's centre),
    ``radial`` (k1, k2) and ``tangential`` (p1, p2) coefficients (see the module docstring)."""

    center: tuple[float, float] = (0.5, 0.5)
    radial: tuple[float, float] = (0.0, 0.0)
    tangential: tuple[float, float] = (0.0, 0.0)


def lens_source(lens: Lens, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The source coordinates ``(us, vs)`` Webots' lens shader samples for the output coordinates
    ``(u, v)`` (image units, v down), not clamped; where its divisor is 0 (no source: the shader
    divides by zero) the output coordinate itself."""
    cx, cy = (float(a) for a in lens.center)
    k1, k2 = (float(a) for a in lens.radial)
    p1, p2 = (float(a) for a in lens.tangential)
    x = u - cx
    y = v - cy
    r = x * x + y * y
    d1 = k1 * r + k2 * r * r
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        d2 = 1.0 / (4.0 * k1 * r + 6.0 * k2 * r * r + 8.0 * p1 * y + 8.0 * p2 * x + 1.0)
        us = u - d2 * (d1 * x + 2.0 * p1 * x * y + p2 * (r + 2.0 * x * x))
        vs = v - d2 * (d1 * y + 2.0 * p2 * x * y + p1 * (r + 2.0 * y * y))
    bad = ~(np.isfinite(us) & np.isfinite(vs))
    if bad.any():
        us = np.where(bad, u, us)
        vs = np.where(bad, v, vs)
    return us, vs


def _grid(g: ImageGeometry, samples) -> tuple[np.ndarray, np.ndarray]:
    """Image coordinates ``u`` (S, 1, W) and ``v`` (S, H, 1) of every sample."""
    W, H = int(g.width), int(g.height)
    off = np.asarray(samples, dtype=np.float64).reshape(-1, 2)
    u = (np.arange(W)[None, None, :] + off[:, 0][:, None, None]) / W
    v = (np.arange(H)[None, :, None] + off[:, 1][:, None, None]) / H
    return u, v


def pixel_directions(g: ImageGeometry, samples=SAMPLES_CENTRE, lens: Lens | None = None) -> np.ndarray:
    """Unit ray directions (S, H, W, 3) in the device frame (FLU) for each sample of each pixel;
    with a ``lens``, each sample's ray through its lens source: in the image itself for a planar
    image, in its cube face's sub-image for the others (module docstring)."""
    u, v = _grid(g, samples)
    S, H, W = len(u), int(g.height), int(g.width)
    if lens is not None and g.projection == "planar":
        us, vs = lens_source(lens, np.broadcast_to(u, (S, H, W)), np.broadcast_to(v, (S, H, W)))
        # Webots' clamp to the edge: to the span of the image's own samples
        u = np.clip(us, u.min(), u.max())
        v = np.clip(vs, v.min(), v.max())
    d = _nominal(g, u, v, S, H, W)
    if lens is not None and g.projection != "planar":
        d = _face_lens(g, lens, d)[0]
    return d


def _nominal(g: ImageGeometry, u: np.ndarray, v: np.ndarray, S: int, H: int, W: int) -> np.ndarray:
    """The projection's unit rays (S, H, W, 3) through image coordinates ``(u, v)``."""
    fov = float(g.field_of_view)
    if g.projection == "planar":
        t = math.tan(fov / 2.0)
        y = np.broadcast_to((1.0 - 2.0 * u) * t, (S, H, W))
        z = np.broadcast_to((1.0 - 2.0 * v) * (t * H / W), (S, H, W))
        d = np.stack([np.ones((S, H, W)), y, z], axis=-1)
        return d / np.linalg.norm(d, axis=-1, keepdims=True)
    if g.projection == "cylindrical":
        a = np.broadcast_to((0.5 - u) * fov, (S, H, W))
        e = np.broadcast_to((0.5 - v) * (fov * H / W), (S, H, W))
        ce = np.cos(e)
        return np.stack([ce * np.cos(a), ce * np.sin(a), np.sin(e)], axis=-1)
    dx = np.broadcast_to(u - 0.5, (S, H, W))
    dy = np.broadcast_to(v - 0.5, (S, H, W))
    rho = np.hypot(dx, dy)
    psi = rho * fov
    with np.errstate(invalid="ignore", divide="ignore"):
        k = np.where(rho > 0.0, np.sin(psi) / rho, 0.0)
    return np.stack([np.cos(psi), -k * dx, -k * dy], axis=-1)


FACES = ("front", "right", "back", "left", "up", "down")
"""Webots' sub-cameras (``WbWrenCamera::CameraOrientation``'s order)."""
_FACE_AXES = np.array([
    # the face image's left axis, its up axis, the face's axis (FLU): the merge shader's face coordinates
    [[0, 1, 0], [0, 0, 1], [1, 0, 0]],       # front (+x)
    [[1, 0, 0], [0, 0, 1], [0, -1, 0]],      # right (−y)
    [[0, -1, 0], [0, 0, 1], [-1, 0, 0]],     # back (−x)
    [[-1, 0, 0], [0, 0, 1], [0, 1, 0]],      # left (+y)
    [[0, 1, 0], [-1, 0, 0], [0, 0, 1]],      # up (+z)
    [[0, 1, 0], [1, 0, 0], [0, 0, -1]],      # down (−z)
], dtype=np.float64)


def sub_camera_extents(g: ImageGeometry) -> tuple[float, float]:
    """``(tx, ty)``: the half-width and half-height, in tangents, of the planar image of each of
    the cube-face sub-cameras Webots renders a spherical or cylindrical image with
    (``WbWrenCamera::setFieldOfView``: horizontal field ``min(Φ, π/2)``, aspect ``W/H`` shrunk by
    ``(π/2)/Φ`` when Φ > π/2, vertical field ``2·atan(tan(fx/2)/aspect)`` at most π/2, where the
    aspect becomes 1)."""
    fov, aspect = float(g.field_of_view), int(g.width) / int(g.height)
    if fov > math.pi / 2.0:
        aspect *= (math.pi / 2.0) / fov
        fov = math.pi / 2.0
    fov_y = 2.0 * math.atan(math.tan(fov / 2.0) / aspect)
    if fov_y > math.pi / 2.0:
        fov_y, aspect = math.pi / 2.0, 1.0
    ty = math.tan(fov_y / 2.0)
    return ty * aspect, ty


def face_of(d: np.ndarray) -> np.ndarray:
    """Each direction's cube face (index into :data:`FACES`): its largest component by magnitude,
    x before y before z on a tie (Webots' ``merge_spherical.frag``)."""
    a = np.abs(d)
    axis = np.zeros(d.shape[:-1], dtype=np.int64)
    axis[a[..., 1] > a[..., 0]] = 1
    best = np.take_along_axis(a, axis[..., None], axis=-1)[..., 0]
    axis[a[..., 2] > best] = 2
    negative = np.take_along_axis(d, axis[..., None], axis=-1)[..., 0] < 0.0
    # (axis, sign) -> face: +x front, −x back, +y left, −y right, +z up, −z down
    table = np.array([[0, 2], [3, 1], [4, 5]])
    return table[axis, negative.astype(np.int64)]


def _face_lens(g: ImageGeometry, lens: Lens, d: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rays (same shape as ``d``, unit) a lens gives the nominal rays ``d`` of a spherical or
    cylindrical image (module docstring), each ray's face axis (…, 3) and whether the lens moved it."""
    tx, ty = sub_camera_extents(g)
    axes = _FACE_AXES[face_of(d)]                         # (..., 3 [left, up, axis], 3)
    left, up, axis = axes[..., 0, :], axes[..., 1, :], axes[..., 2, :]
    n = np.einsum("...k,...k->...", d, axis)
    a = np.einsum("...k,...k->...", d, left) / n
    b = np.einsum("...k,...k->...", d, up) / n
    s = 0.5 * (1.0 - a / tx)
    t = 0.5 * (1.0 - b / ty)
    ss, ts = lens_source(lens, s, t)
    inside = (s >= 0.0) & (s <= 1.0) & (t >= 0.0) & (t <= 1.0)
    # Webots' lens pass reads its face image clamped to the edge; a sample outside its face's image
    # (a corner Webots' merge reads out of the sub-image) keeps its source unclamped
    ss = np.where(inside, np.clip(ss, 0.0, 1.0), ss)
    ts = np.where(inside, np.clip(ts, 0.0, 1.0), ts)
    moved = (ss != s) | (ts != t)
    if not moved.any():
        return d, axis, moved
    a2 = ((1.0 - 2.0 * ss) * tx)[..., None]
    b2 = ((1.0 - 2.0 * ts) * ty)[..., None]
    out = a2 * left + b2 * up + axis
    out /= np.linalg.norm(out, axis=-1, keepdims=True)
    return np.where(moved[..., None], out, d), axis, moved


def depth_factors(g: ImageGeometry, directions: np.ndarray, lens: Lens | None = None) -> np.ndarray | None:
    """The factor turning a ray's hit distance into the stored range: the ray's cosine with +x
    for a planar image (depth); for a spherical or cylindrical image ``None`` (1), or, with a
    ``lens`` that moves rays, Webots' merge of its distorted faces: the ray's cosine with its face's
    axis over the nominal ray's (1 exactly where the lens moves nothing; ``directions``: the
    lens's rays, one sample per pixel)."""
    if g.planar:
        return np.ascontiguousarray(directions[..., 0])
    if lens is None:
        return None
    nominal = pixel_directions(g)
    bent, axis, moved = _face_lens(g, lens, nominal)
    if not moved.any():
        return None
    d = np.asarray(directions).reshape(bent.shape)
    ratio = np.einsum("...k,...k->...", d, axis) / np.einsum("...k,...k->...", nominal, axis)
    out = np.where(moved, ratio, 1.0)
    return np.ascontiguousarray(out.reshape(np.asarray(directions).shape[:-1]))


def clip_limits(g: ImageGeometry, factors: np.ndarray | None, near: float, far: float
                ) -> tuple[np.ndarray | float, np.ndarray | float]:
    """Per-ray ``(t_near, t_far)`` of the clipping planes ``near`` and ``far`` (``far`` = inf: none):
    planes at those depths for a planar image (the OpenGL frustum), spheres of those radii for the
    others (Webots: the near and far planes of a spherical camera are sphere parts) — with a lens's
    :func:`depth_factors` there, ``far`` bounds the stored value: the ray reaches ``far/factor``."""
    if factors is None:
        return float(near), float(far)
    f = factors.reshape(-1)
    with np.errstate(divide="ignore"):
        if not g.planar:
            return float(near), (float(far) / f if math.isfinite(far) else float(far))
        return float(near) / f, (float(far) / f if math.isfinite(far) else float(far))


def range_values(distances: np.ndarray, factors: np.ndarray | None, min_range: float, max_range: float,
                 noise: float, resolution: float, rng: np.random.Generator | None,
                 blur: tuple[np.ndarray, Any] | None = None) -> np.ndarray:
    """The range image (float32, shape of ``distances``) from the hit distances (``+inf`` = no hit)
    and :func:`depth_factors` (module docstring: validity, motion blur, noise σ = ``noise·max_range``,
    resolution, bounds). ``rng`` None: no noise. ``blur``: motion blur, ``(B, w)``: the last image's
    blurred values (float64, shape of ``distances``; ``+inf`` before the first image), replaced in
    place by this one's, and the last image's weight ``w`` (a number, or one per leading row that
    broadcasts: a batch of copies' images)."""
    d = np.asarray(distances, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        v = d if factors is None else d * np.asarray(factors).reshape(d.shape)
    lo, hi = float(min_range), float(max_range)
    noisy = noise > 0.0 and rng is not None
    with np.errstate(invalid="ignore", over="ignore"):
        valid = np.isfinite(v) & (v >= lo) & (v < hi)
        if blur is not None:       # motion_blur.frag on the depth texture: a mix where both are finite
            last, w = blur
            v = np.where(valid, v, np.inf)
            mixed = v * (1.0 - w) + last * w
            v = np.where(valid & np.isfinite(last), mixed, v)
            last[...] = v
        if not noisy and resolution == RESOLUTION_OFF:
            out = v.astype(np.float32)
            out[~valid | (out >= np.float32(hi))] = np.inf     # a value just below maxRange may round up to it
            return out
        v = np.where(valid, v, np.inf)
        if noisy:
            count = int(np.count_nonzero(valid))
            if count:
                v[valid] += float(noise) * hi * gaussian(rng, count)   # type: ignore[arg-type]
        v = quantize_lidar(v, resolution)
        out = np.where((v >= lo) & (v < hi), v, np.inf).astype(np.float32)
    out[out >= np.float32(hi)] = np.inf
    return out


def pinhole_intrinsics(g: ImageGeometry) -> tuple[float, float, float, float]:
    """``(fx, fy, cx, cy)`` of a planar image in pixels, pixel centres at integer coordinates (ROS'
    CameraInfo convention): ``fx = fy = (W/2)/tan(Φ/2)``, ``cx = (W − 1)/2``, ``cy = (H − 1)/2`` —
    exactly the rays of :func:`pixel_directions` (square pixels)."""
    if not g.planar:
        raise ValueError("only a planar image has pinhole intrinsics")
    f = (int(g.width) / 2.0) / math.tan(float(g.field_of_view) / 2.0)
    return f, f, (int(g.width) - 1) / 2.0, (int(g.height) - 1) / 2.0
