"""A Supervisor's movies (``wb_supervisor_movie_*``): the server renders the Viewpoint's frames at
the movie's frame times and this client pipes them, raw RGB, into an ``ffmpeg`` it starts (H.264 in
an MP4 file, written to a temporary file beside the movie's and renamed onto it once complete: the
server never writes a file a client names). On POSIX a shell that waits for ffmpeg does the rename
(:data:`FINISHER`), so a controller killed while ffmpeg completes the file (``sensorium run`` ends a
controller 1 s after its last step) still leaves the movie. ``ffmpeg`` is an optional system tool:
without it on PATH a recording fails at its start with one line. Status values are Webots'
(``WB_SUPERVISOR_MOVIE_*``); the world ending while recording (a worldReload, a worldLoad, a quit: the
step answers -1) ends the movie with the frames taken, its status Webots' for the recording its world
load cancels (SIMULATION_ERROR) once the file is written.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
from typing import Any

from sensorium.client.connection import ErrorCode, SensoriumError
from sensorium.client.wb_robot import RobotClient, c_string
from sensorium.client.wb_supervisor import _supervisor

READY, RECORDING, SAVING, WRITE_ERROR, ENCODING_ERROR, SIMULATION_ERROR = range(6)
FINISH_WAIT_S = 600.0            # how long a controller ending waits for its movie's encoder
FINISHER = ('f=$1 t=$2; shift 2; "$@" || { s=$?; rm -f -- "$t"; exit $s; }; '
            'mv -f -- "$t" "$f" 2>/dev/null || { rm -f -- "$t"; exit 99; }')
"""sh -c script run as ``FINISHER sh MOVIE TMP ffmpeg ARGS...``: ffmpeg, then TMP renamed onto MOVIE (exit 99: the
rename failed; ffmpeg's own status when it failed), TMP removed unless renamed: whether or not the controller lives."""
RENAME_FAILED = 99
TMP_BASE = 192
"""Bytes of the movie's name kept in its temporary's: a name near the 255-byte limit of a file name leaves
room for the dot, the process id and the suffix."""


def temporary(folder: str, base: str, pid: int) -> str:
    """The temporary file beside the movie ``base`` in ``folder`` that ffmpeg writes: hidden, the name cut
    to TMP_BASE bytes (as the C client cuts it: within a character, the bytes kept as they are)."""
    cut = os.fsdecode(os.fsencode(base)[:TMP_BASE])
    return os.path.join(folder, f".{cut}.{pid}.tmp.mp4")


class Recorder:
    """One controller's movie: its encoder process, its files and Webots' status."""

    def __init__(self, robot: RobotClient) -> None:
        self.robot = robot
        self.status = READY
        self.process: subprocess.Popen | None = None
        self.filename = ""
        self.tmp = ""
        self.frames = 0
        self.said_full = False
        self.world_ended = False    # the world ended while recording: Webots' status for it once written
        robot.step_end_hooks.append(self.take)
        robot.close_hooks.append(self.finish)

    def _call(self, item: str, args: dict | None = None) -> dict:
        return self.robot.conn.call(f"/{self.robot.name}/robot/{item}", args)

    def start(self, func: str, filename: str, width: int, height: int, quality: int, acceleration: int,
              caption: bool) -> None:
        if not filename.lower().endswith(".mp4"):
            filename += ".mp4"          # Webots completes the extension
        folder, base = os.path.split(os.path.abspath(filename))
        if not os.path.isdir(folder) or os.path.isdir(filename):
            self._fail(func, f"cannot write the movie {filename!r}: "
                       + ("it is a folder" if os.path.isdir(filename) else f"no folder {folder!r}"), SIMULATION_ERROR)
            return
        ffmpeg = shutil.which("ffmpeg")
        if ffmpeg is None:
            self._fail(func, "ffmpeg is not on PATH: Sensorium's movies are encoded by ffmpeg (install it, e.g. "
                       "apt-get install ffmpeg); nothing recorded", ENCODING_ERROR)
            return
        if self.robot.terminated:       # the world ended before: a movie that ends with it, without a frame
            self._fail(func, "nothing was recorded because the simulation did not run", SIMULATION_ERROR)
            return
        try:
            reply = self._call("movie_start", {"width": width, "height": height, "acceleration": acceleration,
                                               "caption": bool(caption)})
        except SensoriumError as err:
            if err.code != ErrorCode.INVALID_ARGUMENT:
                raise
            self._fail(func, err.message, SIMULATION_ERROR)
            return
        step_ms = int(reply["step_ms"])
        # Webots' bit rate: quality x fps x pixels / 256; its frame rate: acceleration x 1000 / step_ms
        bitrate = quality * acceleration * 1000 * width * height // (256 * step_ms)
        self.tmp = temporary(folder, base, os.getpid())
        self.filename = filename
        self.frames = 0
        self.said_full = False
        self.world_ended = False
        command = [ffmpeg, "-hide_banner", "-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt", "rgb24",
                   "-s", f"{width}x{height}", "-framerate", f"{acceleration * 1000}/{step_ms}", "-i", "pipe:0",
                   "-an", "-c:v", "libx264", "-b:v", str(max(bitrate, 1000)), "-g", "132", "-pix_fmt", "yuv420p",
                   "-f", "mp4", self.tmp]
        if os.name == "posix":
            command = ["/bin/sh", "-c", FINISHER, "sh", self.filename, self.tmp, *command]
        try:
            self.process = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL,
                                            start_new_session=True)
        except OSError as exc:
            self._call("movie_stop")
            self._fail(func, f"cannot start ffmpeg: {exc.strerror or exc}", ENCODING_ERROR)
            return
        self.status = RECORDING

    def _fail(self, func: str, why: str, status: int) -> None:
        print(f"Error: {func}(): {why}.", file=sys.stderr)
        self.status = status

    def take(self) -> None:
        """After each step: the frames the server rendered, into the encoder. Also the one place the world's
        end is seen: every way this controller's steps end runs it (RobotClient.end_steps)."""
        if self.status == RECORDING and self.robot.terminated:
            self._end_with_world()
        if self.status != RECORDING or self.robot.terminated:
            return
        func = "wb_supervisor_movie_start_recording"
        more = True
        while more:
            try:
                reply = self._call("movie_frames")
            except SensoriumError:
                self._abort(func, "the server ended the movie", SIMULATION_ERROR)
                return
            more = bool(reply["more"])
            for frame in reply["frames"]:
                if not self._write(func, bytes(frame)):
                    return
            if reply["full"] and not self.said_full:
                self.said_full = True
                print(f"Warning: {func}(): the movie reached its frame limit; later frames are not recorded.",
                      file=sys.stderr)
            if reply["failed"]:
                self._call("movie_stop")
                self._abort(func, str(reply["failed"]), SIMULATION_ERROR)
                return

    def _write(self, func: str, frame: bytes) -> bool:
        process = self.process
        assert process is not None and process.stdin is not None
        try:
            process.stdin.write(frame)
        except (BrokenPipeError, OSError):
            self._call("movie_stop")
            self._abort(func, "ffmpeg stopped encoding the movie", ENCODING_ERROR)
            return False
        self.frames += 1
        return True

    def _end_with_world(self) -> None:
        """The world ended while recording (its step answered -1: a worldReload, a worldLoad, a quit): Webots
        cancels the recording at a world load; here the frames taken so far are the movie, encoded at once
        (while the controller is given its last second), its status Webots' once the file is written."""
        self.world_ended = True
        func = "wb_supervisor_movie_start_recording"
        if self.frames:
            print(f"Warning: {func}(): the world ended while recording (a reload, a load, a quit): the movie is "
                  f"written with its {self.frames} frames; movieFailed() is then true, as Webots reports a recording "
                  "a world load cancels.", file=sys.stderr)
        self.stop(func)

    def _abort(self, func: str, why: str, status: int) -> None:
        """The recording ends without a movie: the encoder stopped, its file removed."""
        process, self.process = self.process, None
        if process is not None:
            if process.stdin is not None:
                try:
                    process.stdin.close()
                except OSError:
                    pass
            try:
                if os.name == "posix":      # its group: the shell that renames and ffmpeg
                    os.killpg(process.pid, signal.SIGKILL)
                else:
                    process.kill()
            except OSError:
                pass
            process.wait()
        self._remove_tmp()
        self._fail(func, why, status)

    def _remove_tmp(self) -> None:
        try:
            os.unlink(self.tmp)
        except OSError:
            pass

    def stop(self, func: str) -> None:
        if self.status != RECORDING:
            return
        if not self.robot.terminated:       # (the world ended: the frames taken so far are the movie)
            self.take()
            if self.status != RECORDING:
                return
            self._call("movie_stop")
        if self.frames == 0:
            self._abort(func, "nothing was recorded because the simulation did not run", SIMULATION_ERROR)
            return
        process = self.process
        assert process is not None and process.stdin is not None
        try:
            process.stdin.close()         # ffmpeg ends the file and exits
        except OSError:
            pass
        self.status = SAVING

    def poll(self, wait: float | None = None) -> int:
        """Webots' status, the encoder's end looked at (waited for ``wait`` s when given)."""
        if self.status != SAVING or self.process is None:
            return self.status
        try:
            code = self.process.wait(wait) if wait is not None else self.process.poll()
        except subprocess.TimeoutExpired:
            code = None
        if code is None:
            return self.status
        self.process = None
        if code == RENAME_FAILED and os.name == "posix":
            self._remove_tmp()
            self._fail("wb_supervisor_movie_stop_recording", f"cannot write {self.filename!r}: the encoded movie could "
                       "not be renamed onto it", WRITE_ERROR)
        elif code != 0:
            self._remove_tmp()
            self._fail("wb_supervisor_movie_stop_recording", f"ffmpeg failed to encode the movie (exit status {code})",
                       ENCODING_ERROR)
        else:
            try:
                if os.path.exists(self.tmp):        # (no finisher shell: renamed here)
                    os.replace(self.tmp, self.filename)
                self.status = SIMULATION_ERROR if self.world_ended else READY
            except OSError as exc:
                self._remove_tmp()
                self._fail("wb_supervisor_movie_stop_recording",
                           f"cannot write {self.filename!r}: {exc.strerror or exc}", WRITE_ERROR)
        return self.status

    def finish(self) -> None:
        """The controller ends: a movie still recording is stopped and its file completed."""
        if self.status == RECORDING:
            try:
                self.stop("wb_supervisor_movie_stop_recording")
            except SensoriumError:
                self._abort("wb_supervisor_movie_stop_recording", "the server ended the movie", SIMULATION_ERROR)
        self.poll(FINISH_WAIT_S)
        if self.status == SAVING and self.process is not None:
            self.process.kill()
            self.process.wait()
            self.process = None
            self._remove_tmp()
            self._fail("wb_supervisor_movie_stop_recording", "ffmpeg did not finish the movie in time", ENCODING_ERROR)


