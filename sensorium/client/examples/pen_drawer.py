"""Draw a circle with the pen, then follow it with the infra-red ground sensors: a Webots controller.

    sensorium serve pen_drawing &
    sensorium controller example:pen_drawer --robot epuck [STEPS]

The e-puck-like robot of the pen_drawing world carries a Pen under its centre (black ink, a
1.5 cm lead) and three infra-red ground sensors gs0..gs2 under its front, on a white floor. First it
drives one lap of a 0.5 m circle with the pen writing (both wheels at constant speeds: the drive is
kinematic, so the circle is exact); then it switches the pen off and follows the ink it laid with
the line follower's law (``example:line_follower``): the sensors read about 800 over white and 0
over black ink. It prints every second what it does and where it sees the line; it goes on for
ever (or for STEPS steps). ``PenDrawer`` is the whole law, which the in-process test and
``python -m sensorium.worlds.pen_drawing picture`` use as well.
"""

import math
import sys

try:                                   # as a bundled module, and as a script run by `sensorium controller`
    from sensorium.client.examples.line_follower import LineFollower
except ImportError:                    # pragma: no cover - a copy of this file next to line_follower.py
    from line_follower import LineFollower  # type: ignore[no-redef]

RADIUS = 0.5             # m, the circle the robot's centre drives
SPEED = 0.08             # m/s along it
WHEEL_RADIUS = 0.0205    # m (the world's differential drive)
AXLE = 0.052             # m
INK = 0x000000           # black: the ground sensors read 0 over it
DENSITY = 1.0


def circle_speeds(radius: float = RADIUS, speed: float = SPEED) -> tuple[float, float]:
    """(left, right) wheel speeds in rad/s that drive a circle of ``radius`` anticlockwise."""
    omega = speed / radius
    return (speed - omega * AXLE / 2) / WHEEL_RADIUS, (speed + omega * AXLE / 2) / WHEEL_RADIUS


def lap_steps(timestep_ms: int, radius: float = RADIUS, speed: float = SPEED) -> int:
    """Basic steps of one lap, rounded up (the ink closes the circle)."""
    return math.ceil(2 * math.pi * radius / speed * 1000 / timestep_ms)


class PenDrawer:
    """The commands of each step, (left, right, write), from the readings after the previous one:
    the first ``lap_steps`` steps drive the circle writing, the next ones follow the ink."""

    def __init__(self, timestep_ms: int) -> None:
        self.draw_steps = lap_steps(timestep_ms)
        self.steps = 0
        self.follower = LineFollower()

    def step(self, values) -> tuple[float, float, bool]:
        self.steps += 1
        if self.steps <= self.draw_steps:
            left, right = circle_speeds()
            return left, right, True
        left, right = self.follower.step(values)
        return left, right, False


def main() -> None:
    from controller import Robot

    robot = Robot()
    timestep = int(robot.getBasicTimeStep())
    max_steps = int(sys.argv[1]) if len(sys.argv) > 1 else None
    pen = robot.getDevice("pen")
    pen.setInkColor(INK, DENSITY)
    ground = [robot.getDevice(f"gs{i}") for i in range(3)]
    for sensor in ground:
        sensor.enable(timestep)
    motors = [robot.getDevice("left wheel motor"), robot.getDevice("right wheel motor")]
    for motor in motors:
        motor.setPosition(float("inf"))          # velocity control
    law = PenDrawer(timestep)
    values = [math.nan] * 3
    writing = None
    while max_steps is None or law.steps < max_steps:
        left, right, write = law.step(values)
        if write != writing:                     # sent at once: the coming step inks (or not)
            pen.write(write)
            if writing:
                print(f"t={robot.getTime():.2f}s the circle is drawn: pen off, following the ink", flush=True)
            writing = write
        motors[0].setVelocity(left)
        motors[1].setVelocity(right)
        if robot.step(timestep) == -1:
            break
        values = [s.getValue() for s in ground]
        if law.steps % max(1, 1000 // timestep) == 0:
            offset = law.follower.offset(values)
            where = "none" if offset is None else f"{offset:+.2f}"
            print(f"t={robot.getTime():.2f}s {'drawing' if writing else 'following'} "
                  f"ground={[round(v) for v in values]} line={where}", flush=True)


if __name__ == "__main__":
    main()
