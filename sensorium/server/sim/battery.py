"""Robots' batteries and Webots' Chargers (README 'Battery and Charger').

Each basic step, first every Charger (WbCharger::prePhysicsStep, at the step's starting positions):
a full Charger takes the first robot with a 3-value battery whose position comes within its radius;
while it holds one (within 1.1 radius) it gives min(robot's recharge speed x dt, its energy) a step,
the robot's battery keeping at most its maximum (what is beyond is lost); an idle Charger gathers its
own upload speed x dt up to its maximum; the robot leaving empties it. Then every battery with energy
loses cpuConsumption x dt (WbRobot::postPhysicsStep), stopping at 0. A battery emptying powers its
robot off (WbRobot::powerOn(false)) until a Charger gives it energy (Battery.powered), or a Supervisor
writes some that outlasts a step's drain. Energies in J, powers in W, the step in integer ms."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sensorium.schemas import world as wm

_CONTACT_TOLERANCE = 1.1      # Webots keeps a charging robot within 1.1 x radius


@dataclass(eq=False)
class Battery:
    """A robot's battery: ``energy`` (J; NaN: no battery), ``maximum`` (J) and ``speed`` (W, the
    recharge speed a Charger gives; NaN when the world gives fewer than three values)."""

    energy: float
    maximum: float
    speed: float
    cpu: float
    initial: float
    powered: bool = True    # Webots' mPowerOn: off only once a step empties the battery (a robot
                            # loaded with 0 J is on), on again when a Charger gives it energy
    gained: float = 0.0     # J a Charger gave it in the last step (its topic says "charging" then)

    @classmethod
    def from_model(cls, robot: wm.Robot) -> Battery:
        b = [*robot.battery, math.nan, math.nan, math.nan]
        return cls(float(b[0]), float(b[1]), float(b[2]), float(robot.cpu_consumption), float(b[0]))

    def reset(self) -> None:
        self.energy, self.powered, self.gained = self.initial, True, 0.0

    @property
    def state(self) -> str:
        """What the battery does now: ``full`` (at its maximum), ``charging`` (a Charger gave it energy
        in the last step), ``discharging`` (it holds energy that cpuConsumption takes), else ``idle``."""
        if self.maximum > 0.0 and self.energy >= self.maximum:
            return "full"
        if self.gained > 0.0:
            return "charging"
        if self.energy > 0.0 and self.cpu > 0.0:
            return "discharging"
        return "idle"

    def power_back(self) -> None:
        """A robot off whose battery holds energy again (a Charger's) powers on."""
        if self.energy > 0.0:
            self.powered = True

    @property
    def present(self) -> bool:
        return not math.isnan(self.energy)

    @property
    def chargeable(self) -> bool:
        return not math.isnan(self.speed)

    def drain(self, dt_ms: int) -> bool:
        """One step's consumption; True when the battery became empty in it."""
        if not self.energy > 0.0:
            return False
        self.energy -= self.cpu * dt_ms * 0.001
        if self.energy <= 0.0:
            self.energy, self.powered = 0.0, False
            return True
        self.powered = True     # energy left: on (a Supervisor's refill of a robot off; WbRobot::setCurrentEnergy)
        return False


@dataclass(eq=False)
class Charger:
    solid: str
    radius: float
    energy: float
    maximum: float
    speed: float
    initial: float
    robot: int | None = None       # the index of the robot it charges
    done: bool = True              # that robot's battery is full: what the Charger still gives is lost
    emissive: tuple[float, float, float] = (0.0, 1.0, 0.0)
    gradual: bool = True
    glow_shapes: int = 0           # how many of its solid's first shapes glow with its energy
    glow_lights: int = 0           # how many of its solid's first lights take that colour
    glow_solids: int = 0           # how many of its solid's first children glow, all their shapes and lights

    @classmethod
    def from_model(cls, c: wm.Charger) -> Charger | None:
        """None when its battery has fewer than three values (Webots' Charger then does nothing)."""
        if len(c.battery) < 3:
            return None
        e, m, s = (float(v) for v in c.battery)
        return cls(c.solid, float(c.radius), e, m, s, e, emissive=tuple(float(v) for v in c.emissive_color),  # type: ignore[arg-type]
                   gradual=c.gradual, glow_shapes=c.glow_shapes, glow_lights=c.glow_lights, glow_solids=c.glow_solids)

    def glow(self, initial: tuple[float, float, float]) -> tuple[float, float, float]:
        """The emissive colour of a glowing shape (or the colour of a light) whose own is ``initial``
        (WbCharger::updateMaterialsAndLights, one rule for both):
        ``emissive`` when full; else, ``gradual``, ``initial + (emissive − initial)·E/Emax``, or ``initial``."""
        if self.energy >= self.maximum:          # (a maximum of 0: full)
            return self.emissive
        if not self.gradual:
            return initial
        r = self.energy / self.maximum
        return tuple((e - i) * r + i for e, i in zip(self.emissive, initial))  # type: ignore[return-value]

    def reset(self) -> None:
        self.energy, self.robot, self.done = self.initial, None, True

    def _contact(self, index: int, battery: Battery, offset: np.ndarray) -> None:
        if self.robot is not None and self.robot != index:
            return                                    # busy with another robot
        reach = self.radius * (_CONTACT_TOLERANCE if self.robot is not None else 1.0)
        if float(offset @ offset) > reach * reach:
            if self.robot == index:                   # leaving: the Charger is emptied
                self.energy = 0.0
            self.robot, self.done = None, True
        elif self.robot is None and self.energy == self.maximum:
            self.robot, self.done = index, False

    def step(self, batteries: list[Battery], positions: np.ndarray, own: np.ndarray, dt_ms: int) -> None:
        """One step: ``positions`` (n, 3) the robots' positions, ``own`` its position (same frame)."""
        for i, b in enumerate(batteries):
            self._contact(i, b, own - positions[i])
        held = batteries[self.robot] if self.robot is not None else None
        if held is None or not held.chargeable:
            self.energy = min(self.energy + self.speed * dt_ms * 0.001, self.maximum)
            return
        given = min(held.speed * dt_ms * 0.001, self.energy)
        self.energy -= given
        if self.done:
            return
        if held.energy > held.maximum:                # a battery above its maximum takes nothing
            self.done = True
            return
        held.energy += given
        held.gained += given
        if held.energy > held.maximum:
            held.energy, self.done = held.maximum, True
