"""A Webots-style supervisor reaching the nodes inside its robot and a solid (tests/test_supervisor_nested.py
on tests/worlds/nested_nodes.wbt): by DEF and dotted path, by device, through parents and children; a
camera's world position and the solid ARM's centre of mass before and after driving straight ahead. Written as for Webots; prints one JSON line."""

import json
import math

from controller import Node, Supervisor

robot = Supervisor()
timestep = int(robot.getBasicTimeStep())
robot.step(timestep)

cam = robot.getFromDef("CAM")
tip = robot.getFromDef("ROVER.ARM.TIP")
lid = robot.getFromDef("SHELF.BOARD.LID")
found = [[n.getTypeName(), n.getDef(), n.getField("name").getSFString()] for n in (cam, tip, lid)]
parents = [cam.getParentNode().getDef(), robot.getFromDef("ARM").getParentNode().getDef(),
           tip.getParentNode().getDef()]
motor = robot.getDevice("left wheel")
wheel = robot.getFromDevice(motor)
device = [wheel is not None, wheel.getTypeName(), wheel.getParentNode().getDef(),
          wheel.getType() == Node.ROTATIONAL_MOTOR, wheel.getParentNode().getType() == Node.HINGE_JOINT,
          robot.getFromDevice(robot.getDevice("cam")).getType() == Node.CAMERA]
children = robot.getSelf().getField("children")
kinds = [children.getMFNode(i).getTypeName() for i in range(children.getCount())]
cam_before = cam.getPosition()
arm = robot.getFromDef("ARM")
com_before = arm.getCenterOfMass()

for name in ("left wheel", "right wheel"):
    m = robot.getDevice(name)
    m.setPosition(math.inf)
    m.setVelocity(2.0)
for _ in range(10):
    robot.step(timestep)
pose = cam.getPose(robot.getSelf())
print(json.dumps({"found": found, "parents": parents, "device": device, "children": kinds,
                  "tip": tip.getField("translation").getSFVec3f(), "cam_before": cam_before,
                  "cam_after": cam.getPosition(), "pose_in_robot": [pose[3], pose[7], pose[11]],
                  "no_pose": math.isnan(wheel.getPosition()[0]), "com_before": com_before,
                  "com_after": arm.getCenterOfMass(), "com_robot": robot.getSelf().getCenterOfMass()}), flush=True)
