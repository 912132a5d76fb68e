"""A VacuumGripper and a Speaker from Python (tests/worlds/vacuum_speaker.yaml, the gripper resting
on the crate): the pump and the presence, then a sound played to its end, a looping one stopped, a
missing and an unreadable file, the engine and language setters and speech. The same sequence as
tests/c/vacuum_speaker.c. Arguments: the WAV, the unreadable file, the missing file."""

import sys

from controller import Robot, Speaker, VacuumGripper

robot = Robot()
wav, bad, missing = sys.argv[1:4]
gripper = robot.getDevice("gripper")
speaker = robot.getDevice("speaker")
assert isinstance(gripper, VacuumGripper) and isinstance(speaker, Speaker)
print("on", int(gripper.isOn()))
gripper.enablePresence(16)
robot.step(16)
print("presence off", int(gripper.getPresence()))
gripper.turnOn()
print("on", int(gripper.isOn()))
robot.step(16)
print("presence on", int(gripper.getPresence()), gripper.getPresenceSamplingPeriod())
gripper.turnOff()
robot.step(16)
print("presence off", int(gripper.getPresence()), int(gripper.isOn()))

Speaker.playSound(speaker, speaker, wav, 1.0, 1.0, 0.0, False)
n = 0
while speaker.isSoundPlaying(wav):
    robot.step(16)
    n += 1
print("played", n)
Speaker.playSound(speaker, speaker, wav, 0.5, 1.0, 0.0, True)
for _ in range(50):
    robot.step(16)
print("looping", int(speaker.isSoundPlaying(wav)), int(speaker.isSoundPlaying("")))
speaker.stop(wav)
robot.step(16)
print("stopped", int(speaker.isSoundPlaying(wav)), int(speaker.isSoundPlaying("")))
Speaker.playSound(speaker, speaker, missing, 1.0, 1.0, 0.0, False)
Speaker.playSound(speaker, speaker, bad, 1.0, 1.0, 0.0, False)
print("bad files", int(speaker.isSoundPlaying(missing)), int(speaker.isSoundPlaying(bad)))
print("engine", speaker.getEngine(), int(speaker.setEngine("microsoft")), int(speaker.setEngine("pico")))
print("language", speaker.getLanguage(), int(speaker.setLanguage("fr-FR")), int(speaker.setLanguage("pt-BR")),
      int(speaker.setLanguage("french")), speaker.getLanguage())
speaker.speak("one two three", 1.0)
n = 0
while speaker.isSpeaking():
    robot.step(16)
    n += 1
print("spoke", n)
