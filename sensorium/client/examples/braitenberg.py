"""Light follower for the e-puck of worlds/arena.yaml, written as a Webots controller.

    sensorium serve &
    sensorium controller example:braitenberg --robot epuck [STEPS]

It first looks around (one turn on the spot, reading ls0 + ls1 at each heading), turns back to the
brightest heading, then drives toward the light as a Braitenberg vehicle that loves it: the two
light sensors ls0 (forward-left) and ls1 (forward-right) steer it toward the brighter side, and it
slows down as the light grows. Its light sensors saturate (4096 each) about 0.4 m from the arena's
lamp: it stops there and stays, and drives on only if the light drops well below that (the lamp
moved, or a robot blocks it). If the light falls far below the brightest it saw (an obstacle
turned it away), it looks around again. The eight infra-red proximity sensors ps0..ps7 push it away
from obstacles. The wheel speeds go to the e-puck's two wheel motors (velocity control) and are
printed with the readings and each change of state.
"""

import sys

from controller import Robot

MAX_SPEED = 6.28                 # rad/s, the e-puck's wheel limit
CRUISE = MAX_SPEED               # 0.13 m/s with 2.05 cm wheels
ARRIVED = 7900.0                 # ls0 + ls1 at which it stops (both sensors close to saturation)
LEAVE = 6000.0                   # ... and below which it drives again (hysteresis: no creeping)
LOST = 0.6                       # light below this fraction of the brightest seen: look around again
SCAN_SPEED = 3.0                 # rad/s wheel speed while turning on the spot to look around
STEER_GAIN = 3.0                 # rad/s of wheel speed difference per unit of (left - right) / total
IR_THRESHOLD = 150.0             # raw IR reading above which something is close (nothing in range: ~67)
# how much each proximity sensor brakes (+) or boosts (-) the left and right wheels (ps0..ps7)
IR_WEIGHTS_LEFT = (-1.0, -0.8, -0.4, 0.0, 0.0, 0.4, 0.8, 1.0)
IR_WEIGHTS_RIGHT = (1.0, 0.8, 0.4, 0.0, 0.0, -0.4, -0.8, -1.0)
WHEEL_RADIUS, AXLE = 0.0205, 0.052

robot = Robot()
timestep = int(robot.getBasicTimeStep())
max_steps = int(sys.argv[1]) if len(sys.argv) > 1 else None

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
    """look around (one turn on the spot) -> face the brightest heading -> approach -> stay."""

    def __init__(self, timestep_ms):
        turn_rate = 2 * SCAN_SPEED * WHEEL_RADIUS / AXLE                       # rad/s
        self.scan_steps = int(2 * 3.141592653589793 / turn_rate / (timestep_ms / 1000)) + 1
        self.state = "look around"
        self.count = 0
        self.seen = []                     # total light at each step of the scan
        self.best = 0.0                    # brightest total seen during the last scan

    def decide(self, light_left, light_right, ir):
        total = light_left + light_right
        if total != total:                                    # NaN: no reading yet
            return 0.0, 0.0
        if self.state == "look around":
            self.seen.append(total)
            self.count += 1
            if self.count >= self.scan_steps:                 # one full turn: turn on to the brightest heading
                self.best = max(self.seen)
                self.state, self.count = "face the light", self.seen.index(self.best) + 1
            return -SCAN_SPEED, SCAN_SPEED
        if self.state == "face the light":
            self.count -= 1
            if self.count <= 0:
                self.state = "approach"
            return -SCAN_SPEED, SCAN_SPEED
        if self.state == "at the light":
            if total < LEAVE:
                self.state = "approach"
            else:
                return 0.0, 0.0
        if total >= ARRIVED:
            self.state = "at the light"
            return 0.0, 0.0
        self.best = max(self.best, total)
        if total < LOST * self.best:                          # lost it (an obstacle turned us away): look again
            self.state, self.count, self.seen = "look around", 0, []
            return -SCAN_SPEED, SCAN_SPEED
        forward = CRUISE * min(1.0, 2.0 * (ARRIVED - total) / ARRIVED)     # slow down over the last half
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
    if follower.state != state:
        state = follower.state
        print(f"t={robot.getTime():7.3f}  -> {state}", flush=True)
    print(f"t={robot.getTime():7.3f}  ls0={light[0]:8.2f} ls1={light[1]:8.2f}  "
          f"ps=[{' '.join(f'{v:6.1f}' for v in ir)}]  wheels {left:+5.2f} {right:+5.2f} rad/s", flush=True)
    if left_motor is not None and right_motor is not None:
        left_motor.setVelocity(left)
        right_motor.setVelocity(right)
    step += 1
    if max_steps is not None and step >= max_steps:
        break
