"""The shape of a Webots device class whose device Sensorium lists but does not simulate: every
method of its table answers Webots' "no value" (NaN, ``None``, 0, False, an empty list) after the
device's one warning line (:meth:`sensorium.client.wb_robot.RobotClient.warn_unsimulated`)."""

from __future__ import annotations

import ast
import functools
import inspect
import re
from collections.abc import Callable
from typing import Any, ClassVar

from sensorium.client import wb
from sensorium.client.wb_robot import answers

from .device import Device


def _snake(name: str) -> str:
    return re.sub(r"(?<=[a-z0-9])([A-Z])", r"_\1", name).lower()


def signed(method: Callable[..., Any], params: str) -> Callable[..., Any]:
    """``method(self, *args, **kwargs)`` with Webots' parameters ``params`` (``"index, value=1"``):
    ``inspect.signature`` shows them, keywords by those names work, and a call that does not fit
    raises Python's ``TypeError`` before ``method`` runs, as Webots' method would."""
    parsed = ast.parse(f"def f(self, {params}): pass").body[0].args     # type: ignore[attr-defined]
    names = [a.arg for a in parsed.args]
    defaults = [ast.literal_eval(d) for d in parsed.defaults]
    first_default = len(names) - len(defaults)
    sig = inspect.Signature([inspect.Parameter(n, inspect.Parameter.POSITIONAL_OR_KEYWORD,
                                               default=defaults[i - first_default] if i >= first_default
                                               else inspect.Parameter.empty) for i, n in enumerate(names)])

    @functools.wraps(method)
    def call(*args: Any, **kwargs: Any) -> Any:
        bound = sig.bind(*args, **kwargs)
        bound.apply_defaults()
        return method(*bound.args)
    call.__signature__ = sig        # type: ignore[attr-defined]
    return call


def no_value_method(kind: str, name: str, answer: Any, params: str = "") -> Callable[..., Any]:
    """A method ``name(self, *args)`` of a ``kind`` device answering ``answer`` (its warning names
    the C function, as Webots' Python classes report through the C library)."""
    func = f"wb_{_snake(kind)}_{_snake(name)}"

    @answers(answer)
    def method(self: Device, *args: Any, **kwargs: Any) -> Any:
        wb.current().device(self._tag, kind, func)          # NoValue for a listed device
        return answer
    method.__name__ = method.__qualname__ = name
    return signed(method, params)


class UnsimulatedDevice(Device):
    """Base of the classes below: ``_KIND`` is the Webots node type, ``_NO_VALUES`` maps each
    Webots method name to its answer (a property name listed in ``_PROPERTIES`` reads the same)."""

    _KIND: ClassVar[str] = ""
    _NO_VALUES: ClassVar[dict[str, Any]] = {}
    _PROPERTIES: ClassVar[dict[str, str]] = {}       # property -> the getter it reads
    _PARAMS: ClassVar[dict[str, str]] = {}           # method -> Webots' parameters ("index, absolute")

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        for name, answer in cls._NO_VALUES.items():
            if name not in cls.__dict__:
                setattr(cls, name, no_value_method(cls._KIND, name, answer, cls._PARAMS.get(name, "")))
        for prop, getter in cls._PROPERTIES.items():
            setattr(cls, prop, property(getattr(cls, getter)))
