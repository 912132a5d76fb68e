"""Emitters, receivers and the medium between them, with Webots' timing (WbEmitter/WbReceiver).

A controller's packets come with its step request (the client paces them by the emitter's baud
rate and keeps Webots' ``bufferSize``, as libController does) and wait in the emitter's outbox.
At the next basic step, before anything moves, :meth:`Radio.forward` hands each packet to every
*enabled* receiver of another robot on the same medium and channel (Webots' prePhysicsStep); after
the motion, :meth:`Radio.deliver` keeps those within the emitter's range — infra-red ones also
within both cones and with no bounding object of a third party on the segment between the two
devices (rays) — and computes what the receiver reads (``server/devices/radio.py``) at the
end-of-step poses. A receiver hands its waiting packets to its controller whenever its sampling
period is due (the first time one period after ``enable``); the step reply carries them.

Queues are bounded whatever the clients do: an emitter's outbox and a receiver's queues hold at
most :data:`MAX_QUEUED_PACKETS` packets and :data:`MAX_QUEUED_BYTES` bytes; what would exceed
them is dropped and counted (``sim.counters["radio_dropped"]``).
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from sensorium.server.devices import radio as rmath
from sensorium.server.raycast.kinds import RayKind
from sensorium.server.sim.sensors import Device

__all__ = ["Emitter", "Receiver", "Radio", "Packet", "Received", "MAX_QUEUED_PACKETS", "MAX_QUEUED_BYTES"]

MAX_QUEUED_PACKETS = 16_384
MAX_QUEUED_BYTES = 4 << 20
OCCLUSION_ROUNDS = 8          # rays re-cast past the receiving robot's own shapes beyond two per shape
                              # (FAST's float32 may meet a surface again; then: blocked)


@dataclass(frozen=True, slots=True)
class Packet:
    """A packet as sent: its bytes and the emitter's channel when it was sent."""

    data: bytes
    channel: int


@dataclass(frozen=True, slots=True)
class Received:
    """A packet as a receiver reads it: bytes, signal strength, emitter direction (receiver frame)."""

    data: bytes
    signal_strength: float
    direction: tuple[float, float, float]

    def as_wire(self) -> dict:
        return {"data": self.data, "signal_strength": self.signal_strength, "direction": list(self.direction)}


class _Queue:
    """A bounded FIFO of packets (count and bytes)."""

    def __init__(self) -> None:
        self.items: list[Any] = []
        self.bytes = 0

    def push(self, item: Any, size: int) -> bool:
        if len(self.items) >= MAX_QUEUED_PACKETS or self.bytes + size > MAX_QUEUED_BYTES:
            return False
        self.items.append(item)
        self.bytes += size
        return True

    def take(self) -> list[Any]:
        out, self.items, self.bytes = self.items, [], 0
        return out

    def __len__(self) -> int:
        return len(self.items)


def _allowed_channel(config: Any, channel: int) -> int:
    """``channel`` if an emitter or receiver of ``config`` may use it: an integer >= -1 and, when the
    device lists ``allowed_channels``, one of them (else ValueError)."""
    if isinstance(channel, bool) or not isinstance(channel, (int, np.integer)) or channel < -1:
        raise ValueError(f"channel must be an integer >= -1, got {channel!r}")
    if config.allowed_channels and channel not in config.allowed_channels:
        raise ValueError(f"channel {channel} is not one of allowed_channels {list(config.allowed_channels)}")
    return int(channel)


class Emitter(Device):
    """Webots Emitter: ``send`` queues a packet for the next basic step (channel and range as they
    are now); ``channel`` and ``range`` are the emitter's current ones (a controller's packets carry
    its own, as libController's do)."""

    def __post_init__(self) -> None:
        super().__post_init__()
        c = self.config
        self.channel = int(c.channel)
        self.range = float(c.range)
        self.outbox = _Queue()
        self.dropped = 0

    def set_channel(self, channel: int) -> None:
        self.channel = _allowed_channel(self.config, channel)

    def set_range(self, range_m: float) -> None:
        """Webots' ``wb_emitter_set_range``: -1 asks for the maximum, larger values are capped at it."""
        if not isinstance(range_m, (int, float)) or isinstance(range_m, bool) or not (
                range_m == -1.0 or (math.isfinite(range_m) and range_m >= 0.0)):
            raise ValueError(f"range must be -1 or a finite number >= 0, got {range_m!r}")
        cap = float(self.config.max_range)
        self.range = cap if range_m == -1.0 else (float(range_m) if cap == -1.0 else min(float(range_m), cap))

    def send(self, data: bytes, channel: int | None = None, range_m: float | None = None) -> bool:
        """Queue a packet for the next basic step (``channel``/``range_m``: set first, as a
        controller's packet carries them). False (and counted) when the outbox bound is reached."""
        if channel is not None:
            self.set_channel(channel)
        if range_m is not None:
            self.set_range(range_m)
        data = bytes(data)
        if not data:
            raise ValueError("a packet must have at least 1 byte")
        if not self.outbox.push(Packet(data, self.channel), len(data)):
            self.dropped += 1
            return False
        return True

    def readings(self) -> dict:
        """What ``sensorium probe`` shows (numbers as floats, as other readings): the channel and
        range packets leave with now."""
        return {"channel": float(self.channel), "range": self.range}

    @property
    def byte_rate(self) -> float:
        """Bytes per millisecond the controller may send (Webots: baudRate / byteSize / 1000); -1: unlimited."""
        c = self.config
        return -1.0 if c.baud_rate == -1 else c.baud_rate / c.byte_size / 1000.0

    def describe(self) -> dict:
        c = self.config
        return {"medium": c.type, "channel": self.channel, "range": self.range, "max_range": float(c.max_range),
                "aperture": float(c.aperture), "buffer_size": int(c.buffer_size), "byte_rate": self.byte_rate,
                "allowed_channels": [int(v) for v in c.allowed_channels]}


