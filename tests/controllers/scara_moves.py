"""The calls of Webots' scara sample, our own text (tests/test_sweep15.py runs Webots' file instead when
WEBOTS_HOME has it): the three targets set after every step, the LED blinked each second with
``set(True)`` / ``set(False)`` as Webots' ctypes takes them."""

from controller import Robot

robot = Robot()
step = int(robot.getBasicTimeStep())
for name in ("base_arm_position", "arm_position"):
    robot.getDevice(name).enable(step)
base, arm, shaft = (robot.getDevice(n) for n in ("base_arm_motor", "arm_motor", "shaft_linear_motor"))
led, lit, last = robot.getDevice("epson_led"), True, 0.0
while robot.step(step) != -1:
    if robot.getTime() - last > 1:
        led.set(lit)
        lit, last = not lit, robot.getTime()
    arm.setPosition(0.14)
    base.setPosition(0.5)
    shaft.setPosition(-0.1)
