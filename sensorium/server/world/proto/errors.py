"""The one error type of PROTO reading and expansion."""

from __future__ import annotations

from sensorium.server.world.wbt.parser import WbtSyntaxError


class ProtoError(WbtSyntaxError):
    """A PROTO that cannot be found, read, instantiated or templated: one line ``FILE:LINE:COL:
    what`` (a ``WbtSyntaxError``, so every caller that prints those prints this)."""
