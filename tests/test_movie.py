"""A Supervisor's movies (``movieStartRecording`` …): Webots' frame times, the server's frames of
the Viewpoint (tests/worlds/movie.wbt: a wall filling the view, lit head-on, so every pixel is its
colour in closed form), the bounds, and the Python client's MP4 through ffmpeg decoded back."""

from __future__ import annotations

import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from test_run import clib  # noqa: F401  (a fixture: our libController built once, for the C controllers)

from sensorium.schemas.wire import ErrorCode
from sensorium.server.daemon import supervisor as sv
from sensorium.server.sim import viewshot
from sensorium.server.sim.simulation import Simulation

REPO = Path(__file__).resolve().parents[1]
WORLD = REPO / "tests" / "worlds" / "movie.wbt"
FACE = math.floor(255.0 * (1.0 - math.exp(-1.0)) ** (1.0 / 2.2) + 0.5)     # a lit channel of 1: 207


@pytest.mark.parametrize(("basic", "acceleration", "step"), [
    (16, 1, 32),      # 2.5 steps: 32 and 48 ms are as near 40 ms; the lower is kept
    (32, 1, 32),      # 1.25: 32 ms (8 from 40) before 64 ms (24 from 40)
    (8, 1, 40), (10, 1, 40), (30, 1, 30),
    (64, 1, 64),      # 0.625 steps: the lower is 0, so the upper
    (16, 4, 160), (32, 2, 64), (20, 3, 120)])
def test_the_frame_step_is_webots_whole_basic_steps_near_acceleration_times_40_ms(basic, acceleration, step) -> None:
    assert viewshot.movie_frame_step(basic, acceleration) == step


def _live():
    from test_supervisor import A, Live
    lv = Live(Simulation.from_file(WORLD))
    lv.ok(A, "attach", {"robot": "boss"})
    return lv, A


def _frames(lv, A) -> list[np.ndarray]:
    got = lv.ok(A, "/boss/robot/movie_frames")
    return [np.frombuffer(f, dtype=np.uint8).reshape(got["height"], got["width"], 3) for f in got["frames"]]


def test_frames_are_the_viewpoints_pictures_every_frame_step_and_a_colour_set_shows_from_the_next(monkeypatch) -> None:
    lv, A = _live()
    calls = []
    real = viewshot.picture
    monkeypatch.setattr(viewshot, "picture", lambda *a, **k: calls.append(a[0].time_ms) or real(*a, **k))
    for _ in range(5):                                    # no movie: nothing rendered
        lv.step(A, "boss", {"duration": 16})
    assert calls == []
    assert lv.ok(A, "/boss/robot/movie_start", {"width": 64, "height": 48, "acceleration": 1}) == {"step_ms": 32}
    start = lv.sim.time_ms                                # 80 ms
    for _ in range(20):
        lv.step(A, "boss", {"duration": 16})
    assert calls == [start + 32 * k for k in range(1, 11)]     # floor(320 / 32) frames, at their times
    red = _frames(lv, A)
    assert len(red) == 10 and all((f == [FACE, 0, 0]).all() for f in red)
    sv.set_field(lv.sim, sv.find_node(lv.sim, "WALL_APP"), "baseColor", [0.0, 0.0, 1.0])
    lv.step(A, "boss", {"duration": 64})                   # two frames, 32 ms apart
    blue = _frames(lv, A)
    assert len(blue) == 2 and all((f == [0, 0, FACE]).all() for f in blue)
    assert lv.ok(A, "/boss/robot/movie_stop") == {"value": 12}
    calls.clear()
    lv.step(A, "boss", {"duration": 64})                  # stopped: nothing rendered
    assert calls == []


