"""Progress bars on stderr for long commands (tqdm), only on a terminal; a no-op otherwise or when
tqdm is not installed (the client-side commands need only pyzmq + msgpack)."""

from __future__ import annotations

import sys
from typing import Any


class _Quiet:
    def update(self, n: float = 1) -> None:
        pass

    def set_postfix_str(self, text: str, refresh: bool = True) -> None:
        pass

    def close(self) -> None:
        pass

    def __enter__(self) -> _Quiet:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def bar(total: float | None, desc: str, unit: str = "it", enabled: bool | None = None) -> Any:
    """A tqdm bar on stderr (throttled to a few redraws per second), or a silent stand-in when
    stderr is not a terminal (logs, CI, pipes) or ``enabled`` is False."""
    if enabled is None:
        enabled = sys.stderr.isatty()
    if not enabled:
        return _Quiet()
    try:
        from tqdm import tqdm
    except ImportError:
        return _Quiet()
    return tqdm(total=total, desc=desc, unit=unit, file=sys.stderr, mininterval=0.25, leave=False,
                dynamic_ncols=True)
