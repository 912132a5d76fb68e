"""``SensoriumParallelEnv``: several robots of one world as a PettingZoo ``ParallelEnv``.

    env = SensoriumParallelEnv("sensorium/worlds/arena.yaml",
                               {"epuck": Task(reward=ReachLight("lamp")), "scout": Task(observations=["lidar"])})
    obs, infos = env.reset(seed=0)
    obs, rewards, terms, truncs, infos = env.step({a: env.action_space(a).sample() for a in env.agents})

Every agent is a robot with a differential drive, a car-like robot (an ackermann drive), a mecanum
robot (four wheel speeds) or an omni-wheel robot (a speed per wheel) and its own :class:`~sensorium.gym.task.Task`
(spaces as in :class:`~sensorium.gym.env.SensoriumEnv`); all act every control period, which must
be the same for all. An agent that terminates or truncates leaves ``agents`` and its robot stops;
the world keeps running for the others. Resets are exact as in the single-agent environment.

``engine`` as :class:`~sensorium.gym.env.SensoriumEnv`: ``"batched"`` runs the world on the
batched simulation of the vector environment (one copy: a reset reuses the built scene; ``sim`` is
a view of that copy, :mod:`sensorium.gym.views`), ``"simulation"`` rebuilds a
:class:`~sensorium.server.sim.simulation.Simulation` per reset (every device kind; ``sim`` is it),
``"auto"`` (the default) the first when it simulates everything observed. Both give the same
episodes bit for bit (tested).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from gymnasium.utils import seeding
from pettingzoo import ParallelEnv

from sensorium.gym.env import DEFAULT_PRECISION, Agent, batched_engine, check_precision, has_drive, load, rebuild
from sensorium.gym.render import TopDown, TopDownRendering, check_render_size
from sensorium.gym.task import Task
from sensorium.gym.views import CopySim
from sensorium.schemas import world as wm
from sensorium.server.world.loader import LoadedWorld

__all__ = ["SensoriumParallelEnv"]


class SensoriumParallelEnv(TopDownRendering, ParallelEnv):
    metadata = {"render_modes": ["rgb_array"], "name": "sensorium_parallel_v0", "render_fps": 30}

    def __init__(self, world: str | Path | LoadedWorld | wm.World | None = None,
                 tasks: Mapping[str, Task] | None = None, render_mode: str | None = None,
                 precision: str = DEFAULT_PRECISION, render_size: int = 256, actions: str = "normalized",
                 engine: str = "auto"):
        self.loaded = load(world)
        if tasks is None:
            tasks = {r.name: Task(robot=r.name) for r in self.loaded.world.robots if has_drive(r)}
        if not tasks:
            raise ValueError(f"{self.loaded.source}: no robot with a differential_drive, an ackermann_drive, a "
                             "mecanum_drive or an omni_drive to act as an agent")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be one of {self.metadata['render_modes']} or None, got {render_mode!r}")
        self.render_mode = render_mode
        self.precision = precision = check_precision(precision)
        self.render_size = check_render_size(render_size)
        self._agents = {name: Agent(self.loaded, task, default_robot=name, actions=actions) for name, task in tasks.items()}
        for name, ag in self._agents.items():
            if ag.robot != name:
                raise ValueError(f"agent {name!r}: its task names robot {ag.robot!r}; agents are named after their robot")
        periods = {ag.control_period_ms for ag in self._agents.values()}
        if len(periods) != 1:
            raise ValueError(f"every agent must act at the same control period, got {sorted(periods)} ms")
        self.control_period_ms = periods.pop()
        self.steps_per_action = self.control_period_ms // self.loaded.world.world_info.basic_time_step
        self.possible_agents = list(self._agents)
        self.agents: list[str] = []
        self.observation_spaces = {a: ag.observation_space for a, ag in self._agents.items()}
        self.action_spaces = {a: ag.action_space for a, ag in self._agents.items()}
        self.sim: Any = None
        self._batched = batched_engine(self.loaded, list(self._agents.values()), precision, engine)
        self.engine = "batched" if self._batched is not None else "simulation"
        self.steps = 0
        self._rng, _ = seeding.np_random()
        self._renderer: TopDown | None = None

    def observation_space(self, agent: str):
        return self.observation_spaces[agent]

    def action_space(self, agent: str):
        return self.action_spaces[agent]

    def reset(self, seed: int | None = None, options: dict | None = None):
        if seed is not None:
            self._rng, _ = seeding.np_random(seed)
        world_seed = int(self._rng.integers(0, 2**62))
        if self._batched is not None:           # the built scene, that copy as new (nothing rebuilt)
            self._batched.reset([0], [world_seed])
            self.sim = sim = CopySim(self._batched, 0)
        else:
            self.sim = sim = rebuild(self.loaded, world_seed, self.precision)
        for ag in self._agents.values():
            ag.start(sim, self._rng)
        sim.run(max(ag.warmup_steps for ag in self._agents.values()))
        for ag in self._agents.values():
            ag.reset_callables(sim)
        self.steps = 0
        self.agents = list(self.possible_agents)
        self._renderer = None
        obs = {a: self._agents[a].observe(sim) for a in self.agents}
        return obs, {a: self._agents[a].info(sim, 0) for a in self.agents}

    def step(self, actions: Mapping[str, np.ndarray]):
        if self.sim is None:
            raise RuntimeError("call reset() before step()")
        for a in actions:           # a misspelt agent's action would be dropped unseen
            if a not in self._agents:
                raise ValueError(f"an action for {a!r}, which is not an agent (agents: {', '.join(self.possible_agents)})")
        for a in self.agents:
            if a not in actions:
                raise ValueError(f"no action for agent {a!r} (agents: {', '.join(self.agents)})")
            self._agents[a].act(self.sim, actions[a])
        self.sim.run(self.steps_per_action)
        self.steps += 1
        obs, rewards, terms, truncs, infos = {}, {}, {}, {}, {}
        for a in self.agents:
            ag = self._agents[a]
            obs[a] = ag.observe(self.sim)
            rewards[a], terms[a], truncs[a] = ag.outcome(self.sim, obs[a], self.steps)
            infos[a] = ag.info(self.sim, self.steps)
        for a in list(self.agents):
            if terms[a] or truncs[a]:
                self._agents[a].act(self.sim, np.zeros(self._agents[a].n_actions))   # a finished robot stops where it is
                self.agents.remove(a)
        return obs, rewards, terms, truncs, infos