def test_the_caption_is_the_acceleration_in_white_at_the_top_right_over_the_labels() -> None:
    lv, A = _live()
    lv.ok(A, "/boss/robot/set_label", {"id": 1, "text": "run", "x": 0.05, "y": 0.05, "size": 0.1,
                                       "color": 0x00FF00, "transparency": 0.0, "font": "Arial"})
    lv.ok(A, "/boss/robot/movie_start", {"width": 320, "height": 240, "acceleration": 4, "caption": True})
    lv.step(A, "boss", {"duration": 160})                  # 4 x 40 ms: one frame
    (frame,) = _frames(lv, A)
    labels = viewshot.Labels()
    labels.set(1, "run", 0.05, 0.05, 0.1, 0x00FF00, 0.0, "Arial")
    over = viewshot.draw_labels(viewshot.render(lv.sim, 320, 240), labels)
    caption = viewshot.Labels()
    caption._by_id[viewshot.CAPTION_ID] = viewshot.Label("4x", 1.0 - 0.227 * 240 / 320, 0.025, 0.2, 0xFFFFFF, 0.0, "A")
    assert (frame == viewshot.draw_labels(over, caption)).all()
    white = np.argwhere((frame == 255).all(axis=2))
    assert len(white) > 0 and white[:, 1].min() >= math.floor((1.0 - 0.227 * 0.75) * 320)
    assert white[:, 0].min() >= math.floor(0.025 * 240)
    assert (frame[5:30, 16:60] == [0, 255, 0]).all(axis=2).any()        # the Supervisor's label too


@pytest.mark.parametrize(("args", "words"), [
    ({"width": 161, "height": 120}, "must be even"),
    ({"width": 4096, "height": 4096}, "more than 4194304 pixels"),
    ({"width": 8192, "height": 2}, "width"),
    ({"acceleration": 10_001}, "acceleration"),
    ({"acceleration": 0}, "acceleration"),
])
def test_bad_sizes_and_accelerations_are_one_line_and_start_nothing(args, words) -> None:
    lv, A = _live()
    full = {"width": 160, "height": 120, "acceleration": 1, "caption": False, **args}
    msg = lv.err(A, "/boss/robot/movie_start", full, ErrorCode.INVALID_ARGUMENT)
    assert words in msg and "\n" not in msg
    assert getattr(lv.sim, "_movie", None) is None


def test_one_movie_at_a_time_and_only_its_robot_takes_or_stops_it() -> None:
    lv, A = _live()
    lv.ok(A, "/boss/robot/movie_start", {"width": 64, "height": 48, "acceleration": 1})
    msg = lv.err(A, "/boss/robot/movie_start", {"width": 64, "height": 48, "acceleration": 1},
                 ErrorCode.INVALID_ARGUMENT)
    assert "already being recorded" in msg and "\n" not in msg
    lv.ok(A, "/boss/robot/movie_stop")
    for item in ("movie_frames", "movie_stop"):
        msg = lv.err(A, f"/boss/robot/{item}", None, ErrorCode.INVALID_ARGUMENT)
        assert msg.endswith("no movie is being recorded by this robot")


def test_frames_left_waiting_past_the_bound_fail_the_movie_in_one_line(monkeypatch) -> None:
    monkeypatch.setattr(viewshot, "MOVIE_QUEUE_BYTES", 3 * 64 * 48 * 3)
    lv, A = _live()
    lv.ok(A, "/boss/robot/movie_start", {"width": 64, "height": 48, "acceleration": 1})
    lv.step(A, "boss", {"duration": 32 * 5})              # five frames due, three may wait
    got = lv.ok(A, "/boss/robot/movie_frames")
    assert len(got["frames"]) == 3 and "step it more often" in got["failed"] and "\n" not in got["failed"]


def test_the_frame_limit_stops_taking_frames_and_says_so(monkeypatch) -> None:
    monkeypatch.setattr(viewshot, "MOVIE_MAX_FRAMES", 2)
    lv, A = _live()
    lv.ok(A, "/boss/robot/movie_start", {"width": 64, "height": 48, "acceleration": 1})
    lv.step(A, "boss", {"duration": 32 * 4})
    got = lv.ok(A, "/boss/robot/movie_frames")
    assert len(got["frames"]) == 2 and got["full"] and got["failed"] == ""


