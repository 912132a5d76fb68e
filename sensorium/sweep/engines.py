"""Where runs execute: a local process pool, or Ray tasks (local or on a cluster). Both call the
same :func:`sensorium.sweep.run.run_one` and yield ``(index, row)`` as runs finish; the caller
orders the rows. No scheduling of our own: Ray (or the pool) places the tasks.

Ray on one machine is started bound to loopback (single-machine mode, see :func:`_loopback_only`;
no dashboard; ``num_cpus`` = the workers asked for, default all CPUs). With ``address`` the sweep joins an
existing cluster instead (``"auto"``, ``"ray://head:10001"`` or ``"head:6379"``); an already
initialised Ray in the calling process is reused as is.
"""

from __future__ import annotations

import multiprocessing
import os
import socket
from collections.abc import Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from sensorium.sweep.run import run_one
from sensorium.sweep.spec import RunSpec

__all__ = ["ENGINES", "available", "local_pool", "shutdown_pools", "ray_tasks", "init_ray", "default_workers"]

ENGINES = ("auto", "local", "ray")


def default_workers() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:   # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def available(engine: str) -> bool:
    if engine == "ray":
        try:
            import ray  # noqa: F401
        except ImportError:
            return False
    return True


def _failed(run: RunSpec, exc: BaseException) -> dict:
    """The row of a run whose worker died (the run itself never raises)."""
    return {"run": run.index, "world": run.world, "seed": run.seed, "controller": run.controller_name,
            **{f"param:{k}": v for k, v in run.parameters}, "status": "error",
            "error": f"worker failed: {type(exc).__name__}: {exc}".splitlines()[0][:2000],
            "recording": run.recording or ""}


_POOLS: dict[int, ProcessPoolExecutor] = {}


def _pool(workers: int) -> ProcessPoolExecutor:
    """A spawned pool of ``workers`` processes, kept for the next sweep of this process (like a
    Ray session keeps its workers); ``shutdown_pools()`` ends them (also done at exit)."""
    pool = _POOLS.get(workers)
    if pool is None:
        pool = ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"))
        _POOLS[workers] = pool
    return pool


def shutdown_pools() -> None:
    while _POOLS:
        _, pool = _POOLS.popitem()
        pool.shutdown(wait=True, cancel_futures=True)


def _fresh_pool(workers: int) -> ProcessPoolExecutor:
    old = _POOLS.pop(workers, None)
    if old is not None:
        old.shutdown(wait=False, cancel_futures=True)
    return _pool(workers)


def local_pool(runs: Sequence[RunSpec], workers: int | None = None) -> Iterator[tuple[int, dict]]:
    """Runs on a pool of ``workers`` spawned processes (nothing inherited but the runs).

    A worker that dies (a controller calling ``os._exit``, a segfault, the OOM killer) breaks a
    ``ProcessPoolExecutor`` for every run in flight: those runs are then retried one at a time in
    a fresh pool, so only the run that kills its worker gets an error row."""
    workers = max(1, workers or default_workers())
    pool = _pool(workers)
    try:
        pending = {pool.submit(run_one, r): r for r in runs}
    except BrokenProcessPool:
        pool = _fresh_pool(workers)
        pending = {pool.submit(run_one, r): r for r in runs}
    suspects: list[RunSpec] = []
    try:
        while pending:
            done, _ = wait(pending, return_when=FIRST_COMPLETED)
            for fut in done:
                run = pending.pop(fut)
                try:
                    row = fut.result()
                except BrokenProcessPool:
                    suspects.append(run)
                    continue
                except Exception as exc:   # e.g. the row could not be sent back
                    row = _failed(run, exc)
                yield run.index, row
        if suspects:
            pool = _fresh_pool(workers)
        for run in sorted(suspects, key=lambda r: r.index):
            try:
                row = pool.submit(run_one, run).result()
            except BrokenProcessPool:
                row = _failed(run, RuntimeError("the worker process died during this run"))
                pool = _fresh_pool(workers)
            except Exception as exc:
                row = _failed(run, exc)
            yield run.index, row
    finally:
        for fut in pending:
            fut.cancel()


def _reachable(address: str, timeout: float = 5.0) -> None:
    """Fail fast on a ``host:port`` / ``ray://host:port`` nobody listens on (Ray itself retries
    for minutes). ``auto`` and other forms are left to Ray."""
    hostport = address[len("ray://"):] if address.startswith("ray://") else address
    host, sep, port = hostport.rpartition(":")
    if not sep or not port.isdigit() or not host:
        return
    try:
        socket.create_connection((host.strip("[]"), int(port)), timeout=timeout).close()
    except OSError as exc:
        raise ConnectionError(f"nothing answers at {address} ({exc.strerror or exc})") from None


def init_ray(address: str | None = None, workers: int | None = None, **kwargs: Any):
    """Connect to Ray: reuse an initialised session, join ``address``, or start a local one bound
    to 127.0.0.1. Returns the ``ray`` module."""
    import ray

    if ray.is_initialized():
        return ray
    if address:
        _reachable(address)
        ray.init(address=address, log_to_driver=False, **kwargs)
    else:
        _loopback_only(ray)
        opts: dict[str, Any] = dict(num_cpus=workers or default_workers(), include_dashboard=False,
                                    _node_ip_address="127.0.0.1", log_to_driver=False, configure_logging=False)
        opts.update(kwargs)
        ray.init(**opts)
    return ray


LOOPBACK_ENV = "RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"


def _loopback_only(ray) -> None:
    """Make a Ray started here a single-machine Ray on 127.0.0.1.

    Ray (2.60) replaces a loopback ``_node_ip_address`` by the host's network address, and its GCS,
    raylet and workers then listen there. Its single-machine mode (``RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0``,
    the default on macOS and Windows) keeps the node address, and every listener, on loopback. Set
    for this process and the Ray processes it starts, unless the user chose a value."""
    if os.environ.get(LOOPBACK_ENV) is None:
        os.environ[LOOPBACK_ENV] = "0"
        constants = getattr(getattr(ray, "_private", None), "ray_constants", None)
        if constants is not None and hasattr(constants, "ENABLE_RAY_CLUSTER"):
            constants.ENABLE_RAY_CLUSTER = False      # read at import: ray may be imported already


def ray_tasks(runs: Sequence[RunSpec], workers: int | None = None, address: str | None = None,
              **ray_init: Any) -> Iterator[tuple[int, dict]]:
    """Runs as Ray tasks, one CPU each; rows come back through the object store as they finish."""
    ray = init_ray(address, workers, **ray_init)
    task = ray.remote(num_cpus=1, max_retries=0)(run_one)
    refs = {task.remote(r): r for r in runs}
    while refs:
        done, _ = ray.wait(list(refs), num_returns=1)
        for ref in done:
            run = refs.pop(ref)
            try:
                yield run.index, ray.get(ref)
            except Exception as exc:   # worker crash / lost node
                yield run.index, _failed(run, exc)
