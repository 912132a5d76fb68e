"""Prints the robot's URDF with the prefix "p_" as Webots' arm samples read it (tests/test_urdf.py
compares it with the server's export), then takes one step (so the test sees it attached). Written as
for Webots."""

from controller import Robot

robot = Robot()
print(robot.getUrdf("p_"), end="", flush=True)
robot.step(int(robot.getBasicTimeStep()))
