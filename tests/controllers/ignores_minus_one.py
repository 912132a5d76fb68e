"""A controller whose loop ignores wb_robot_step's -1, as Webots' khepera_gripper sample does (it loops
while the step is not 1): prints each step's status. libController ends such a controller at the step
after the -1 (status 0); the twin of tests/c/ignores_minus_one.c (tests/test_controller_end.py)."""

from controller import Robot

robot = Robot()
step = int(robot.getBasicTimeStep())
while True:
    print(robot.step(step), flush=True)