def test_a_reply_hands_over_at_most_its_bytes_and_says_more_wait(monkeypatch) -> None:
    monkeypatch.setattr(viewshot, "MOVIE_REPLY_BYTES", 2 * 64 * 48 * 3)
    lv, A = _live()
    lv.ok(A, "/boss/robot/movie_start", {"width": 64, "height": 48, "acceleration": 1})
    lv.step(A, "boss", {"duration": 32 * 5})
    first = lv.ok(A, "/boss/robot/movie_frames")
    assert len(first["frames"]) == 2 and first["more"]
    lv.ok(A, "/boss/robot/movie_frames")
    last = lv.ok(A, "/boss/robot/movie_frames")
    assert len(last["frames"]) == 1 and not last["more"]


def test_a_controller_leaving_ends_its_movie() -> None:
    lv, A = _live()
    lv.ok(A, "/boss/robot/movie_start", {"width": 64, "height": 48, "acceleration": 1})
    lv.ok(A, "detach", {"session": "s0"})
    assert getattr(lv.sim, "_movie", None) is None


# ---------------------------------------------------------------------- the Python client, ffmpeg

def _python(url: str) -> list[str]:
    from _serve import sensorium
    return sensorium("controller", "--url", url, str(REPO / "tests" / "controllers" / "movie.py"))


def _run(argv, out: Path, env: dict[str, str | None] | None = None) -> tuple[list[str], str]:
    from _serve import Proc, serve
    with serve(WORLD, "--mode", "fast") as server:
        url = server.url("boss")
        proc = Proc(argv(url), env={**(env or {}), "MOVIE_OUT": str(out), "SENSORIUM_CONTROLLER_URL": url})
        try:
            code = proc.wait(300)
        finally:
            proc.stop()
        assert code == 0, proc.stderr()
        return proc.stdout().splitlines(), proc.stderr()


@pytest.fixture(scope="module")
def c_movie(tmp_path_factory) -> str:
    from test_c_client import sanitized_controller
    return sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "movie.c")


def _client(request, which: str):
    """The controller's argv maker and environment: the Python client, or the C one (sanitizers on)."""
    if which == "python":
        return _python, {}
    from test_c_client import SAN_ENV
    exe = request.getfixturevalue("c_movie")
    return (lambda url: [exe]), dict(SAN_ENV)


def _decode(path: Path) -> np.ndarray:
    raw = subprocess.run(["ffmpeg", "-hide_banner", "-loglevel", "error", "-i", str(path), "-f", "rawvideo",
                          "-pix_fmt", "rgb24", "-"], capture_output=True, check=True, timeout=120).stdout
    return np.frombuffer(raw, dtype=np.uint8).reshape(-1, 120, 160, 3)


