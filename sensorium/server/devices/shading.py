"""A camera pixel's colour — pure math, world frame, float64.

The light a surface point sends to the camera is the LightSensor's sum (``light.py``, spec §2.2)
with the surface's normal in place of the sensor's axis and its albedo in place of the colour
filter, per RGB channel ``c``::

    L_c = albedo_c · Σ_lights att · (Ia + I · max(N·L, 0) · spot · lit) · C_c

``att`` the light's attenuation ``1/(a1 + a2 d + a3 d²)`` (1 for a directional light), ``Ia`` its
ambient intensity, ``I`` its intensity, ``spot`` Webots' spot cut-off factor, ``lit`` 0 where a
shadow-casting light is occluded and, for a point or spot light, where the point is farther than
its ``radius`` (``d > radius``: WREN's phong.frag and pbr.frag skip the light there; its ambient
term stays, WREN's ambient light being the scene's; light sensors ignore ``radius``), ``C`` its colour; ``N`` faces the camera (both faces of a surface
are lit as seen). The albedo is the shape's ``base_color`` times its texture's texel, the texel
converted from sRGB to linear as Webots' shaders do (``SRGBtoLINEAR``).

Semi-transparent surfaces are composited front to back (Webots' alpha blending: a surface of
``transparency`` τ adds ``(1 − τ)·L`` and lets ``τ`` of what is behind through); what no surface
covers is the background (:func:`background_radiance`: the sky colour reverse tone mapped, as
Webots clears its HDR buffer). The sum is a radiance in Webots' HDR buffer; the pixel is
Webots' ``hdr_resolve``: ``v = (1 − exp(−L·exposure))^(1/2.2)``; then ``noise`` (Gaussian, σ =
``noise`` in [0, 1] units, per channel, clamped: ``color_noise.frag``) and the byte
``⌊255·v + ½⌋``. Anti-aliasing averages the radiance of a 2×2 grid of rays per pixel.

Fog (Webots' Fog node, WREN's ``pbr.frag``/``phong.frag``): each surface's radiance is mixed with
the fog colour (sRGB to linear) in the HDR buffer, before the resolve and the noise, by
``w = (1 − f)^2.2`` of Webots' fog factor ``f`` at the surface's distance ``d`` from the camera
(the length of its view-space position: Webots' "point" depth, not the planar depth), ``V`` the
visibility range: ``f = 1 − d/V`` (LINEAR), ``exp(−d/V)`` (EXPONENTIAL), ``exp(−(d/V)²)``
(EXPONENTIAL2), clamped to [0, 1]. The background is not fogged (Webots' sky is drawn without it).

Motion blur (Webots' ``motionBlur``, ``motion_blur.frag`` before ``hdr_resolve``): each image's
pixel radiance ``L`` (the samples' mean) is mixed with the previous image's mixed radiance ``R``,
``R ← L·(1 − w) + R·w``, ``w = 0.005^(period/motionBlur)`` (:func:`motion_blur_weight`; the pixel
reaches 99.5% of a new colour after ``motionBlur`` ms); the first image is ``L`` itself. The noise
mask (Webots' ``noiseMaskUrl``, ``noise_mask.frag``, after the colour noise, on the 8-bit image):
each byte ``c`` becomes ``⌊255·((c/255)(1 − a) + m·a) + ½⌋`` of the mask's texel colour ``m`` and
alpha ``a``, the mask read bilinearly, repeated, at the pixel's centre shifted by a random offset per
image (:func:`apply_noise_mask`).
"""

from __future__ import annotations

import math

import numpy as np

from .light import LightArrays, LightKind
from .noise import gaussian

__all__ = ["GAMMA", "FOG_TYPES", "background_radiance", "srgb_to_linear", "radiance", "within_radius", "fog_weight", "fog",
           "tone_map", "to_bytes", "resolve_bgra", "motion_blur_weight", "noise_mask_factor", "apply_noise_mask",
           "take_rows", "add_to_rows", "set_rows", "scaled_rows"]

GAMMA = 2.2
"""Webots' ``hdr_resolve.frag`` gamma."""


def background_radiance(sky_color) -> np.ndarray:
    """The radiance Webots clears a camera's HDR buffer with for a Background ``skyColor``
    (``WbBackground::applyColorToWren``): the colour de-gamma'd (``c^2.2``) and reverse tone mapped,
    ``−ln(1.000000001 − c^2.2)`` (over the Viewpoint's exposure, 1 here), so that the resolve at
    exposure 1 shows the sky colour itself."""
    c = np.asarray(sky_color, dtype=np.float64)
    return -np.log(1.000000001 - c ** GAMMA)


