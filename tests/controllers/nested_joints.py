"""A Webots-style supervisor reading its arm's nodes past the joints (tests/test_supervisor_nested_joints.py
on tests/worlds/nested_joints.wbt): the link's, the hand's and the carriage's world poses and the
end points' fields and the joints' parameters' positions before and after the shoulder turned a
quarter turn and the slider slid 0.25 m.
Written as for Webots; prints one JSON line."""

import json
import math

from controller import Supervisor

robot = Supervisor()
timestep = int(robot.getBasicTimeStep())
robot.step(timestep)

link, hand, carriage = (robot.getFromDef(name) for name in ("ARMBOT.SHOULDER.LINK", "HAND", "CARRIAGE"))
parameters = [robot.getFromDef(name).getField("jointParameters").getSFNode() for name in ("SHOULDER", "SLIDE")]


def read() -> dict:
    return {"link": link.getPosition(), "link_orientation": link.getOrientation(), "hand": hand.getPosition(),
            "carriage": carriage.getPosition(), "link_translation": link.getField("translation").getSFVec3f(),
            "link_rotation": link.getField("rotation").getSFRotation(),
            "carriage_translation": carriage.getField("translation").getSFVec3f(),
            "hand_in_link": [v for k, v in enumerate(hand.getPose(link)) if k in (3, 7, 11)],
            "positions": [p.getField("position").getSFFloat() for p in parameters]}


before = read()
targets = {"shoulder": math.pi / 2, "slide": 0.35}
sensors = {}
for name, target in targets.items():
    robot.getDevice(name).setPosition(target)
    sensors[name] = robot.getDevice(name + " sensor")
    sensors[name].enable(timestep)
for _ in range(2000):           # a generous limit: the joints are there within a second
    if robot.step(timestep) == -1 or all(sensors[n].getValue() == t for n, t in targets.items()):
        break
print(json.dumps({"before": before, "after": read(), "at": [sensors[n].getValue() for n in targets],
                  "parameters": [[p.getTypeName(), p.getParentNode().getDef()] for p in parameters]}), flush=True)
