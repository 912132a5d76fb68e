"""Obstacle-avoiding wanderer for the scout of the arena world, written as a Webots controller.

    sensorium serve arena &
    sensorium controller example:wanderer --robot scout [STEPS]

It keeps exploring: it drives straight, veers away from what is close on its sides, and when the
way ahead is blocked it turns toward the more open side - committing to that direction until the
way is clear again (no dithering left-right in front of a wall) and by a random extra angle, so it
does not retrace the same line. Every 8 to 15 s it also changes heading at random. If something is
very close in front (a sonar below 0.12 m, or the lidar sees nothing ahead but the robot stopped
moving - e.g. a glass pane only the sonars see), it backs up first.

The 360-degree one-layer lidar gives the free corridor ahead of the body (its width plus a margin)
and the free space to each side; the four sonars watch the close range, including what the lidar
cannot see (transparent objects). The random draws come from a fixed seed: two runs are the same.
"""

import math
import random
import sys

from controller import Robot

CONTROL_STEP = 64                # ms: twice the world's basic step, the lidar at the same rate
HALF_LENGTH, HALF_WIDTH = 0.15, 0.10   # m: the scout's body, lidar at its centre
MARGIN = 0.08                    # m: clearance kept on each side of the body
TURN_AT = 0.30                   # m: free distance ahead of the body below which it turns
CLEAR_AT = 0.55                  # m: ... and above which a turn may end
SONAR_BACK_UP = 0.12             # m: closer than this in front means back up first
CRUISE = 5.0                     # rad/s wheel speed (0.25 m/s with 5 cm wheels)
TURN = 3.0                       # rad/s wheel speed when turning on the spot
VEER = 1.5                       # rad/s of wheel speed difference per metre of side imbalance

robot = Robot()
max_steps = int(sys.argv[1]) if len(sys.argv) > 1 else None
rng = random.Random(7)

lidar = robot.getDevice("lidar")
lidar.enable(CONTROL_STEP)
sonars = {side: robot.getDevice(f"sonar_{side}") for side in ("front", "left", "right", "back")}
for sonar in sonars.values():
    sonar.enable(CONTROL_STEP)

resolution = lidar.getHorizontalResolution()
fov = lidar.getFov()
# ray i points at angle fov/2 - i * fov / resolution (counter-clockwise positive, 0 = ahead)
angles = [fov / 2 - i * fov / resolution for i in range(resolution)]

# ---- motors (looked up softly, so the controller still runs on a robot without a drive)
left_motor = robot.devices.get("left wheel motor")
right_motor = robot.devices.get("right wheel motor")
for motor in (left_motor, right_motor):
    if motor is not None:
        motor.setPosition(float("inf"))
        motor.setVelocity(0.0)


def perceive(ranges, sonar_front):
    """(free distance ahead of the body, free space on the left, on the right) in metres."""
    ahead, left, right = math.inf, math.inf, math.inf
    for r, a in zip(ranges, angles):
        if not math.isfinite(r):
            continue
        x, y = r * math.cos(a), r * math.sin(a)
        if x > 0 and abs(y) < HALF_WIDTH + MARGIN:
            ahead = min(ahead, x - HALF_LENGTH)
        if 0.35 < a < 2.0:
            left = min(left, r)
        elif -2.0 < a < -0.35:
            right = min(right, r)
    if math.isfinite(sonar_front):
        ahead = min(ahead, sonar_front)
    return ahead, left, right


class Wanderer:
    """forward / turn (committed direction, until clear and a random extra angle) / back up."""

    def __init__(self):
        self.state = "forward"
        self.direction = 1                # +1 left, -1 right
        self.turn_steps = 0               # control steps of turning still to do once clear
        self.back_steps = 0
        self.next_wander = self._wander_time(0.0)

    @staticmethod
    def _wander_time(now):
        return now + rng.uniform(8.0, 15.0)

    def _start_turn(self, direction, min_angle, max_angle):
        self.state = "turn"
        self.direction = direction
        rate = 2 * TURN * 0.05 / 0.22                            # rad/s of the scout turning on the spot
        self.turn_steps = int(rng.uniform(min_angle, max_angle) / rate / (CONTROL_STEP / 1000))

    def decide(self, now, ahead, left, right, sonar):
        if self.state == "back":
            self.back_steps -= 1
            if self.back_steps <= 0:
                self._start_turn(1 if left >= right else -1, 0.6, 1.6)
            return "back up", (-0.6 * CRUISE, -0.6 * CRUISE)
        if sonar["front"] < SONAR_BACK_UP and sonar["back"] > 0.3:
            self.state, self.back_steps = "back", 8
            return "back up", (-0.6 * CRUISE, -0.6 * CRUISE)
        if self.state == "turn":
            self.turn_steps -= 1
            if ahead > CLEAR_AT and self.turn_steps <= 0:
                self.state = "forward"
            else:
                return ("turn left" if self.direction > 0 else "turn right"), (-self.direction * TURN, self.direction * TURN)
        if ahead < TURN_AT:
            self._start_turn(1 if left >= right else -1, 0.2, 1.2)
            return "blocked: turn", (-self.direction * TURN, self.direction * TURN)
        if now >= self.next_wander:
            self.next_wander = self._wander_time(now)
            self._start_turn(rng.choice((-1, 1)), 0.5, 2.5)
            return "wander: turn", (-self.direction * TURN, self.direction * TURN)
        # veer away from the nearer side (only what is within a metre matters)
        imbalance = min(left, 1.0) - min(right, 1.0)             # > 0: more room on the left
        veer = max(-1.0, min(1.0, VEER * imbalance))
        return "forward", (CRUISE - veer, CRUISE + veer)


wanderer = Wanderer()
step = 0
while robot.step(CONTROL_STEP) != -1:
    ranges = lidar.getRangeImage()
    sonar = {side: s.getValue() for side, s in sonars.items()}
    sonar = {k: (v if v == v else math.inf) for k, v in sonar.items()}   # NaN before the first sample
    ahead, left, right = perceive(ranges, sonar["front"])
    action, (wl, wr) = wanderer.decide(robot.getTime(), ahead, left, right, sonar)
    print(f"t={robot.getTime():7.3f}  ahead={ahead:5.2f} left={left:5.2f} right={right:5.2f}  "
          f"sonar {' '.join(f'{k}={v:4.2f}' for k, v in sonar.items())}  -> {action}", flush=True)
    if left_motor is not None and right_motor is not None:
        left_motor.setVelocity(wl)
        right_motor.setVelocity(wr)
    step += 1
    if max_steps is not None and step >= max_steps:
        break
