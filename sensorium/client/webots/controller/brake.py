"""Webots' ``Brake`` class (listed, not simulated: no joint has a brake here)."""

from __future__ import annotations

from sensorium.client import wb

from .unsimulated import UnsimulatedDevice


class Brake(UnsimulatedDevice):
    ROTATIONAL = wb.WB_ROTATIONAL
    LINEAR = wb.WB_LINEAR
    _KIND = "Brake"
    _NO_VALUES = {"setDampingConstant": None, "getType": 0, "getMotor": None, "getPositionSensor": None}
    _PROPERTIES = {"type": "getType", "motor": "getMotor", "position_sensor": "getPositionSensor"}
