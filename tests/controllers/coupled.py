"""Python twin of tests/c/coupled.c (same output lines) on tests/worlds/coupled.yaml: coupled.py STEPS.

The motors' multipliers and grip::b's limits; grip::a commanded to 0.1 (grip::b follows at -2
times it), the elbow to 0.1 and then a negative velocity, refused in position control; per step
the float64 bits of the three sensors; then grip::a's velocity 0.5 (grip::b's -1) and its target
0.8, clamped by both motors with Webots' warnings, and STEPS more steps."""

import struct
import sys

from controller import Robot

robot = Robot()
steps = int(sys.argv[1]) if len(sys.argv) > 1 else 8
dt = int(robot.getBasicTimeStep())
a, b, elbow = robot.getDevice("grip::a"), robot.getDevice("grip::b"), robot.getDevice("elbow")
sensors = [m.getPositionSensor() for m in (a, b, elbow)]


def bits(name, v):
    return f"{name}={struct.unpack('<Q', struct.pack('<d', v))[0]:016x}"


def run(n):
    for _ in range(n):
        status = robot.step(dt)
        print(f"{round(robot.getTime() * 1000)} {status} " + " ".join(
            bits(n, s.getValue()) for n, s in zip(("a", "b", "elbow"), sensors)), flush=True)


print(" ".join(f"{v:g}" for v in (a.getMultiplier(), b.getMultiplier(), elbow.getMultiplier(), b.getMinPosition(),
                                  b.getMaxPosition(), b.getMaxVelocity())), flush=True)
for s in sensors:
    s.enable(dt)
a.setPosition(0.1)
elbow.setPosition(0.1)
elbow.setVelocity(-1.0)
print(f"{a.getTargetPosition():g} {b.getTargetPosition():g} {elbow.getVelocity():g}", flush=True)
run(steps)
a.setVelocity(0.5)
a.setPosition(0.8)
print(f"{a.getVelocity():g} {b.getVelocity():g} {a.getTargetPosition():g} {b.getTargetPosition():g}", flush=True)
run(steps)
