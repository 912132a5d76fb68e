"""A Webots-style controller using the everyday API beyond sensors (tests/test_webots_api.py):
wheel encoders, LEDs, the keyboard, custom data and the Supervisor. Written as for Webots; prints
one JSON line per checkpoint for the test to compare with closed forms."""

import json
import math

from controller import LED, Keyboard, PositionSensor, Supervisor

robot = Supervisor()
timestep = int(robot.getBasicTimeStep())
keyboard = Keyboard()
keyboard.enable(timestep)
left_motor = robot.getDevice("left wheel motor")
right_motor = robot.getDevice("right wheel motor")
left_sensor = left_motor.getPositionSensor()
right_sensor = robot.getDevice("right wheel sensor")
assert isinstance(left_sensor, PositionSensor) and left_sensor.getName() == "left wheel sensor"
left_sensor.enable(timestep)
right_sensor.enable(timestep)
led = robot.getDevice("led0")
rgb = robot.getDevice("rgb")
assert isinstance(led, LED)


def emit(tag, **values):
    print(json.dumps({"tag": tag, **values}), flush=True)


emit("info", model=robot.getModel(), data=robot.getCustomData(), supervisor=robot.getSupervisor(),
     mode=robot.getMode(), before=left_sensor.getValue(), motor=left_sensor.getMotor().getName())
robot.setCustomData("gain=3")
me = robot.getSelf()
translation = me.getField("translation")
rotation = me.getField("rotation")
start = translation.getSFVec3f()

for motor in (left_motor, right_motor):
    motor.setPosition(math.inf)
    motor.setVelocity(5.0)
keys = set()
leds = []
encoders = []
for i in range(150):
    led.set(1 + i % 2)
    if robot.step(timestep) == -1:
        break
    keys.add(keyboard.getKey())
    leds.append(led.get())
    encoders.append([left_sensor.getValue(), right_sensor.getValue()])
rgb.set(0x336699)
emit("drive", keys=sorted(keys), leds=leds[:4], encoders=encoders, position=me.getPosition(),
     translation=translation.getSFVec3f(), data=robot.getCustomData(), rgb=rgb.get())

# supervisor: turn the robot in place, move the wall, then reset everything
rotation.setSFRotation([0.0, 0.0, 1.0, math.pi / 2])
robot.step(0)
emit("turned", translation=translation.getSFVec3f(), rotation=rotation.getSFRotation(),
     orientation=me.getOrientation())
wall = robot.getFromDef("wall")
wall.getField("translation").setSFVec3f([3.0, 0.0, 0.25])
robot.simulationReset()
robot.step(timestep)
emit("reset", translation=translation.getSFVec3f(), rotation=rotation.getSFRotation(),
     wall=wall.getPosition(), encoders=[left_sensor.getValue(), right_sensor.getValue()],
     velocity=left_motor.getVelocity(), data=robot.getCustomData(), missing=robot.getFromDef("nothing") is None)
for motor in (left_motor, right_motor):
    motor.setPosition(math.inf)
    motor.setVelocity(5.0)
robot.step(10 * timestep)          # one request, ten basic steps
robot.step(timestep + 1)           # not a multiple: rounded up to two basic steps (Webots)
emit("after", translation=translation.getSFVec3f(), time_ms=round(robot.getTime() * 1000))
