"""Flat-API (wb_*) test controller: step until the end (or STEPS), printing "time_ms status value".

    SENSORIUM_CONTROLLER_URL=... python stepper.py DURATION STEPS DEVICE
STEPS 0 means until the simulation ends (status -1).
"""

import sys

from sensorium.client.wb import (
    wb_distance_sensor_enable,
    wb_distance_sensor_get_value,
    wb_robot_cleanup,
    wb_robot_get_device,
    wb_robot_get_time,
    wb_robot_init,
    wb_robot_step,
)

duration, steps, device = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
wb_robot_init()
tag = wb_robot_get_device(device)
wb_distance_sensor_enable(tag, duration)
print("attached", flush=True)
n = 0
while True:
    status = wb_robot_step(duration)
    print(round(wb_robot_get_time() * 1000), status, wb_distance_sensor_get_value(tag), flush=True)
    n += 1
    if status == -1 or n == steps:
        break
wb_robot_cleanup()
