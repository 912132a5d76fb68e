"""Webots' Supervisor subset as ``wb_supervisor_*`` functions (PROTOCOL.md, Supervisor services).

Only a controller of a robot whose world entry has ``supervisor: true`` may call them; any other
prints Webots' error and gets the null answer (the server refuses too). Nodes are the world's
robots and solids, found by name (DEF names are the names); a node is an ``int`` id (0 = NULL),
a field a ``(node, name)`` pair — only ``translation`` and ``rotation`` exist. Every call is one
round trip, answered at once; setters take effect before the next measurement.
"""

from __future__ import annotations

import sys
from typing import Any

from sensorium.client.connection import ErrorCode, SensoriumError
from sensorium.client.wb_robot import RobotClient, current

WB_SUPERVISOR_SIMULATION_MODE_PAUSE = 0
WB_SUPERVISOR_SIMULATION_MODE_REAL_TIME = 1
WB_SUPERVISOR_SIMULATION_MODE_FAST = 2

WB_NO_FIELD = 0
WB_SF_VEC3F = 5
WB_SF_ROTATION = 6

_FIELD_TYPES = {"translation": WB_SF_VEC3F, "rotation": WB_SF_ROTATION}

Field = tuple[int, str]


def _supervisor(func: str) -> RobotClient | None:
    r = current()
    if not r.supervisor:
        print(f"Error: ignoring illegal call to {func}() in a 'Robot' controller.\n"
              f"Error: this function can only be used in a 'Supervisor' controller "
              f"(set 'supervisor: true' on robot {r.name!r} in the world file).", file=sys.stderr)
        return None
    return r


def _call(r: RobotClient, item: str, args: dict | None = None) -> dict:
    return r.conn.call(f"/{r.name}/robot/{item}", args)


def wb_supervisor_node_get_from_def(name: str) -> int:
    """The node (robot or solid) of that name, 0 if there is none."""
    r = _supervisor("wb_supervisor_node_get_from_def")
    if r is None:
        return 0
    if not isinstance(name, str) or not name:
        print("Error: wb_supervisor_node_get_from_def() called with a NULL or empty 'def' argument.", file=sys.stderr)
        return 0
    return int(_call(r, "get_from_def", {"name": name})["node"])


def wb_supervisor_node_get_self() -> int:
    r = _supervisor("wb_supervisor_node_get_self")
    return 0 if r is None else int(_call(r, "get_self")["node"])


def wb_supervisor_node_get_field(node: int, field_name: str) -> Field | None:
    """``translation`` or ``rotation`` of ``node``; None (with Webots' message) for another name."""
    if _supervisor("wb_supervisor_node_get_field") is None or not node:
        return None
    if field_name not in _FIELD_TYPES:
        print(f"Error: wb_supervisor_node_get_field(): field {field_name!r} is not supported by Sensorium "
              f"(only 'translation' and 'rotation').", file=sys.stderr)
        return None
    return (int(node), field_name)


def wb_supervisor_field_get_type(field: Field | None) -> int:
    return WB_NO_FIELD if field is None else _FIELD_TYPES[field[1]]


def wb_supervisor_field_get_name(field: Field | None) -> str:
    return "" if field is None else field[1]


def _field_get(field: Field | None, name: str, func: str) -> list[float] | None:
    r = _supervisor(func)
    if r is None or field is None:
        return None
    if field[1] != name:
        print(f"Error: {func}() called with a field of the wrong type ({field[1]}).", file=sys.stderr)
        return None
    return [float(v) for v in _call(r, "get_field", {"node": field[0], "field": field[1]})["value"]]


def _field_set(field: Field | None, name: str, values: Any, n: int, func: str) -> None:
    r = _supervisor(func)
    if r is None or field is None:
        return
    if field[1] != name:
        print(f"Error: {func}() called with a field of the wrong type ({field[1]}).", file=sys.stderr)
        return
    try:
        vals = [float(v) for v in values]
    except (TypeError, ValueError):
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): expected {n} numbers, got {values!r}") from None
    if len(vals) != n:
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): expected {n} numbers, got {len(vals)}")
    _call(r, "set_field", {"node": field[0], "field": field[1], "value": vals})


