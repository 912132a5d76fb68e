"""Webots' user-input and robot extras on a headless server: ``wb_joystick_*`` (never connected),
``wb_mouse_*`` (no state: NaN), ``wb_robot_wait_for_user_input_event`` (no event ever comes: the
simulation runs for the whole timeout), the battery sensor (the server's ``battery_sensor_*``), project/world paths (""), the URDF (the server's
``get_urdf``), robot-window texts (sent to the server's ``wwi_send``, received with the step replies). The keyboard is in :mod:`sensorium.client.wb_robot`."""

from __future__ import annotations

import math
import os
import sys
from dataclasses import dataclass

from sensorium.client.connection import ErrorCode, SensoriumError
from sensorium.client.wb_robot import WB_EVENT_NO_EVENT, WB_EVENT_QUIT, c_string, current


@dataclass
class _Input:
    joystick_period: int = 0
    mouse_period: int = 0
    mouse_3d: bool = False
    battery_period: int = 0


_state = _Input()


def _period(value: int, func: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): sampling period must be an integer >= 0 (ms), got {value!r}")
    current()
    return value


def wb_robot_wait_for_user_input_event(event_type: int, timeout: int) -> int:
    """Steps whole basic time steps covering ``timeout`` ms and answers ``WB_EVENT_NO_EVENT``
    (``WB_EVENT_QUIT`` when the simulation ends): headless, no key, click or joystick event comes."""
    r = current()
    if isinstance(timeout, bool) or not isinstance(timeout, int) or timeout < 0:
        print(f"Error: wb_robot_wait_for_user_input_event(): negative timeout {timeout} ms", file=sys.stderr)
        return WB_EVENT_NO_EVENT
    step = r.basic_time_step
    steps = -(-timeout // step)
    if steps == 0:
        return WB_EVENT_NO_EVENT
    return WB_EVENT_QUIT if r.step(steps * step) == -1 else WB_EVENT_NO_EVENT


# ---------------------------------------------------------------------- battery, paths, windows

def wb_robot_battery_sensor_enable(sampling_period: int) -> None:
    """The server samples the robot's battery every ``sampling_period`` ms from now (0 disables)."""
    period = _period(sampling_period, "wb_robot_battery_sensor_enable")
    r = current()
    if not r.terminated:
        r.conn.call(f"/{r.name}/robot/battery_sensor_enable", {"value": period})
    _state.battery_period = period


def wb_robot_battery_sensor_disable() -> None:
    wb_robot_battery_sensor_enable(0)


def wb_robot_battery_sensor_get_sampling_period() -> int:
    return _state.battery_period


def wb_robot_battery_sensor_get_value() -> float:
    """The battery's energy (J) at the latest sample: NaN before the first one, -1 for a robot
    without a battery (Webots' values; README "Battery and Charger")."""
    r = current()
    if r.terminated:
        return math.nan
    return float(r.conn.call(f"/{r.name}/robot/battery_sensor_get_value", {})["value"])


def wb_robot_get_project_path() -> str:
    """"": a controller of a Sensorium server has no Webots project."""
    current()
    return ""


def wb_robot_get_world_path() -> str:
    current()
    return ""


def wb_robot_get_urdf(prefix: str = "") -> str:
    """The robot's URDF as Webots exports it, ``prefix`` before every link and joint name (the
    server's ``get_urdf``: the poses the world file gives, README "getUrdf")."""
    prefix = c_string(prefix)
    r = current()
    if not isinstance(prefix, str):
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"wb_robot_get_urdf(): prefix must be a string, got {prefix!r}")
    return str(r.conn.call(f"/{r.name}/robot/get_urdf", {"prefix": prefix})["value"])


ROBOT_WINDOW_ENV = "SENSORIUM_ROBOT_WINDOW_LOG"   # set to "1" by `sensorium run --robot-window-log`
ROBOT_WINDOW_CHARS = 4096     # of one message printed; the rest is counted, not shown (the C client's bound too)
MAX_WINDOW_TEXT = 1 << 18     # characters of one text the server takes (schemas/services.py's bound)


def robot_window_line(text: str) -> str:
    """The stderr line of a robot-window message: one line (its line breaks shown as \\n), bounded."""
    shown = text[:ROBOT_WINDOW_CHARS].replace("\\", "\\\\").replace("\n", "\\n").replace("\r", "\\r")
    cut = len(text) - ROBOT_WINDOW_CHARS
    return f"robot window: {shown}" + (f" ... ({cut} more characters not shown)" if cut > 0 else "")


