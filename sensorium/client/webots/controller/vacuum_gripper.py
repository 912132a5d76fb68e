"""Webots' ``VacuumGripper`` class (listed, not simulated: nothing is picked up without physics)."""

from __future__ import annotations

from .unsimulated import UnsimulatedDevice


class VacuumGripper(UnsimulatedDevice):
    _KIND = "VacuumGripper"
    _NO_VALUES = {"enablePresence": None, "disablePresence": None, "getPresenceSamplingPeriod": 0,
                  "getPresence": False, "turnOn": None, "turnOff": None, "isOn": False}
    _PROPERTIES = {"presence": "getPresence", "presence_sampling_period": "getPresenceSamplingPeriod", "on": "isOn"}
