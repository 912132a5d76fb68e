"""A Webots-style supervisor resetting its arm (tests/test_supervisor_states.py on
tests/worlds/nested_joints.wbt): setJointPosition on the shoulder (the link's position at once, the
shoulder sensor's reading), the slider driven out and the robot's state saved, loadState("__init__")
(the link and the robot where the world file puts them, the clock going on), loadState of the saved
state, then bad calls (each one error line, nothing changed). Written as for Webots; prints one JSON line."""

import json
import math

from controller import Supervisor

robot = Supervisor()
timestep = int(robot.getBasicTimeStep())
robot.step(timestep)

me = robot.getSelf()
shoulder, link, carriage = (robot.getFromDef(name) for name in ("SHOULDER", "LINK", "CARRIAGE"))
out = {}

shoulder.setJointPosition(math.pi / 2)
out["set"] = link.getPosition()
sensor = robot.getDevice("shoulder sensor")
sensor.enable(timestep)
robot.step(timestep)
out["sensor"] = sensor.getValue()

slide, slide_sensor = robot.getDevice("slide"), robot.getDevice("slide sensor")
slide.setPosition(0.35)
slide_sensor.enable(timestep)
for _ in range(2000):           # a generous limit: the slider is there within a second
    if robot.step(timestep) == -1 or slide_sensor.getValue() == 0.35:
        break
out["reach"] = carriage.getPosition()
me.saveState("reach")

before = robot.getTime()
me.loadState("__init__")
out["init"] = link.getPosition()
out["robot"] = me.getPosition()
robot.step(timestep)
out["times"] = [before, robot.getTime()]

me.loadState("reach")
out["back"] = carriage.getPosition()

shoulder.setJointPosition(1.0, 0)
shoulder.setJointPosition(1.0, 2)
link.setJointPosition(1.0)
shoulder.setJointPosition(math.nan)
me.loadState("nope")
me.loadState("x" * (1 << 20))
out["after_bad"] = carriage.getPosition()
print(json.dumps(out), flush=True)
