"""The ROUTER socket's request path: batches of requests in, replies out (used by transport.py only).

Two implementations with one interface, :class:`PyGate` (pyzmq) and the optional C extension
``_steppath.Gate`` (built at install when a C compiler is there; ``setup.py``), chosen by
:func:`gate_for`. The C gate reads requests with the GIL released and recognises the plainest step
request of an attached controller, ``{"id": <uint>, "service": "/<robot>/robot/step", "args": {}
| {"duration": <ms>}}`` from the socket the robot is attached to, and keeps reading until every
controller the world waits for has asked for its step: Python then runs once per world step
instead of once per request. Neither decides anything: a recognised step is handed to
:meth:`sensorium.server.daemon.services.Core.handle_step`, which runs the handler
:meth:`~sensorium.server.daemon.services.Core.handle` would run for the same bytes, so the replies
are the same (``tests/test_steppath.py`` runs scripted sessions through both and compares bytes).

``receive(wait_ms, waiting, limit)`` returns ``None`` (nothing arrived within ``wait_ms``) or a
list, in arrival order, of ``(slot, identity, rid, duration)`` for a recognised step, a list of
frames for any other message, or the identity alone (``bytes``) for a message of more than
``max_frames`` frames (:attr:`discarding` is then set and :meth:`discard` drops the rest, a
bounded number of frames per call). A batch ends at the first message after which the world might
step: any message but a recognised step, or the step that completes the barrier (``waiting``: the
slots of the controllers the world waits for; none: every message ends it). So both gates hand
the same messages to the core between the same world steps.

``SENSORIUM_STEP_PATH=python`` (or ``Transport(step_path="python")``) uses the pure-Python gate
even when the extension is built; ``c`` requires the extension.
"""

from __future__ import annotations

import os
from typing import Any

import zmq

from sensorium.schemas.wire import pack

__all__ = ["PyGate", "chosen_gate_class", "gate_for", "native_gate_class", "step_path_choice", "STEP_PATHS"]

STEP_PATHS = ("auto", "c", "python")
_NOBLOCK, _SNDMORE, _RCVTIMEO = int(zmq.NOBLOCK), int(zmq.SNDMORE), int(zmq.RCVTIMEO)
ZERO_COPY_MIN = 64 * 1024       # replies at least this large are sent zero-copy (PyGate)
_BAD_REPLY = "send_steps: a reply is a list of frames or (envelope: list of bytes, rid, status, time_ms)"

# what the transport calls on a gate (PyGate has them all)
_GATE_METHODS = ("receive", "send", "send_steps", "exchange")

# libzmq functions the C gate calls, in the order _steppath.bind takes them
_LIBZMQ = ("zmq_msg_init", "zmq_msg_init_size", "zmq_msg_close", "zmq_msg_data", "zmq_msg_size", "zmq_msg_more",
           "zmq_msg_recv", "zmq_msg_send", "zmq_setsockopt", "zmq_errno")
_native: tuple[Any, str] | None = None     # (Gate class or None, why not)


def native_gate_class() -> tuple[Any, str]:
    """``(the C Gate class, "")``, or ``(None, why it is not available)``. The extension is bound to
    the libzmq pyzmq loaded (its functions found through pyzmq's own compiled module), so the
    sockets and the functions come from one library; checked by comparing ``zmq_version``."""
    global _native
    if _native is not None:
        return _native
    try:
        from sensorium.server.daemon import _steppath  # type: ignore[attr-defined]
    except ImportError as exc:
        _native = (None, f"the C step path is not built ({exc}); `pip install .` builds it when a C compiler is there")
        return _native
    missing = [name for name in _GATE_METHODS if not hasattr(_steppath.Gate, name)]
    if missing:     # an extension built from older sources (an in-place build not redone)
        _native = (None, f"the C step path was built from older sources (no Gate.{', Gate.'.join(missing)}); "
                         "rebuild it: `pip install .` (or `python setup.py build_ext --inplace`)")
        return _native
    try:
        import ctypes

        import zmq.backend.cython._zmq as pyzmq_backend  # type: ignore[import-not-found]

        lib = ctypes.CDLL(pyzmq_backend.__file__)           # already loaded: dlsym searches its libzmq too
        major, minor, patch = ctypes.c_int(), ctypes.c_int(), ctypes.c_int()
        lib.zmq_version(ctypes.byref(major), ctypes.byref(minor), ctypes.byref(patch))
        if (major.value, minor.value, patch.value) != zmq.zmq_version_info() or _steppath.MSG_SIZE != 64:
            raise OSError(f"libzmq {major.value}.{minor.value}.{patch.value} found beside pyzmq's "
                          f"{zmq.zmq_version()} (message size {_steppath.MSG_SIZE})")
        _steppath.bind(tuple(ctypes.cast(getattr(lib, name), ctypes.c_void_p).value for name in _LIBZMQ))
    except (ImportError, OSError, AttributeError, ValueError) as exc:
        _native = (None, f"the C step path cannot use pyzmq's libzmq ({type(exc).__name__}: {exc})")
        return _native
    _native = (_steppath.Gate, "")
    return _native


def step_path_choice(step_path: str | None = None) -> str:
    """``step_path`` or ``SENSORIUM_STEP_PATH`` (default ``auto``), checked: ValueError for another value."""
    choice = (step_path or os.environ.get("SENSORIUM_STEP_PATH") or "auto").strip().lower()
    if choice not in STEP_PATHS:
        raise ValueError(f"SENSORIUM_STEP_PATH / step_path must be one of {', '.join(STEP_PATHS)}, got {choice!r}")
    return choice


