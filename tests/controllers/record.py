"""Webots-style test controller: enable devices, step, print every reading bit-exactly.

    record.py DURATION STEPS NAME:PERIOD[:pc] ...

One JSON line per step: {"t": time_ms, "status": s, "values": {name: {...}}} with floats as
float.hex() and lidar buffers as hex strings, so the test can compare them bit for bit.
"""

import json
import sys

from controller import DistanceSensor, Lidar, LightSensor, Robot

duration, steps = int(sys.argv[1]), int(sys.argv[2])
robot = Robot()
devices = {}
for spec in sys.argv[3:]:
    name, period, *flags = spec.split(":")
    dev = robot.getDevice(name)
    dev.enable(int(period))
    if "pc" in flags:
        dev.enablePointCloud()
    devices[name] = dev


def reading(dev):
    if isinstance(dev, Lidar):
        out = {"range": dev.getRangeImage(data_type="buffer").hex()}
        if dev.isPointCloudEnabled():
            out["cloud"] = dev.getPointCloud(data_type="buffer").hex()
        return out
    assert isinstance(dev, (LightSensor, DistanceSensor))
    return {"value": dev.getValue().hex()}


for _ in range(steps):
    status = robot.step(duration)
    print(json.dumps({"t": round(robot.getTime() * 1000), "status": status,
                      "values": {name: reading(dev) for name, dev in devices.items()}}), flush=True)
    if status == -1:
        break
