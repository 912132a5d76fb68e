"""Webots' ``Receiver`` class: the packets that reached the receiver, head first (see
:mod:`sensorium.client.wb_radio`)."""

from __future__ import annotations

import struct
import sys

from sensorium.client import wb

from .device import Sensor


class Receiver(Sensor):
    CHANNEL_BROADCAST = wb.WB_CHANNEL_BROADCAST

    _enable = staticmethod(wb.wb_receiver_enable)
    _get_sampling_period = staticmethod(wb.wb_receiver_get_sampling_period)

    def getQueueLength(self) -> int:
        return wb.wb_receiver_get_queue_length(self._tag)

    def nextPacket(self) -> None:
        wb.wb_receiver_next_packet(self._tag)

    def getDataSize(self) -> int:
        return wb.wb_receiver_get_data_size(self._tag)

    def getBytes(self) -> bytes:
        data = wb.wb_receiver_get_data(self._tag)
        return b"" if data is None else data

    def getString(self) -> str:
        return self.getBytes().decode()

    def getData(self) -> str:
        print("DEPRECATION: Receiver.getData is deprecated, please use Receiver.getString instead.", file=sys.stderr)
        return self.getString()

    def getFloats(self) -> tuple[float, ...]:
        data = self.getBytes()
        return struct.unpack(f"{len(data) // 8}d", data[:len(data) // 8 * 8])

    def getInts(self) -> tuple[int, ...]:
        data = self.getBytes()
        return struct.unpack(f"{len(data) // 4}i", data[:len(data) // 4 * 4])

    def getBools(self) -> tuple[bool, ...]:
        data = self.getBytes()
        return struct.unpack(f"{len(data)}?", data)

    def getSignalStrength(self) -> float:
        return wb.wb_receiver_get_signal_strength(self._tag)

    def getEmitterDirection(self) -> list[float] | None:
        return wb.wb_receiver_get_emitter_direction(self._tag)

    def getChannel(self) -> int:
        return wb.wb_receiver_get_channel(self._tag)

    def setChannel(self, channel: int) -> None:
        wb.wb_receiver_set_channel(self._tag, channel)

    queue_length = property(getQueueLength)
    data = property(getBytes)
    data_size = property(getDataSize)
    string = property(getString)
    signal_strength = property(getSignalStrength)
    emitter_direction = property(getEmitterDirection)
    channel = property(getChannel, setChannel)
