"""Webots' ``Connector`` class (listed, not simulated: nothing docks without physics)."""

from __future__ import annotations

from .unsimulated import UnsimulatedDevice


class Connector(UnsimulatedDevice):
    _KIND = "Connector"
    _NO_VALUES = {"enablePresence": None, "disablePresence": None, "getPresenceSamplingPeriod": 0,
                  "getPresence": -1, "lock": None, "unlock": None, "isLocked": False}
    _PROPERTIES = {"presence": "getPresence", "presence_sampling_period": "getPresenceSamplingPeriod",
                   "locked": "isLocked"}
