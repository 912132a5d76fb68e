"""Webots' ``Mouse`` and ``MouseState`` classes. A headless server has no pointer: no button is
pressed and the position is NaN."""

from __future__ import annotations

import math
from dataclasses import dataclass

from sensorium.client import wb


@dataclass
class MouseState:
    u: float = math.nan
    v: float = math.nan
    x: float = math.nan
    y: float = math.nan
    z: float = math.nan
    left: bool = False
    middle: bool = False
    right: bool = False


class Mouse:
    def __init__(self, sampling_period: int | None = None):
        """Enabled at ``sampling_period`` (the basic time step by default, as Webots); 0 leaves it off."""
        if sampling_period is None:
            sampling_period = int(wb.wb_robot_get_basic_time_step())
        if sampling_period:
            self.enable(sampling_period)

    def enable(self, p: int) -> None:
        wb.wb_mouse_enable(p)

    def disable(self) -> None:
        wb.wb_mouse_disable()

    def getSamplingPeriod(self) -> int:
        return wb.wb_mouse_get_sampling_period()

    def getState(self) -> MouseState:
        s = wb.wb_mouse_get_state()
        return MouseState(s.u, s.v, s.x, s.y, s.z, s.left, s.middle, s.right)

    def enable3dPosition(self) -> None:
        wb.wb_mouse_enable_3d_position()

    def disable3dPosition(self) -> None:
        wb.wb_mouse_disable_3d_position()

    def is3dPositionEnabled(self) -> bool:
        return wb.wb_mouse_is_3d_position_enabled()

    sampling_period = property(getSamplingPeriod, lambda self, p: self.enable(0 if p is None else p))
