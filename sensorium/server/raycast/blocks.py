"""Both cores for large casts: a batch of rays split into blocks that threads trace side by side.

Embree (through embreex or the packet helper) and numpy's loops release the GIL, so two threads
on two halves of a lidar's scan take about half the time on two free cores. No ray's answer
depends on the block it is traced in (the engine never mixes rays), so the answers are the same
on any number of threads (tests/test_packets.py). Below ``MIN_RAYS`` a batch stays on the calling
thread: handing a block to another thread costs tens of microseconds, more than it saves there
(measured: ``sensorium bench`` peers section, table "threads").

``SENSORIUM_THREADS`` sets the number of threads (default: the cores this process may use).
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

MIN_RAYS = 16384        # a batch this large is split over the threads ...
MIN_BLOCK = 4096        # ... in blocks of at least this many rays
_PREFIX = "sensorium-rays"

_lock = threading.Lock()
_pool: ThreadPoolExecutor | None = None
_workers = 0
_pid = os.getpid()

T = TypeVar("T")
B = TypeVar("B")


def available() -> int:
    """Threads a cast may use: ``SENSORIUM_THREADS``, else the cores this process may run on."""
    env = os.environ.get("SENSORIUM_THREADS", "").strip()
    if env:
        try:
            return max(1, int(env))
        except ValueError:
            return 1
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:   # not Linux
        return max(1, os.cpu_count() or 1)


def split(n: int, threads: int, chunk: int) -> list[slice]:
    """Slices of ``range(n)`` of at most ``chunk`` rays (bounded temporaries), and at least one per
    thread when the batch is large enough to share (``MIN_RAYS``, blocks of ``MIN_BLOCK``)."""
    k = max(1, -(-n // chunk))
    if threads > 1 and n >= MIN_RAYS:
        # two blocks per thread: a thread that starts late (its core busy) leaves less undone
        k = max(k, min(2 * threads, n // MIN_BLOCK))
        k = -(-k // threads) * threads          # whole rounds: every thread gets as many blocks
    size = -(-n // k)
    return [slice(a, min(n, a + size)) for a in range(0, n, size)]


# the CPUs of the process as it started (before a server pinned its loop thread: serve --cpu)
_CPUS = os.sched_getaffinity(0) if hasattr(os, "sched_getaffinity") else None


def process_cpus() -> list[int]:
    """The CPUs of the process as it started (empty where the platform does not say): where block
    workers and the packet helper's threads run, whichever CPU the calling thread was pinned to."""
    return sorted(_CPUS or ())


def _every_core() -> None:
    """A block worker runs on every CPU of the process, even when the thread that started the pool
    was pinned to one (``serve --cpu`` pins the server's loop, whose casts start the pool)."""
    if _CPUS is not None:
        try:
            os.sched_setaffinity(0, _CPUS)
        except OSError:
            pass


_local = threading.local()   # .working: the calling thread of run() is taking blocks


def in_block() -> bool:
    """Whether the calling thread is tracing a block (a pool worker, or run()'s caller while it
    takes blocks beside them): work nested in a block stays on that thread."""
    return getattr(_local, "working", False) or threading.current_thread().name.startswith(_PREFIX)


def _executor(workers: int) -> ThreadPoolExecutor:
    global _pool, _workers, _pid
    with _lock:
        if _pid != os.getpid():       # a forked child (a process pool of sweeps): its threads are gone
            _pool, _workers, _pid = None, 0, os.getpid()
        if _pool is None or _workers < workers:
            if _pool is not None:
                _pool.shutdown(wait=False)
            _pool = ThreadPoolExecutor(max_workers=workers, thread_name_prefix=_PREFIX, initializer=_every_core)
            _workers = workers
        return _pool


def run(fn: Callable[[B], T], blocks: Sequence[B], threads: int, first: Callable[[], None] | None = None) -> list[T]:
    """``[fn(b) for b in blocks]`` on up to ``threads`` threads: the calling thread and pool workers
    take the next block until none is left, and the call returns once every block taken is done.
    A worker that has not started by then (its core busy with another process) finds nothing to do
    and is not waited for, so on a busy machine this costs at most what one thread would. A block's
    exception is raised here. Called from a pool worker (a nested split), the blocks run on that
    thread. ``first``: work the calling thread does before it takes a block, while the workers start
    on theirs (blocks that need its result wait for it themselves); its exception is raised here."""
    if threads <= 1 or len(blocks) <= 1 or in_block():
        if first is not None:
            first()
        return [fn(b) for b in blocks]
    results: list = [None] * len(blocks)
    errors: list[BaseException] = []
    state = {"next": 0, "busy": 0}
    cond = threading.Condition()

    def work() -> None:
        while True:
            with cond:
                i = state["next"]
                if i >= len(blocks) or errors:
                    return
                state["next"] = i + 1
                state["busy"] += 1
            try:
                results[i] = fn(blocks[i])
            except BaseException as exc:  # noqa: BLE001 - handed to the calling thread
                with cond:
                    errors.append(exc)
            finally:
                with cond:
                    state["busy"] -= 1
                    cond.notify_all()

    pool = _executor(threads - 1)
    for _ in range(min(threads, len(blocks)) - 1):
        pool.submit(work)
    if first is not None:
        try:
            first()
        except BaseException as exc:  # noqa: BLE001 - raised below, once the blocks taken are done
            with cond:
                errors.append(exc)
    _local.working = True
    try:
        work()
    finally:
        _local.working = False
    with cond:
        cond.wait_for(lambda: state["busy"] == 0)
    if errors:
        raise errors[0]
    return results