REFUSED = ["Error: wb_supervisor_movie_start_recording(): movie recording has already been started.",
           "Error: wb_supervisor_movie_start_recording() called with NULL or empty 'filename' argument.",
           "Error: wb_supervisor_movie_start_recording(): 'width' and 'height' arguments must be postitive.",
           "Error: wb_supervisor_movie_start_recording(): 'quality' argument (0) must be between 1 and 100.",
           "Error: wb_supervisor_movie_start_recording(): 'acceleration' argument must be greater than or equal to 1."]


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("ffmpeg") is None or sys.platform == "win32", reason="needs ffmpeg (POSIX)")
@pytest.mark.parametrize("which", ["python", "c"])
def test_the_client_writes_an_mp4_of_the_frames_with_webots_states_and_lines(tmp_path: Path, request, which) -> None:
    argv, env = _client(request, which)
    lines, err = _run(argv, tmp_path, env)
    assert "Sanitizer" not in err and "runtime error" not in err, err
    assert lines == ["before True False", "recording False False", "stopped True False", "checked True False",
                     "odd True True", "folder True True", "done"], err
    errors = [line for line in err.splitlines() if line.startswith("Error")]
    assert errors[:5] == REFUSED, err
    assert "must be even" in errors[5] and errors[5].startswith("Error: wb_supervisor_movie_start_recording(): ")
    assert errors[6].startswith("Error: wb_supervisor_movie_start_recording(): cannot write the movie ") \
        and "no folder" in errors[6], err
    # a name's line break and tab are shown escaped: its error stays one line
    assert errors[7] == (f"Error: wb_supervisor_movie_start_recording(): cannot write the movie "
                         f"'{tmp_path}/no\\nsuch/a\\tb.mp4': no folder '{tmp_path}/no\\nsuch'."), err
    assert len(errors) == 8 and "not served" not in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.mp4"]      # no temporary left behind
    probe = json.loads(subprocess.run(["ffprobe", "-v", "error", "-select_streams", "v:0", "-show_entries",
                                       "stream=codec_name,width,height,r_frame_rate,nb_frames", "-of", "json",
                                       str(tmp_path / "run.mp4")], capture_output=True, check=True, text=True,
                                      timeout=60).stdout)["streams"][0]
    assert probe["codec_name"] == "h264" and (probe["width"], probe["height"]) == (160, 120)
    assert probe["r_frame_rate"] == "125/4"              # 1000 / 32 ms: 31.25 fps
    frames = _decode(tmp_path / "run.mp4")
    # 640 ms recorded, a frame each 32 ms: 20; the colour set at 320 ms shows from the 11th
    assert len(frames) == 20
    mean = frames.reshape(20, -1, 3).mean(axis=1)
    # H.264 is lossy (4:2:0 colour, limited range): each channel's mean within 6 of the closed form
    assert np.abs(mean[:10] - [FACE, 0, 0]).max() <= 6, mean
    assert np.abs(mean[10:] - [0, 0, FACE]).max() <= 6, mean


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("ffmpeg") is None or sys.platform == "win32", reason="needs ffmpeg (POSIX)")
@pytest.mark.parametrize("which", ["python", "c"])
@pytest.mark.parametrize("name", ["left.mp4", "l" * 247 + ".mp4", "é" * 123 + "l.mp4"])
def test_a_controller_ending_while_recording_writes_the_movie_so_far(tmp_path: Path, request, which, name) -> None:
    # a name of 251 bytes (255 the file system's limit) leaves no room for a temporary named after it whole:
    # the temporary takes its first wb_movie.TMP_BASE bytes
    argv, env = _client(request, which)
    lines, err = _run(argv, tmp_path, {**env, "MOVIE_LEAVE": "1", "MOVIE_LEFT_NAME": name})
    assert lines == ["left"] and "Error" not in err and "Sanitizer" not in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]
    frames = _decode(tmp_path / name)
    assert len(frames) == 5                              # 160 ms, a frame each 32 ms
    assert np.abs(frames.reshape(5, -1, 3).mean(axis=1) - [FACE, 0, 0]).max() <= 6


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("ffmpeg") is None or sys.platform == "win32", reason="needs ffmpeg (POSIX)")
@pytest.mark.parametrize("which", ["python", "c"])
def test_a_quit_while_recording_writes_the_movie_so_far_with_webots_status(tmp_path: Path, request, which) -> None:
    """simulationQuit while recording ends the movie at once, as a world reload does (the quit runs the same
    end-of-world path as a step answering -1): its 5 frames written, the status Webots' (ready and failed) once
    it is; a movie started after the end records nothing, in one line."""
    argv, env = _client(request, which)
    lines, err = _run(argv, tmp_path, {**env, "MOVIE_QUIT": "1"})
    assert lines == ["quit -1", "saved True True", "late True True"], err
    assert err.splitlines() == [ENDED_LINE.replace("its 10 frames", "its 5 frames"),
                                "Error: wb_supervisor_movie_start_recording(): nothing was recorded because the "
                                "simulation did not run."], err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["quit.mp4"]     # no temporary left behind
    frames = _decode(tmp_path / "quit.mp4")
    assert len(frames) == 5                              # 160 ms, a frame each 32 ms
    assert np.abs(frames.reshape(5, -1, 3).mean(axis=1) - [FACE, 0, 0]).max() <= 6


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="POSIX PATH")
@pytest.mark.parametrize("which", ["python", "c"])
def test_without_ffmpeg_on_path_a_recording_fails_in_one_line(tmp_path: Path, request, which) -> None:
    empty = tmp_path / "bin"
    empty.mkdir()
    out = tmp_path / "out"
    out.mkdir()
    argv, env = _client(request, which)
    lines, err = _run(argv, out, {**env, "PATH": str(empty)})
    assert lines[:3] == ["before True False", "recording True True", "stopped True True"], err
    errors = [line for line in err.splitlines() if "ffmpeg is not on PATH" in line]
    # each start past Webots' checks says so (run, again, the odd size: the client looks before the server)
    assert errors == 3 * ["Error: wb_supervisor_movie_start_recording(): ffmpeg is not on PATH: Sensorium's movies "
                          "are encoded by ffmpeg (install it, e.g. apt-get install ffmpeg); nothing recorded."], err
    assert list(out.iterdir()) == []


