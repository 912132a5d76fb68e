"""A Webots-style supervisor recording a movie (tests/test_movie.py, tests/worlds/movie.wbt):
the wall red for 20 basic steps (320 ms), blue for 20 more, then the recording stopped and waited
for; then the arguments Webots' libController refuses, and those Sensorium refuses beyond it, one
line each. Prints the movie's states as it goes and "done". With $MOVIE_LEAVE set: 10 steps of a movie
($MOVIE_LEFT_NAME, else left.mp4), then the end without stopping it, "left". With $MOVIE_QUIT set: 10 steps of a
movie, then simulationQuit while recording, the states once it is written; then a movie started after the end."""

import os
import time

from controller import Supervisor

out = os.environ["MOVIE_OUT"]
robot = Supervisor()
colour = robot.getFromDef("WALL_APP").getField("baseColor")
if os.environ.get("MOVIE_LEAVE"):         # ends while recording: the controller's end writes the movie
    robot.movieStartRecording(os.path.join(out, os.environ.get("MOVIE_LEFT_NAME", "left.mp4")), 160, 120, 0, 90, 1,
                              False)
    for _ in range(10):
        robot.step(16)
    print("left")
    raise SystemExit(0)
if os.environ.get("MOVIE_QUIT"):          # the world quits while recording: the frames so far are the movie
    robot.movieStartRecording(os.path.join(out, "quit.mp4"), 160, 120, 0, 90, 1, False)
    for _ in range(10):
        robot.step(16)
    robot.simulationQuit(0)
    print("quit", robot.step(16))
    while not robot.movieIsReady():     # (a step after -1 would end the process, as Webots' library does)
        time.sleep(0.01)
    print("saved", robot.movieIsReady(), robot.movieFailed())
    robot.movieStartRecording(os.path.join(out, "late.mp4"), 160, 120, 0, 90, 1, False)     # one line
    print("late", robot.movieIsReady(), robot.movieFailed())
    raise SystemExit(0)
print("before", robot.movieIsReady(), robot.movieFailed())
robot.movieStartRecording(os.path.join(out, "run"), 160, 120, 0, 90, 1, False)      # ".mp4" added
print("recording", robot.movieIsReady(), robot.movieFailed())
robot.movieStartRecording(os.path.join(out, "again.mp4"), 160, 120, 0, 90, 1, False)  # refused: one line
for _ in range(20):
    robot.step(16)
colour.setSFColor([0, 0, 1])
for _ in range(20):
    robot.step(16)
robot.movieStopRecording()
while not robot.movieIsReady():
    robot.step(16)
print("stopped", robot.movieIsReady(), robot.movieFailed())
# refused, one line each, nothing recorded
robot.movieStartRecording("", 160, 120, 0, 90, 1, False)
robot.movieStartRecording(os.path.join(out, "bad.mp4"), 0, 120, 0, 90, 1, False)
robot.movieStartRecording(os.path.join(out, "bad.mp4"), 160, 120, 0, 0, 1, False)
robot.movieStartRecording(os.path.join(out, "bad.mp4"), 160, 120, 0, 90, 0, False)
print("checked", robot.movieIsReady(), robot.movieFailed())
robot.movieStartRecording(os.path.join(out, "bad.mp4"), 161, 120, 0, 90, 1, False)     # the server's refusal
print("odd", robot.movieIsReady(), robot.movieFailed())
robot.movieStartRecording(os.path.join(out, "no", "such", "folder.mp4"), 160, 120, 0, 90, 1, False)
print("folder", robot.movieIsReady(), robot.movieFailed())
robot.movieStartRecording(os.path.join(out, "no\nsuch", "a\tb.mp4"), 160, 120, 0, 90, 1, False)  # one line
robot.step(16)
print("done")