def chosen_gate_class(step_path: str | None = None) -> Any:
    """The C gate class a transport will use (``step_path`` or ``SENSORIUM_STEP_PATH``: ``auto``,
    ``c``, ``python``), None for :class:`PyGate`. ValueError for another choice, or for ``c``
    without the extension (checked before a world is loaded: ``ServeOptions.check``)."""
    choice = step_path_choice(step_path)
    if choice == "python":
        return None
    cls, why = native_gate_class()
    if cls is None and choice == "c":
        raise ValueError(f"{'step_path' if step_path else 'SENSORIUM_STEP_PATH'}=c: {why}")
    return cls


def gate_for(sock: zmq.Socket, *, max_frames: int, max_request: int, max_duration: int, discard_budget: int,
             step_path: str | None = None) -> Any:
    """The gate for ``sock``: C when built and allowed (:func:`chosen_gate_class`), else :class:`PyGate`."""
    cls = chosen_gate_class(step_path)
    if cls is not None:
        return cls(sock, sock.underlying, max_frames, max_request, max_duration, discard_budget)
    return PyGate(sock, max_frames=max_frames, discard_budget=discard_budget)


class PyGate:
    """The pure-Python gate: the same interface and batches, without recognising steps (every
    message comes back as its frames, for ``Core.handle``)."""

    native = False

    def __init__(self, sock: zmq.Socket, *, max_frames: int, discard_budget: int):
        self.sock = sock
        self.max_frames = max_frames
        self.discard_budget = discard_budget
        self.discarding = False
        self._rcvtimeo = -2
        self.counts = {"messages": 0, "fast_steps": 0, "frames_dropped": 0}

    def set_peers(self, peers: list[tuple[bytes, bytes, int]]) -> None:
        """(Recognising steps is the C gate's: nothing to keep.)"""

    def close(self) -> None:
        """(The C gate forgets its socket here; pyzmq guards this one.)"""

    def _recv(self, wait_ms: int) -> list[bytes] | bytes | None:
        sock = self.sock
        if wait_ms:
            if wait_ms != self._rcvtimeo:
                sock.setsockopt(_RCVTIMEO, wait_ms)
                self._rcvtimeo = wait_ms
            flags = 0
        else:
            flags = _NOBLOCK
        recv = sock.recv
        try:
            # zero-copy frames: their ``more`` flag is read from the message itself, cheaper than a
            # ZMQ_RCVMORE query per frame (libzmq delivers messages whole, so the rest is there)
            frame = recv(flags, copy=False)
            frames = [frame.bytes]
            while frame.more:
                if len(frames) >= self.max_frames:
                    self.discarding = True
                    return frames[0]
                frame = recv(_NOBLOCK, copy=False)
                frames.append(frame.bytes)
        except zmq.Again:
            return None
        return frames

    def receive(self, wait_ms: int, waiting: Any, limit: int) -> list | None:
        """One message per call: it is never a recognised step, so the world may step after it."""
        if self.discarding:
            raise RuntimeError("receive() while an over-long message is being dropped: discard() first")
        first = self._recv(wait_ms)
        if first is None:
            return None
        self.counts["messages"] += 1
        return [first]

    def discard(self) -> bool:
        """Drop frames of the over-long message, at most ``discard_budget``; True when it is gone.
        (~0.7 µs a frame here, ~0.05 µs in the C gate.)"""
        recv = self.sock.recv
        for _ in range(self.discard_budget):
            try:
                frame = recv(_NOBLOCK, copy=False)
            except zmq.Again:
                return False
            self.counts["frames_dropped"] += 1
            if not frame.more:
                self.discarding = False
                return True
        return False

    def send_steps(self, replies: list, pieces: tuple[bytes, bytes, bytes, bytes]) -> None:
        """:meth:`send` for a world step's replies: a list of frames, or ``(envelope, rid, status,
        time_ms)`` for the step reply without new values, packed from ``pieces`` (as the C gate does).
        A bad reply raises before anything is sent."""
        head, status_key, time_key, tail = pieces
        out = []
        for r in replies:
            if type(r) is list:
                out.append(r)
                continue
            if type(r) is not tuple or len(r) != 4:
                raise TypeError(_BAD_REPLY)
            envelope, rid, status, time_ms = r
            if type(envelope) is not list or type(rid) is not int or type(status) is not int \
                    or type(time_ms) is not int:
                raise TypeError(_BAD_REPLY)
            out.append(envelope + [b"".join((head, pack(rid), status_key, pack(status), time_key, pack(time_ms),
                                             tail))])
        self.send(out)

    def exchange(self, replies: list, pieces: tuple[bytes, bytes, bytes, bytes], wait_ms: int, waiting: Any,
                 limit: int) -> list | None:
        """:meth:`send_steps` (when there are replies), then :meth:`receive`: the transport's hot
        path goes from sending a world step's replies straight to waiting for the next requests."""
        if replies:
            self.send_steps(replies, pieces)
        return self.receive(wait_ms, waiting, limit)

    def send(self, replies: list[list[bytes]]) -> None:
        # frame by frame (what send_multipart does, without its per-call type checks and enum flags)
        send = self.sock.send
        for frames in replies:
            body = frames[-1]
            try:
                for frame in frames[:-1]:
                    send(frame, _SNDMORE)
                # small frames: copying is cheaper than zero-copy bookkeeping
                send(body, 0, copy=len(body) < ZERO_COPY_MIN)
            except zmq.ZMQError:
                pass                                     # peer gone: ROUTER drops, never raises upward
