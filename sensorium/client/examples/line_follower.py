"""Line following with three infra-red ground sensors, written as a Webots controller.

    sensorium serve line_following &
    sensorium controller example:line_follower --robot epuck [STEPS]

The e-puck-like robot of the line_following world carries gs0 (left), gs1 (centre) and gs2
(right) under its front, 1 cm above the floor, looking down: infra-red sensors read the floor's
texture, high (about 800) on white and low (about 320) on the dark line. Each sensor's darkness
in [0, 1] gives where the line is under the array (left +1, centre 0, right -1); the robot turns
toward it, in proportion and with a damping term, slowing down in sharp corrections. When no
sensor sees the line any more it turns on the spot toward the side where it saw it last. It goes
round the loop anticlockwise for ever (or for STEPS steps), printing every second where it sees
the line. ``LineFollower`` is the whole control law, a pure function of the readings, which the
in-process test and ``python -m sensorium.worlds.line_loop picture`` use as well.
"""

import sys

MAX_SPEED = 6.28         # rad/s, the e-puck's wheel limit
CRUISE = 4.0             # rad/s on a straight line (8 cm/s with 2.05 cm wheels)
GAIN = 2.2               # rad/s of wheel speed difference per unit of line offset
DAMPING = 1.5            # ... per unit of offset change per step
SEARCH = 2.0             # rad/s, turning on the spot when the line is lost
WHITE, BLACK = 800.0, 320.0   # what the sensors read over white and over the line


class LineFollower:
    """Wheel speeds (left, right) from the three ground-sensor readings, one call per step."""

    def __init__(self) -> None:
        self.last_offset = 0.0
        self.last_side = 1.0          # +1: the line was last seen on the left

    def offset(self, values) -> float | None:
        """Where the line is under the array (+1 left ... -1 right), None when no sensor sees it."""
        dark = [min(1.0, max(0.0, (WHITE - v) / (WHITE - BLACK))) if v == v else 0.0 for v in values]
        total = sum(dark)
        if total < 0.2:
            return None
        return (dark[0] - dark[2]) / total

    def step(self, values) -> tuple[float, float]:
        offset = self.offset(values)
        if offset is None:                       # lost: turn toward where it was
            turn = SEARCH * self.last_side
            return -turn, turn
        if abs(offset) > 0.2:
            self.last_side = 1.0 if offset > 0 else -1.0
        turn = GAIN * offset + DAMPING * (offset - self.last_offset)
        self.last_offset = offset
        base = CRUISE * (1.0 - 0.4 * abs(offset))
        clip = lambda v: max(-MAX_SPEED, min(MAX_SPEED, v))  # noqa: E731
        return clip(base - turn), clip(base + turn)


def main() -> None:
    from controller import Robot

    robot = Robot()
    timestep = int(robot.getBasicTimeStep())
    max_steps = int(sys.argv[1]) if len(sys.argv) > 1 else None
    ground = [robot.getDevice(f"gs{i}") for i in range(3)]
    for sensor in ground:
        sensor.enable(timestep)
    left_motor = robot.getDevice("left wheel motor")
    right_motor = robot.getDevice("right wheel motor")
    for motor in (left_motor, right_motor):
        motor.setPosition(float("inf"))          # velocity control
        motor.setVelocity(0.0)
    law = LineFollower()
    steps = 0
    while robot.step(timestep) != -1:
        values = [s.getValue() for s in ground]
        left, right = law.step(values)
        left_motor.setVelocity(left)
        right_motor.setVelocity(right)
        steps += 1
        if steps % max(1, 1000 // timestep) == 0:
            offset = law.offset(values)
            where = "lost" if offset is None else f"{offset:+.2f}"
            print(f"t={robot.getTime():.2f}s ground={[round(v) for v in values]} line={where}", flush=True)
        if max_steps is not None and steps >= max_steps:
            break


if __name__ == "__main__":
    main()
