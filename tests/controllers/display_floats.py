"""A Display drawn with float coordinates (tests/worlds/display.yaml), as Webots' own
display_supervisor sample does (``drawLine(width / 2, 0, width / 2, height - 1)``, an oval at a
robot's position scaled to pixels): Webots' Python class passes each through ``int()``, truncating
toward zero. Saves the display as $DISPLAY_OUT/floats.png and prints "done"."""

import os

from controller import Robot

robot = Robot()
screen = robot.getDevice("screen")
width, height = screen.getWidth(), screen.getHeight()
screen.setColor(0x505050)
screen.fillRectangle(0.0, 0.0, width * 1.0, height * 1.0)
screen.setColor(0xBB2222)
screen.drawLine(width / 2, 0, width / 2, height - 1)
screen.drawText("x", width / 2 - 10.5, height - 10)
screen.setColor(0x22BB11)
screen.drawLine(0, height / 2, width - 1, height / 2)
screen.setOpacity(0.5)
screen.setColor(0x2222BB)
screen.fillOval(100.7, 50.2, 4.9, 4.0)
screen.drawOval(-3.6, 200.9, 10.5, 6.2)
screen.setOpacity(1.0)
screen.drawPixel(310.99, 5.5)
screen.drawRectangle(200.5, 100.5, 30.9, 20.1)
ref = screen.imageCopy(0.0, 0.0, 50.5, 40.2)
screen.imagePaste(ref, 250.8, 180.3, False)
robot.step(16)
screen.imageSave(None, os.path.join(os.environ["DISPLAY_OUT"], "floats.png"))
screen.imageDelete(ref)
print("done")
