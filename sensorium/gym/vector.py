"""``SensoriumVectorEnv``: N copies of a world in ONE batched simulation, as a Gymnasium ``VectorEnv``.

    import gymnasium as gym, sensorium.gym
    envs = gym.make_vec("sensorium/ReachLight-v0", num_envs=256, vectorization_mode="vector_entry_point")
    obs, info = envs.reset(seed=0)                     # sub-env i: seed 0 + i
    obs, rewards, terminations, truncations, info = envs.step(envs.action_space.sample())

Unlike ``SyncVectorEnv``/``AsyncVectorEnv`` (N environments, N simulations), the copies share one
:class:`~sensorium.server.sim.batched.BatchedSimulation`: the static world is built once, every
copy's rays go out in one cast per ray kind and every device model runs once per step over all
copies. Sub-environment *i* reset with seed *s* and given the same actions is bit-identical to
``SensoriumEnv`` (the single environment) reset with seed *s*, at the same precision: the same
world seed drawn from the same generator, the same start pose, clock, noise streams, observations,
rewards and flags (tests compare them step by step, resets included).

* Autoreset: Gymnasium 1.x's ``AutoresetMode.NEXT_STEP`` by default (declared in ``metadata``):
  the step after a sub-env's episode ended resets it and returns its first observation with reward
  0 and both flags False (its action is ignored). ``autoreset_mode=SAME_STEP`` resets within the
  ending step (the ended episode's last observation and info in ``info["final_obs"]`` /
  ``info["final_info"]``, masks ``info["_final_obs"]``); ``DISABLED`` leaves it to
  ``reset(options={"reset_mask": mask})``.
* A reset reuses the built scene (nothing is rebuilt): the world seed, the copy's state and its
  start pose, then the warm-up steps (until every observed device has a value) run batched with
  whatever else steps at that time.
* ``sub_env(i)``: sub-environment *i* as a plain ``gymnasium.Env`` (reset and step it alone; for
  checkers and tests).
* Options as ``SensoriumEnv``: ``actions`` (``"normalized"``: [-1, 1], the default; ``"wheel"``:
  rad/s; a car-like agent's (steering, speed), a mecanum or omni-wheel agent's wheels as there), ``flatten`` (one Box), ``precision``; a task's reward and termination use their
  vectorised form when they have one (``ReachLight``, ``AvoidObstacles``, :mod:`.task`), else
  they are called per copy with views of that copy.
* ``threads``: the threads a cast of >= 16,384 rays (all copies' lidar beams) may be split over
  (default: the process's cores, or ``SENSORIUM_THREADS``); the same bits on any number.
  ``sensorium bench --only training`` measures LidarAvoid x64 on one and on two.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from sensorium.gym.env import DEFAULT_PRECISION, SEGMENTATION, Agent, check_precision, device_of, load, missing_fill
from sensorium.gym.render import TopDown, check_render_size
from sensorium.gym.task import Task, VectorGoal, never, whole, zero
from sensorium.gym.views import CopySim
from sensorium.schemas import world as wm
from sensorium.server.raycast import packets
from sensorium.server.sim.batched import BatchedError, BatchedSimulation, check_observable
from sensorium.server.sim.batched_holonomic import HolonomicDrives
from sensorium.server.sim.frames import heading
from sensorium.server.world.loader import LoadedWorld

__all__ = ["SensoriumVectorEnv", "SubEnv"]

RANGE_IMAGES = ("Lidar", "RangeFinder")
"""The observed kinds whose observation is a range image (``sim.range_image``), not ``sim.values``."""


class _PerCopy(VectorGoal):
    """A reward/termination callable without a vectorised form: called once per copy with views."""

    def __init__(self, fn, venv: SensoriumVectorEnv, owner):
        self.fn, self.venv, self.owner = fn, venv, owner

    def reset(self, copies: np.ndarray) -> None:
        if self.owner is not None:
            for c in copies.tolist():
                self.owner.reset(self.venv._view(c), self.venv._view(c).robot(self.venv.agent.robot))

    def _call(self, copies: np.ndarray, dtype) -> np.ndarray:
        out = np.empty(len(copies), dtype=dtype)
        for k, c in enumerate(copies.tolist()):
            view = self.venv._view(c)
            out[k] = self.fn(view, view.robot(self.venv.agent.robot), self.venv._last_obs_of(c))
        return out

    def reward(self, copies: np.ndarray) -> np.ndarray:
        return self._call(copies, np.float64)

    def terminated(self, copies: np.ndarray) -> np.ndarray:
        return self._call(copies, bool)


def _owner(fn):
    """The object a reward/termination callable belongs to (itself, or the instance of a bound method)."""
    if hasattr(fn, "vectorized") or hasattr(fn, "reset"):
        return fn
    return getattr(fn, "__self__", None)


def check_counts(num_envs: Any, threads: Any) -> int:
    """``num_envs`` as an int, or ValueError (one line) when it or ``threads`` (None: the default) is
    not a whole number >= 1."""
    if not whole(num_envs) or num_envs < 1:
        raise ValueError(f"num_envs must be an integer >= 1, got {num_envs!r}")
    if threads is not None and (not whole(threads) or threads < 1):
        raise ValueError(f"threads must be an integer >= 1 or None, got {threads!r}")
    return int(num_envs)


def reset_seeds(seed: Any, n: int) -> list[int | None]:
    """Each sub-env's seed for ``reset(seed=...)``: an int s gives sub-env i the seed s + i, a list
    one seed (or None) per sub-env, None none; ValueError (one line) for anything else."""
    if seed is None:
        return [None] * n
    if whole(seed):
        return [int(seed) + i for i in range(n)]
    if not isinstance(seed, (list, tuple, np.ndarray)):
        raise ValueError(f"reset: seed must be an integer, a list of num_envs integers (or None), or None; "
                         f"got {seed!r}")
    seeds = list(seed)
    if len(seeds) != n:
        raise ValueError(f"reset: {len(seeds)} seeds for num_envs={n}")
    bad = [s for s in seeds if s is not None and not whole(s)]
    if bad:
        raise ValueError(f"reset: a seed must be an integer or None, got {bad[0]!r}")
    return [None if s is None else int(s) for s in seeds]


def reset_mask(options: dict | None, n: int) -> np.ndarray:
    """The sub-envs a reset resets: ``options["reset_mask"]`` (a bool array of shape (n,) with a True
    value; ValueError otherwise), or all of them."""
    if options is None or "reset_mask" not in options:
        return np.ones(n, dtype=bool)
    mask = np.asarray(options["reset_mask"])
    if mask.shape != (n,) or mask.dtype != np.bool_ or not mask.any():
        raise ValueError(f"options['reset_mask'] must be a bool array of shape ({n},) with a True value")
    return mask


class SensoriumVectorEnv(VectorEnv):
    """N copies of a world stepped in one batched simulation (see the module docstring)."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 30, "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(self, world: str | Path | LoadedWorld | wm.World | None = None, task: Task | None = None,
                 num_envs: int = 1, *, precision: str = DEFAULT_PRECISION, actions: str = "normalized",
                 flatten: bool = False, autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
                 render_mode: str | None = None, render_size: int = 256, threads: int | None = None,
                 **_spec_kwargs):
        check_counts(num_envs, threads)
        self.loaded = load(world)
        self.task = task or Task()
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be one of {self.metadata['render_modes']} or None, got {render_mode!r}")
        self.autoreset_mode = AutoresetMode(autoreset_mode)
        self.metadata = {**type(self).metadata, "autoreset_mode": self.autoreset_mode}
        self.render_mode = render_mode
        self.render_size = check_render_size(render_size)
        self.num_envs = n = int(num_envs)
        self.precision = precision = check_precision(precision)
        self.agent = Agent(self.loaded, self.task, actions=actions, flatten=flatten)
        try:      # what the batched simulation does not simulate: one line, before anything is built
            check_observable(self.loaded.world, self.agent.robot, map(device_of, self.agent.periods))
            self.sim = BatchedSimulation(self.loaded, n, precision=precision, threads=threads)
        except BatchedError as e:
            raise BatchedError(f"{str(e).removesuffix(' (use Simulation)')}: the batched vector environment cannot "
                               "run this task (SensoriumEnv can: gymnasium.vector.SyncVectorEnv or "
                               "AsyncVectorEnv of it)") from None
        self.slot = self.sim.slot(self.agent.robot)
        self.refs = {name: self.sim.check_observable(self.agent.robot, device_of(name)) for name in self.agent.periods}
        self._scalars = self._scalar_groups()
        self._image_bounds = self._uniform_image_bounds()
        self.basic_time_step = self.sim.basic_time_step
        self.steps_per_action = self.agent.control_period_ms // self.basic_time_step
        self.single_observation_space = self.agent.observation_space
        self.single_action_space = self.agent.action_space
        self.observation_space = batch_space(self.single_observation_space, n)
        self.action_space = batch_space(self.single_action_space, n)
        self._goals = self._vector_goals()
        self._rngs = [seeding.np_random()[0] for _ in range(n)]
        self.steps = np.zeros(n, dtype=np.int64)
        self._autoreset = np.zeros(n, dtype=bool)
        self._every = np.arange(n)      # (every sub-env, in order: the usual step's copies; never written)
        self._every.flags.writeable = False
        self._needs_reset = np.ones(n, dtype=bool)       # before the first reset: stepping is an error
        self._obs_cache: Any = None
        self._renderers: dict[int, TopDown] = {}

    # ------------------------------------------------------------------ building
    def _vector_goals(self) -> tuple[VectorGoal, VectorGoal, list]:
        """(reward goal, termination goal, the objects whose reset(copies) runs after a reset)."""
        t = self.task
        made: dict[int, VectorGoal] = {}

        def goal(fn, trivial) -> VectorGoal:
            if fn is trivial:
                return VectorGoal()
            owner = _owner(fn)
            if owner is not None and hasattr(owner, "vectorized"):
                if id(owner) not in made:
                    made[id(owner)] = owner.vectorized(self.sim, self.slot)
                return made[id(owner)]
            vg = _PerCopy(fn, self, owner if owner is not None and hasattr(owner, "reset") else None)
            made.setdefault(id(owner) if owner is not None else id(vg), vg)
            return vg

        reward = goal(t.reward, zero)
        term = goal(t.terminated, never)
        return reward, term, list(made.values())

    def _view(self, copy: int) -> CopySim:
        return CopySim(self.sim, copy)

    # ------------------------------------------------------------------ the batched core
    def _begin_reset(self, copies: np.ndarray, seeds: list[int | None]) -> None:
        """Reset these copies as SensoriumEnv.reset does (warm-up left to the next run)."""
        world_seeds = []
        for c, s in zip(copies.tolist(), seeds):
            if s is not None:
                self._rngs[c], _ = seeding.np_random(int(s))
            world_seeds.append(int(self._rngs[c].integers(0, 2**62)))
        self.sim.reset(copies, world_seeds)
        # Agent.start for all these copies: the task's start per copy (on a view: the single
        # environment's own draws), then wheels at rest in velocity control and the observed
        # devices enabled, for all of them at once
        if self.task.start is not None:
            for c in copies.tolist():
                view = self._view(c)
                self.task.start(view, view.robot(self.agent.robot), self._rngs[c])
        if self.agent.wheel_motors is not None:      # a mecanum or omni-wheel robot: its wheels at rest, velocity control
            self._wheels().command(self.slot, np.zeros((len(copies), self.agent.n_actions)), copies)
        elif self.agent.car is None:
            self.sim.set_wheels(self.slot, np.zeros(len(copies)), np.zeros(len(copies)), copies)
        else:       # a car: its driven wheels at rest in velocity control (its steering as built)
            assert self.sim.cars is not None
            self.sim.cars.roll(self.slot, np.zeros(len(copies)), copies)
        for name, period in self.agent.periods.items():
            if name.endswith(SEGMENTATION):
                self.sim.recognition_enable(self.refs[name], period, copies)
                self.sim.enable_segmentation(self.refs[name], True, copies)
            else:
                self.sim.enable(self.refs[name], period, copies)
        self.steps[copies] = 0
        self._needs_reset[copies] = False

    def _run(self, stepping: np.ndarray, resetting: np.ndarray) -> None:
        """The basic steps of one vector step: ``steps_per_action`` for the stepping copies, the
        warm-up for the resetting ones, interleaved in one loop (copies are independent)."""
        spa = self.steps_per_action if stepping.any() else 0
        warm = self.agent.warmup_steps if resetting.any() else 0
        for k in range(max(spa, warm)):
            active = (stepping & (k < spa)) | (resetting & (k < warm))
            self.sim.step(active)

    def _wheels(self) -> HolonomicDrives:
        """The batched wheels of a mecanum or omni-wheel agent."""
        drives = self.sim.mecanum if self.agent.mecanum is not None else self.sim.omni
        assert drives is not None
        return drives

    def _act(self, copies: np.ndarray, actions: np.ndarray) -> None:
        width = self.agent.n_actions
        a = np.asarray(actions, dtype=np.float64).reshape(len(copies), width)
        if not np.isfinite(a).all():
            bad = int(np.flatnonzero(~np.isfinite(a).all(axis=1))[0])
            raise ValueError(f"sub-env {int(copies[bad])}: action must be {width} finite values, got {actions[bad]!r}")
        cmd = self.agent.scaled(a)          # (the single env's commands, row by row)
        # (every copy in order: the simulation's own default, a slice rather than a gather)
        which = None if copies is self._every else copies
        if self.agent.wheel_motors is not None:     # a mecanum or omni-wheel robot: its wheels (the drive's order)
            self._wheels().command(self.slot, cmd, which)
        elif self.agent.car is None:      # (a side mounted mirrored commanded negated, as the single env's act)
            sign = self.sim.wheel_sign[self.slot]
            self.sim.set_wheels(self.slot, sign[0] * cmd[:, 0], sign[1] * cmd[:, 1], which)
        elif len(copies):       # a car: its steering motors to the Ackermann angles, its driven wheels to the speed
            assert self.sim.cars is not None
            right, left = (np.array(side) for side in zip(*map(self.agent.steering_positions, cmd[:, 0].tolist())))
            self.sim.cars.command(self.slot, right, left, cmd[:, 1], which)

    def _scalar_groups(self) -> list[tuple[str, list[str], np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
        """The observed devices whose values are ``sim.values`` (one value, or three: a GPS, a
        compass, an inertial unit) by kind: (kind, names, value columns, each one's fill for a
        missing value (float64), its Box's low and high (float32); (devices,) for one value, (devices,
        3) for three), so that :meth:`_observe` reads each kind's columns with one gather and one clip."""
        groups: dict[str, list] = {}
        for name, box in self.agent.dict_space.spaces.items():
            ref = self.refs[name]
            if ref.kind not in RANGE_IMAGES and ref.kind != "Camera":
                low, high = (box.low[0], box.high[0]) if box.shape == (1,) else (box.low, box.high)
                groups.setdefault(ref.kind, []).append((name, ref.column, missing_fill(low), low, high))
        return [(kind, [g[0] for g in items], np.array([g[1] for g in items], dtype=np.int64),
                 np.array([g[2] for g in items], dtype=np.float64), np.array([g[3] for g in items], dtype=np.float32),
                 np.array([g[4] for g in items], dtype=np.float32)) for kind, items in groups.items()]

    def _uniform_image_bounds(self) -> dict[str, tuple[np.float32, np.float32]]:
        """Per observed range image whose Box has one finite low and one high over every entry (a
        lidar's 0 and maximum range) with low <= high, high > 0: those two float32 bounds. Clipping
        to them gives the clip to the Box of :meth:`_observe` with its nan_to_num's +inf (and NaN)
        -> high and -inf -> -3.4e38 -> low, element by element the same values, once the NaNs are
        set to high and a zero at a zero low bound is that bound's zero (numpy's clip against an
        array returns the bound on a tie, against a number the value: -0.0 vs 0.0), so that path
        clips against two numbers (tests/test_gym_vector.py compares the two bit for bit)."""
        out = {}
        for name, box in self.agent.dict_space.spaces.items():
            if self.refs[name].kind not in RANGE_IMAGES:
                continue
            low, high = np.asarray(box.low, dtype=np.float32), np.asarray(box.high, dtype=np.float32)
            lo, hi = low.flat[0], high.flat[0]
            if (np.isfinite(lo) and lo <= hi and hi > 0.0 and lo > np.finfo(np.float32).min
                    and (low == lo).all() and (high == hi).all()):
                out[name] = (lo, hi)
        return out

    def _observe(self, copies: np.ndarray | slice = slice(None)):
        got = {}
        for kind, names, cols, fill, low, high in self._scalars:
            # per device the same elementwise steps: a missing value filled, float32, clipped to its Box
            v = self.sim.values[kind][copies][:, cols]
            v = np.clip(np.where(np.isfinite(v), v, fill).astype(np.float32), low, high)
            for j, name in enumerate(names):
                got[name] = v[:, j:j + 1] if v.ndim == 2 else v[:, j]
        out = {}
        for name, box in self.agent.dict_space.spaces.items():
            if name in got:
                out[name] = got[name] if self.agent.flatten else got[name].copy()   # (each its own array)
                continue
            ref = self.refs[name]
            if ref.kind == "Camera":      # BGRA -> RGB, as the single env's observation
                bgra = self.sim.segmentation_image(ref) if name.endswith(SEGMENTATION) else self.sim.image(ref)
                out[name] = np.ascontiguousarray(bgra[copies][..., 2::-1])
                continue
            img = self.sim.range_image(ref)[copies]
            bounds = self._image_bounds.get(name)
            if bounds is not None:   # (see _uniform_image_bounds: the same values, two passes fewer)
                clipped = packets.box_clip32(img, bounds[0], bounds[1])   # (the steps below in one C pass)
                if clipped is not None:
                    out[name] = clipped
                    continue
                v = np.clip(img, bounds[0], bounds[1])
                nan = np.isnan(v)
                if nan.any():
                    v[nan] = bounds[1]
                if bounds[0] == 0.0:   # a zero at the low bound is the bound's zero (as the Box's array clip gives it)
                    v[v == 0.0] = bounds[0]
                out[name] = v
                continue
            hi = box.high.flat[0]
            out[name] = np.clip(np.nan_to_num(img, nan=hi, posinf=hi), box.low, box.high).astype(np.float32)
        if self.agent.flatten:
            m = len(next(iter(out.values()))) if out else 0
            return np.concatenate([out[k].reshape(m, -1) for k in self.agent.dict_space.spaces], axis=1).astype(np.float32)
        return out

    def _last_obs_of(self, copy: int):
        obs = self._observe(np.array([copy]))
        return obs[0] if self.agent.flatten else {k: v[0] for k, v in obs.items()}

    def _outcome(self, copies: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        reward_goal, term_goal, _ = self._goals
        reward = np.asarray(reward_goal.reward(copies), dtype=np.float64)
        term = np.asarray(term_goal.terminated(copies), dtype=bool)
        ms = self.task.max_steps
        trunc = (self.steps[copies] >= ms) & ~term if ms is not None else np.zeros(len(copies), dtype=bool)
        return reward, term, trunc

    def _info(self, copies: np.ndarray | slice) -> dict[str, np.ndarray]:
        rot = self.sim.rot[copies, self.slot]
        pos = self.sim.pos[copies, self.slot]
        pose = np.empty((len(pos), 3))
        e, n, _ = self.agent.axes              # (east, north, yaw) as the single env's frame.planar_pose
        if e == 0 and n == 1:
            pose[:, :2] = pos[:, :2]
        else:
            pose[:, 0], pose[:, 1] = pos[:, e], pos[:, n]
        # the yaw as math.atan2 gives it (the single environment's): libm's atan2 in one C pass, of
        # the drive's forward (frame.heading, element-wise as the single env's)
        head = heading(rot, self.agent.forward)
        north, east = head[:, n], head[:, e]
        if packets.atan2(north, east, pose[:, 2]) is None:
            pose[:, 2] = list(map(math.atan2, north.tolist(), east.tolist()))
        return {"time_ms": self.sim.time_ms[copies].copy(), "steps": self.steps[copies].copy(), "pose": pose}

    def _full_info(self, mask: np.ndarray) -> dict[str, np.ndarray]:
        """Info of every sub-env (Gymnasium's vector layout: one array per key and a ``_key`` mask)."""
        info = self._info(slice(None))      # every sub-env (views, not gathers)
        out: dict[str, np.ndarray] = {}
        for k, v in info.items():
            out[k] = v
            out["_" + k] = mask.copy()
        return out

    # ------------------------------------------------------------------ gymnasium API
    def reset(self, *, seed: int | list[int | None] | None = None, options: dict | None = None):
        self._check_open()
        n = self.num_envs
        seeds = reset_seeds(seed, n)
        mask = reset_mask(options, n)
        copies = mask.nonzero()[0]
        self._begin_reset(copies, [seeds[c] for c in copies.tolist()])
        self._run(np.zeros(n, dtype=bool), mask)
        for g in self._goals[2]:
            g.reset(copies)
        self._autoreset[copies] = False
        return self._observe(), self._full_info(mask)

    def step(self, actions):
        self._check_open()
        n = self.num_envs
        if self._needs_reset.any():
            raise RuntimeError("call reset() before step()")
        actions = np.asarray(actions)
        if actions.shape != (n, self.agent.n_actions):
            raise ValueError(f"actions must have shape ({n}, {self.agent.n_actions}), got {actions.shape}")
        resetting = self._autoreset.copy() if self.autoreset_mode == AutoresetMode.NEXT_STEP else np.zeros(n, bool)
        if self.autoreset_mode == AutoresetMode.DISABLED and self._autoreset.any():
            raise RuntimeError(f"sub-envs {self._autoreset.nonzero()[0].tolist()} ended: reset them "
                               "(options={'reset_mask': ...}) before stepping (autoreset is disabled)")
        stepping = ~resetting
        resets = resetting.nonzero()[0]
        # the usual step (no sub-env resets): every sub-env in order, the arrays without gathers
        moving = self._every if not len(resets) else stepping.nonzero()[0]
        self._act(moving, actions if moving is self._every else actions[moving])
        if len(resets):
            self._begin_reset(resets, [None] * len(resets))
        self._run(stepping, resetting)
        for g in self._goals[2] if len(resets) else ():
            g.reset(resets)
        self.steps[moving] += 1
        rewards = np.zeros(n)
        terms = np.zeros(n, dtype=bool)
        truncs = np.zeros(n, dtype=bool)
        if len(moving):
            r, te, tr = self._outcome(moving)
            rewards[moving], terms[moving], truncs[moving] = r, te, tr
        done = terms | truncs
        info = self._full_info(np.ones(n, dtype=bool))
        if self.autoreset_mode == AutoresetMode.SAME_STEP and done.any():
            ended = done.nonzero()[0]
            final_obs = self._observe()
            info["final_obs"], info["_final_obs"] = final_obs, done.copy()
            info["final_info"], info["_final_info"] = {k: v.copy() for k, v in info.items()}, done.copy()
            self._begin_reset(ended, [None] * len(ended))
            self._run(np.zeros(n, dtype=bool), done)
            for g in self._goals[2]:
                g.reset(ended)
            fresh = self._info(slice(None))
            for k in ("time_ms", "steps", "pose"):
                info[k] = fresh[k]
            done = np.zeros(n, dtype=bool)
        self._autoreset = done
        return self._observe(), rewards, terms, truncs, info

    def render(self):
        """Top-down images of every sub-env (``render_mode="rgb_array"``), a tuple of (H, W, 3) uint8."""
        if self.render_mode != "rgb_array":
            return None
        return tuple(self.render_copy(i) for i in range(self.num_envs))

    def render_copy(self, i: int) -> np.ndarray:
        self._check_open()
        r = self._renderers.get(i)
        if r is None:
            r = self._renderers[i] = TopDown(self._view(i), self.render_size)
        return r.render()

    def close_extras(self, **kwargs) -> None:
        self._renderers.clear()
        self.sim = None      # type: ignore[assignment]  # the copies' scenes and arrays go with it

    def _check_open(self) -> None:
        if self.closed:
            raise RuntimeError("the environment is closed; build a new one")

    def sub_env(self, i: int) -> SubEnv:
        """Sub-environment ``i`` as a plain ``gymnasium.Env`` (see :class:`SubEnv`)."""
        if not 0 <= i < self.num_envs:
            raise IndexError(f"sub-env {i} outside [0, {self.num_envs - 1}]")
        return SubEnv(self, i)

    # the one-copy paths the SubEnv view uses
    def _reset_one(self, i: int, seed: int | None):
        self._check_open()
        mask = np.zeros(self.num_envs, dtype=bool)
        mask[i] = True
        self._begin_reset(np.array([i]), [seed])
        self._run(np.zeros(self.num_envs, dtype=bool), mask)
        for g in self._goals[2]:
            g.reset(np.array([i]))
        self._autoreset[i] = False
        return self._last_obs_of(i), {k: v[0] for k, v in self._info(np.array([i])).items()}

    def _step_one(self, i: int, action):
        self._check_open()
        if self._needs_reset[i]:
            raise RuntimeError("call reset() before step()")
        mask = np.zeros(self.num_envs, dtype=bool)
        mask[i] = True
        copies = np.array([i])
        self._act(copies, np.asarray(action)[None])
        self._run(mask, np.zeros(self.num_envs, dtype=bool))
        self.steps[i] += 1
        r, te, tr = self._outcome(copies)
        info = {k: v[0] for k, v in self._info(copies).items()}
        return self._last_obs_of(i), float(r[0]), bool(te[0]), bool(tr[0]), info


class SubEnv(gym.Env):
    """Sub-environment ``i`` of a :class:`SensoriumVectorEnv` as a ``gymnasium.Env``: ``reset`` and
    ``step`` act on that copy alone (the others stay where they are), with the single
    environment's semantics (no autoreset)."""

    def __init__(self, venv: SensoriumVectorEnv, i: int):
        self.venv, self.index = venv, i
        self.observation_space = venv.single_observation_space
        self.action_space = venv.single_action_space
        self.render_mode = venv.render_mode
        self.metadata = {"render_modes": ["rgb_array"], "render_fps": 30}
        # the registered single environment's spec (what a sub-env is), for tools that remake it
        self.spec = gym.spec(venv.spec.id) if venv.spec is not None else None

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        return self.venv._reset_one(self.index, seed)

    def step(self, action):
        return self.venv._step_one(self.index, action)

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        return self.venv.render_copy(self.index)