def wb_supervisor_field_get_sf_vec3f(field: Field | None) -> list[float] | None:
    return _field_get(field, "translation", "wb_supervisor_field_get_sf_vec3f")


def wb_supervisor_field_set_sf_vec3f(field: Field | None, values: Any) -> None:
    _field_set(field, "translation", values, 3, "wb_supervisor_field_set_sf_vec3f")


def wb_supervisor_field_get_sf_rotation(field: Field | None) -> list[float] | None:
    return _field_get(field, "rotation", "wb_supervisor_field_get_sf_rotation")


def wb_supervisor_field_set_sf_rotation(field: Field | None, values: Any) -> None:
    _field_set(field, "rotation", values, 4, "wb_supervisor_field_set_sf_rotation")


def _node_pose(node: int, func: str) -> dict | None:
    r = _supervisor(func)
    if r is None or not node:
        return None
    return _call(r, "get_node_pose", {"node": int(node)})


def wb_supervisor_node_get_position(node: int) -> list[float] | None:
    """World position (m) of the node's origin."""
    p = _node_pose(node, "wb_supervisor_node_get_position")
    return None if p is None else [float(v) for v in p["position"]]


def wb_supervisor_node_get_orientation(node: int) -> list[float] | None:
    """World rotation matrix of the node, 9 numbers row-major (Webots)."""
    p = _node_pose(node, "wb_supervisor_node_get_orientation")
    return None if p is None else [float(v) for v in p["orientation"]]


def wb_supervisor_simulation_reset() -> None:
    """Robots and solids back to their initial poses, wheel motors to their initial commands,
    LEDs off, custom data as in the world file; the clock keeps running (see README)."""
    r = _supervisor("wb_supervisor_simulation_reset")
    if r is not None:
        _call(r, "simulation_reset")
        for dev in r.devices:                      # the server reset the motors' commands
            if dev.kind == "RotationalMotor":
                dev.target_position, dev.velocity = 0.0, dev.max_velocity
            if dev.kind == "LED":
                dev.value = 0
        r.motor_commands.clear()
        r.custom_data = str(_call(r, "get_custom_data")["value"])     # a field of the robot: reset too


def wb_supervisor_simulation_set_mode(mode: int) -> None:
    r = _supervisor("wb_supervisor_simulation_set_mode")
    if r is None:
        return
    if mode not in (0, 1, 2) or isinstance(mode, bool):
        print(f"Error: wb_supervisor_simulation_set_mode() called with an invalid mode {mode!r}.", file=sys.stderr)
        return
    _call(r, "simulation_set_mode", {"mode": int(mode)})


def wb_supervisor_simulation_get_mode() -> int:
    r = _supervisor("wb_supervisor_simulation_get_mode")
    return WB_SUPERVISOR_SIMULATION_MODE_FAST if r is None else int(_call(r, "simulation_get_mode")["value"])


def wb_supervisor_simulation_quit(status: int) -> None:
    """The server serves other controllers and runs until it is stopped; for this controller the
    simulation ends as in Webots: its next steps return -1."""
    r = _supervisor("wb_supervisor_simulation_quit")
    if r is None:
        return
    print(f"Warning: wb_supervisor_simulation_quit({status}): the server runs on until it is stopped; robot "
          f"'{r.name}' steps no more (wb_robot_step() returns -1).", file=sys.stderr)
    r.terminated = True


_unserved_warned: set[str] = set()


def supervisor_unserved(func: str) -> None:
    """A Supervisor function Sensorium does not serve: Webots' error in a Robot controller, else one
    line the first time it is called (the same words as the C library's)."""
    if _supervisor(func) is None or func in _unserved_warned:
        return
    _unserved_warned.add(func)
    print(f"Error: {func}(): not served by Sensorium (its Supervisor finds robots and solids by DEF, reads and sets "
          "their translation and rotation, reads poses, resets and sets the run mode): ignored, Webots' \"no value\" "
          "returned.", file=sys.stderr)