def recorder(r: RobotClient) -> Recorder:
    rec: Any = getattr(r, "_movie", None)
    if rec is None:
        rec = Recorder(r)
        r._movie = rec          # type: ignore[attr-defined]
    return rec


def _integer(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def wb_supervisor_movie_start_recording(filename: str, width: int, height: int, codec: int, quality: int,
                                        acceleration: int, caption: bool) -> None:
    """Webots' movie recording: the Viewpoint's frames (``width`` × ``height``, both even here) at
    Webots' frame times, encoded by ffmpeg (H.264, MP4) into ``filename`` once stopped; ``codec``
    is ignored as in Webots."""
    filename = c_string(filename)
    func = "wb_supervisor_movie_start_recording"
    r = _supervisor(func)
    if r is None:
        return
    rec = recorder(r)
    if rec.poll() in (RECORDING, SAVING):
        print(f"Error: {func}(): movie recording has already been started.", file=sys.stderr)
        return
    name = os.fspath(filename) if isinstance(filename, str | os.PathLike) else None
    if not name or not isinstance(name, str):
        print(f"Error: {func}() called with NULL or empty 'filename' argument.", file=sys.stderr)
        return
    if not _integer(width) or not _integer(height) or width <= 0 or height <= 0:
        print(f"Error: {func}(): 'width' and 'height' arguments must be postitive.", file=sys.stderr)
        return
    if not _integer(quality) or not 1 <= quality <= 100:
        print(f"Error: {func}(): 'quality' argument ({quality!r}) must be between 1 and 100.", file=sys.stderr)
        return
    if not _integer(acceleration) or acceleration < 1:
        print(f"Error: {func}(): 'acceleration' argument must be greater than or equal to 1.", file=sys.stderr)
        return
    for arg, value in (("width", width), ("height", height), ("acceleration", acceleration)):
        if value >= 1 << 31:          # Webots' C ints (the request could not even hold one past 64 bits)
            print(f"Error: {func}(): '{arg}' argument ({value!r}) is not a 32-bit whole number.", file=sys.stderr)
            return
    rec.start(func, name, width, height, quality, acceleration, bool(caption))


def wb_supervisor_movie_stop_recording() -> None:
    func = "wb_supervisor_movie_stop_recording"
    r = _supervisor(func)
    if r is not None:
        recorder(r).stop(func)


def wb_supervisor_movie_is_ready() -> bool:
    r = _supervisor("wb_supervisor_movie_is_ready")
    if r is None:
        return False
    status = recorder(r).poll()
    return status == READY or status > SAVING


def wb_supervisor_movie_failed() -> bool:
    r = _supervisor("wb_supervisor_movie_failed")
    if r is None:
        return True
    return recorder(r).poll() > SAVING


def wb_supervisor_movie_get_status() -> int:
    r = _supervisor("wb_supervisor_movie_get_status")
    if r is None:
        return SIMULATION_ERROR
    return recorder(r).poll()
