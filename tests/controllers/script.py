"""Scripted Python controller, the twin of tests/c/script.c (same ops, same output lines; the format is
sensorium/schemas/conformance/README.md's):

    script.py OP...   enable NAME PERIOD | disable NAME | pc NAME | nopc NAME | pos NAME RAD |
                      vel NAME RAD_S | send NAME HEX | channel NAME C | range NAME M | next NAME |
                      step DURATION COUNT | sleep MS

A line per step: "T STATUS" then, per device used so far (in order of first use), " NAME=<float64 bits,
16 hex>[,<bits>...]" (a vector sensor's values in getter order), a lidar's " NAME.range=<hex>" and,
while its point cloud is enabled, " NAME.cloud=<hex>", an emitter's " NAME.sent=<1/0 per send since
the last line>", a receiver's " NAME=<queue length>" and, when it has one, ":<data hex>/<signal
bits>/<direction bits>" of its head packet.
"""

import struct
import sys
import time

from sensorium.client import wb

wb.wb_robot_init()
seen: list[int] = []
sent: dict[int, str] = {}


def device(name: str) -> int:
    tag = wb.wb_robot_get_device(name)
    if tag == 0:
        sys.exit(f"script: no device {name!r}")
    if tag not in seen:
        seen.append(tag)
        sent[tag] = ""
    return tag


def bits(values) -> str:
    return ",".join(f"{struct.unpack('<Q', struct.pack('<d', v))[0]:016x}" for v in values)


READ = {"LightSensor": lambda t: [wb.wb_light_sensor_get_value(t)],
        "DistanceSensor": lambda t: [wb.wb_distance_sensor_get_value(t)],
        "PositionSensor": lambda t: [wb.wb_position_sensor_get_value(t)],
        "Altimeter": lambda t: [wb.wb_altimeter_get_value(t)],
        "TouchSensor": lambda t: [wb.wb_touch_sensor_get_value(t)],
        "Compass": wb.wb_compass_get_values, "Accelerometer": wb.wb_accelerometer_get_values,
        "Gyro": wb.wb_gyro_get_values,
        "GPS": lambda t: [*wb.wb_gps_get_values(t), wb.wb_gps_get_speed(t), *wb.wb_gps_get_speed_vector(t)],
        "InertialUnit": lambda t: [*wb.wb_inertial_unit_get_roll_pitch_yaw(t), *wb.wb_inertial_unit_get_quaternion(t)]}


def receiver_item(tag: int) -> str:
    n = wb.wb_receiver_get_queue_length(tag)
    if n == 0:
        return "0"
    return (f"{n}:{wb.wb_receiver_get_data(tag).hex()}/{bits([wb.wb_receiver_get_signal_strength(tag)])}"
            f"/{bits(wb.wb_receiver_get_emitter_direction(tag))}")


def line(status: int) -> str:
    out = [f"{round(wb.wb_robot_get_time() * 1000)} {status}"]
    for tag in seen:
        name, kind = wb.wb_device_get_name(tag), wb.wb_device_get_type_name(tag)
        if kind == "Lidar":
            out.append(f"{name}.range={wb.lidar_range_bytes(tag).hex()}")
            if wb.wb_lidar_is_point_cloud_enabled(tag) and wb.wb_lidar_get_sampling_period(tag) > 0:
                out.append(f"{name}.cloud={wb.lidar_cloud_bytes(tag).hex()}")
        elif kind == "Emitter":
            out.append(f"{name}.sent={sent[tag]}")
            sent[tag] = ""
        elif kind == "Receiver":
            out.append(f"{name}={receiver_item(tag)}")
        else:
            out.append(f"{name}={bits(READ[kind](tag))}")
    return " ".join(out)


ENABLE = {"LightSensor": (wb.wb_light_sensor_enable, wb.wb_light_sensor_disable),
          "DistanceSensor": (wb.wb_distance_sensor_enable, wb.wb_distance_sensor_disable),
          "Lidar": (wb.wb_lidar_enable, wb.wb_lidar_disable),
          "PositionSensor": (wb.wb_position_sensor_enable, wb.wb_position_sensor_disable),
          "GPS": (wb.wb_gps_enable, wb.wb_gps_disable),
          "InertialUnit": (wb.wb_inertial_unit_enable, wb.wb_inertial_unit_disable),
          "Compass": (wb.wb_compass_enable, wb.wb_compass_disable),
          "Accelerometer": (wb.wb_accelerometer_enable, wb.wb_accelerometer_disable),
          "Gyro": (wb.wb_gyro_enable, wb.wb_gyro_disable),
          "Altimeter": (wb.wb_altimeter_enable, wb.wb_altimeter_disable),
          "TouchSensor": (wb.wb_touch_sensor_enable, wb.wb_touch_sensor_disable),
          "Receiver": (wb.wb_receiver_enable, wb.wb_receiver_disable)}
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
        i += 3 if op == "enable" else 2
    elif op in ("pc", "nopc"):
        (wb.wb_lidar_enable_point_cloud if op == "pc" else wb.wb_lidar_disable_point_cloud)(device(args[i + 1]))
        i += 2
    elif op in ("pos", "vel"):
        (wb.wb_motor_set_position if op == "pos" else wb.wb_motor_set_velocity)(
            wb.wb_robot_get_device(args[i + 1]), float(args[i + 2]))
        i += 3
    elif op == "send":
        tag = device(args[i + 1])
        sent[tag] += str(wb.wb_emitter_send(tag, bytes.fromhex(args[i + 2])))
        i += 3
    elif op == "channel":
        tag = device(args[i + 1])
        set_channel = wb.wb_emitter_set_channel if wb.wb_device_get_type_name(tag) == "Emitter" else wb.wb_receiver_set_channel
        set_channel(tag, int(args[i + 2]))
        i += 3
    elif op == "range":
        wb.wb_emitter_set_range(device(args[i + 1]), float(args[i + 2]))
        i += 3
    elif op == "next":
        wb.wb_receiver_next_packet(device(args[i + 1]))
        i += 2
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
