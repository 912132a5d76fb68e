"""A tiny RGB canvas with PNG output (numpy + zlib), so pictures need no plotting library."""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np


class Canvas:
    """Top-down picture of a rectangle of the world xy-plane (y up in the image)."""

    def __init__(self, xmin: float, xmax: float, ymin: float, ymax: float, pixels_per_metre: float = 150.0,
                 background=(255, 255, 255)):
        self.xmin, self.ymax = xmin, ymax
        self.scale = pixels_per_metre
        w = max(1, int(round((xmax - xmin) * pixels_per_metre)))
        h = max(1, int(round((ymax - ymin) * pixels_per_metre)))
        self.image = np.empty((h, w, 3), dtype=np.uint8)
        self.image[:] = background

    def to_pixels(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        col = np.round((xy[:, 0] - self.xmin) * self.scale).astype(np.int64)
        row = np.round((self.ymax - xy[:, 1]) * self.scale).astype(np.int64)
        return row, col

    def points(self, xy: np.ndarray, color, radius: int = 0) -> None:
        row, col = self.to_pixels(xy)
        h, w, _ = self.image.shape
        for dr in range(-radius, radius + 1):
            for dc in range(-radius, radius + 1):
                if dr * dr + dc * dc > radius * radius:
                    continue
                r, c = row + dr, col + dc
                ok = (r >= 0) & (r < h) & (c >= 0) & (c < w)
                self.image[r[ok], c[ok]] = color

    def polyline(self, xy: np.ndarray, color, width: int = 1) -> None:
        xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        if len(xy) == 0:
            return
        # sample each segment densely enough to leave no gaps at this resolution
        seg = np.diff(xy, axis=0)
        steps = np.maximum(1, np.ceil(np.linalg.norm(seg, axis=1) * self.scale * 2).astype(int))
        pts = [xy[:1]]
        for a, d, n in zip(xy[:-1], seg, steps):
            t = (np.arange(1, n + 1) / n)[:, None]
            pts.append(a + t * d)
        self.points(np.concatenate(pts), color, radius=width // 2)

    def rectangle(self, cx: float, cy: float, sx: float, sy: float, yaw: float, color) -> None:
        """Filled rotated rectangle."""
        h, w, _ = self.image.shape
        rr, cc = np.mgrid[0:h, 0:w]
        x = self.xmin + cc / self.scale - cx
        y = self.ymax - rr / self.scale - cy
        c, s = np.cos(yaw), np.sin(yaw)
        u, v = c * x + s * y, -s * x + c * y
        self.image[(np.abs(u) <= sx / 2) & (np.abs(v) <= sy / 2)] = color

    def disc(self, cx: float, cy: float, radius: float, color) -> None:
        h, w, _ = self.image.shape
        rr, cc = np.mgrid[0:h, 0:w]
        x = self.xmin + cc / self.scale - cx
        y = self.ymax - rr / self.scale - cy
        self.image[x * x + y * y <= radius * radius] = color

    def save(self, path: str | Path) -> None:
        write_png(path, self.image)


def write_png(path: str | Path, rgb: np.ndarray) -> None:
    rgb = np.ascontiguousarray(rgb, dtype=np.uint8)
    h, w, _ = rgb.shape
    raw = b"".join(b"\x00" + rgb[i].tobytes() for i in range(h))   # filter type 0 per row

    def chunk(tag: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b"")
    Path(path).write_bytes(png)
