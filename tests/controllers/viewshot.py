"""A Webots-style supervisor taking pictures (tests/test_viewshot.py, tests/worlds/viewshot.wbt):
two labels, a PNG and a JPEG of the Viewpoint's view in $VIEWSHOT_OUT, then the bad arguments
Webots' libController refuses (and those Sensorium refuses beyond it), one line each. The C
controller tests/c/viewshot.c does the same; prints "done"."""

import math
import os

from controller import Supervisor

out = os.environ["VIEWSHOT_OUT"]
robot = Supervisor()
robot.step(16)
robot.setLabel(7, "Sensorium", 0.05, 0.05, 0.1, 0x0000FF)
robot.setLabel(2, "old text", 0.5, 0.8, 0.05, 0xFFFF00, 0.5, "Impact")
robot.setLabel(2, "half", 0.6, 0.85, 0.05, 0xFFFFFF, 0.5, "Impact")     # the same id: replaced
robot.exportImage(os.path.join(out, "view.png"), 100)
robot.exportImage(os.path.join(out, "view.jpg"), 90)
# refused, one line each, nothing written or changed
robot.setLabel(70000, "huge id", 0.1, 0.1, 0.1, 0xFF0000)
robot.setLabel(3, "nan x", math.nan, 0.1, 0.1, 0xFF0000)
robot.setLabel(3, "bad colour", 0.1, 0.1, 0.1, -1)
robot.setLabel(3, "tab\there", 0.1, 0.1, 0.1, 0xFF0000)        # the server's refusal: not displayable
robot.exportImage("", 100)
robot.exportImage(os.path.join(out, "view.bmp"), 100)
robot.exportImage(os.path.join(out, "bad.png"), 0)
robot.step(16)
print("done")
