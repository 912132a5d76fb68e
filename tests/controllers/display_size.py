"""A Display from Python (tests/worlds/display.yaml or .wbt), as Webots' sample display
controllers use it: its size bounds the drawing loops; the drawing calls answer like an
unsimulated device's, and an image reference from imageNew/imageCopy is usable. The same
sequence as tests/c/display_size.c; prints "NAME WIDTH HEIGHT" and what the loops did."""

from controller import Display, Robot

robot = Robot()
screen, small = robot.getDevice("screen"), robot.getDevice("small")
robot.step(16)
for d in (screen, small):
    print(d.getName(), d.getWidth(), d.getHeight())
print("properties", screen.width, screen.height)
pixels = 0
for x in range(screen.getWidth()):          # the loop of Webots' samples: it runs now
    for y in range(0, screen.getHeight(), 40):
        screen.setColor(0xFF0000)
        screen.drawPixel(x, y)
        pixels += 1
print("pixels", pixels)
screen.drawText("hello", 0, 0)
ref = screen.imageNew(bytes(4 * 2 * 2), Display.RGBA, 2, 2)
copy = screen.imageCopy(0, 0, 10, 10)
screen.imagePaste(ref, 0, 0, False)
screen.imageSave(None, "screen.png")
screen.imageSave(copy, "copy.png")
screen.imageDelete(ref)
screen.imageDelete(copy)
print("refs", int(ref is not None), int(copy is not None), int(ref != copy))
robot.step(16)
print("done")
