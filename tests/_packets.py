"""Switching a test between the packets helper (the C passes, packets.c) and the numpy/math fallback
that ``SENSORIUM_PACKETS=0`` selects, which must give the same bits."""

from __future__ import annotations

import pytest

from sensorium.server.raycast import packets


def use_packets(helper: bool, monkeypatch: pytest.MonkeyPatch) -> None:
    """With ``helper`` the packets helper (skipping the test on a machine without it), else the fallback."""
    if not helper:
        monkeypatch.setattr(packets, "_state", {})
        monkeypatch.setenv("SENSORIUM_PACKETS", "0")
        assert packets.library() is None
    elif packets.library() is None:
        pytest.skip(f"no packets helper: {packets.status()}")