def test_a_frame_that_cannot_be_rendered_ends_the_movie_in_one_line_and_the_world_steps_on(monkeypatch) -> None:
    lv, A = _live()
    lv.ok(A, "/boss/robot/movie_start", {"width": 64, "height": 48, "acceleration": 1})

    def broken(*a, **k):
        raise RuntimeError("no picture")
    monkeypatch.setattr(viewshot, "picture", broken)
    assert lv.step(A, "boss", {"duration": 64})["time_ms"] == 64
    got = lv.ok(A, "/boss/robot/movie_frames")
    assert got["frames"] == [] and got["failed"] == "the frame at 32 ms could not be rendered: RuntimeError: no picture"


class _FakeSupervisor:
    """The client's view of a Supervisor: its calls packed as the connection packs them (msgpack), the
    server's start answered, each call kept."""

    def __init__(self) -> None:
        import msgpack
        self.name, self.calls, self.step_end_hooks, self.close_hooks = "boss", [], [], []
        self.terminated = False
        self.conn = self
        self._pack = msgpack.packb

    def call(self, service: str, args: dict | None = None) -> dict:
        self._pack(args)
        self.calls.append(service)
        return {"step_ms": 32} if service.endswith("movie_start") else {"value": 0}


@pytest.mark.parametrize(("filename", "width", "quality", "acceleration", "line"), [
    ("run.mp4", 1 << 70, 90, 1, "'width' argument (1180591620717411303424) is not a 32-bit whole number."),
    ("run.mp4", 160, 90, 1 << 64, "'acceleration' argument (18446744073709551616) is not a 32-bit whole number."),
    ("run.mp4", 160, -(1 << 64), 1, "'quality' argument (-18446744073709551616) must be between 1 and 100."),
    ("run.mp4", 160, 90, 1 << 31, "'acceleration' argument (2147483648) is not a 32-bit whole number."),
    (b"run.mp4", 160, 90, 1, None),
])
def test_a_number_past_a_c_int_or_a_bytes_name_is_one_line_and_asks_the_server_nothing(
        tmp_path: Path, monkeypatch, capsys, filename, width, quality, acceleration, line) -> None:
    from sensorium.client import wb_movie
    fake = _FakeSupervisor()
    monkeypatch.setattr(wb_movie, "_supervisor", lambda func: fake)
    monkeypatch.setattr(wb_movie.shutil, "which", lambda name: "/bin/true")
    monkeypatch.chdir(tmp_path)
    wb_movie.wb_supervisor_movie_start_recording(filename, width, 120, 0, quality, acceleration, False)
    err = capsys.readouterr().err
    func = "wb_supervisor_movie_start_recording"
    assert err == (f"Error: {func}() called with NULL or empty 'filename' argument.\n" if line is None
                   else f"Error: {func}(): {line}\n")
    assert fake.calls == [] and wb_movie.wb_supervisor_movie_get_status() == wb_movie.READY


# ---------------------------------------------------------------------- a world reload while recording

# `sensorium run`'s supervisor: records from 0, reloads the world at 320 ms (its first run); its steps answer -1,
# the movie ends with the frames taken; with the argument "stay" it never leaves (killed 1 s on by `run`)
RELOADER_PY = """import os, sys, time
from controller import Supervisor
boss = Supervisor()
again = os.path.exists("reloaded")
print("start", "again" if again else "first", boss.movieIsReady(), boss.movieFailed())
if not again:
    boss.movieStartRecording("m.mp4", 160, 120, 0, 90, 1, False)
while boss.step(16) != -1:
    if round(boss.getTime() * 1000) == 320 and not again:
        open("reloaded", "w").close()
        boss.worldReload()
print("ended", round(boss.getTime() * 1000))
if "stay" in sys.argv[1:] and not again:
    while True:
        time.sleep(0.05)
while not boss.movieIsReady():          # (a step after -1 would end the process, as Webots' library does)
    time.sleep(0.01)
print("saved", boss.movieIsReady(), boss.movieFailed())
"""

