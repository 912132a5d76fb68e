"""Python twin of tests/c/encoders.c (same arithmetic, same output lines): encoders.py STEPS."""

import math
import struct
import sys

from controller import Robot

robot = Robot()
steps = int(sys.argv[1]) if len(sys.argv) > 1 else 40
dt = int(robot.getBasicTimeStep())
lm, rm = robot.getDevice("left wheel motor"), robot.getDevice("right wheel motor")
le, re = lm.getPositionSensor(), rm.getPositionSensor()
ps = [robot.getDevice("ps0"), robot.getDevice("ps7")]
ls = [robot.getDevice("ls0"), robot.getDevice("ls1")]
le.enable(dt)
re.enable(dt)
for i in range(2):
    ps[i].enable(dt)
    ls[i].enable(2 * dt)
lm.setPosition(math.inf)
rm.setPosition(math.inf)
lm.setVelocity(2.0)
rm.setVelocity(1.0)


def bits(name, v):
    return f"{name}={struct.unpack('<Q', struct.pack('<d', v))[0]:016x}"


for s in range(steps):
    status = robot.step(dt)
    a, b = le.getValue(), re.getValue()
    d0, d7 = ps[0].getValue(), ps[1].getValue()
    l0, l1 = ls[0].getValue(), ls[1].getValue()
    print(f"{round(robot.getTime() * 1000)} {status} " + " ".join(
        bits(n, v) for n, v in (("left", a), ("right", b), ("ps0", d0), ("ps7", d7), ("ls0", l0), ("ls1", l1))),
        flush=True)
    if status == -1:
        break
    if s >= 9:
        total, left, right = l0 + l1, 3.0, 3.0
        if total == total and total > 0:
            left += 2.0 * (l1 - l0) / total
            right += 2.0 * (l0 - l1) / total
        if d0 == d0 and d0 > 200.0:
            left -= (d0 - 200.0) / 500.0
        if d7 == d7 and d7 > 200.0:
            right -= (d7 - 200.0) / 500.0
        turned = abs(a - b)
        left -= 0.1 * turned
        right -= 0.1 * turned
        lm.setVelocity(left)
        rm.setVelocity(right)
