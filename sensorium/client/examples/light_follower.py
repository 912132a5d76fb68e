"""Light follower for the e-puck of the arena world (the demo's), written as a Webots controller.

    sensorium serve arena &
    sensorium controller example:light_follower --robot epuck [STEPS]

It first looks around (one turn on the spot, reading ls0 + ls1 at each heading), turns back to the
brightest heading, then drives toward the light as a Braitenberg vehicle that loves it: the two
light sensors ls0 (forward-left) and ls1 (forward-right) steer it toward the brighter side, and it
slows down as the light grows. It drives in legs of 3 s: if a leg did not make the light grow, the
heading led nowhere (the rim of the arena's overhead spot light is such a trap), so it looks around
again and tries the brightest other heading. Its light sensors near saturation (4096 each) about 0.5 m
from the arena's lamp: it stops there and stays, and drives on only if the light drops well below
that (the lamp moved, or a robot blocks it). The eight infra-red proximity sensors ps0..ps7 push it away
from obstacles. The wheel speeds go to the e-puck's two wheel motors (velocity control) and are
printed with the readings and each change of state.
"""

import math
import os
import sys

from controller import Robot

MAX_SPEED = 6.28                 # rad/s, the e-puck's wheel limit
CRUISE = MAX_SPEED               # 0.13 m/s with 2.05 cm wheels
ARRIVED = 7600.0                 # ls0 + ls1 at which it stops (both sensors near saturation, ~0.5 m)
LEAVE = 6000.0                   # ... and below which it drives again (hysteresis: no creeping)
LEG_S = 3.0                      # s: an approach leg, after which the light must have grown ...
GROWTH = 1.10                    # ... by this factor, else it looks around again
EXCLUDE = math.radians(60)       # after a leg that failed, skip headings this close to it
SCAN_SPEED = 5.0                 # rad/s wheel speed while turning on the spot to look around
STEER_GAIN = 3.0                 # rad/s of wheel speed difference per unit of (left - right) / total
IR_THRESHOLD = 150.0             # raw IR reading above which something is close (nothing in range: ~67)
# how much each proximity sensor brakes (+) or boosts (-) the left and right wheels (ps0..ps7)
IR_WEIGHTS_LEFT = (-1.0, -0.8, -0.4, 0.0, 0.0, 0.4, 0.8, 1.0)
IR_WEIGHTS_RIGHT = (1.0, 0.8, 0.4, 0.0, 0.0, -0.4, -0.8, -1.0)
WHEEL_RADIUS, AXLE = 0.0205, 0.052

robot = Robot()
timestep = int(robot.getBasicTimeStep())
args = [a for a in sys.argv[1:] if a not in ("-v", "--verbose")]
max_steps = int(args[0]) if args else None
# a line per control step is ~350 lines/s in fast mode: by default one per simulated second (and
# every change of state); -v (or SENSORIUM_VERBOSE=1) prints every step
VERBOSE = len(args) < len(sys.argv) - 1 or os.environ.get("SENSORIUM_VERBOSE") == "1"
next_report = 0.0

eyes = [robot.getDevice(name) for name in ("ls0", "ls1")]
proximity = [robot.getDevice(f"ps{i}") for i in range(8)]
for sensor in eyes + proximity:
    sensor.enable(timestep)

# ---- motors (looked up softly, so the controller still runs on a robot without a drive)
left_motor = robot.devices.get("left wheel motor")
right_motor = robot.devices.get("right wheel motor")
for motor in (left_motor, right_motor):
    if motor is not None:
        motor.setPosition(float("inf"))      # velocity control
        motor.setVelocity(0.0)


def clip(v):
    return max(-MAX_SPEED, min(MAX_SPEED, v))


