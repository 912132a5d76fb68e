"""Bad input to the newer devices from Python (tests/worlds/new_devices.yaml; tests/test_bad_input.py):
NaN and infinite volumes, pitches, balances and damping constants, empty and impossible sound names
and texts, a sampling period too large to send, a text too large for one request. The lines both
clients print come first (the same as tests/c/bad_input.c's); then Python's own: what a C caller
cannot pass (a NUL inside a name, a str that is no UTF-8), each refused in one line. Arguments: the
WAV, a WAV whose header says 3e9 frames/s."""

import math
import sys

from controller import Brake, Connector, Robot, Speaker

from sensorium.client.connection import SensoriumError

robot = Robot()
wav, fast = sys.argv[1:3]
speaker = robot.getDevice("speaker")
brake = robot.getDevice("arm brake")
dock = robot.getDevice("dock")
assert isinstance(speaker, Speaker) and isinstance(brake, Brake) and isinstance(dock, Connector)


def steps_playing(sound: str) -> int:
    n = 0
    while speaker.isSoundPlaying(sound) and n < 1000:
        robot.step(16)
        n += 1
    return n


for name, args in (("volume", (math.nan, 1.0, 0.0)), ("pitch", (1.0, math.nan, 0.0)), ("balance", (1.0, 1.0, math.nan))):
    Speaker.playSound(speaker, speaker, wav, *args, False)
    print("nan", name, int(speaker.isSoundPlaying(wav)))
speaker.speak("hello there", math.nan)
print("nan speak", int(speaker.isSpeaking()))
brake.setDampingConstant(math.nan)
for pitch in (math.inf, 1e308):
    Speaker.playSound(speaker, speaker, wav, 1.0, pitch, 0.0, False)
    print("pitch", pitch, int(speaker.isSoundPlaying(wav)), steps_playing(wav))
Speaker.playSound(speaker, speaker, "", 1.0, 1.0, 0.0, False)
print("empty sound", int(speaker.isSoundPlaying("")))
Speaker.playSound(speaker, speaker, fast, 1.0, 1.0, 0.0, False)
print("damaged rate", int(speaker.isSoundPlaying(fast)))
speaker.speak("", 1.0)
print("empty speech", int(speaker.isSpeaking()), steps_playing(""))
dock.enablePresence(16)
robot.step(16)
print("presence", dock.getPresence())

# Python's own
Speaker.playSound(speaker, speaker, "be\0ep.wav", 1.0, 1.0, 0.0, False)
print("nul sound", int(speaker.isSoundPlaying("")))
for label, call in (("huge period", lambda: dock.enablePresence(1e308)),
                    ("surrogate speech", lambda: speaker.speak("caf\udce9", 1.0)),
                    ("surrogate stop", lambda: speaker.stop("caf\udce9")),
                    ("huge speech", lambda: speaker.speak("word " * 300_000, 1.0)),
                    ("list sound playing", lambda: speaker.isSoundPlaying(["beep.wav"])),   # unhashable
                    ("list sound stop", lambda: speaker.stop(["beep.wav"]))):
    try:
        call()
        print(label, "accepted")
    except SensoriumError as exc:
        print(label, exc.name, "wb_" in exc.message or "/bot/" in exc.message)   # names what refused it
print("still", dock.getPresenceSamplingPeriod(), int(speaker.isSpeaking()), robot.step(16))
