"""Every device of the world present in Webots' Python API: by index with name and model, found by
name (listed-only kinds included); headless, waiting for user input steps its timeout."""

from controller import Robot

robot = Robot()
for i in range(robot.getNumberOfDevices()):
    dev = robot.getDeviceByIndex(i)
    print("device", i, dev.getName(), dev.getModel() or "-")
print("found", " ".join(n for n in ("radar", "gps", "display", "speaker") if robot.getDevice(n) is not None))
t0 = robot.getTime()
event = robot.waitForUserInputEvent(Robot.EVENT_KEYBOARD, 96)
print("wait", event, round((robot.getTime() - t0) * 1000))
