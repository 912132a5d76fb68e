"""A plain Braitenberg vehicle for the e-puck of the arena world, written as a Webots controller.

    sensorium serve arena &
    sensorium controller example:braitenberg --robot epuck [STEPS]

The light sensors ls0 (forward-left) and ls1 (forward-right) drive the opposite wheels harder
(vehicle 2b, "aggression": it turns toward the light), and the eight infra-red proximity sensors
ps0..ps7 push it away from obstacles. It never slows down: it turns toward the brightest light it
sees and drives past it, which is what this vehicle does. The demo's e-puck runs
``light_follower.py`` instead, which looks around, drives to the lamp and stops there. This one
is kept minimal on purpose: tests/c/braitenberg.c and braitenberg_cpp.cpp port it line by line
and must print exactly what it prints.
"""

import sys

from controller import Robot

MAX_SPEED = 6.28                 # rad/s, the e-puck's wheel limit
LIGHT_GAIN = 4.0                 # wheel speed per unit of normalised light difference
IR_THRESHOLD = 150.0             # raw IR reading above which something is close
# how much each proximity sensor brakes (+) or boosts (-) the left and right wheels (ps0..ps7)
IR_WEIGHTS_LEFT = (-1.0, -0.8, -0.4, 0.0, 0.0, 0.4, 0.8, 1.0)
IR_WEIGHTS_RIGHT = (1.0, 0.8, 0.4, 0.0, 0.0, -0.4, -0.8, -1.0)

robot = Robot()
timestep = int(robot.getBasicTimeStep())
max_steps = int(sys.argv[1]) if len(sys.argv) > 1 else None

eyes = [robot.getDevice(name) for name in ("ls0", "ls1")]
proximity = [robot.getDevice(f"ps{i}") for i in range(8)]
for sensor in eyes + proximity:
    sensor.enable(timestep)

# ---- motors (looked up softly, so the controller still runs on a robot without a drive)
left_motor = robot.devices.get("left wheel motor")
right_motor = robot.devices.get("right wheel motor")
for motor in (left_motor, right_motor):
    if motor is not None:
        motor.setPosition(float("inf"))      # velocity control
        motor.setVelocity(0.0)


def wheel_speeds(light_left, light_right, ir):
    """Crossed excitatory light coupling plus obstacle avoidance; speeds clipped to MAX_SPEED."""
    total = light_left + light_right
    if total > 0:
        left = 0.5 * MAX_SPEED + LIGHT_GAIN * (light_right - light_left) / total
        right = 0.5 * MAX_SPEED + LIGHT_GAIN * (light_left - light_right) / total
    else:
        left = right = 0.5 * MAX_SPEED                        # darkness: cruise
    for value, wl, wr in zip(ir, IR_WEIGHTS_LEFT, IR_WEIGHTS_RIGHT):
        if value == value and value > IR_THRESHOLD:           # skip NaN (no reading yet)
            push = (value - IR_THRESHOLD) / 1000.0 * MAX_SPEED
            left += wl * push
            right += wr * push
    clip = lambda v: max(-MAX_SPEED, min(MAX_SPEED, v))  # noqa: E731
    return clip(left), clip(right)


step = 0
while robot.step(timestep) != -1:
    light = [eye.getValue() for eye in eyes]
    ir = [sensor.getValue() for sensor in proximity]
    left, right = wheel_speeds(light[0], light[1], ir)
    print(f"t={robot.getTime():7.3f}  ls0={light[0]:8.2f} ls1={light[1]:8.2f}  "
          f"ps=[{' '.join(f'{v:6.1f}' for v in ir)}]  wheels {left:+5.2f} {right:+5.2f} rad/s", flush=True)
    if left_motor is not None and right_motor is not None:
        left_motor.setVelocity(left)
        right_motor.setVelocity(right)
    step += 1
    if max_steps is not None and step >= max_steps:
        break
