"""``Device`` and ``Sensor``: the base classes of Webots' Python API, over a device tag."""

from __future__ import annotations

from collections.abc import Callable

from sensorium.client import wb


class Device:
    """A robot device, found by name (or given by tag)."""

    def __init__(self, name: str | int):
        if isinstance(name, int) and not isinstance(name, bool):
            tag = name
        else:
            tag = wb.wb_robot_get_device(str(name))
            if tag == 0:
                raise ValueError(f"robot {wb.wb_robot_get_name()!r} has no device {name!r}")
        self._tag = tag
        self._state = wb.current().device(tag, None, type(self).__name__)

    def getName(self) -> str:
        return self._state.name

    def getModel(self) -> str:
        return self._state.model

    def getNodeType(self) -> int:
        """Webots' node type (``Node.GPS``, ...)."""
        return self._state.node_type

    def getTag(self) -> int:
        return self._tag

    @property
    def name(self) -> str:
        return self._state.name

    @property
    def model(self) -> str:
        return self.getModel()

    @property
    def tag(self) -> int:
        return self._tag

    @property
    def node_type(self) -> int:
        return self._state.node_type

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self._state.name!r})"


class Sensor(Device):
    """A device with Webots' sampling period: ``enable(ms)``, ``disable()``, ``sampling_period``."""

    # each sensor class sets these to its wb_*_enable / wb_*_get_sampling_period
    _enable: Callable[[int, int], None]
    _get_sampling_period: Callable[[int], int]

    def __init__(self, name: str | int, sampling_period: int | None = None):
        """By name (``DistanceSensor("ds0")``), as Webots: enabled at ``sampling_period``, the basic
        time step by default; by tag (what ``Robot.getDevice`` does), only when a period is given."""
        super().__init__(name)
        if sampling_period is None and isinstance(name, str):
            sampling_period = int(wb.wb_robot_get_basic_time_step())
        if sampling_period is not None:
            self.enable(sampling_period)

    def enable(self, p: int) -> None:
        self._enable(self._tag, p)

    def disable(self) -> None:
        self._enable(self._tag, 0)

    def getSamplingPeriod(self) -> int:
        return self._get_sampling_period(self._tag)

    @property
    def sampling_period(self) -> int:
        return self.getSamplingPeriod()

    @sampling_period.setter
    def sampling_period(self, period: int | None) -> None:
        self._enable(self._tag, 0 if period is None else period)
