"""Ray for the tests that start it: the module, or a skip."""

from __future__ import annotations

import os

import pytest


def ray_or_skip():
    """``ray``, or a skip without it, or in `.ci/run`'s sanitizer step: there every process inherits
    the sanitizers' LD_PRELOAD, Ray's own binaries (raylet, GCS) included, which are not ours to check
    and were seen to hang there in ``ray.init``."""
    ray = pytest.importorskip("ray")
    if "libasan" in os.environ.get("LD_PRELOAD", ""):
        pytest.skip("Ray is not started under the sanitizers' LD_PRELOAD (its own binaries would inherit it)")
    return ray