class Receiver(Device):
    """Webots Receiver: while enabled it collects the packets the medium delivers (``waiting``);
    each time its sampling period is due they become ``ready`` for the controller (one
    measurement when any arrived). Disabling it empties both queues."""

    kinematic = True
    TYPES: ClassVar[tuple[str, ...]] = ("radio", "serial", "infra-red")

    def __post_init__(self) -> None:
        super().__post_init__()
        self.channel = int(self.config.channel)
        self.waiting = _Queue()
        self.ready = _Queue()
        self.dropped = 0

    def set_channel(self, channel: int) -> None:
        self.channel = _allowed_channel(self.config, channel)

    def disable(self) -> None:
        super().disable()
        self.waiting.take()
        self.ready.take()

    def enable(self, period_ms: int) -> None:
        super().enable(period_ms)
        if period_ms == 0:
            self.waiting.take()
            self.ready.take()

    def arrive(self, packet: Received) -> None:
        if not self.waiting.push(packet, len(packet.data)):
            self.dropped += 1

    def measure(self, now_ms: int) -> None:
        moved = False
        for p in self.waiting.take():
            if self.ready.push(p, len(p.data)):
                moved = True
            else:
                self.dropped += 1
        if moved:
            self._mark(now_ms)

    def take(self) -> list[Received]:
        """The packets ready for the controller, oldest first (they leave the receiver)."""
        return self.ready.take()

    @property
    def queue_length(self) -> int:
        return len(self.ready)

    def readings(self) -> dict:
        """What ``sensorium probe`` shows (the packets stay for the controller): how many are ready."""
        return {"queue_length": float(self.queue_length)}

    def step_reading(self) -> dict:
        return {"packets": [p.as_wire() for p in self.take()]}

    def describe(self) -> dict:
        c = self.config
        return {"medium": c.type, "channel": self.channel, "aperture": float(c.aperture),
                "buffer_size": int(c.buffer_size), "allowed_channels": [int(v) for v in c.allowed_channels],
                "signal_strength_noise": float(c.signal_strength_noise), "direction_noise": float(c.direction_noise)}


