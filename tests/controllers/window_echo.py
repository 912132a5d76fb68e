"""A Webots-style controller talking with its robot window (tests/test_robot_window.py): each text
its window side sends is answered with "echo:TEXT"; "stop" ends it, printing what it received."""

from controller import Robot

robot = Robot()
step = int(robot.getBasicTimeStep())
robot.wwiSendText("ready")
got = []
while robot.step(step) != -1:
    text = robot.wwiReceiveText()
    while text is not None:
        got.append(text)
        robot.wwiSendText("echo:" + text)
        text = robot.wwiReceiveText()
    if got and got[-1] == "stop":
        break
print("received " + "|".join(got), flush=True)
