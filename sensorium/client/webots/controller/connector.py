"""Webots' ``Connector`` class: the presence of a peer connector, read with the step, and the lock
state the server holds (nothing is physically joined: no physics)."""

from __future__ import annotations

from sensorium.client import wb

from .device import Device


class Connector(Device):
    def enablePresence(self, sampling_period: int) -> None:
        wb.wb_connector_enable_presence(self._tag, sampling_period)

    def disablePresence(self) -> None:
        wb.wb_connector_disable_presence(self._tag)

    def getPresenceSamplingPeriod(self) -> int:
        return wb.wb_connector_get_presence_sampling_period(self._tag)

    def getPresence(self) -> int:
        """1: a peer in position, 0: none, -1: passive (or no value yet)."""
        return wb.wb_connector_get_presence(self._tag)

    def lock(self) -> None:
        wb.wb_connector_lock(self._tag)

    def unlock(self) -> None:
        wb.wb_connector_unlock(self._tag)

    def isLocked(self) -> bool:
        return wb.wb_connector_is_locked(self._tag)

    presence = property(getPresence)
    presence_sampling_period = property(getPresenceSamplingPeriod)
    locked = property(isLocked)
