"""A Display from Python (tests/worlds/display.yaml or .wbt), as Webots' sample display
controllers use it: its size bounds the drawing loops, and it draws (lines, shapes, a blended
polygon, text, images made, copied and pasted), then saves the display and a copied image as PNG
files in $DISPLAY_OUT. The same sequence as tests/c/display_size.c; prints what it did."""

import os

from controller import Display, Robot

out = os.environ["DISPLAY_OUT"]
robot = Robot()
screen, small = robot.getDevice("screen"), robot.getDevice("small")
robot.step(16)
for d in (screen, small):
    print(d.getName(), d.getWidth(), d.getHeight())
print("properties", screen.width, screen.height)
pixels = 0
for x in range(screen.getWidth()):          # the loop of Webots' samples
    for y in range(0, screen.getHeight(), 40):
        screen.setColor(0xFF0000)
        screen.drawPixel(x, y)
        pixels += 1
print("pixels", pixels)
screen.setColor(0xFF0000)
screen.drawLine(0, 0, 50, 20)
screen.setColor(0x00FF00)
screen.fillRectangle(60, 10, 30, 20)
screen.setColor(0x0000FF)
screen.drawOval(150, 100, 40, 25)
screen.fillOval(250, 60, 20, 30)
screen.setAlpha(0.5)
screen.setOpacity(0.6)
screen.setColor(0xFFFF00)
screen.fillPolygon([10, 100, 80, 30, 5], [150, 160, 230, 220, 190])
screen.setOpacity(1.0)
screen.setAlpha(1.0)
screen.drawRectangle(200, 150, 60, 40)
screen.drawPolygon([200, 230, 215], [60, 60, 90])
screen.drawText("Sensorium", 100, 200)
ref = screen.imageNew(bytes([255, 0, 0, 128, 0, 255, 0, 255, 0, 0, 255, 64, 255, 255, 255, 0]), Display.RGBA, 2, 2)
screen.imagePaste(ref, 300, 220, True)
copy = screen.imageCopy(60, 10, 30, 20)
screen.imagePaste(copy, 0, 100, False)
for y in range(64):                          # a colour per pixel: more than one request carries
    for x in range(64):
        small.setColor((x << 18) | (y << 10) | 0x40)
        small.drawPixel(x, y)
robot.step(16)
screen.imageSave(None, os.path.join(out, "screen.png"))
screen.imageSave(copy, os.path.join(out, "copy.png"))
small.imageSave(None, os.path.join(out, "small.png"))
screen.imageDelete(ref)
screen.imageDelete(copy)
print("refs", int(ref is not None), int(copy is not None), int(ref != copy))
robot.step(16)
print("done")