def srgb_to_linear(c: np.ndarray) -> np.ndarray:
    """Webots' ``SRGBtoLINEAR`` of colours in [0, 1]."""
    c = np.asarray(c, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def radiance(points: np.ndarray, normals: np.ndarray, albedo: np.ndarray, lights: LightArrays,
             lit: np.ndarray | None = None) -> np.ndarray:
    """``L`` (S, 3) at S surface points (S, 3) with unit normals facing the camera (S, 3) and
    albedos (S, 3); ``lit`` (S, n) False where a light's direct term is shadowed (None: all lit).

    The LightSensor's terms (``light.py``: ``att``, ``c = N·(q − p)/d``, the spot factor from
    ``alpha = atan2(|L × R|, L·R)``) evaluated light by light on columns: an image has many points
    and few lights, so this keeps every temporary one column long."""
    P = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    N = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    A = np.asarray(albedo, dtype=np.float64).reshape(-1, 3)
    S = len(P)
    if len(lights) == 0 or S == 0:
        return np.zeros((S, 3))
    if S <= BLOCK:
        return _radiance_rows(P, N, A, lights, lit)
    out = np.empty((S, 3))
    for a in range(0, S, BLOCK):
        b = min(S, a + BLOCK)
        out[a:b] = _radiance_rows(P[a:b], N[a:b], A[a:b], lights, None if lit is None else lit[a:b])
    return out


BLOCK = 32768
"""Rows shaded at a time: each of radiance's ~12 passes per light over a block's columns stays in
the CPU's cache (a 640x480 image's radiance in blocks of 32,768 rows: ~3x faster than in one)."""


def _radiance_rows(P: np.ndarray, N: np.ndarray, A: np.ndarray, lights: LightArrays, lit: np.ndarray | None
                   ) -> np.ndarray:
    """:func:`radiance` of a block of rows."""
    S = len(P)
    # per channel (a (S, 1) x (3,) broadcast is several times slower in numpy); channels whose sums
    # are equal so far (white lights) share one array: one pass adds a light to all of them
    zero = np.zeros(S)
    acc = [zero, zero, zero]
    px, py, pz = P[:, 0], P[:, 1], P[:, 2]
    nx, ny, nz = N[:, 0], N[:, 1], N[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        for j in range(len(lights)):
            kind = int(lights.kind[j])
            intensity, ambient = float(lights.intensity[j]), float(lights.ambient_intensity[j])
            if kind == LightKind.DIRECTIONAL:          # L = -direction (unit), att = 1
                dx, dy, dz = (-float(c) for c in lights.direction[j])
                c = nx * dx
                c += ny * dy
                c += nz * dz
                direct = np.maximum(c, 0.0)
                if intensity != 1.0:                   # x·1 is x
                    direct *= intensity
                att: np.ndarray | None = None
                length = None
            else:
                vx, vy, vz, length = _to_light(px, py, pz, lights.position[j])
                a1, a2, a3 = (float(c) for c in lights.attenuation[j])
                att = 1.0 / (a1 + length * (a2 + a3 * length)) if (a2 or a3) else None
                if att is None and a1 != 1.0:
                    att = np.full(S, 1.0 / a1)
                away = length > 0.0
                safe = np.where(away, length, 1.0)
                c = nx * vx
                c += ny * vy
                c += nz * vz
                c /= safe
                direct = np.maximum(c, 0.0)
                if intensity != 1.0:
                    direct *= intensity
                if kind == LightKind.SPOT:
                    # alpha = atan2(|L x R|, L.R) as the LightSensor; outside [bw, co] only its side matters
                    rx, ry, rz = (-float(v) for v in lights.direction[j])
                    cosa = (vx * rx + vy * ry + vz * rz) / safe
                    bw, co = float(lights.beam_width[j]), float(lights.cut_off_angle[j])
                    factor = np.where(cosa >= math.cos(bw), 1.0, 0.0)
                    band = ((cosa < math.cos(bw)) & (cosa >= math.cos(co))).nonzero()[0]
                    if len(band):
                        ux, uy, uz = vx[band] / safe[band], vy[band] / safe[band], vz[band] / safe[band]
                        cx, cy, cz = uy * rz - uz * ry, uz * rx - ux * rz, ux * ry - uy * rx
                        alpha = np.arctan2(np.sqrt(cx * cx + cy * cy + cz * cz), ux * rx + uy * ry + uz * rz)
                        factor[band] = np.where(alpha > co, 0.0, np.where(alpha <= bw, 1.0, (alpha - co) / (bw - co)))
                    direct *= factor
                radius = float(lights.radius[j])
                if radius < length.max():      # WREN: no direct term beyond the radius (ambient is the scene's)
                    direct[length > radius] = 0.0
            if lit is not None:
                direct = np.where(lit[:, j], direct, 0.0)
            weight = direct
            weight += ambient
            if att is not None:
                if length is not None and not away.all():     # a point at the light: att may be inf
                    weight = np.where(weight == 0.0, 0.0, att * weight)    # a zero term stays zero
                else:
                    weight *= att
            color = [float(v) for v in lights.color[j]]
            if acc[0] is acc[1] is acc[2] and color[0] == color[1] == color[2]:
                acc[0] += weight if color[0] == 1.0 else weight * color[0]
            else:
                acc = [acc[0], acc[1] if acc[1] is not acc[0] else acc[1].copy(),
                       acc[2] if acc[2] is not acc[0] and acc[2] is not acc[1] else acc[2].copy()]
                for ch in range(3):
                    acc[ch] += weight if color[ch] == 1.0 else weight * color[ch]
    out = np.empty((S, 3))
    for ch in range(3):
        np.multiply(A[:, ch], acc[ch], out=out[:, ch])
    return out


def _to_light(px: np.ndarray, py: np.ndarray, pz: np.ndarray, q) -> tuple[np.ndarray, ...]:
    """The vectors from points (their coordinate columns) to a light at ``q`` and their lengths."""
    qx, qy, qz = (float(c) for c in q)
    vx, vy, vz = qx - px, qy - py, qz - pz
    return vx, vy, vz, np.sqrt(vx * vx + vy * vy + vz * vz)


def within_radius(points: np.ndarray, lights: LightArrays, j: int) -> np.ndarray | None:
    """Which of S points (S, 3) light ``j`` may give a direct term by its ``radius`` (distance ≤
    radius, :func:`radiance`'s arithmetic, so the same points): a bool per point, or None when all
    of them (a directional light; a radius beyond every point). A camera casts shadow rays only
    towards these: what lies beyond gets nothing from the light, shadowed or not."""
    if int(lights.kind[j]) == LightKind.DIRECTIONAL or len(points) == 0:
        return None
    radius = float(lights.radius[j])
    length = _to_light(points[:, 0], points[:, 1], points[:, 2], lights.position[j])[3]
    if not radius < length.max():
        return None
    return ~(length > radius)


FOG_TYPES = ("LINEAR", "EXPONENTIAL", "EXPONENTIAL2")
"""Webots' Fog ``fogType`` values."""

FOG_POWER = 2.2
"""The power WREN's shaders raise ``1 − f`` to before mixing in the fog colour."""


def fog_weight(distance: np.ndarray, visibility_range: float, fog_type: str) -> np.ndarray:
    """The fog colour's share ``(1 − f)^2.2`` in the radiance of surfaces at ``distance`` (m) from
    the camera; ``visibility_range`` > 0 (Webots turns the fog off at 0)."""
    z = np.asarray(distance, dtype=np.float64) / float(visibility_range)
    if fog_type == "LINEAR":          # Webots: (end − d)·(1/|end − start|), start 0, end V
        f = 1.0 - z
    elif fog_type == "EXPONENTIAL":
        f = np.exp(-z)
    elif fog_type == "EXPONENTIAL2":
        f = np.exp(-(z * z))
    else:
        raise ValueError(f"unknown fog type {fog_type!r} (one of {', '.join(FOG_TYPES)})")
    return (1.0 - np.clip(f, 0.0, 1.0)) ** FOG_POWER


def fog(radiance: np.ndarray, distance: np.ndarray, color_linear: np.ndarray, visibility_range: float,
        fog_type: str) -> np.ndarray:
    """Radiances (S, 3) of surfaces at ``distance`` (S,) mixed with the fog's linear colour (3,) as
    GLSL's ``mix(L, fog, w)``: ``L·(1 − w) + fog·w``."""
    w = fog_weight(distance, visibility_range, fog_type)
    L = np.asarray(radiance, dtype=np.float64).reshape(-1, 3)
    color = np.asarray(color_linear, dtype=np.float64)
    out = np.empty(L.shape)
    keep = 1.0 - w
    for ch in range(3):       # column by column (see radiance): L·(1 − w) + fog·w
        np.multiply(L[:, ch], keep, out=out[:, ch])
        out[:, ch] += color[ch] * w
    return out


def tone_map(radiance: np.ndarray, exposure: float) -> np.ndarray:
    """Webots' HDR resolve: ``(1 − exp(−L·exposure))^(1/2.2)`` (values in [0, 1))."""
    L = np.asarray(radiance)
    out = np.empty(L.shape, dtype=np.result_type(L, 0.0))
    src, dst = L.reshape(-1), out.reshape(-1)
    step = 3 * BLOCK
    with np.errstate(over="ignore"):
        for a in range(0, len(dst), step):   # in blocks, in place: the same operations, in the cache
            x = dst[a:a + step]
            np.maximum(src[a:a + step], 0.0, out=x)
            np.negative(x, out=x)
            x *= float(exposure)
            np.exp(x, out=x)
            np.subtract(1.0, x, out=x)
            np.power(x, 1.0 / GAMMA, out=x)
    return out


def to_bytes(values: np.ndarray, noise: float = 0.0, rng: np.random.Generator | None = None) -> np.ndarray:
    """Display values in [0, 1] → uint8, with Webots' colour noise first (σ = ``noise``, one
    standard normal per value in C order from ``rng``, clamped to [0, 1])."""
    v = np.asarray(values, dtype=np.float64)
    if noise > 0.0 and rng is not None:
        v = np.clip(v + float(noise) * gaussian(rng, v.size).reshape(v.shape), 0.0, 1.0)
    x = np.clip(v, 0.0, 1.0)
    x *= 255.0
    x += 0.5
    return np.floor(x, out=x).astype(np.uint8)


def motion_blur_weight(period_ms: int, motion_blur_ms: float) -> float:
    """The previous image's weight in a new one (Webots' ``WbAbstractCamera::applyMotionBlurToWren``):
    ``0.005^(period/motionBlur)``, so that a pixel is within 0.5% of a new colour ``motionBlur`` ms
    after it appeared."""
    return 0.005 ** (float(period_ms) / float(motion_blur_ms))


def resolve_bgra(radiance: np.ndarray, exposure: float, noise: float = 0.0, rng: np.random.Generator | None = None,
                 samples: int = 1, blur: tuple[np.ndarray, float] | None = None) -> np.ndarray:
    """A camera's pixels (M, 4) BGRA uint8 (alpha 255) from the radiance (samples·M, 3) of its
    rays (sample-major, as ``pixel_directions`` makes them): the samples' mean, :func:`tone_map`,
    :func:`to_bytes`, on blocks of pixels that stay in the CPU's cache: the same operations per
    value in the same order, so the same bytes as those calls on the whole image (the noise drawn
    first, all of it, in C order as ``to_bytes`` draws it). ``blur``: motion blur, ``(R, w)``: the
    previous image's mixed radiance (M, 3), replaced in place by this one's, and its weight ``w``
    (0 for the first image: ``L`` itself), mixed in before the tone mapping."""
    L = np.asarray(radiance, dtype=np.float64).reshape(samples, -1, 3)
    M = L.shape[1]
    draws = float(noise) * gaussian(rng, M * 3).reshape(M, 3) if noise > 0.0 and rng is not None else None
    out = np.empty((M, 4), dtype=np.uint8)
    out[:, 3] = 255
    x = np.empty((min(M, BLOCK), 3))
    with np.errstate(over="ignore"):
        for a in range(0, M, BLOCK):
            b = min(M, a + BLOCK)
            v = x[:b - a]
            if samples > 1:        # numpy's mean over the samples: ((L0 + L1) + L2) + ... then / S
                np.add(L[0, a:b], L[1, a:b], out=v)
                for i in range(2, samples):
                    v += L[i, a:b]
                np.true_divide(v, samples, out=v)
                np.maximum(v, 0.0, out=v)
            else:
                np.maximum(L[0, a:b], 0.0, out=v)
            if blur is not None:             # motion_blur.frag's mix(L, R, w), kept as the next R
                last, w = blur[0][a:b], float(blur[1])
                v *= 1.0 - w
                last *= w
                v += last
                last[...] = v
            np.negative(v, out=v)            # tone_map
            v *= float(exposure)
            np.exp(v, out=v)
            np.subtract(1.0, v, out=v)
            np.power(v, 1.0 / GAMMA, out=v)
            if draws is not None:            # to_bytes
                v += draws[a:b]
                np.clip(v, 0.0, 1.0, out=v)
            np.clip(v, 0.0, 1.0, out=v)
            v *= 255.0
            v += 0.5
            np.floor(v, out=v)
            for ch in range(3):              # RGB → BGR
                out[a:b, 2 - ch] = v[:, ch]
    return out


def noise_mask_factor(width: int, height: int, mask_width: int, mask_height: int) -> tuple[float, float]:
    """How many mask widths and heights one image spans (Webots' ``WbWrenCamera::setNoiseMask``): a
    mask at least as large as the image is read one texel per pixel, ``(W/w, H/h)``; a smaller one
    spans the image once along one axis and keeps its texels square along the other (the axis the
    mask falls shorter on relative to the image keeps 1)."""
    dw, dh = mask_width - width, mask_height - height
    if dw < 0 or dh < 0:
        ratio = width / height
        return (ratio, 1.0) if dw > dh else (1.0, 1.0 / ratio)
    return width / mask_width, height / mask_height


def apply_noise_mask(bgra: np.ndarray, width: int, height: int, mask: np.ndarray, offset: tuple[float, float],
                     factor: tuple[float, float]) -> None:
    """Webots' noise mask over an image of ``width`` × ``height`` BGRA pixels (M, 4) uint8, in place:
    each pixel's RGB ``c`` (bytes / 255) becomes ``c·(1 − a) + m·a`` of the mask's RGBA ``(m, a)``
    (``mask``: (4, h, w) float64 planes R, G, B, A in [0, 1], top row first) read bilinearly with the
    mask repeated, at ``(centre + offset)·factor`` in texture units (``u = (i + ½)/W``, ``v = (j + ½)/H``,
    rows from the top), then ``⌊255·x + ½⌋``."""
    th, tw = mask.shape[1:]
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height

    def taps(t: np.ndarray, shift: float, scale: float, size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        x = (t + shift) * scale * size - 0.5            # texel coordinate; texel k's centre at k
        k0 = np.floor(x)
        f = x - k0
        k0 = k0.astype(np.int64) % size
        return k0, (k0 + 1) % size, f

    x0, x1, fx = taps(u, offset[0], factor[0], tw)
    y0, y1, fy = taps(v, offset[1], factor[1], th)
    planes = mask.reshape(4, -1)

    def texel(rows: np.ndarray, cols: np.ndarray) -> np.ndarray:     # (4, H·W): one gather per corner
        return np.take(planes, (rows[:, None] * tw + cols[None, :]).reshape(-1), axis=1)

    fx = np.broadcast_to(fx[None, :], (height, width)).reshape(-1)
    fy = np.broadcast_to(fy[:, None], (height, width)).reshape(-1)
    top = texel(y0, x0)                   # each tap as a + (b − a)·f: equal texels give theirs
    top += (texel(y0, x1) - top) * fx
    bottom = texel(y1, x0)
    bottom += (texel(y1, x1) - bottom) * fx
    bottom -= top
    bottom *= fy
    top += bottom                         # (R, G, B, A) planes of the H·W pixels
    a = top[3]
    keep = 1.0 - a
    for ch in range(3):                   # RGB channel ch is BGRA column 2 − ch
        x = bgra[:, 2 - ch] / 255.0
        x *= keep
        x += top[ch] * a
        np.clip(x, 0.0, 1.0, out=x)
        x *= 255.0
        x += 0.5
        bgra[:, 2 - ch] = np.floor(x)


# Rows of (n, 3) float64 arrays, as an image's shading gathers and scatters them: numpy's fancy
# indexing of such rows is ~3x slower than np.take and than moving each row as one 24-byte item.
_ROW = np.dtype((np.void, 24))


def take_rows(a: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """``a[rows]`` of an (n, 3) array (a new C-contiguous array, the same values)."""
    return np.take(a, rows, axis=0)


def add_to_rows(out: np.ndarray, rows: np.ndarray, values: np.ndarray) -> None:
    """``out[rows] += values`` for an (n, 3) C-contiguous float64 ``out`` and distinct ``rows``:
    the same sums, gathered and scattered as 24-byte items."""
    items = out.view(_ROW).reshape(-1)
    cur = items.take(rows).view(np.float64).reshape(-1, 3)
    cur += values
    items[rows] = cur.view(_ROW).reshape(-1)


def set_rows(out: np.ndarray, where: np.ndarray, values: np.ndarray) -> None:
    """``out[where] = values`` for an (n, 3) C-contiguous float64 ``out``, a bool mask ``where``
    (n,) and ``values`` one row (3,) or one row per True (m, 3): moved as 24-byte items (a 2-D
    mask assignment is several times slower)."""
    rows = np.ascontiguousarray(values, dtype=np.float64).view(_ROW).reshape(-1)
    out.view(_ROW).reshape(-1)[where] = rows[0] if values.ndim == 1 else rows


def scaled_rows(v: np.ndarray, vec) -> np.ndarray:
    """``v[:, None] * vec``: (len(v), 3) with column c = v · vec[c], made column by column."""
    out = np.empty((len(v), 3))
    for ch in range(3):
        np.multiply(v, float(vec[ch]), out=out[:, ch])
    return out
