"""Three bumpers from Python (tests/worlds/create_bumpers.yaml): forward at 10 rad/s for 150 steps,
then stopped for 5; one line per step whose readings changed (step, left, right, rear, at 17
significant digits), and a last line. The same as tests/c/bumpers.c."""

from controller import Robot

robot = Robot()
names = ("bumper_left", "bumper_right", "bumper_rear")
bumpers = [robot.getDevice(n) for n in names]
for b in bumpers:
    b.enable(16)
left, right = robot.getDevice("left wheel motor"), robot.getDevice("right wheel motor")
for m in (left, right):
    m.setPosition(float("inf"))
    m.setVelocity(10.0)
last = None
for k in range(155):
    if k == 150:
        left.setVelocity(0.0)
        right.setVelocity(0.0)
    robot.step(16)
    now = tuple(b.getValue() for b in bumpers)
    if now != last:
        print(k, *(f"{v:.17g}" for v in now))
        last = now
print("type", *(b.getType() for b in bumpers))
