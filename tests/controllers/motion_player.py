"""Python twin of tests/c/motion_player.c (same output lines) on tests/worlds/motion.yaml, robot leg:
motion_player.py DIR NAME..., DIR holding the motion files tests/test_motion_clients.py writes.

Loads DIR/NAME.motion for each NAME (missing, damaged, naming unknown motors: "NAME 0|1"), then plays wave.motion forwards to its end,
in a loop (with lift.motion playing beside it, both setting the slide), and in reverse from 200 ms.
Each step prints: phase, simulated time (ms), the motion's time, isOver, then the float64 bits of
the hip, knee and slide target positions and of the hip sensor."""

import struct
import sys
from pathlib import Path

from controller import Motion, Robot

robot = Robot()
folder = Path(sys.argv[1])
dt = int(robot.getBasicTimeStep())
motors = [robot.getDevice(n) for n in ("hip", "knee", "slide")]
hip_sensor = robot.getDevice("hip sensor")
hip_sensor.enable(dt)


def bits(v):
    return f"{struct.unpack('<Q', struct.pack('<d', v))[0]:016x}"


for name in sys.argv[2:]:
    m = Motion(str(folder / f"{name}.motion"))
    print(f"{name} {int(m.isValid())}", flush=True)
    del m
null = Motion(str(folder / "absent.motion"))
null.play()
null.setLoop(True)
print(f"null {int(null.isOver())} {null.getDuration()} {null.getTime()}", flush=True)

wave = Motion(str(folder / "wave.motion"))
print(f"wave {wave.getDuration()} {wave.getTime()} {int(wave.isOver())}", flush=True)


def run(phase, steps, *playing):
    for _ in range(steps):
        if robot.step(dt) == -1:
            sys.exit(1)
        print(f"{phase} {round(robot.getTime() * 1000)} {wave.getTime()} {int(wave.isOver())} "
              + " ".join(bits(m.getTargetPosition()) for m in motors) + f" {bits(hip_sensor.getValue())}",
              flush=True)


wave.play()
run("forward", 33)
lift = Motion(str(folder / "lift.motion"))
wave.setLoop(True)
wave.play()
lift.play()
run("loop", 36)
wave.stop()
lift.stop()
wave.setLoop(False)
wave.setReverse(True)
wave.setTime(200)
wave.play()
run("reverse", 15)
print(f"end {wave.getTime()} {int(wave.isOver())} {lift.getTime()}", flush=True)
