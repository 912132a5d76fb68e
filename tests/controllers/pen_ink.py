"""The Pen from Python (tests/worlds/pen.yaml): the same sequence as tests/c/pen_ink.c, through
Webots' ``Pen`` class; prints "ink STEP VALUE" with 17 significant digits."""

from controller import Robot

robot = Robot()
pen, ir = robot.getDevice("pen"), robot.getDevice("over")
ir.enable(16)


def show(k: int) -> None:
    print("ink", k, f"{ir.getValue():.17g}")


robot.step(16)
show(0)
pen.setInkColor(0xFF0000, float("nan"))     # printed and ignored
pen.setInkColor(0x336699, 0.5)
pen.write(True)
robot.step(16)
show(1)
pen.write(False)
pen.setInkColor(0x7F000000, 3.0)            # black (bits above 24 ignored), density clamped to 1
robot.step(16)
show(2)
pen.write(True)
robot.step(16)
show(3)
print("class", type(pen).__name__)
