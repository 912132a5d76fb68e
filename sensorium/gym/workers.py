"""``SensoriumWorkersEnv``: the batched vector environment on several cores (``workers=k``).

    import gymnasium as gym, sensorium.gym
    envs = gym.make_vec("sensorium/LidarAvoid-v0", num_envs=64, vectorization_mode="vector_entry_point", workers=2)

or, for a task or world of your own, the class itself (the same arguments as
:class:`~sensorium.gym.vector.SensoriumVectorEnv`, plus ``workers``)::

    from sensorium.gym.workers import SensoriumWorkersEnv
    envs = SensoriumWorkersEnv("my_world.yaml", my_task, num_envs=64, workers=2)

The N copies are split into k contiguous slices (sizes differing by at most one: worker 0 holds
sub-envs 0 ... , worker 1 the next ones, ...), each a :class:`SensoriumVectorEnv` in its own process,
stepped side by side. The parent is a Gymnasium ``VectorEnv`` with the same spaces, metadata,
autoreset modes, infos and errors as ``SensoriumVectorEnv``: sub-env *i* is bit-identical to
sub-env *i* of ``SensoriumVectorEnv(num_envs=N)`` given the same seeds and actions (tests compare
every array step by step, autoresets included); ``reset(seed=s)`` gives sub-env *i* the seed s + i.

* Processes: started with multiprocessing's "spawn" method (a fresh interpreter: nothing is
  forked from a process that may hold Embree/TBB/BLAS threads), so, as for any spawn-started
  process, a script building the env must keep its top level behind ``if __name__ == "__main__":``.
  The world and the task reach the workers through cloudpickle (a custom ``Task`` with lambdas
  works). The workers talk only to this process, over pipes, semaphores and shared memory: nothing
  is bound to the network.
* Hand-over: a step's actions and results go through shared memory and each worker's pair of
  semaphores (go, done), without pickling; a call with arguments (reset, render) also carries them
  on the worker's pipe. A worker that answered sleeps on its semaphore until the next command; with
  ``poll_s`` > 0 it first polls for it that long (at most :data:`MAX_POLL_S`), which can save the
  wake-up when the caller's turn between two steps is shorter (the training section of
  docs/benchmarks.md measures two workers with and without a poll) and costs up to ``poll_s`` of a
  core per step when it is longer (a policy's forward pass). It pays only with a free core per worker.
* Failure: an exception in a worker (a task's callable raising, ...) is raised here as one
  :class:`WorkerError` naming the worker, its sub-envs and the original error (and where it was
  raised); the env then wants a ``reset()``. A worker that dies makes the call waiting on it raise
  (the parent looks at the workers' processes every :data:`WATCH_S` while it waits: no hang), and
  the env is then unusable. ``close()``, garbage collection and interpreter exit end the worker
  processes; a worker whose parent is gone ends within :data:`PARENT_WATCH_S`.
* ``workers=1`` in ``make_vec`` is today's ``SensoriumVectorEnv`` in this process; this class with
  ``workers=1`` is one worker process.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import signal
import time
import traceback
import weakref
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

import cloudpickle
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from sensorium.gym.env import DEFAULT_PRECISION, Agent, check_precision, device_of, load
from sensorium.gym.render import check_render_size
from sensorium.gym.task import Task, whole
from sensorium.gym.vector import check_counts, reset_mask, reset_seeds
from sensorium.schemas import world as wm
from sensorium.server.sim.batched import BatchedError, check_observable
from sensorium.server.world.loader import LoadedWorld

__all__ = ["SensoriumWorkersEnv", "WorkerError", "check_poll", "check_workers", "one_process", "split"]

CLOSE_WAIT_S = 5.0
"""How long close() lets a worker finish on its own before it is terminated."""

BASE_INFO = {"time_ms": ((), np.dtype(np.int64)), "steps": ((), np.dtype(np.int64)), "pose": ((3,), np.dtype(np.float64))}
"""The info keys of every step and reset (SensoriumVectorEnv's: shape of one copy, dtype), each with its
``_key`` mask: they go through shared memory; any other key (SAME_STEP's final ones) through the pipe."""


MAX_POLL_S = 0.01
"""The longest ``poll_s`` accepted."""

WATCH_S = 0.05
"""While the parent waits for replies, it checks this often that every worker is alive."""

PARENT_WATCH_S = 0.2
"""A sleeping worker checks this often that its parent is alive (orphaned, it ends)."""

# A worker's command (shared memory, written before its go semaphore is released): a step (nothing on
# the pipe), or a call whose (name, argument) waits on the pipe. Its reply's status (written before
# its done semaphore is released): done, nothing more; done, the reply on the pipe; failed, the error
# on the pipe.
_STEP, _CALL = 1, 2
_DONE, _DONE_PIPE, _FAILED = 0, 1, 2


class WorkerError(RuntimeError):
    """A worker process failed: its exception, or its death."""


def check_workers(workers: Any, num_envs: Any) -> int:
    """``workers`` as an int, or ValueError (one line) when it is not a whole number in [1, num_envs]."""
    if not whole(workers):
        raise ValueError(f"workers must be a whole number of processes, got {workers!r}")
    if workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    if check_counts(num_envs, None) < workers:
        raise ValueError(f"workers={workers} is more than num_envs={num_envs}: each worker needs at least one copy")
    return int(workers)


def check_poll(poll_s: Any) -> float:
    """A worker's poll in seconds: a number in [0, :data:`MAX_POLL_S`], or ValueError (one line)."""
    if isinstance(poll_s, bool) or not isinstance(poll_s, (int, float, np.integer, np.floating)) \
            or not 0.0 <= float(poll_s) <= MAX_POLL_S:
        raise ValueError(f"poll_s must be a number of seconds in [0, {MAX_POLL_S:g}], got {poll_s!r}")
    return float(poll_s)


def one_process(kw: dict) -> dict:
    """``kw`` for the one-process env (``workers=1``): ValueError (one line) if it holds ``poll_s``,
    which only worker processes have."""
    if "poll_s" in kw:
        raise ValueError("poll_s is the worker processes' poll: it needs workers=k > 1")
    return kw


def split(num_envs: int, workers: int) -> list[tuple[int, int]]:
    """Contiguous [lo, hi) slices of the copies, one per worker, sizes differing by at most one
    (the first ``num_envs % workers`` one larger)."""
    base, extra = divmod(num_envs, workers)
    bounds, lo = [], 0
    for w in range(workers):
        hi = lo + base + (w < extra)
        bounds.append((lo, hi))
        lo = hi
    return bounds


# ---------------------------------------------------------------------- shared memory
def _layout(agent: Agent) -> list[tuple[str | None, tuple[int, ...], np.dtype]]:
    """The observation's arrays as (key, shape of one copy, dtype): one per observed name in the
    order SensoriumVectorEnv returns them, or one (key None) for a flattened observation."""
    space = agent.observation_space
    if isinstance(space, spaces.Box):
        return [(None, tuple(space.shape), np.dtype(space.dtype))]
    return [(k, tuple(b.shape or ()), np.dtype(b.dtype)) for k, b in agent.dict_space.spaces.items()]


def _shapes(layout, width: int) -> dict[str | None, tuple[tuple[int, ...], np.dtype]]:
    """Every shared array's shape of one copy and dtype: the observation's arrays, actions (``width``
    values: Agent.n_actions), rewards, flags, and the infos' arrays and masks."""
    shapes: dict[str | None, tuple[tuple[int, ...], np.dtype]] = {key: (shape, dtype) for key, shape, dtype in layout}
    shapes.update({"@actions": ((width,), np.dtype(np.float64)), "@rewards": ((), np.dtype(np.float64)),
                   "@terminations": ((), np.dtype(bool)), "@truncations": ((), np.dtype(bool))})
    for key, (shape, dtype) in BASE_INFO.items():
        shapes["@" + key], shapes["@_" + key] = (shape, dtype), ((), np.dtype(bool))
    return shapes


def _buffers(ctx, layout, n: int, width: int) -> dict:
    """The shared buffers (raw bytes, zeroed), one per array of :func:`_shapes`."""
    return {key: ctx.RawArray("B", max(1, n * int(np.prod(shape, dtype=np.int64)) * dtype.itemsize))
            for key, (shape, dtype) in _shapes(layout, width).items()}


def _arrays(raws: dict, layout, n: int, width: int) -> dict:
    """numpy views of the shared buffers, each (n, *shape of one copy)."""
    return {key: np.frombuffer(memoryview(raws[key]).cast("B"), dtype=dtype,
                               count=n * int(np.prod(shape, dtype=np.int64))).reshape(n, *shape)
            for key, (shape, dtype) in _shapes(layout, width).items()}


# ---------------------------------------------------------------------- the worker process
def _where(exc: BaseException) -> str:
    """Where an exception was raised: the innermost frame's file:line and function (a function
    cloudpickle sent by value, e.g. a lambda of the parent's script, keeps its lines but not its file)."""
    frames = traceback.extract_tb(exc.__traceback__)
    if not frames:
        return ""
    f = frames[-1]
    if f.filename == "<dynamic-code>":
        return f" (at {f.name}, line {f.lineno} of the file defining it)"
    return f" (at {Path(f.filename).name}:{f.lineno} in {f.name})"


def _describe(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or "(no message)"
    return f"{type(exc).__name__}: {text}{_where(exc)}"


def _wait_for_command(go, parent: int, poll_s: float) -> bool:
    """A worker's wait for its go semaphore: polled for ``poll_s``, then slept on; False when the
    parent is gone (checked every :data:`PARENT_WATCH_S` while asleep)."""
    start = time.perf_counter()
    while not go.acquire(False):
        if time.perf_counter() - start > poll_s:
            while not go.acquire(timeout=PARENT_WATCH_S):
                if os.getppid() != parent:
                    return False
            return True
    return True


def _serve(conn: Connection, go, done, control, w: int, poll_s: float, parent: int, payload: bytes, lo: int,
           hi: int, raws: dict, layout, n: int) -> None:
    """Worker ``w``: build the batched env of copies [lo, hi) and answer the parent's commands until
    it says close (or the parent, process ``parent``, is gone)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)     # Ctrl-C is the parent's: it closes us
    command, status = _control(control)

    def answer(code: int, message: Any = None) -> None:
        # signal first, then send: the parent reads the pipe only once signalled, and a reply larger
        # than the pipe holds (render's images) would block this send forever
        status[w] = code
        done.release()
        if code != _DONE:
            conn.send(message)

    try:
        from sensorium.gym.vector import SensoriumVectorEnv

        loaded, task, options = cloudpickle.loads(payload)
        env = SensoriumVectorEnv(loaded, task, hi - lo, **options)
        mine = {key: a[lo:hi] for key, a in _arrays(raws, layout, n, env.agent.n_actions).items()}
    except Exception as exc:  # noqa: BLE001 - every failure goes to the parent as one message
        answer(_FAILED, _describe(exc))
        return
    answer(_DONE)

    def publish(obs) -> None:
        for key, _, dtype in layout:
            got = obs if key is None else obs[key]
            if got.dtype != dtype:     # (a silent cast would change the bits: never expected)
                raise TypeError(f"observation {key or '(flat)'}: {got.dtype}, the space says {dtype}")
            mine[key][...] = got

    def shared_info(info: dict) -> dict:
        """Write the usual info arrays to shared memory; the rest (what the pipe carries) returned."""
        rest = dict(info)
        for key in BASE_INFO:
            value, mask, out = rest.get(key), rest.get("_" + key), mine["@" + key]
            if (isinstance(value, np.ndarray) and value.dtype == out.dtype and value.shape == out.shape
                    and isinstance(mask, np.ndarray) and mask.dtype == np.bool_ and mask.shape == (hi - lo,)):
                out[...], mine["@_" + key][...] = value, mask
                del rest[key], rest["_" + key]
        return rest

    while True:
        if not _wait_for_command(go, parent, poll_s):
            return
        arg: Any
        if command[w] == _STEP:
            what, arg = "step", None
        else:
            try:
                what, arg = conn.recv()
            except (EOFError, OSError):
                return
        if what == "close":
            env.close()
            return
        try:
            if what == "step":
                obs, rew, term, trunc, info = env.step(mine["@actions"].copy())
                publish(obs)
                mine["@rewards"][...] = rew
                mine["@terminations"][...] = term
                mine["@truncations"][...] = trunc
                rest = shared_info(info)
                code, reply = (_DONE_PIPE, rest) if rest else (_DONE, None)
            elif what == "reset":
                obs, info = env.reset(**arg)
                publish(obs)
                code, reply = _DONE_PIPE, shared_info(info)
            elif what == "peek":        # a reset of other workers' copies: ours as they are (not reset)
                publish(env._observe())
                code, reply = _DONE_PIPE, shared_info(env._full_info(np.zeros(hi - lo, dtype=bool)))
            elif what == "render":
                code, reply = _DONE_PIPE, env.render()
            else:
                raise ValueError(f"unknown call {what!r}")
        except Exception as exc:  # noqa: BLE001
            answer(_FAILED, _describe(exc))
            continue
        answer(code, reply)


def _control(control) -> tuple[np.ndarray, np.ndarray]:
    """The shared (command, status) arrays of every worker, views of ``control`` (2k int64)."""
    both = np.frombuffer(memoryview(control).cast("B"), dtype=np.int64)
    k = len(both) // 2
    return both[:k], both[k:]


def _shutdown(procs: list, conns: list[Connection], gos: list, command: np.ndarray) -> None:
    """End the workers: ask each to close, then terminate (and kill) whatever is still running."""
    for w, c in enumerate(conns):
        try:
            command[w] = _CALL
            c.send(("close", None))
            gos[w].release()
        except (OSError, ValueError):
            pass
    for p in procs:
        p.join(CLOSE_WAIT_S)
        if p.is_alive():
            p.terminate()
            p.join(CLOSE_WAIT_S)
        if p.is_alive():
            p.kill()
            p.join()
    for c in conns:
        c.close()


# ---------------------------------------------------------------------- merging the workers' infos
def _concat(parts: list):
    """The workers' pieces (arrays, or dicts of them) joined along the sub-env axis."""
    if isinstance(parts[0], dict):
        return {k: _concat([p[k] for p in parts]) for k in parts[0]}
    return np.concatenate(parts)


def _with_final(info: dict, obs, m: int) -> dict:
    """A worker's step info with SAME_STEP's final keys as SensoriumVectorEnv gives them for copies
    that did not end (when another worker's did): their observation and info, masks False."""
    if "final_obs" in info:
        return info
    out = dict(info)
    out["final_obs"], out["_final_obs"] = obs, np.zeros(m, dtype=bool)
    out["final_info"] = {k: (v.copy() if isinstance(v, (np.ndarray, dict)) else v) for k, v in out.items()}
    out["_final_info"] = np.zeros(m, dtype=bool)
    return out


class SensoriumWorkersEnv(VectorEnv):
    """N copies of a world in k worker processes, each a batched simulation (see the module docstring)."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 30, "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(self, world: str | Path | LoadedWorld | wm.World | None = None, task: Task | None = None,
                 num_envs: int = 1, *, workers: int = 2, precision: str = DEFAULT_PRECISION,
                 actions: str = "normalized", flatten: bool = False,
                 autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP, render_mode: str | None = None,
                 render_size: int = 256, threads: int | None = 1, poll_s: float = 0.0, **_spec_kwargs):
        self._procs: list = []
        self._conns: list[Connection] = []
        self._broken = ""
        check_counts(num_envs, threads)
        self.workers = check_workers(workers, num_envs)
        poll_s = check_poll(poll_s)
        precision, render_size = check_precision(precision), check_render_size(render_size)
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be one of {self.metadata['render_modes']} or None, got {render_mode!r}")
        self.autoreset_mode = AutoresetMode(autoreset_mode)
        self.metadata = {**type(self).metadata, "autoreset_mode": self.autoreset_mode}
        self.render_mode = render_mode
        self.num_envs = n = int(num_envs)
        loaded = load(world)
        task = task or Task()
        # the spaces, and what the batched simulation cannot run, here: one line before any process starts
        agent = Agent(loaded, task, actions=actions, flatten=flatten)
        try:
            check_observable(loaded.world, agent.robot, map(device_of, agent.periods))
        except BatchedError as e:
            raise BatchedError(f"{str(e).removesuffix(' (use Simulation)')}: the batched vector environment cannot "
                               "run this task (SensoriumEnv can: gymnasium.vector.SyncVectorEnv or "
                               "AsyncVectorEnv of it)") from None
        self.single_observation_space = agent.observation_space
        self.single_action_space = agent.action_space
        self.observation_space = batch_space(self.single_observation_space, n)
        self.action_space = batch_space(self.single_action_space, n)
        self._layout = _layout(agent)
        self.slices = split(n, self.workers)
        self._needs_reset = np.ones(n, dtype=bool)
        self._autoreset = np.zeros(n, dtype=bool)

        ctx = mp.get_context("spawn")
        self._width = agent.n_actions
        raws = _buffers(ctx, self._layout, n, self._width)
        self._shared = _arrays(raws, self._layout, n, self._width)
        control = ctx.RawArray("q", 2 * self.workers)
        self._command, self._status = _control(control)
        self._gos = [ctx.Semaphore(0) for _ in range(self.workers)]
        self._dones = [ctx.Semaphore(0) for _ in range(self.workers)]
        payload = cloudpickle.dumps((loaded, task, {
            "precision": precision, "actions": actions, "flatten": flatten, "autoreset_mode": self.autoreset_mode,
            "render_mode": render_mode, "render_size": render_size, "threads": threads}))
        # (the finalizer holds the processes, pipes and semaphores, not self: garbage collection and exit end them)
        self._finalizer = weakref.finalize(self, _shutdown, self._procs, self._conns, self._gos, self._command)
        for w, (lo, hi) in enumerate(self.slices):
            mine, theirs = ctx.Pipe()
            proc = ctx.Process(target=_serve, args=(theirs, self._gos[w], self._dones[w], control, w, poll_s,
                                                    os.getpid(), payload, lo, hi, raws, self._layout, n),
                               name=f"sensorium-worker-{w}", daemon=True)
            proc.start()
            theirs.close()
            self._procs.append(proc)
            self._conns.append(mine)
        try:
            self._call([("start", None)] * self.workers, send=False)
        except BaseException:
            self._finalizer()
            raise

    # ------------------------------------------------------------------ talking to the workers
    def _name(self, w: int) -> str:
        lo, hi = self.slices[w]
        return f"worker {w} of {self.workers} (sub-envs {lo}-{hi - 1}, pid {self._procs[w].pid})"

    def _died(self, w: int, what: str) -> WorkerError:
        """The env is unusable once a worker is gone: the others are ended, every later call says why."""
        p = self._procs[w]
        p.join(1.0)
        code = p.exitcode
        how = (f"killed by signal {signal.Signals(-code).name}" if code is not None and code < 0
               else f"exit code {code}")
        self._broken = f"{self._name(w)} died during {what} ({how})"
        self._finalizer()
        return WorkerError(f"{self._broken}: the environment is closed; build a new one")

    def _call(self, requests: list[tuple[str, Any] | None], send: bool = True) -> list:
        """Send each worker its (call, argument) (None: none) and wait for every reply, looking at
        the workers' processes every :data:`WATCH_S` meanwhile (a worker that dies is seen then)."""
        if self._broken:
            raise WorkerError(f"{self._broken}: the environment is closed; build a new one")
        if self.closed:
            raise RuntimeError("the environment is closed")
        whats = [r[0] if r is not None else "" for r in requests]
        waiting = [w for w, r in enumerate(requests) if r is not None]
        replies: list = [None] * self.workers
        errors: list[tuple[int, str]] = []
        try:
            for w in waiting if send else ():
                request = requests[w]
                assert request is not None
                if request[0] == "step":          # the arguments are in shared memory
                    self._command[w] = _STEP
                else:
                    self._command[w] = _CALL
                    try:
                        self._conns[w].send(request)
                    except OSError:
                        raise self._died(w, whats[w]) from None
                self._gos[w].release()
            answered: set[int] = set()        # replies seen while checking on a dead worker
            for w in waiting:
                while w not in answered and not self._dones[w].acquire(timeout=WATCH_S):
                    self._watch(waiting, answered, whats)
                code = int(self._status[w])
                reply: Any = {}
                if code != _DONE:
                    try:
                        reply = self._conns[w].recv()
                    except (EOFError, OSError):
                        raise self._died(w, whats[w]) from None
                if code == _FAILED:
                    errors.append((w, f"{self._name(w)} failed in {whats[w]}: {reply}"))
                replies[w] = reply
        except WorkerError:
            raise
        except BaseException:         # interrupted while replies were owed: the workers are out of step
            self._broken = "an earlier call was interrupted"
            self._finalizer()
            raise
        if errors:
            self._needs_reset[:] = True
            errors.sort()
            more = f" (and {len(errors) - 1} more worker(s) failed)" if len(errors) > 1 else ""
            after = "" if whats[errors[0][0]] == "start" else "; reset() before stepping again"
            raise WorkerError(errors[0][1] + more + after)
        return replies

    def _watch(self, waiting: list[int], answered: set[int], whats: list[str]) -> None:
        """Raise for a worker process that ended (any worker's: the env is broken), unless it is one
        whose reply is still to read (then noted in ``answered``)."""
        for v, proc in enumerate(self._procs):
            if proc.exitcode is None or v in answered:
                continue
            if v in waiting and self._dones[v].acquire(False):
                answered.add(v)
                continue
            raise self._died(v, whats[v] or "another worker's call")

    def _infos(self, replies: list[dict], obs=None) -> dict:
        """The info of every sub-env: the usual arrays from shared memory, the rest from the replies
        (with ``obs``, the step's observation: SAME_STEP's final keys completed for every worker)."""
        sh = self._shared
        if not any(replies):        # the usual case: every worker's info in shared memory
            out = {}
            for key in BASE_INFO:
                out[key], out["_" + key] = sh["@" + key].copy(), sh["@_" + key].copy()
            return out
        parts = []
        for reply, (lo, hi) in zip(replies, self.slices):
            part = {}
            for key in BASE_INFO:
                if key not in reply:
                    part[key], part["_" + key] = sh["@" + key][lo:hi], sh["@_" + key][lo:hi]
            part.update(reply)
            parts.append(part)
        if obs is not None and any("final_obs" in p for p in parts):
            parts = [_with_final(p, _part(obs, lo, hi), hi - lo) for p, (lo, hi) in zip(parts, self.slices)]
        return _concat(parts)

    def _observations(self):
        sh = self._shared
        if self._layout[0][0] is None:
            return sh[None].copy()
        return {key: sh[key].copy() for key, _, _ in self._layout}

    # ------------------------------------------------------------------ gymnasium API
    def reset(self, *, seed: int | list[int | None] | None = None, options: dict | None = None):
        n = self.num_envs
        seeds = reset_seeds(seed, n)
        mask = reset_mask(options, n)
        requests: list[tuple[str, Any] | None] = []
        for lo, hi in self.slices:
            part = mask[lo:hi]
            if part.any():
                opts = {**(options or {}), "reset_mask": part.copy()}
                requests.append(("reset", {"seed": seeds[lo:hi], "options": opts}))
            else:           # none of this worker's copies reset: it reports them as they are
                requests.append(("peek", None))
        infos = self._call(requests)
        self._needs_reset[mask] = False
        self._autoreset[mask] = False
        return self._observations(), self._infos(infos)

    def step(self, actions):
        n = self.num_envs
        if self._broken:
            raise WorkerError(f"{self._broken}: the environment is closed; build a new one")
        if self._needs_reset.any():
            raise RuntimeError("call reset() before step()")
        actions = np.asarray(actions)
        if actions.shape != (n, self._width):
            raise ValueError(f"actions must have shape ({n}, {self._width}), got {actions.shape}")
        if self.autoreset_mode == AutoresetMode.DISABLED and self._autoreset.any():
            raise RuntimeError(f"sub-envs {self._autoreset.nonzero()[0].tolist()} ended: reset them "
                               "(options={'reset_mask': ...}) before stepping (autoreset is disabled)")
        # SensoriumVectorEnv's check of the moving sub-envs' actions (an autoresetting one's is ignored)
        a = np.asarray(actions, dtype=np.float64)
        moving = ~self._autoreset if self.autoreset_mode == AutoresetMode.NEXT_STEP else np.ones(n, dtype=bool)
        bad = np.flatnonzero(moving & ~np.isfinite(a).all(axis=1))
        if len(bad):
            raise ValueError(f"sub-env {int(bad[0])}: action must be {self._width} finite values, "
                             f"got {actions[bad[0]]!r}")
        self._shared["@actions"][...] = a
        infos = self._call([("step", None)] * self.workers)
        obs = self._observations()
        rewards = self._shared["@rewards"].copy()
        terms = self._shared["@terminations"].copy()
        truncs = self._shared["@truncations"].copy()
        info = self._infos(infos, obs)
        self._autoreset = (terms | truncs) if self.autoreset_mode != AutoresetMode.SAME_STEP else np.zeros(n, bool)
        return obs, rewards, terms, truncs, info

    def render(self):
        """Top-down images of every sub-env (``render_mode="rgb_array"``), a tuple of (H, W, 3) uint8."""
        if self.render_mode != "rgb_array":
            return None
        return tuple(image for part in self._call([("render", None)] * self.workers) for image in part)

    def close_extras(self, **kwargs) -> None:
        self._finalizer()

    @property
    def pids(self) -> list[int]:
        """The worker processes' ids (worker 0 first)."""
        return [p.pid for p in self._procs]


def _part(obs, lo: int, hi: int):
    return obs[lo:hi] if not isinstance(obs, dict) else {k: v[lo:hi] for k, v in obs.items()}
