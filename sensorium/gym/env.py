"""``SensoriumEnv``: a Gymnasium environment over the in-process simulation.

    env = SensoriumEnv("sensorium/worlds/arena.yaml", Task(robot="epuck", reward=ReachLight(), ...))
    obs, info = env.reset(seed=1)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())

Observation: a ``Dict`` with one ``Box`` per observed device. A light or distance sensor is a
float32 ``(1,)`` box bounded by its lookup table's output column (values are clipped into it:
relative lookup noise is Gaussian and could leave it); a lidar is its float32 ``(layers,
width)`` range image bounded by ``[0, max_range]``, with "no hit" (``inf`` in Webots) given as
``max_range``. Action: float32 ``(2,)`` = left, right wheel velocity (rad/s), bounded by the
drive's max wheel speed. One action lasts ``control_period_ms``.

``reset(seed=s)`` rebuilds the simulation from the world model with world seed drawn from the
environment's generator seeded with ``s``: every device noise stream, the start pose drawn by
``Task.start`` and the clock restart exactly, so the same seed and actions give a bit-identical
episode. Before the first observation the simulation runs until every observed device has a value
(its longest sampling period), as a Webots controller would wait.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from sensorium.gym.render import TopDown
from sensorium.gym.task import Task
from sensorium.schemas import world as wm
from sensorium.server.sim.sensors import Lidar
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld, default_world_path, load_world

__all__ = ["SensoriumEnv", "load"]


def load(world: str | Path | LoadedWorld | wm.World | None) -> LoadedWorld:
    """A world file path, a loaded world or a world model (None: the embedded arena world)."""
    if world is None:
        return load_world(default_world_path())
    if isinstance(world, LoadedWorld):
        return world
    if isinstance(world, wm.World):
        return LoadedWorld(world=world, source="<memory>", base_dir=Path.cwd())
    return load_world(world)


class SensoriumEnv(gym.Env):
    metadata = {"render_modes": ["rgb_array"], "render_fps": 30}

    def __init__(self, world: str | Path | LoadedWorld | wm.World | None = None, task: Task | None = None,
                 render_mode: str | None = None, precision: str = "exact", render_size: int = 256):
        self.loaded = load(world)
        self.task = task or Task()
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be one of {self.metadata['render_modes']} or None, got {render_mode!r}")
        self.render_mode = render_mode
        self.precision = precision
        self.render_size = render_size
        w = self.loaded.world
        self.basic_time_step = w.world_info.basic_time_step
        robots = {r.name: r for r in w.robots}
        name = self.task.robot
        if name is None:
            driven = [r.name for r in w.robots if r.differential_drive is not None]
            if not driven:
                raise ValueError(f"{self.loaded.source}: no robot with a differential_drive to act as the agent")
            name = driven[0]
        if name not in robots:
            raise ValueError(f"{self.loaded.source}: task robot {name!r} not in the world (robots: {', '.join(robots)})")
        model = robots[name]
        if model.differential_drive is None:
            raise ValueError(f"{self.loaded.source}: task robot {name!r} has no differential_drive to act with")
        self.robot_name = name
        ctrl = self.task.control_period_ms or self.basic_time_step
        if ctrl <= 0 or ctrl % self.basic_time_step:
            raise ValueError(f"task control_period_ms={ctrl} must be a positive multiple of the world's "
                             f"basic_time_step ({self.basic_time_step} ms)")
        self.control_period_ms = int(ctrl)
        self.steps_per_action = ctrl // self.basic_time_step
        devices = {d.name: d for d in model.devices}
        obs = self.task.observations
        if obs is None:
            periods = {n: self.control_period_ms for n in devices}
        elif isinstance(obs, dict):
            periods = {str(k): int(v) for k, v in obs.items()}
        else:
            periods = {str(n): self.control_period_ms for n in obs}
        for n, p in periods.items():
            if n not in devices:
                raise ValueError(f"task observation {n!r}: robot {name!r} has no such device "
                                 f"(devices: {', '.join(devices) or 'none'})")
            if p <= 0:
                raise ValueError(f"task observation {n!r}: sampling period must be > 0 ms, got {p}")
        self.periods = periods
        self.observation_space = spaces.Dict({n: self._space(devices[n]) for n in periods})
        vmax = float(model.differential_drive.max_wheel_speed)
        self.action_space = spaces.Box(-vmax, vmax, shape=(2,), dtype=np.float32)
        self.sim: Simulation | None = None
        self.steps = 0
        self._renderer: TopDown | None = None

    # ---------------------------------------------------------------- spaces and observations
    @staticmethod
    def _space(cfg) -> spaces.Box:
        if cfg.device == "Lidar":
            return spaces.Box(0.0, np.float32(cfg.max_range), shape=(cfg.number_of_layers, cfg.horizontal_resolution),
                              dtype=np.float32)
        out = [row[1] for row in cfg.lookup_table] or [0.0]
        lo, hi = float(min(out)), float(max(out))
        return spaces.Box(np.float32(lo), np.float32(hi), shape=(1,), dtype=np.float32)

    def _observe(self) -> dict[str, np.ndarray]:
        robot = self.sim.robot(self.robot_name)
        out = {}
        for n, box in self.observation_space.spaces.items():
            dev = robot.device(n)
            if isinstance(dev, Lidar):
                img = np.nan_to_num(dev.range_image, nan=box.high.flat[0], posinf=box.high.flat[0])
                out[n] = np.clip(img, box.low, box.high).astype(np.float32)
            else:
                v = dev.value if math.isfinite(dev.value) else box.low[0]
                out[n] = np.clip(np.array([v], dtype=np.float32), box.low, box.high)
        return out

    def _info(self) -> dict[str, Any]:
        pose = self.sim.robot(self.robot_name).pose
        fwd = pose.rotation[:, 0]
        return {"time_ms": self.sim.time_ms, "steps": self.steps,
                "pose": np.array([pose.translation[0], pose.translation[1], math.atan2(fwd[1], fwd[0])])}

    # ---------------------------------------------------------------- gymnasium API
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        world_seed = int(self.np_random.integers(0, 2**62))
        w = self.loaded.world
        w = w.model_copy(update={"world_info": w.world_info.model_copy(update={"random_seed": world_seed})})
        loaded = LoadedWorld(world=w, source=self.loaded.source, base_dir=self.loaded.base_dir, text=self.loaded.text)
        self.sim = sim = Simulation(loaded, precision=self.precision)
        robot = sim.robot(self.robot_name)
        if self.task.start is not None:
            self.task.start(sim, robot, self.np_random)
        for m in robot.motors.values():
            m.set_position(math.inf)
            m.set_velocity(0.0)
        for n, p in self.periods.items():
            robot.device(n).enable(p)
        # run until every observed device has measured once (Webots: first value one period later)
        warmup = max(math.ceil(p / self.basic_time_step) for p in self.periods.values()) if self.periods else 0
        sim.run(warmup)
        self.steps = 0
        owners: list = []
        for fn in (self.task.reward, self.task.terminated):
            owner = fn if hasattr(fn, "reset") else getattr(fn, "__self__", None)
            if owner is not None and hasattr(owner, "reset") and not any(o is owner for o in owners):
                owners.append(owner)
                owner.reset(sim, robot)
        self._renderer = None
        return self._observe(), self._info()

    def step(self, action):
        if self.sim is None:
            raise RuntimeError("call reset() before step()")
        a = np.asarray(action, dtype=np.float64).reshape(-1)
        if a.shape != (2,) or not np.all(np.isfinite(a)):
            raise ValueError(f"action must be 2 finite wheel velocities (left, right), got {action!r}")
        robot = self.sim.robot(self.robot_name)
        drive = robot.drive
        drive.left.set_velocity(float(a[0]))
        drive.right.set_velocity(float(a[1]))
        self.sim.run(self.steps_per_action)
        self.steps += 1
        obs = self._observe()
        reward = float(self.task.reward(self.sim, robot, obs))
        terminated = bool(self.task.terminated(self.sim, robot, obs))
        truncated = self.task.max_steps is not None and self.steps >= self.task.max_steps and not terminated
        return obs, reward, terminated, bool(truncated), self._info()

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        if self.sim is None:
            raise RuntimeError("call reset() before render()")
        if self._renderer is None:
            self._renderer = TopDown(self.sim, self.render_size)
        return self._renderer.render()

    def close(self) -> None:
        self.sim = None
        self._renderer = None
