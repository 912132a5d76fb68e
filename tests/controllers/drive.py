"""Webots-style test controller: drive with both wheels in velocity control, then print the time.

    drive.py STEPS LEFT_SPEED RIGHT_SPEED [SWITCH_AT LEFT2 RIGHT2]

Speeds in rad/s; after SWITCH_AT steps the wheels change to LEFT2/RIGHT2 (a turn).
"""

import sys

from controller import Motor, Robot

steps = int(sys.argv[1])
speeds = [float(v) for v in sys.argv[2:4]]
switch_at, later = (int(sys.argv[4]), [float(v) for v in sys.argv[5:7]]) if len(sys.argv) > 4 else (None, None)
robot = Robot()
wheels = [robot.getDevice("left wheel motor"), robot.getDevice("right wheel motor")]
assert all(isinstance(w, Motor) for w in wheels)
for wheel, speed in zip(wheels, speeds):
    wheel.setPosition(float("inf"))
    wheel.setVelocity(speed)
for n in range(steps):
    if n == switch_at:
        for wheel, speed in zip(wheels, later):
            wheel.setVelocity(speed)
    if robot.step() == -1:
        break
print(round(robot.getTime() * 1000), flush=True)
