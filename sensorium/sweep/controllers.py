"""In-process controllers for sweeps.

A controller is a *factory* ``make(sim) -> step | None``: it is called once per run with the
fresh :class:`~sensorium.server.sim.simulation.Simulation` (enable devices, set motors there), and
the ``step(sim)`` it returns is called before every basic step (read devices, set wheel speeds).
Keep state in the closure: each run calls the factory anew, so runs never share state.

A spec names a controller as

* a built-in name: ``idle`` (nothing moves; the recorder still measures every recorded device),
  ``circle`` (every two-wheel or skid-steer robot drives a circle: left wheel at half, right at full speed),
  ``spin`` (every driven robot turns in place), ``braitenberg`` (every robot with light sensors
  ``ls0``/``ls1`` turns toward the light, proximity sensors ``ps0..ps7`` push it off walls);
* ``package.module:function``;
* ``path/to/file.py:function`` or ``path/to/file.py`` (the function named ``make``).
"""

from __future__ import annotations

import importlib
import importlib.util
import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from sensorium.server.sim.motion import DifferentialDrive

Step = Callable[[Any], None]
Factory = Callable[[Any], Step | None]

__all__ = ["BUILTIN", "resolve", "idle", "circle", "spin", "braitenberg"]


def _wheeled(robot) -> bool:
    """The built-ins drive two-wheel and skid-steer robots (a car's steering is left alone)."""
    return isinstance(robot.drive, DifferentialDrive)


def _velocity(robot, left: float, right: float) -> None:
    # every wheel of a side (a skid-steer robot has several; sim/motion.py rolls a side at their mean); a
    # side mounted mirrored (reversed_motors) is commanded negated, so that left and right roll forward
    drive = robot.drive
    for motors, v in ((drive.lefts, drive.left_sign * left), (drive.rights, drive.right_sign * right)):
        for motor in motors:
            motor.set_position(math.inf)
            motor.set_velocity(v)


def _top_speed(robot) -> float:
    # one speed both wheels reach (each wheel motor has its own maxVelocity): the smaller maximum
    return min(robot.drive.left.max_velocity, robot.drive.right.max_velocity)


def idle(sim) -> None:
    return None


def circle(sim) -> None:
    for robot in sim.robots.values():
        if _wheeled(robot):
            vmax = _top_speed(robot)
            _velocity(robot, 0.5 * vmax, vmax)
    return None


def spin(sim) -> None:
    for robot in sim.robots.values():
        if _wheeled(robot):
            vmax = _top_speed(robot)
            _velocity(robot, -0.5 * vmax, 0.5 * vmax)
    return None


def braitenberg(sim) -> Step:
    """Light seeking with obstacle avoidance for every driven robot that has ``ls0`` and ``ls1``."""
    dt = sim.basic_time_step
    crew = []
    for robot in sim.robots.values():
        if not _wheeled(robot) or not {"ls0", "ls1"} <= set(robot.devices):
            continue
        eyes = [robot.device("ls0"), robot.device("ls1")]
        ir = [robot.devices[f"ps{i}"] for i in range(8) if f"ps{i}" in robot.devices]
        for d in (*eyes, *ir):
            d.enable(dt)
        crew.append((robot, eyes, ir))
    weights = (-1.0, -0.8, -0.4, 0.0, 0.0, 0.4, 0.8, 1.0)

    def step(sim) -> None:
        for robot, (l0, l1), ir in crew:
            vmax = _top_speed(robot)
            a, b = l0.value, l1.value
            left = right = 0.5 * vmax
            if a == a and b == b and a + b > 0:           # NaN before the first measurement
                left += 0.5 * vmax * (b - a) / (a + b)
                right += 0.5 * vmax * (a - b) / (a + b)
            for dev, w in zip(ir, weights):
                v = dev.value
                if v == v and v > 150.0:
                    push = (v - 150.0) / 1000.0 * vmax
                    left += w * push
                    right -= w * push
            _velocity(robot, max(-vmax, min(vmax, left)), max(-vmax, min(vmax, right)))

    return step


BUILTIN: dict[str, Factory] = {"idle": idle, "circle": circle, "spin": spin, "braitenberg": braitenberg}


def resolve(ref: str | Factory) -> Factory:
    """The factory a spec's controller entry names (ValueError with the reason if it cannot)."""
    if callable(ref):
        return ref
    if ref in BUILTIN:
        return BUILTIN[ref]
    target, _, fn = ref.rpartition(":") if ":" in ref else (ref, "", "")
    if target.endswith(".py") or (not fn and ref.endswith(".py")):
        path = Path(target if target.endswith(".py") else ref)
        fn = fn or "make"
        if not path.is_file():
            raise ValueError(f"controller {ref!r}: no file {path}")
        name = f"_sensorium_sweep_controller_{abs(hash(str(path.resolve())))}"
        mod = sys.modules.get(name)
        if mod is None:
            spec = importlib.util.spec_from_file_location(name, path)
            assert spec is not None and spec.loader is not None
            mod = importlib.util.module_from_spec(spec)
            sys.modules[name] = mod
            try:
                spec.loader.exec_module(mod)
            except Exception as exc:
                del sys.modules[name]
                raise ValueError(f"controller {ref!r}: {path} failed to import: {type(exc).__name__}: {exc}") from None
    elif fn:
        try:
            mod = importlib.import_module(target)
        except ImportError as exc:
            raise ValueError(f"controller {ref!r}: cannot import {target}: {exc}") from None
    else:
        raise ValueError(f"controller {ref!r}: not a built-in ({', '.join(BUILTIN)}), 'module:function' "
                         "or 'file.py[:function]'")
    factory = getattr(mod, fn, None)
    if not callable(factory):
        raise ValueError(f"controller {ref!r}: {fn!r} is not a function of {getattr(mod, '__file__', target)}")
    return factory
