"""Python twin of tests/c/joints.c (same output lines) on tests/worlds/joints.yaml: joints.py STEPS.

One line of the motors' answers, then per step the float64 bits of the shoulder, wrist, lift and
left wheel sensors: the shoulder commanded to 2 rad (clamped to 0.5 with Webots' warning), the
wrist to -1 rad with acceleration 5, the lift from 0.005 to 0.01 m, the left wheel at 2 rad/s; then
a simulation reset and one more step: the lift's target and reading, back at 0.005."""

import math
import struct
import sys

from controller import Supervisor

robot = Supervisor()
steps = int(sys.argv[1]) if len(sys.argv) > 1 else 40
dt = int(robot.getBasicTimeStep())
shoulder, wrist, lift = robot.getDevice("shoulder"), robot.getDevice("wrist"), robot.getDevice("lift")
wheel = robot.getDevice("left wheel motor")
sensors = [m.getPositionSensor() for m in (shoulder, wrist, lift, wheel)]


def bits(name, v):
    return f"{name}={struct.unpack('<Q', struct.pack('<d', v))[0]:016x}"


print(" ".join(f"{v:g}" for v in (
    shoulder.getMinPosition(), shoulder.getMaxPosition(), shoulder.getMaxVelocity(), shoulder.getMaxTorque(),
    shoulder.getAvailableTorque(), shoulder.getAcceleration(), shoulder.getTargetPosition(), wrist.getMaxTorque(),
    lift.getMaxForce(), lift.getType(), shoulder.getType(), wheel.getMinPosition(), wheel.getMaxPosition())),
    flush=True)
for s in sensors:
    s.enable(dt)
shoulder.setPosition(2.0)
wrist.setAcceleration(5.0)
wrist.setPosition(-1.0)
lift.setPosition(0.01)
wheel.setPosition(math.inf)
wheel.setVelocity(2.0)
print(f"{shoulder.getTargetPosition():g} {wrist.getAcceleration():g}", flush=True)
for _ in range(steps):
    status = robot.step(dt)
    print(f"{round(robot.getTime() * 1000)} {status} " + " ".join(
        bits(n, s.getValue()) for n, s in zip(("shoulder", "wrist", "lift", "wheel"), sensors)), flush=True)
    if status == -1:
        break
robot.simulationReset()
robot.step(dt)
print(f"reset {lift.getTargetPosition():g} {sensors[2].getValue():g} {shoulder.getTargetPosition():g}", flush=True)
