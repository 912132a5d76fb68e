"""A Webots-style supervisor framing the ball with moveViewpoint (tests/test_move_viewpoint.py on
tests/worlds/move_viewpoint.wbt): the Viewpoint's position before, after, and after simulationReset.
The same lines as tests/c/supervisor_move_viewpoint.c."""

from controller import Supervisor

robot = Supervisor()
step = int(robot.getBasicTimeStep())
position = robot.getFromDef("VIEW").getField("position")


def show(what: str) -> None:
    print(what, " ".join(f"{c:.3f}" for c in position.getSFVec3f()))


robot.step(step)
show("before")
robot.getFromDef("BALL").moveViewpoint()
show("after")
robot.simulationReset()
robot.step(step)
show("reset")