class Follower:
    """look around (one turn on the spot) -> face the brightest heading -> approach in legs -> stay.

    An approach leg lasts LEG_S; if the light did not grow by GROWTH over a leg, that heading led
    to no light source (e.g. the rim of an overhead spot light's cone, a local maximum): it looks
    around again and skips the headings within EXCLUDE of every heading that failed since the last
    leg that worked. Headings come from integrating the wheel speeds it commands (turning on the
    spot, which nothing blocks for a round robot)."""

    def __init__(self, timestep_ms):
        turn_rate = 2 * SCAN_SPEED * WHEEL_RADIUS / AXLE                       # rad/s
        self.scan_steps = int(2 * math.pi / turn_rate / (timestep_ms / 1000)) + 1
        self.leg_steps = int(LEG_S * 1000 / timestep_ms)
        self.state = "look around"
        self.count = 0
        self.seen = []                     # total light at each step of the scan
        self.failed = []                   # headings of the legs that did not get brighter
        self.leg_start = 0.0
        self.heading = 0.0                 # rad, dead reckoning from the commanded wheel speeds
        self.scan_headings = []
        self.dt = timestep_ms / 1000

    def turned(self, left, right):
        """Account for one step of the wheel speeds just commanded."""
        self.heading += (right - left) * WHEEL_RADIUS / AXLE * self.dt

    def _near_failed(self, heading):
        return any(abs((heading - h + math.pi) % (2 * math.pi) - math.pi) < EXCLUDE for h in self.failed)

    def _best_heading(self):
        n = len(self.seen)
        candidates = [i for i in range(n) if not self._near_failed(self.scan_headings[i])]
        if not candidates:                                  # everything failed from here: start afresh
            self.failed = []
            candidates = list(range(n))
        return max(candidates, key=lambda i: self.seen[i])

    def _look_around(self):
        self.state, self.count, self.seen, self.scan_headings = "look around", 0, [], []
        return -SCAN_SPEED, SCAN_SPEED

    def decide(self, light_left, light_right, ir):
        total = light_left + light_right
        if total != total:                                    # NaN: no reading yet
            return 0.0, 0.0
        if self.state == "look around":
            self.seen.append(total)
            self.scan_headings.append(self.heading)
            self.count += 1
            if self.count >= self.scan_steps:                 # one full turn: turn on to the brightest heading
                self.state, self.count = "face the light", self._best_heading() + 1
            return -SCAN_SPEED, SCAN_SPEED
        if self.state == "face the light":
            self.count -= 1
            if self.count <= 0:
                self.state, self.count, self.leg_start = "approach", 0, total
            return -SCAN_SPEED, SCAN_SPEED
        if self.state == "at the light":
            if total >= LEAVE:
                return 0.0, 0.0
            self.state, self.count, self.leg_start = "approach", 0, total
        if total >= ARRIVED:
            self.state = "at the light"
            return 0.0, 0.0
        self.count += 1
        if self.count >= self.leg_steps:                      # end of a leg: brighter? go on, else look again
            if total < GROWTH * self.leg_start:
                self.failed.append(self.heading)
                return self._look_around()
            self.failed = []
            self.count, self.leg_start = 0, total
        forward = CRUISE * max(0.3, min(1.0, 2.0 * (ARRIVED - total) / ARRIVED))   # slower over the last half
        turn = STEER_GAIN * (light_left - light_right) / total
        left, right = forward - turn, forward + turn
        for value, wl, wr in zip(ir, IR_WEIGHTS_LEFT, IR_WEIGHTS_RIGHT):
            if value == value and value > IR_THRESHOLD:       # skip NaN (no reading yet)
                push = (value - IR_THRESHOLD) / 1000.0 * MAX_SPEED
                left += wl * push
                right += wr * push
        return clip(left), clip(right)


follower = Follower(timestep)
state = None
step = 0
while robot.step(timestep) != -1:
    light = [eye.getValue() for eye in eyes]
    ir = [sensor.getValue() for sensor in proximity]
    left, right = follower.decide(light[0], light[1], ir)
    follower.turned(left, right)
    if follower.state != state:
        state = follower.state
        print(f"t={robot.getTime():7.3f}  -> {state}", flush=True)
    if VERBOSE or robot.getTime() >= next_report:
        next_report = robot.getTime() + 1.0
        print(f"t={robot.getTime():7.3f}  ls0={light[0]:8.2f} ls1={light[1]:8.2f}  "
              f"ps=[{' '.join(f'{v:6.1f}' for v in ir)}]  wheels {left:+5.2f} {right:+5.2f} rad/s", flush=True)
    if left_motor is not None and right_motor is not None:
        left_motor.setVelocity(left)
        right_motor.setVelocity(right)
    step += 1
    if max_steps is not None and step >= max_steps:
        break
