"""Obstacle-avoiding wanderer for the scout of the arena world, written as a Webots controller.

    sensorium serve arena &
    sensorium controller example:wanderer --robot scout [STEPS]

It keeps exploring: it drives straight, veers away from what is close on its sides, and when the
way ahead is blocked it turns toward the more open side - committing to that direction until the
way is clear again (no dithering left-right in front of a wall) and by a random extra angle, so it
does not retrace the same line. Every 8 to 15 s it also changes heading at random. If something is
very close in front (a sonar below 0.12 m, or the lidar sees nothing ahead but the robot stopped
moving - e.g. a glass pane only the sonars see), it backs up first.

It also notices when it makes no progress: the robot has no odometry, so it compares its lidar scan
with the scans of the last seconds; a scan (nearly) equal to one taken 3 to 8 s ago means it is back
where it was, and 7 s of turning without once driving freely for 1.5 s means the same (wedged
between a wall and the glass pane the lidar cannot see, turning back and forth against a corner).
It then escapes: drives to whichever end (front or back) has room, turns toward the most open
direction the lidar sees (the other way at the next escape, in case that one was blocked), and
drives on.

The 360-degree one-layer lidar gives the free corridor ahead of the body (its width plus a margin)
and the free space to each side; the four sonars watch the close range, including what the lidar
cannot see (transparent objects). The random draws come from a fixed seed: two runs are the same.
"""

import math
import os
import random
import sys

from controller import Robot

CONTROL_STEP = 64                # ms: twice the world's basic step, the lidar at the same rate
HALF_LENGTH, HALF_WIDTH = 0.15, 0.10   # m: the scout's body, lidar at its centre
MARGIN = 0.08                    # m: clearance kept on each side of the body
TURN_AT = 0.30                   # m: free distance ahead of the body below which it turns
CLEAR_AT = 0.55                  # m: ... and above which a turn may end
SONAR_BACK_UP = 0.12             # m: closer than this in front means back up first
SONAR_MAX = 3.0                  # m: a sonar's reading when nothing echoes
CRUISE = 5.0                     # rad/s wheel speed (0.25 m/s with 5 cm wheels)
TURN = 3.0                       # rad/s wheel speed when turning on the spot
VEER = 1.5                       # rad/s of wheel speed difference per metre of side imbalance
SCAN_EVERY = 1.0                 # s: a scan is kept this often to judge progress
SAME_PLACE = 0.03                # m: median range change below which two scans are taken at one place
STUCK_AFTER, STUCK_WITHIN = 3.0, 8.0   # s: a scan this old (up to this old) seen again = no progress
FREE_RUN = 1.5                   # s: driving forward this long without a turn counts as progress ...
NO_FREE_RUN = 7.0                # s: ... and this long without one is no progress (turning on the spot)

