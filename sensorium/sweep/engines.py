"""Where runs execute: a local process pool, or Ray tasks (local or on a cluster). Both call the
same :func:`sensorium.sweep.run.run_one` and yield ``(index, row)`` as runs finish; the caller
orders the rows. No scheduling of our own: Ray (or the pool) places the tasks.

Ray on one machine is started bound to loopback (``_node_ip_address="127.0.0.1"``, no dashboard,
``num_cpus`` = the workers asked for, default all CPUs). With ``address`` the sweep joins an
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


def local_pool(runs: Sequence[RunSpec], workers: int | None = None) -> Iterator[tuple[int, dict]]:
    """Runs on a pool of ``workers`` spawned processes (nothing inherited but the runs)."""
    workers = max(1, workers or default_workers())
    pool = _pool(workers)
    try:
        pending = {pool.submit(run_one, r): r for r in runs}
    except BrokenProcessPool:
        _POOLS.pop(workers, None)
        pool = _pool(workers)
        pending = {pool.submit(run_one, r): r for r in runs}
    try:
        while pending:
            done, _ = wait(pending, return_when=FIRST_COMPLETED)
            for fut in done:
                run = pending.pop(fut)
                try:
                    yield run.index, fut.result()
                except Exception as exc:   # a crashed worker (e.g. killed): that run's row says so
                    if isinstance(exc, BrokenProcessPool):
                        _POOLS.pop(workers, None)
                    yield run.index, _failed(run, exc)
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
        opts: dict[str, Any] = dict(num_cpus=workers or default_workers(), include_dashboard=False,
                                    _node_ip_address="127.0.0.1", log_to_driver=False, configure_logging=False)
        opts.update(kwargs)
        ray.init(**opts)
    return ray


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