class Radio:
    """The medium of one world: every emitter and receiver, whatever robot carries it."""

    def __init__(self, emitters: list[Emitter], receivers: list[Receiver], scene: Any, counters: Counter):
        self.emitters = emitters
        self.receivers = receivers
        self.scene = scene
        self.counters = counters
        self._in_flight: list[tuple[Packet, Emitter, Receiver]] = []
        self._own_shapes: dict[int, int] = {}     # robot index -> its shapes in the scene (counted once)

    def __bool__(self) -> bool:
        return bool(self.emitters)              # (packets leave an emitter even when nobody listens)

    def reset(self) -> None:
        """Webots' simulation reset: queued and travelling packets are gone."""
        self._in_flight = []
        for e in self.emitters:
            e.outbox.take()
        for r in self.receivers:
            r.waiting.take()
            r.ready.take()

    def forward(self) -> None:
        """Before the motion: each queued packet goes to the enabled receivers of other robots on
        the emitter's medium and the packet's channel (Webots' prePhysicsStep)."""
        flight = self._in_flight
        for e in self.emitters:
            if not e.outbox:
                continue
            medium = e.config.type
            listeners = [r for r in self.receivers if r.enabled and r.robot_index != e.robot_index
                         and r.config.type == medium]
            for p in e.outbox.take():
                for r in listeners:
                    if rmath.channels_match(p.channel, r.channel):
                        flight.append((p, e, r))
        for r in self.receivers:
            self.counters["radio_dropped"] += r.dropped
            r.dropped = 0
        for e in self.emitters:
            self.counters["radio_dropped"] += e.dropped
            e.dropped = 0

    def deliver(self, poses: list) -> None:
        """After the motion: range (and, for infra-red, cones and line of sight) at the end-of-step
        poses; what each receiver reads is computed then (Webots' postPhysicsStep)."""
        if not self._in_flight:
            return
        flight, self._in_flight = self._in_flight, []
        # each device's world pose once per step, as plain floats (a few packets cost no numpy calls)
        world: dict[int, tuple[list[float], list[list[float]]]] = {}

        def pose(d: Device) -> tuple[list[float], list[list[float]]]:
            p = world.get(id(d))
            if p is None:
                w = d.world_pose(poses[d.robot_index])
                p = world[id(d)] = (w.translation.tolist(), w.rotation.tolist())
            return p

        def x_axis(rotation: list[list[float]]) -> list[float]:
            return [rotation[0][0], rotation[1][0], rotation[2][0]]

        passed: list[tuple[Packet, Emitter, Receiver]] = []
        infra_red: list[tuple[Packet, Emitter, Receiver]] = []
        for t in flight:
            _, e, r = t
            (pe, re), (pr, rr) = pose(e), pose(r)
            if not rmath.within_range(pe, pr, e.range):
                continue
            if e.config.type != "infra-red":
                passed.append(t)
            elif (rmath.within_cone(pe, x_axis(re), pr, e.config.aperture)
                  and rmath.within_cone(pr, x_axis(rr), pe, r.config.aperture)):
                infra_red.append(t)
        if infra_red:
            clear = self._line_of_sight([(pose(e)[0], pose(r)[0], e.robot_index, r.robot_index)
                                         for _, e, r in infra_red])
            passed += [t for t, ok in zip(infra_red, clear) if ok]
            # in the order the packets were sent (Webots keeps it per receiver)
            order = {id(t): i for i, t in enumerate(flight)}
            passed.sort(key=lambda t: order[id(t)])
        for p, e, r in passed:
            pr, rr = pose(r)
            c = r.config
            noisy = c.direction_noise != 0.0 or c.signal_strength_noise != 0.0
            direction, strength = rmath.reception(
                rr, pr, pose(e)[0], direction_noise=c.direction_noise,
                signal_strength_noise=c.signal_strength_noise, rng=r.rng if noisy else None)
            r.arrive(Received(p.data, strength, direction))
        self.counters["radio_packets"] += len(passed)

    def _line_of_sight(self, segments: list[tuple[list[float], list[float], int, int]]) -> list[bool]:
        """Whether each emitter→receiver segment is free of bounding objects other than the two
        robots' own (Webots: the emitting and receiving robots never block). One batched cast per
        round; a ray stopped by the receiving robot's shapes is cast again from just past them."""
        n = len(segments)
        origin = np.array([s[0] for s in segments], dtype=np.float64)
        delta = np.array([s[1] for s in segments], dtype=np.float64) - origin
        length = np.sqrt(np.einsum("ij,ij->i", delta, delta))
        clear = [True] * n
        todo = [i for i in range(n) if length[i] > 0.0]
        start = np.zeros(n)
        engine, shapes = self.scene.engine, self.scene.shapes
        # a line enters and leaves each of the receiving robot's shapes once (convex ones): two casts
        # per shape may stop there before the receiver (a robot's shapes never change)
        for i in todo:
            robot = segments[i][3]
            if robot not in self._own_shapes:
                self._own_shapes[robot] = sum(1 for s in shapes if s.owner == robot)
        rounds = OCCLUSION_ROUNDS + 2 * max((self._own_shapes[segments[i][3]] for i in todo), default=0)
        for _ in range(rounds):
            if not todo:
                break
            idx = np.array(todo)
            dirs = delta[idx] / length[idx, None]
            hits = engine.cast(origin[idx], dirs, t_near=start[idx], t_far=length[idx], kind=RayKind.BOUNDING,
                               exclude_owner=np.array([segments[i][2] for i in todo], dtype=np.int64))
            self.counters["rays_radio"] += len(todo)
            again = []
            for k, i in enumerate(todo):
                t = float(hits.distance[k])
                if not t < length[i]:
                    continue                              # nothing before the receiver
                owner = shapes[int(hits.shape[k])].owner
                if owner == segments[i][3]:               # the receiving robot itself: look past it
                    start[i] = t + 1e-9 * max(1.0, length[i])
                    again.append(i)
                else:
                    clear[i] = False
            todo = again
        for i in todo:                                    # still inside the receiver's robot: blocked
            clear[i] = False
        return clear