robot = Robot()
args = [a for a in sys.argv[1:] if a not in ("-v", "--verbose")]
max_steps = int(args[0]) if args else None
# a line per control step is ~350 lines/s in fast mode: by default one per simulated second (and
# every change of state); -v (or SENSORIUM_VERBOSE=1) prints every step
VERBOSE = len(args) < len(sys.argv) - 1 or os.environ.get("SENSORIUM_VERBOSE") == "1"
next_report = 0.0
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
        self.scans = []                   # (time, ranges) every SCAN_EVERY s, the last STUCK_WITHIN s
        self.escapes = 0
        self.forward_since = None         # start of the current forward stretch
        self.progress_at = 0.0            # end of the last forward stretch of FREE_RUN s (or an escape)

    @staticmethod
    def _wander_time(now):
        return now + rng.uniform(8.0, 15.0)

    def _start_turn(self, direction, min_angle, max_angle):
        self.state = "turn"
        self.direction = direction
        rate = 2 * TURN * 0.05 / 0.22                            # rad/s of the scout turning on the spot
        self.turn_steps = int(rng.uniform(min_angle, max_angle) / rate / (CONTROL_STEP / 1000))

    def no_progress(self, now, ranges):
        """Whether the robot is back at a place it was 3-8 s ago (the scan says so), or has only
        turned for NO_FREE_RUN s."""
        if now - self.progress_at > NO_FREE_RUN:
            return True
        if self.scans and now - self.scans[-1][0] < SCAN_EVERY:
            return False
        self.scans = [(t, r) for t, r in self.scans if now - t <= STUCK_WITHIN] + [(now, list(ranges))]
        for t, old in self.scans:
            if now - t < STUCK_AFTER:
                break
            diffs = sorted(abs(a - b) for a, b in zip(ranges, old) if math.isfinite(a) and math.isfinite(b))
            if diffs and diffs[len(diffs) // 2] < SAME_PLACE:
                return True
        return False

    def escape(self, now, ahead, ranges, sonar):
        """Get out: between two close obstacles (front and back) centre the body so it can turn and
        face the roomier side (by the sonars, which see what the lidar cannot); else drive to the
        end that has room and turn toward the most open direction the lidar sees."""
        self.escapes += 1
        self.scans = []
        self.progress_at = now
        self.state, self.back_steps = "escape", 20
        self.wedged = sonar["front"] < 0.4 and sonar["back"] < 0.4
        self.escape_speed = 0.6 * CRUISE if ahead > 0.4 else -0.6 * CRUISE
        if self.wedged:
            self.escape_to = math.pi / 2 if sonar["left"] >= sonar["right"] else -math.pi / 2
        else:
            finite = [(r, a) for r, a in zip(ranges, angles) if math.isfinite(r)]
            self.escape_to = max(finite)[1] if finite else math.pi
        if self.escapes % 2 == 0:                       # the other way round this time
            self.escape_to += -2 * math.pi if self.escape_to > 0 else 2 * math.pi

    def decide(self, now, ahead, left, right, sonar, ranges=()):
        action, wheels = self._decide(now, ahead, left, right, sonar, ranges)
        if action == "forward":
            if self.forward_since is None:
                self.forward_since = now
            elif now - self.forward_since >= FREE_RUN:
                self.progress_at = now
        else:
            self.forward_since = None
        return action, wheels

    def _decide(self, now, ahead, left, right, sonar, ranges):
        if self.state not in ("back", "escape") and ranges and self.no_progress(now, ranges):
            self.escape(now, ahead, ranges, sonar)
        if self.state == "escape":
            if self.wedged:
                gap = sonar["front"] - sonar["back"]
                if self.back_steps > 0 and abs(gap) > 0.03:
                    self.back_steps -= 1
                    speed = 0.3 * CRUISE if gap > 0 else -0.3 * CRUISE
                    return "no progress: centre", (speed, speed)
            else:
                room = sonar["front"] > 0.06 if self.escape_speed > 0 else sonar["back"] > 0.06
                if self.back_steps > 0 and room:
                    self.back_steps -= 1
                    return "no progress: move out", (self.escape_speed, self.escape_speed)
            angle = self.escape_to
            self._start_turn(1 if angle >= 0 else -1, abs(angle), abs(angle) + 0.3)
            return "no progress: turn to the open side", (-self.direction * TURN, self.direction * TURN)
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
last_sonar = None
last_action = None
step = 0
while robot.step(CONTROL_STEP) != -1:
    ranges = lidar.getRangeImage()
    sonar = {side: s.getValue() for side, s in sonars.items()}
    sonar = {k: (v if v == v else math.inf) for k, v in sonar.items()}   # NaN before the first sample
    if all(v >= SONAR_MAX for v in sonar.values()) and last_sonar is not None:
        sonar = last_sonar        # no echo on all four at once (e.g. pressed against a pane): keep the last reading
    last_sonar = sonar
    ahead, left, right = perceive(ranges, sonar["front"])
    action, (wl, wr) = wanderer.decide(robot.getTime(), ahead, left, right, sonar, ranges)
    if VERBOSE or robot.getTime() >= next_report or action != last_action:
        next_report = robot.getTime() + 1.0
        print(f"t={robot.getTime():7.3f}  ahead={ahead:5.2f} left={left:5.2f} right={right:5.2f}  "
              f"sonar {' '.join(f'{k}={v:4.2f}' for k, v in sonar.items())}  -> {action}", flush=True)
    last_action = action
    if left_motor is not None and right_motor is not None:
        left_motor.setVelocity(wl)
        right_motor.setVelocity(wr)
    step += 1
    if max_steps is not None and step >= max_steps:
        break
