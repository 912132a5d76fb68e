"""Webots' ``wb_emitter_*`` and ``wb_receiver_*``, with libController's client-side rules:

* ``wb_emitter_send`` queues a packet (with the emitter's channel and range now) if it fits the
  emitter's ``bufferSize``; with each step request the queue's head leaves while the baud rate
  allows (``byte_rate × step duration`` more bytes per step), whole packets only.
* The server delivers packets with the step reply (PROTOCOL.md §3.6); a packet joins the
  receiver's queue if it fits the receiver's ``bufferSize``, else it is lost. ``get_data`` and
  friends read the head packet, ``next_packet`` drops it.
* Channels and ranges are the controller's own copies (sent with every packet); a receiver's
  channel is set on the server at once (it decides which packets the receiver hears).
"""

from __future__ import annotations

import math
import sys
from typing import Any

from sensorium.client.connection import ErrorCode, SensoriumError
from sensorium.client.wb_robot import (
    EMITTER,
    RECEIVER,
    DeviceState,
    current,
    integer,
    real,
    sensor_enable,
    sensor_period,
)


def _emitter(tag: int, func: str) -> DeviceState:
    return current().device(tag, EMITTER, func)


def _receiver(tag: int, func: str) -> DeviceState:
    return current().device(tag, RECEIVER, func)


def _allowed(dev: DeviceState, channel: int, func: str) -> bool:
    if integer(channel) is None or channel < -1:
        print(f"Error: {func}() called with an invalid channel={channel}. Please use a channel inside the range "
              "[-1,inf).", file=sys.stderr)
        return False
    allowed = dev.desc.get("allowed_channels") or []
    if allowed and channel not in allowed:
        print(f"Error: {func}() called with channel={channel}, which is not between allowed channels. Please use "
              "an allowed channel.", file=sys.stderr)
        return False
    return True


# ---------------------------------------------------------------------- emitter

def wb_emitter_send(tag: int, data: bytes | bytearray | memoryview, size: int | None = None) -> int:
    """Queue ``data[:size]`` (all of it by default); 1 if queued, 0 if the emitter's buffer is full
    or the packet is empty (Webots' message)."""
    dev = _emitter(tag, "wb_emitter_send")
    if not isinstance(data, (bytes, bytearray, memoryview)):
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"wb_emitter_send(): data must be bytes, got {type(data).__name__}")
    packet = bytes(data) if size is None else bytes(data)[:max(0, int(size))]
    if size is not None and (size < 1 or size > len(data)):
        print(f"Error: wb_emitter_send(): invalid size={size} argument.", file=sys.stderr)
        return 0
    if not packet:
        print("Error: wb_emitter_send(): invalid size=0 argument.", file=sys.stderr)
        return 0
    limit = int(dev.desc.get("buffer_size", -1))
    if limit != -1 and len(packet) > limit - dev.queue_bytes:
        return 0
    if not dev.queue:
        dev.bytes_to_send = 0.0                  # libController restarts the count with an empty queue
    dev.queue.append((packet, dev.channel, dev.range))
    dev.queue_bytes += len(packet)
    return 1


def wb_emitter_get_buffer_size(tag: int) -> int:
    return int(_emitter(tag, "wb_emitter_get_buffer_size").desc.get("buffer_size", -1))


def wb_emitter_set_channel(tag: int, channel: int) -> None:
    dev = _emitter(tag, "wb_emitter_set_channel")
    if _allowed(dev, channel, "wb_emitter_set_channel"):
        dev.channel = int(channel)


def wb_emitter_get_channel(tag: int) -> int:
    return _emitter(tag, "wb_emitter_get_channel").channel


def wb_emitter_set_range(tag: int, range: float) -> None:  # noqa: A002 - Webots' parameter name
    """-1 (or more than ``maxRange``) sets ``maxRange``; other negative values are refused."""
    dev = _emitter(tag, "wb_emitter_set_range")
    number = real(range)
    if number is None or (number < 0.0 and number != -1.0) or math.isnan(number):
        print(f"Error: wb_emitter_set_range(): invalid range={range} argument.", file=sys.stderr)
        return
    range = number
    cap = float(dev.desc.get("max_range", -1.0))
    if range == -1.0:
        dev.range = cap
    elif cap == -1.0:
        dev.range = float(range)
    else:
        dev.range = min(float(range), cap)


def wb_emitter_get_range(tag: int) -> float:
    return _emitter(tag, "wb_emitter_get_range").range


# ---------------------------------------------------------------------- receiver

def wb_receiver_enable(tag: int, sampling_period: int) -> None:
    sensor_enable(tag, RECEIVER, sampling_period, "wb_receiver_enable")


def wb_receiver_disable(tag: int) -> None:
    sensor_enable(tag, RECEIVER, 0, "wb_receiver_disable")


def wb_receiver_get_sampling_period(tag: int) -> int:
    return sensor_period(tag, RECEIVER, "wb_receiver_get_sampling_period")


def wb_receiver_set_channel(tag: int, channel: int) -> None:
    r = current()
    dev = _receiver(tag, "wb_receiver_set_channel")
    if channel == dev.channel or not _allowed(dev, channel, "wb_receiver_set_channel"):
        return
    channel = int(channel)
    r.device_set(dev, "set_channel", channel, "wb_receiver_set_channel")
    dev.channel = channel


def wb_receiver_get_channel(tag: int) -> int:
    return _receiver(tag, "wb_receiver_get_channel").channel


def wb_receiver_get_queue_length(tag: int) -> int:
    dev = _receiver(tag, "wb_receiver_get_queue_length")
    if dev.sampling_period <= 0:
        print("Error: wb_receiver_get_queue_length() called for a disabled device! Please use: wb_receiver_enable().",
              file=sys.stderr)
    return len(dev.queue)


def wb_receiver_next_packet(tag: int) -> None:
    dev = _receiver(tag, "wb_receiver_next_packet")
    if dev.queue:
        data = dev.queue.popleft()[0]
        dev.queue_bytes -= len(data)


def _head(tag: int, func: str) -> Any:
    dev = _receiver(tag, func)
    if not dev.queue:
        print(f"Error: {func}(): the receiver queue is empty.", file=sys.stderr)
        return None
    return dev.queue[0]


def wb_receiver_get_data_size(tag: int) -> int:
    head = _head(tag, "wb_receiver_get_data_size")
    return -1 if head is None else len(head[0])


def wb_receiver_get_data(tag: int) -> bytes | None:
    """The head packet's bytes; ``None`` when the queue is empty."""
    head = _head(tag, "wb_receiver_get_data")
    return None if head is None else head[0]


def wb_receiver_get_signal_strength(tag: int) -> float:
    """1/r² at the time the packet travelled (r: emitter-receiver distance, m)."""
    head = _head(tag, "wb_receiver_get_signal_strength")
    return math.nan if head is None else head[1]


def wb_receiver_get_emitter_direction(tag: int) -> list[float] | None:
    """Unit vector towards the emitter in the receiver frame; ``None`` when the queue is empty."""
    head = _head(tag, "wb_receiver_get_emitter_direction")
    return None if head is None else list(head[2])

