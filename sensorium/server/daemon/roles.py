"""Who may do what (sans-IO): world-wide controls and the poses a request may set.

* **Controllers** control their own robot: the robot and device services check that the caller is
  the robot's attached controller (:meth:`sensorium.server.daemon.services.Core.handle`).
* **World-wide controls** (:data:`WORLD_CONTROLS`: ``set_mode``, which pauses or speeds up the world
  for everyone, ``/<robot>/robot/set_pose``, which moves any robot, ``/<robot>/robot/window_send``, which hands any
  robot's controller a text as its robot window would, and the debug ``get_counters``) need the *supervisor role*: the caller is the attached controller of a robot with
  ``supervisor: true``, or the server runs with open controls. ``serve --controls`` chooses:
  ``open`` (any caller), ``supervisor`` (supervisor role only) or ``auto`` (the default): open
  when the RPC endpoint is only reachable from this machine (loopback tcp, ipc, inproc),
  supervisor otherwise — so ``sensorium call set_mode`` keeps working on a workstation and a
  server bound to a network interface is not paused by any client that can connect.
* **Poses**: every pose a request sets (``set_pose``, Supervisor ``set_field``) is checked by
  :func:`check_pose` (world/limits.py, also used by the in-process ``Robot.set_pose``) — finite
  numbers, every coordinate within ``±MAX_COORDINATE_M``.
"""

from __future__ import annotations

from ipaddress import ip_address
from typing import Any

from sensorium.server.world.limits import MAX_COORDINATE_M, check_pose

__all__ = ["WORLD_CONTROLS", "MAX_COORDINATE_M", "CONTROLS", "open_controls", "is_local_endpoint", "check_pose",
           "has_supervisor_role", "denied"]

# services any caller could otherwise use to change (or watch) the world for everyone: pausing it,
# moving robots (``/<robot>/robot/set_pose`` is not limited to the robot's own controller), the
# debug counters (which topics others demand), ``/<robot>/robot/window_send`` (text into any robot's controller)
WORLD_CONTROLS = frozenset({"set_mode", "set_pose", "get_counters", "window_send"})
CONTROLS = ("auto", "open", "supervisor")


def is_local_endpoint(url: str) -> bool:
    """True for endpoints only this machine can reach: ``ipc://``, ``inproc://``, tcp on a loopback
    address (``127.0.0.0/8``, ``::1``, ``localhost``)."""
    if url.startswith(("ipc://", "inproc://")):
        return True
    if not url.startswith("tcp://"):
        return False
    host = url[len("tcp://"):].rsplit(":", 1)[0].strip("[]")
    if host == "localhost":
        return True
    try:
        return ip_address(host).is_loopback
    except ValueError:
        return False                                # '*', an interface or host name: reachable from outside


def open_controls(controls: str, rpc_endpoint: str) -> bool:
    """``serve --controls`` → may any caller use the world-wide controls?"""
    if controls not in CONTROLS:
        raise ValueError(f"--controls must be one of {', '.join(CONTROLS)}, got {controls!r}")
    if controls == "auto":
        return is_local_endpoint(rpc_endpoint)
    return controls == "open"


def has_supervisor_role(sim: Any, lockstep: Any, peer: bytes) -> bool:
    """Is ``peer`` the attached controller of a robot with ``supervisor: true``?"""
    return any(s.peer == peer and getattr(sim.robots[s.robot], "supervisor", False) for s in lockstep.sessions)


def denied(service: str) -> str:
    return (f"{service} is a world-wide control: attach a robot with 'supervisor: true' first, "
            f"or run the server with --controls open")
