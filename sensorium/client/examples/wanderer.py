"""Obstacle-avoiding wanderer for the scout of worlds/arena.yaml, written as a Webots controller.

    sensorium serve worlds/arena.yaml &
    sensorium controller client/examples/wanderer.py --robot scout [STEPS]

A 360-degree one-layer lidar gives the free space ahead, left and right; four sonars watch the
close range. The controller picks a motion (forward, turn left/right, back up) each control
step, sets the two wheel motors accordingly and prints it with a summary of what it sees.
"""

import math
import sys

from controller import Robot

CONTROL_STEP = 64                # ms: twice the world's basic step, the lidar at the same rate
SAFE_DISTANCE = 0.5              # m: closer than this ahead means turn
SONAR_STOP = 0.25                # m: closer than this on a sonar means back away
CRUISE = 4.0                     # rad/s wheel speed

robot = Robot()
max_steps = int(sys.argv[1]) if len(sys.argv) > 1 else None

lidar = robot.getDevice("lidar")
lidar.enable(CONTROL_STEP)
sonars = {side: robot.getDevice(f"sonar_{side}") for side in ("front", "left", "right", "back")}
for sonar in sonars.values():
    sonar.enable(CONTROL_STEP)

resolution = lidar.getHorizontalResolution()
fov = lidar.getFov()

# ---- motors (looked up softly, so the controller still runs on a robot without a drive)
left_motor = robot.devices.get("left wheel motor")
right_motor = robot.devices.get("right wheel motor")
for motor in (left_motor, right_motor):
    if motor is not None:
        motor.setPosition(float("inf"))
        motor.setVelocity(0.0)


def sector(ranges, centre, half_width):
    """Nearest finite range among the rays within ``half_width`` rad of angle ``centre``
    (rays go left to right: ray 0 at +fov/2)."""
    nearest = math.inf
    for i, r in enumerate(ranges):
        angle = fov / 2 - i * fov / resolution
        delta = (angle - centre + math.pi) % (2 * math.pi) - math.pi
        if abs(delta) <= half_width and math.isfinite(r):
            nearest = min(nearest, r)
    return nearest


def decide(front, left, right, sonar):
    if min(sonar["front"], sonar["left"], sonar["right"]) < SONAR_STOP:
        return "back up", (-CRUISE, -0.5 * CRUISE)
    if front < SAFE_DISTANCE:
        return ("turn left", (-CRUISE, CRUISE)) if left > right else ("turn right", (CRUISE, -CRUISE))
    return "forward", (CRUISE, CRUISE)


step = 0
while robot.step(CONTROL_STEP) != -1:
    ranges = lidar.getRangeImage()
    front = sector(ranges, 0.0, math.radians(20))
    left = sector(ranges, math.pi / 2, math.radians(30))
    right = sector(ranges, -math.pi / 2, math.radians(30))
    sonar = {side: s.getValue() for side, s in sonars.items()}
    action, (wl, wr) = decide(front, left, right, sonar)
    print(f"t={robot.getTime():7.3f}  lidar front={front:5.2f} left={left:5.2f} right={right:5.2f}  "
          f"sonar {' '.join(f'{k}={v:4.2f}' for k, v in sonar.items())}  -> {action}", flush=True)
    if left_motor is not None and right_motor is not None:
        left_motor.setVelocity(wl)
        right_motor.setVelocity(wr)
    step += 1
    if max_steps is not None and step >= max_steps:
        break
