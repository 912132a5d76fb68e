"""Webots' ``Emitter`` class: ``send`` queues a packet for the next step (see :mod:`sensorium.client.wb_radio`)."""

from __future__ import annotations

import struct
import sys
from typing import Any

from sensorium.client import wb

from .device import Device


class Emitter(Device):
    CHANNEL_BROADCAST = wb.WB_CHANNEL_BROADCAST

    def send(self, message: Any, length: int | None = None) -> int:
        """Webots' forms: ``bytes`` (the first ``length`` bytes), ``str`` (UTF-8, no terminating
        NUL), a list or tuple of floats (packed as doubles) or ints (as 32-bit ints). 1 if queued,
        0 if the buffer is full."""
        if isinstance(message, (bytes, bytearray, memoryview)):
            return wb.wb_emitter_send(self._tag, bytes(message), len(message) if length is None else length)
        if isinstance(message, str):
            data = message.encode()
            return wb.wb_emitter_send(self._tag, data, len(data))
        if isinstance(message, (list, tuple)):
            if not message:
                print("Emitter.send(): empty list", file=sys.stderr)
                return 0
            # Webots tests float first, then int (a bool is an int there, packed as 'i')
            code = "d" if isinstance(message[0], float) else "i" if isinstance(message[0], int) else None
            if code is None:
                print(f"Emitter.send(): unsupported data type list: {type(message)}", file=sys.stderr)
                return 0
            data = struct.pack(f"{len(message)}{code}", *message)
            return wb.wb_emitter_send(self._tag, data, len(data))
        print(f"Emitter.send(): unsupported data type: {type(message)}", file=sys.stderr)
        return 0

    def getBufferSize(self) -> int:
        return wb.wb_emitter_get_buffer_size(self._tag)

    def getChannel(self) -> int:
        return wb.wb_emitter_get_channel(self._tag)

    def setChannel(self, channel: int) -> None:
        wb.wb_emitter_set_channel(self._tag, channel)

    def getRange(self) -> float:
        return wb.wb_emitter_get_range(self._tag)

    def setRange(self, range: float) -> None:  # noqa: A002 - Webots' parameter name
        wb.wb_emitter_set_range(self._tag, range)

    buffer_size = property(getBufferSize)
    channel = property(getChannel, setChannel)
    range = property(getRange, setRange)
