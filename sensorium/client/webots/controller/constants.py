"""Webots' ``controller.constants`` module: ``constant(name)`` is the value of the C library's
``wb_<name>`` (``constant('NODE_ROBOT')``, ``constant('ANSI_RESET', type=str)``), here from the
same tables the classes use."""

from __future__ import annotations

import sys
from typing import Any

from sensorium.client import nodes, wb

from .ansi_codes import AnsiCodes


def constant(name: str, type: Any = int) -> Any:  # noqa: A002 - Webots' parameter name
    """The value of Webots' constant ``WB_<name>``; ``None`` (after one line) for a name it does not have."""
    if type is str:
        value = getattr(AnsiCodes, name[len("ANSI_"):], None) if name.startswith("ANSI_") else None
    else:
        value = nodes.WEBOTS_NODE_TYPES.get(f"WB_{name}", getattr(wb, f"WB_{name}", None))
    if value is None:
        print(f"Error: constant(): Webots has no constant 'wb_{name}'.", file=sys.stderr)
    return value
