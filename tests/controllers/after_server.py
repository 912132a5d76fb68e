"""The newer devices once the server is gone (tests/test_bad_input.py, tests/worlds/new_devices.yaml):
after one step the controller prints "ready" and waits for a line on stdin while the test stops
the server; then each call that needs the server is refused in one line (CONNECTION_LOST), the getters
answer this controller's copy, the step answers -1, and after it the setters keep a local state only
(as after Webots quits). The lines of tests/c/after_server.c, then the codes of the refusals."""

import sys

from controller import Brake, Connector, Motor, Robot, Speaker, VacuumGripper

from sensorium.client.connection import SensoriumError

robot = Robot()
wav = sys.argv[1]
dock, gripper, speaker = robot.getDevice("dock"), robot.getDevice("gripper"), robot.getDevice("speaker")
brake, coupled = robot.getDevice("arm brake"), robot.getDevice("grip::b")
assert isinstance(dock, Connector) and isinstance(gripper, VacuumGripper) and isinstance(speaker, Speaker)
assert isinstance(brake, Brake) and isinstance(coupled, Motor)
robot.step(16)
print("ready", flush=True)
sys.stdin.readline()
refused = []
for call in (dock.lock, gripper.turnOn, lambda: speaker.speak("hi", 1.0),
             lambda: Speaker.playSound(speaker, speaker, wav, 1.0, 1.0, 0.0, False)):
    try:
        call()
    except SensoriumError as exc:
        refused.append(exc.name)
print("refused", len(refused))
print("copies", int(dock.isLocked()), int(gripper.isOn()), int(speaker.isSpeaking()), int(speaker.isSoundPlaying(wav)))
print("brake", brake.getMotor().getName(), brake.getType(), coupled.getMultiplier())
print("step", robot.step(16))
dock.lock()
gripper.turnOn()
speaker.speak("hi", 1.0)
Speaker.playSound(speaker, speaker, wav, 1.0, 1.0, 0.0, False)
print("after", int(dock.isLocked()), int(gripper.isOn()), int(speaker.isSpeaking()), int(speaker.isSoundPlaying(wav)))
print("codes", *sorted(set(refused)))