RELOADER_C = r"""#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

int main(int argc, char **argv) {
  wb_robot_init();
  int again = access("reloaded", F_OK) == 0;
  printf("start %s %s %s\n", again ? "again" : "first", wb_supervisor_movie_is_ready() ? "True" : "False",
         wb_supervisor_movie_failed() ? "True" : "False");
  if (!again)
    wb_supervisor_movie_start_recording("m.mp4", 160, 120, 0, 90, 1, false);
  while (wb_robot_step(16) != -1)
    if (lround(wb_robot_get_time() * 1000) == 320 && !again) {
      fclose(fopen("reloaded", "w"));
      wb_supervisor_world_reload();
    }
  printf("ended %ld\n", lround(wb_robot_get_time() * 1000));
  fflush(stdout);
  struct timespec ts = {0, 10 * 1000 * 1000};
  if (argc > 1 && strcmp(argv[1], "stay") == 0 && !again)
    for (;;)
      nanosleep(&ts, NULL);
  while (!wb_supervisor_movie_is_ready())
    nanosleep(&ts, NULL);
  printf("saved %s %s\n", wb_supervisor_movie_is_ready() ? "True" : "False",
         wb_supervisor_movie_failed() ? "True" : "False");
  wb_robot_cleanup();
  return 0;
}
"""

ENDED_LINE = ("Warning: wb_supervisor_movie_start_recording(): the world ended while recording (a reload, a load, a "
              "quit): the movie is written with its 10 frames; movieFailed() is then true, as Webots reports a "
              "recording a world load cancels.")


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("ffmpeg") is None or sys.platform == "win32", reason="needs ffmpeg (POSIX)")
@pytest.mark.parametrize("stay", [False, True], ids=["leaves", "killed"])
@pytest.mark.parametrize("which", ["python", "c"])
def test_a_world_reload_while_recording_writes_the_movie_so_far_with_webots_status(tmp_path: Path, request, which,
                                                                                  stay) -> None:
    """Webots cancels a recording at a world (re)load (status SIMULATION_ERROR); here the frames taken until the
    reload are the movie, complete and playable, and the status is Webots' once it is written: movieIsReady() and
    movieFailed() true. A controller that never leaves after its -1 is killed by `sensorium run`; the movie is
    still finished (the shell waiting for ffmpeg renames it). The reloaded world's controller starts idle."""
    from test_run import compile_controller, project, run

    text = WORLD.read_text().replace('controller "<extern>"', 'controller "boss"'
                                           + (' controllerArgs [ "stay" ]' if stay else ""))
    folder = tmp_path / "controllers" / "boss"
    if which == "python":
        world = project(tmp_path, "", {"boss.py": RELOADER_PY})
    else:
        world = project(tmp_path, "", {})
        compile_controller(request.getfixturevalue("clib"), folder, "boss", RELOADER_C)
    world.write_text(text)
    proc = run(world, "--until", "640")
    assert proc.wait(300) == 0, proc.stderr()
    out = [line for line in proc.stdout().splitlines() if line.startswith("[boss]")]
    first = ["[boss] start first True False", "[boss] ended 320"]
    assert out == first + ([] if stay else ["[boss] saved True True"]) + [
        "[boss] start again True False", "[boss] ended 640", "[boss] saved True False"], proc.stderr()
    err = proc.stderr()
    assert err.count(ENDED_LINE) == 1 and "Traceback" not in err and "Error" not in err, err
    assert ("forced termination" in err) == stay, err
    assert sorted(p.name for p in folder.iterdir() if p.suffix not in (".py", ".c") and p.name != "boss") == \
        ["m.mp4", "reloaded"]                                   # no temporary left behind
    frames = _decode(folder / "m.mp4")
    assert len(frames) == 10                                    # 320 ms, a frame each 32 ms
    assert np.abs(frames.reshape(10, -1, 3).mean(axis=1) - [FACE, 0, 0]).max() <= 6
