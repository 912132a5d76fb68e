"""Scripted Python controller, the twin of tests/c/script.c (same ops, same output lines):

    script.py OP...   enable NAME PERIOD | disable NAME | pc NAME | nopc NAME | pos NAME RAD |
                      vel NAME RAD_S | step DURATION COUNT | sleep MS

A line per step: "T STATUS" then " NAME=<float64 bits, 16 hex>" per sensor enabled so far, or for a
lidar " NAME.range=<hex>" and, while its point cloud is enabled, " NAME.cloud=<hex>".
"""

import struct
import sys
import time

from sensorium.client import wb

wb.wb_robot_init()
seen: list[int] = []


def device(name: str) -> int:
    tag = wb.wb_robot_get_device(name)
    if tag == 0:
        sys.exit(f"script: no device {name!r}")
    return tag


def line(status: int) -> str:
    out = [f"{round(wb.wb_robot_get_time() * 1000)} {status}"]
    for tag in seen:
        name, kind = wb.wb_device_get_name(tag), wb.wb_device_get_type_name(tag)
        if kind == "Lidar":
            out.append(f"{name}.range={wb.lidar_range_bytes(tag).hex()}")
            if wb.wb_lidar_is_point_cloud_enabled(tag) and wb.wb_lidar_get_sampling_period(tag) > 0:
                out.append(f"{name}.cloud={wb.lidar_cloud_bytes(tag).hex()}")
        else:
            get = {"LightSensor": wb.wb_light_sensor_get_value,
                   "PositionSensor": wb.wb_position_sensor_get_value}.get(kind, wb.wb_distance_sensor_get_value)
            out.append(f"{name}={struct.unpack('<Q', struct.pack('<d', get(tag)))[0]:016x}")
    return " ".join(out)


ENABLE = {"LightSensor": (wb.wb_light_sensor_enable, wb.wb_light_sensor_disable),
          "DistanceSensor": (wb.wb_distance_sensor_enable, wb.wb_distance_sensor_disable),
          "Lidar": (wb.wb_lidar_enable, wb.wb_lidar_disable),
          "PositionSensor": (wb.wb_position_sensor_enable, wb.wb_position_sensor_disable)}
args = sys.argv[1:]
i = 0
while i < len(args):
    op = args[i]
    if op in ("enable", "disable"):
        tag = device(args[i + 1])
        on, off = ENABLE[wb.wb_device_get_type_name(tag)]
        if op == "enable":
            on(tag, int(args[i + 2]))
        else:
            off(tag)
        if tag not in seen:
            seen.append(tag)
        i += 3 if op == "enable" else 2
    elif op in ("pc", "nopc"):
        (wb.wb_lidar_enable_point_cloud if op == "pc" else wb.wb_lidar_disable_point_cloud)(device(args[i + 1]))
        i += 2
    elif op in ("pos", "vel"):
        (wb.wb_motor_set_position if op == "pos" else wb.wb_motor_set_velocity)(device(args[i + 1]), float(args[i + 2]))
        i += 3
    elif op == "sleep":
        time.sleep(int(args[i + 1]) / 1000)
        i += 2
    elif op == "step":
        duration, count = int(args[i + 1]), int(args[i + 2])
        for _ in range(count):
            status = wb.wb_robot_step(duration)
            print(line(status), flush=True)
            if status == -1:
                sys.exit(0)
        i += 3
    else:
        sys.exit(f"script: unknown op {op!r}")
wb.wb_robot_cleanup()
