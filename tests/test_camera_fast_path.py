"""A camera image where nothing is seen through (no semi-transparent surface or clear texel met by
its first rays) is composited on a short path: each hit's radiance is the pixel's, the sky filled
by mask. It must give the bits of the general front-to-back compositing, which an image takes as
soon as one ray meets a semi-transparent surface: here the same scene with and without a pane in
one part of the view, and ``composite`` itself on rays whose radiance includes -0.0."""

from __future__ import annotations

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.raycast.kinds import RayHits
from sensorium.server.sim.cameras import composite
from tests.test_camera import WALL, shoot

CAM = {"width": 40, "height": 30, "field_of_view": 1.2, "anti_aliasing": True}
LAMP = {"type": "PointLight", "location": [1.2, -0.3, 0.6], "intensity": 1.2, "ambient_intensity": 0.1,
        "attenuation": [0.0, 0.0, 1.0], "cast_shadows": True}
SUN = {"type": "DirectionalLight", "direction": [1.0, 0.4, -1.0], "intensity": 0.4, "ambient_intensity": 0.05}
SHORT_WALL = {**WALL, "geometry": {"type": "box", "size": [0.1, 20, 0.9]}}      # the sky above it
BLOCK = {"name": "block", "pose": {"translation": [1.5, -0.2, 0.1]}, "geometry": {"type": "box", "size": [0.1, 0.2, 0.2]},
         "appearance": {"base_color": [0.3, 0.6, 0.9]}}
# semi-transparent, in the image's left part only (the camera looks along +x, +y on its left)
PANE = {"name": "pane", "pose": {"translation": [1.0, 0.6, 0.0]}, "geometry": {"type": "box", "size": [0.02, 0.4, 2.0]},
        "appearance": {"base_color": [0.1, 0.9, 0.2], "transparency": 0.5}}


def _image(pane: bool, fog: bool, precision: str) -> np.ndarray:
    solids = [SHORT_WALL, BLOCK, *([PANE] if pane else [])]
    extra = {"background": {"sky_color": [0.4, 0.6, 0.9]}}
    if fog:
        extra["fog"] = {"color": [0.7, 0.7, 0.7], "visibility_range": 4.0, "fog_type": "EXPONENTIAL"}
    w = wm.World.model_validate({"world_info": {"basic_time_step": 16, "random_seed": 5}, "solids": solids,
                                 "lights": [LAMP, SUN], "robots": [{"name": "r", "devices": [
                                     {"device": "Camera", "name": "cam", **CAM}]}], **extra})
    return shoot(w, precision)[1]


@pytest.mark.parametrize("precision,fog", [("exact", False), ("fast", True)])
def test_an_opaque_view_has_the_bits_of_the_general_compositing(precision: str, fog: bool):
    plain, veiled = _image(False, fog, precision), _image(True, fog, precision)
    differs = (plain != veiled).any(axis=2)
    cols = differs.any(axis=0).nonzero()[0]
    assert len(cols) and cols.max() < CAM["width"] // 2        # the pane is seen, on the left only
    right = plain[:, cols.max() + 1:]
    assert right.tobytes() == veiled[:, cols.max() + 1:].tobytes()
    colours = {tuple(p) for p in right.reshape(-1, 4)[:, :3].tolist()}
    assert len(colours) > 20              # sky, wall, block, shadow: many colours compared


def test_composite_s_short_path_is_the_general_one_bit_for_bit():
    rng = np.random.default_rng(4)
    n = 500
    dirs = rng.normal(size=(n, 3))
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    t = rng.uniform(0.5, 5.0, n)
    t[rng.random(n) < 0.3] = np.inf                      # sky
    shape = np.where(np.isfinite(t), rng.integers(0, 2, n), -1)
    normal = rng.normal(size=(n, 3))
    transparency = np.array([0.0, 0.0, 0.5, 0.0])        # shape 2 semi-transparent, -1 last
    background = np.array([0.3, 0.2, 0.1])

    def surface(s, P, N, D, tk):        # radiances with -0.0, zeros and values of every size
        L = np.outer(tk, [1.0, 1e-300, 3.0]) * np.where(s == 0, 1.0, -1.0)[:, None]
        L[::3, 0] = -0.0
        L[1::3, 1] = 0.0
        return L

    def cast_on(D, tn, tf):             # past the pane: the sky
        return RayHits(np.full(len(D), np.inf), np.zeros((len(D), 3)), np.full(len(D), -1))

    for fog in (None, (np.array([0.5, 0.5, 0.5]), 3.0, "LINEAR")):
        first = RayHits(t.copy(), normal.copy(), shape.copy())
        short = composite(np.zeros(3), dirs, first, (0.0, np.inf), cast_on, transparency, background, fog, surface)
        veiled = shape.copy()
        veiled[np.isfinite(t).nonzero()[0][0]] = 2           # one ray meets the pane: the general path
        general = composite(np.zeros(3), dirs, RayHits(t.copy(), normal.copy(), veiled), (0.0, np.inf), cast_on,
                            transparency, background, fog, surface)
        others = veiled == shape
        assert (others.sum() == n - 1) and short.shape == (n, 3)
        assert short[others].tobytes() == general[others].tobytes()
        assert not np.signbit(short[short == 0.0]).any()          # 0 + (-0.0) is 0.0, as the sums make it
