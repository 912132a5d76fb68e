"""Ctrl-C (and SIGTERM, SIGHUP) that reaches the command wherever it lands.

Python raises ``KeyboardInterrupt`` wherever the main thread is when the signal arrives. Inside an
import that goes wrong two ways: libraries guard optional imports with ``except BaseException``
(trimesh does, around ``trimesh.path`` and ``trimesh.voxel``), so an interrupt landing there is
swallowed and the command runs on to its end; and one escaping an import that a command does
before its own ``try`` is a traceback. :class:`Interrupts` latches the signal instead: outside an
import it raises ``KeyboardInterrupt`` at once, as Python does; inside one it is held and raised
as soon as the import is over (a timer looks again every 20 ms, where ``setitimer`` exists) or
when the block ends; :meth:`Interrupts.check` raises it at a command's own safe points should a
library have caught it anyway, and :attr:`Interrupts.received` tells the command afterwards.
"""

from __future__ import annotations

import signal
import threading
from types import FrameType, TracebackType

_RETRY_S = 0.02          # how soon a held interrupt is looked at again


def importing(frame: FrameType | None) -> bool:
    """True when ``frame`` runs inside an import (importlib's frames are on its stack)."""
    while frame is not None:
        if frame.f_code.co_filename.startswith("<frozen importlib._bootstrap"):
            return True
        frame = frame.f_back
    return False


class Interrupts:
    """``with Interrupts() as ctrl:`` — SIGINT (and any other ``signals``) as described above, the
    previous handlers put back at the end. Outside the main thread it does nothing."""

    def __init__(self, signals: tuple[int, ...] = (signal.SIGINT,)):
        self.signals = signals
        self.received = False           # a signal arrived (raised, held, or caught by a library)
        self._held = False              # arrived inside an import, not raised yet
        self._previous: dict[int, object] = {}
        self._timer = hasattr(signal, "setitimer")

    def __enter__(self) -> Interrupts:
        if threading.current_thread() is not threading.main_thread():
            return self
        for sig in self.signals:
            self._previous[sig] = signal.signal(sig, self._on_signal)
        if self._timer:
            self._previous[signal.SIGALRM] = signal.signal(signal.SIGALRM, self._on_alarm)
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        if signal.SIGALRM in self._previous and self._timer:
            signal.setitimer(signal.ITIMER_REAL, 0)
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)     # type: ignore[arg-type]
        self._previous.clear()
        if self._held and exc_type is None:
            self._held = False
            raise KeyboardInterrupt

    def check(self) -> None:
        """Raise ``KeyboardInterrupt`` if a signal arrived (call where stopping is safe)."""
        if self.received:
            self._held = False
            raise KeyboardInterrupt

    def _on_signal(self, signum: int, frame: FrameType | None) -> None:
        self.received = True
        self._deliver(frame)

    def _on_alarm(self, signum: int, frame: FrameType | None) -> None:
        if self._held:
            self._deliver(frame)

    def _deliver(self, frame: FrameType | None) -> None:
        if importing(frame):
            self._held = True
            if signal.SIGALRM in self._previous:
                signal.setitimer(signal.ITIMER_REAL, _RETRY_S)
            return
        self._held = False
        raise KeyboardInterrupt
