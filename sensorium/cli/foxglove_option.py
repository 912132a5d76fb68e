"""``--foxglove [HOST:]PORT`` for the commands that publish (``serve``, ``replay``): start the
Foxglove bridge, warn when it listens beyond this machine, report a bad address in one line."""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any


def start_foxglove(command: str, address: str, make: Callable[[str, int], Any]) -> Any | None:
    """The bridge ``make(host, port)`` built, or ``None`` after printing why it could not be."""
    from sensorium.server.viewer.bridge import ViewerError, exposure_warning, parse_address

    try:
        host, port = parse_address(address)
        warning = exposure_warning(host)
        if warning:
            print(f"sensorium {command}: warning: {warning}", file=sys.stderr)
        return make(host, port)
    except ViewerError as exc:
        print(f"sensorium {command}: {exc}", file=sys.stderr)
        return None
