"""Deterministic random streams for device noise.

Webots draws every device's noise from one global generator, so enabling a device shifts the noise
of all the others. Here each device owns its own stream, derived from the world seed and the
device's path only:

    seed  = int.from_bytes(sha256(f"{world_seed}/{device_path}".encode("utf-8")).digest(), "big")
    rng   = numpy.random.Generator(numpy.random.PCG64(seed))

(PCG64 feeds the 256-bit integer through numpy's ``SeedSequence``.) The stream therefore depends on
nothing but those two values: another device being enabled, disabled or added never changes it,
and a run with the same world seed reproduces every draw.

All Gaussian draws go through :func:`gaussian`, so the draw method is defined in one place.
"""

from __future__ import annotations

import hashlib

import numpy as np

__all__ = ["device_rng", "device_seed", "gaussian"]


def device_seed(world_seed: int, device_path: str) -> int:
    """The 256-bit integer seed of a device's stream (see the module docstring)."""
    digest = hashlib.sha256(f"{int(world_seed)}/{device_path}".encode()).digest()
    return int.from_bytes(digest, "big")


def device_rng(world_seed: int, device_path: str) -> np.random.Generator:
    """One independent, reproducible PCG64 stream per (world seed, device path)."""
    return np.random.Generator(np.random.PCG64(device_seed(world_seed, device_path)))


def gaussian(rng: np.random.Generator, count: int) -> np.ndarray:
    """``count`` standard normal samples (float64), drawn in order from ``rng``."""
    return rng.standard_normal(int(count))