def wb_robot_wwi_send_text(text: str) -> None:
    """The text goes to the server at once (Webots sends it so too), which publishes it on the topic
    ``/<robot>/robot_window`` (std_msgs/String); with $SENSORIUM_ROBOT_WINDOW_LOG set to 1 (``sensorium
    run --robot-window-log``) it is also printed on stderr as one line (a benchmark's score). The
    controller's stdout is left to the controller. A text over MAX_WINDOW_TEXT characters is not sent
    (one error line)."""
    r = current()
    if not isinstance(text, str):
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"wb_robot_wwi_send_text(): text must be a string, got {text!r}")
    if os.environ.get(ROBOT_WINDOW_ENV) == "1":
        print(robot_window_line(text), file=sys.stderr, flush=True)
    if len(text) > MAX_WINDOW_TEXT:
        print(f"Error: wb_robot_wwi_send_text(): a text of {len(text):,} characters is longer than "
              f"{MAX_WINDOW_TEXT:,}: not sent", file=sys.stderr, flush=True)
        return
    if not r.terminated:
        r.conn.call(f"/{r.name}/robot/wwi_send", {"text": text})


def wb_robot_wwi_receive_text() -> str | None:
    """The next text the robot's window side sent (``sensorium window ROBOT TEXT``, the service
    ``window_send``), None when there is none: as libController, the first call after a step takes
    every text that came with the step replies since the last such call, and returns them one per
    call, in order; what is left of them when the next step begins is dropped."""
    r = current()
    if r.window_fresh:
        r.window_fresh = False
        r.window_batch, r.window_inbox = r.window_inbox, []
        r.window_batch.reverse()                # popped from the end: oldest first
    return r.window_batch.pop() if r.window_batch else None


# ---------------------------------------------------------------------- joystick (never connected)

def wb_joystick_enable(sampling_period: int) -> None:
    _state.joystick_period = _period(sampling_period, "wb_joystick_enable")


def wb_joystick_disable() -> None:
    _state.joystick_period = 0


def wb_joystick_get_sampling_period() -> int:
    return _state.joystick_period


def wb_joystick_is_connected() -> bool:
    return False


def wb_joystick_get_model() -> str | None:
    return None


def wb_joystick_get_number_of_axes() -> int:
    return 0


def wb_joystick_get_axis_value(axis: int) -> int:
    return 0


def wb_joystick_get_number_of_povs() -> int:
    return 0


def wb_joystick_get_pov_value(pov: int) -> int:
    return 0


def wb_joystick_get_pressed_button() -> int:
    return -1


def wb_joystick_set_constant_force(level: int) -> None:
    pass


def wb_joystick_set_constant_force_duration(duration: float) -> None:
    pass


def wb_joystick_set_auto_centering_gain(gain: float) -> None:
    pass


def wb_joystick_set_resistance_gain(gain: float) -> None:
    pass


def wb_joystick_set_force_axis(axis: int) -> None:
    pass


# ---------------------------------------------------------------------- mouse (no pointer)

@dataclass(frozen=True)
class WbMouseState:
    """Webots' mouse state: no button pressed, no position (NaN)."""

    left: bool = False
    middle: bool = False
    right: bool = False
    u: float = math.nan
    v: float = math.nan
    x: float = math.nan
    y: float = math.nan
    z: float = math.nan


def wb_mouse_enable(sampling_period: int) -> None:
    _state.mouse_period = _period(sampling_period, "wb_mouse_enable")


def wb_mouse_disable() -> None:
    _state.mouse_period = 0


def wb_mouse_get_sampling_period() -> int:
    return _state.mouse_period


def wb_mouse_enable_3d_position() -> None:
    _state.mouse_3d = True


def wb_mouse_disable_3d_position() -> None:
    _state.mouse_3d = False


def wb_mouse_is_3d_position_enabled() -> bool:
    return _state.mouse_3d


def wb_mouse_get_state() -> WbMouseState:
    if _state.mouse_period <= 0:
        print("Error: wb_mouse_get_state() called for a disabled device! Please use: wb_mouse_enable().", file=sys.stderr)
    return WbMouseState()
