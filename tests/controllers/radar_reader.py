"""A Radar from Python (tests/worlds/radar.yaml), as an adaptive cruise control reads it: its range
and fields of view, then the targets after its first two values. The same sequence as
tests/c/radar_reader.c; prints values as the 16 hex digits of their float64 bits."""

import struct

from controller import Radar, Robot


def h(v: float) -> str:
    return f"{struct.unpack('<Q', struct.pack('<d', v))[0]:016x}"


robot = Robot()
radar = robot.getDevice("radar")
assert isinstance(radar, Radar)
print("fields", h(radar.getMinRange()), h(radar.getMaxRange()), h(radar.getHorizontalFov()), h(radar.getVerticalFov()))
radar.enable(32)
print("before", radar.getNumberOfTargets(), len(radar.getTargets()), radar.getSamplingPeriod())
for _ in range(2):
    robot.step(32)
    print("targets", radar.getNumberOfTargets())
    for t in radar.getTargets():
        print("target", h(t.distance), h(t.received_power), h(t.speed), h(t.azimuth))
