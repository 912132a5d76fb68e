"""Colour-blob following with a camera, written as a Webots controller.

    sensorium serve blob_chase &
    sensorium controller example:blob_follower --robot epuck [STEPS]

The robot of the blob_chase world carries Webots' e-puck camera (52 x 39 pixels). Every step the
controller reads the camera image (Webots' BGRA bytes, ``Camera.getImage``) and keeps the pixels
that are clearly red; their mean column says where the red ball is (left -1 ... right +1) and
their number how close it is. It turns toward the blob, in proportion, and drives forward slower as
the blob grows, stopping when the ball fills a quarter of the image. With no red pixel in sight it
turns on the spot, searching. It prints every second what it sees. ``BlobFollower`` is the whole
control law, a pure function of the image bytes, which the in-process test uses as well.
"""

import sys

MAX_SPEED = 6.28         # rad/s, the e-puck's wheel limit
CRUISE = 5.0             # rad/s with the blob far away
GAIN = 3.0               # rad/s of wheel speed difference per unit of blob offset
SEARCH = 2.0             # rad/s, turning on the spot when no red is in sight
STOP_AREA = 0.25         # the blob's share of the image at which it stops


def red_pixels(image: bytes, width: int, height: int) -> tuple[int, float]:
    """(count, mean column) of the clearly red pixels of a BGRA image: red above 80 and above
    1.6 times both green and blue."""
    blue, green, red = image[0::4], image[1::4], image[2::4]
    count, columns = 0, 0
    for i, r in enumerate(red):
        if r > 80 and r > 1.6 * green[i] and r > 1.6 * blue[i]:
            count += 1
            columns += i % width
    return count, (columns / count if count else 0.0)


class BlobFollower:
    """Wheel speeds (left, right) from one camera image, one call per step."""

    def __init__(self) -> None:
        self.seen = 0                 # red pixels in the latest image
        self.offset = 0.0             # where the blob is: -1 left ... +1 right

    def step(self, image: bytes | None, width: int, height: int) -> tuple[float, float]:
        if image is None:
            return 0.0, 0.0
        count, column = red_pixels(image, width, height)
        self.seen = count
        if count == 0:                                    # search: turn on the spot (left)
            return -SEARCH, SEARCH
        half = (width - 1) / 2.0
        self.offset = (column - half) / half
        area = count / float(width * height)
        base = 0.0 if area >= STOP_AREA else CRUISE * (1.0 - area / STOP_AREA)
        turn = GAIN * self.offset
        clip = lambda v: max(-MAX_SPEED, min(MAX_SPEED, v))  # noqa: E731
        return clip(base + turn), clip(base - turn)


def main() -> None:
    from controller import Robot

    robot = Robot()
    timestep = int(robot.getBasicTimeStep())
    max_steps = int(sys.argv[1]) if len(sys.argv) > 1 else None
    camera = robot.getDevice("camera")
    camera.enable(timestep)
    width, height = camera.getWidth(), camera.getHeight()
    left_motor = robot.getDevice("left wheel motor")
    right_motor = robot.getDevice("right wheel motor")
    for motor in (left_motor, right_motor):
        motor.setPosition(float("inf"))          # velocity control
        motor.setVelocity(0.0)
    law = BlobFollower()
    steps = 0
    while robot.step(timestep) != -1:
        left, right = law.step(camera.getImage(), width, height)
        left_motor.setVelocity(left)
        right_motor.setVelocity(right)
        steps += 1
        if steps % max(1, 1000 // timestep) == 0:
            where = "none" if law.seen == 0 else f"{law.offset:+.2f}"
            print(f"t={robot.getTime():.2f}s red_pixels={law.seen} offset={where}", flush=True)
        if max_steps is not None and steps >= max_steps:
            break


if __name__ == "__main__":
    main()
