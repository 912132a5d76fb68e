"""The server's sans-IO core: service name → handler table, argument validation, typed errors.

:class:`Core` owns one simulation with its :class:`~sensorium.server.daemon.lockstep.Lockstep` and
:class:`~sensorium.server.daemon.topics.Topics`. The transport hands it raw ROUTER frames and XPUB
events and sends back what it returns; no socket or clock is touched here (``now`` is passed in).

    core = Core(sim, pub_endpoint="tcp://127.0.0.1:5561")
    replies = core.handle([identity, body], now)     # -> [[identity, reply_body], ...]
    while (t := core.next_advance(now)) is not None and t <= now:
        replies, publications = core.step_once(now)

Every concrete service name of the world is resolved once, at start, to (spec, handler, robot,
device): the hot path is one dict lookup, one pydantic validation, one handler call. A request
that fails gets exactly one error reply with a protocol code; the core never raises out of
:meth:`Core.handle`.
"""

from __future__ import annotations

import math
import sys
import traceback
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from types import UnionType
from typing import Any, Union, cast, get_args, get_origin

from pydantic import ValidationError
from pydantic_core import ErrorDetails

from sensorium.schemas import services as S
from sensorium.schemas.devices import KINDS
from sensorium.schemas.wire import (
    MAX_REPLY,
    SOFT_LIMIT,
    ErrorCode,
    RequestError,
    check_args_shape,
    error_reply,
    ok_reply,
    pack,
    parse_request,
)
from sensorium.server.daemon import roles, supervisor
from sensorium.server.daemon.device_services import MOTOR, DeviceServices, ServiceError
from sensorium.server.daemon.lockstep import Lockstep, LockstepError, Session, StepDone
from sensorium.server.daemon.nested import robot_entries
from sensorium.server.daemon.topics import Control, Topics, pose_quaternion
from sensorium.server.sim.joints import JointMotor
from sensorium.server.sim.simulation import DeviceEntry
from sensorium.server.world.urdf import robot_urdf

__all__ = ["Core", "ServiceError"]

Frames = list[bytes]


@dataclass(slots=True)
class Call:
    """One validated request, as a handler sees it."""

    envelope: Frames          # routing frames to echo (identity, REQ delimiter, ...)
    peer: bytes
    id: int
    args: Any                 # the spec's pydantic Args model
    robot: str                # the robot of a robot/device/motor service ("" for world services)
    ctl: Control              # the device of a device service (never read by other handlers)
    motor: Any                # the WheelMotor of a motor service, else None
    now: float
    extra: list[Frames]       # more replies to send (e.g. a step answered by detach)
    session: Session | None = None   # the caller's session, for services that need it attached


@dataclass(frozen=True, slots=True)
class Route:
    spec: S.ServiceSpec
    handler: Callable[[Call], dict | None]
    robot: str | None
    device: str | None        # "robot/device" path of a sensor
    motor: str | None = None  # motor name of a motor service


_DEFERRED = None              # a handler returning None answers later (step)
# ok_reply(rid, {"status": s, "time_ms": t, "values": {}}) in pieces, around the packed rid, s and t
# (tests/test_steppath.py checks the bytes against ok_reply)
_STEP_HEAD = b"\x83\xa2id"
_STEP_STATUS = b"\xa2ok\xc3\xa6result\x83\xa6status"
_STEP_TIME = b"\xa7time_ms"
_STEP_NO_VALUES = b"\xa6values\x80"
STEP_REPLY_PIECES = (_STEP_HEAD, _STEP_STATUS, _STEP_TIME, _STEP_NO_VALUES)   # the gate's send_steps packs with these
ARG_CACHE_KEYS = 4            # argument maps of at most this many int/str values are cached once validated
ARG_CACHE_SIZE = 1024         # validated argument maps kept


# pydantic's errors that only say "not this member's type": in a union (SetFieldArgs.value) one comes per
# member; the line keeps the member errors that say more ("should be a finite number", a list's length)
_TYPE_MISMATCH = frozenset({"bool_type", "bool_parsing", "int_type", "int_parsing", "int_from_float", "float_type",
                            "float_parsing", "list_type", "string_type", "dict_type", "model_type", "none_required"})
_SHOWN_INPUT = 80             # characters of a refused value echoed back (a 4 KiB string is not sent back 5 times)


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= _SHOWN_INPUT else text[:_SHOWN_INPUT - 3] + "..."


def _union_fields(model: Any) -> frozenset[str]:
    """The arguments of ``model`` that take one of several types (pydantic reports each member's error)."""
    names = []
    for name, info in getattr(model, "model_fields", {}).items():
        if get_origin(info.annotation) in (Union, UnionType):
            if sum(1 for a in get_args(info.annotation) if a is not type(None)) > 1:
                names.append(name)
    return frozenset(names)


def _arg_errors(exc: ValidationError, model: Any = None) -> str:
    """One line for a request's refused arguments: each named once, a long value shortened."""
    unions = _union_fields(model)
    parts: list[str] = []
    members: dict[str, list[ErrorDetails]] = {}     # a union argument -> its members' errors, in order
    for e in exc.errors(include_url=False):
        loc = ".".join(str(x) for x in e["loc"]) or "args"
        if e["type"] == "extra_forbidden":
            parts.append(f"unknown argument {loc!r}")
        elif e["type"] == "missing":
            parts.append(f"missing argument {loc!r}")
        elif len(e["loc"]) >= 2 and e["loc"][0] in unions:
            name = str(e["loc"][0])
            if name not in members:
                parts.append(name)          # placeholder: its line goes where it first failed
            members.setdefault(name, []).append(e)
        else:
            parts.append(f"argument {loc!r}: {e['msg']} (got {_shown(e.get('input'))})")
    for name, errors in members.items():
        # a member's own complaint (not finite, too long, a list's length, a list's item)
        said = [e for e in errors if e["type"] not in _TYPE_MISMATCH or len(e["loc"]) > 2]
        if said:
            lines: dict[str, None] = {}
            for m in said:                  # its path without the member's type tag (value.1, not value.list[float].1)
                where = ".".join(str(x) for x in (m["loc"][0], *m["loc"][2:]))
                lines.setdefault(f"argument {where!r}: {m['msg']} (got {_shown(m.get('input'))})", None)
            line = "; ".join(lines)
        else:
            kinds = ", ".join(dict.fromkeys(str(e["loc"][1]).removeprefix("constrained-") for e in errors))
            line = f"argument {name!r}: Input should be one of {kinds} (got {_shown(errors[0].get('input'))})"
        parts[parts.index(name)] = line
    return "; ".join(parts)


class Core(DeviceServices):
    """One world served: requests in, replies and publications out."""

    def __init__(self, sim: Any, *, world_name: str | None = None, heartbeat_ms: int = 1000, mode: str = "fast",
                 pub_endpoint: str = "", version: str | None = None, new_token: Callable[[], str] | None = None,
                 log: Callable[[str], None] | None = None, max_request: int = SOFT_LIMIT,
                 open_controls: bool = True):
        from sensorium import __version__

        self.sim = sim
        self.world_name = world_name or getattr(getattr(getattr(sim, "world", None), "world_info", None), "name", "world")
        self.version = version or __version__
        self.pub_endpoint = pub_endpoint
        self.max_request = max_request
        self.open_controls = open_controls       # world-wide controls for any caller (roles.py)
        # ``sensorium run``'s controller launcher (restart(robot), reload(), load(robot, filename)):
        # restartController, worldReload and worldLoad
        self.launcher: Any = None
        # simulationQuit: its status (the server's exit status; the first call counts) and how the
        # server is stopped (Server sets it to its transport's stop)
        self.quit_status: int | None = None
        self.request_stop: Callable[[], None] = lambda: None
        self.log = log or (lambda line: print(f"sensorium: {line}", file=sys.stderr, flush=True))
        self._log_counts: dict[str, int] = {}             # first line of a message -> times seen
        self.lockstep = Lockstep({name: bool(r.synchronization) for name, r in sim.robots.items()},
                                 sim.basic_time_step, heartbeat_ms=heartbeat_ms, mode=mode,
                                 time_ms=sim.time_ms, new_token=new_token,
                                 uncontrolled=[n for n, r in sim.robots.items()
                                               if getattr(r, "controller", "<extern>") == "<none>"])
        self._announced = False              # the waiting / running-by-itself line was printed
        self.topics = Topics(sim)
        self._seen: dict[str, dict[str, int]] = {}          # session token -> device path -> measurements
        self._custom_sent: dict[str, str] = {}    # session token -> the robot's customData its controller has
        self._custom_news: set[str] = set()       # robots whose customData a Supervisor's request changed
        self._custom_news_ms: dict[str, int] = {}  # the simulated ms of each change (Webots: set at the next step)
        # texts sent to each robot's window side (window_send), for its controller's next step reply
        self._window_inbox: dict[str, deque[str]] = {name: deque() for name in sim.robots}
        self._window_chars: dict[str, int] = dict.fromkeys(sim.robots, 0)
        self._window_news: set[str] = set()       # robots with texts waiting
        self._controls_by_robot: dict[str, list[Control]] = {name: [] for name in sim.robots}
        for ctl in self.topics.controls.values():
            self._controls_by_robot[ctl.robot].append(ctl)
        self.routes = self._routes()
        # the step service of each robot, by its lockstep slot (the transport's C step path names robots so)
        self._step_service_names = [f"/{name}/robot/step" for name in sim.robots]
        self._step_services = [name.encode() for name in self._step_service_names]
        self._arg_cache: dict[tuple, Any] = {}            # (model, args items) -> validated model
        self.errors = 0

    def log_error(self, line: str) -> None:
        """Log an error a client may trigger again and again: the same first line is printed the
        1st, 10th, 100th… time only, with its count, so a client repeating a failing request
        cannot flood the log (counting, not timing: the core has no clock). The whole first line is the
        key (to 4,000 characters): lines that share a long start (a PROTO's path) and then differ each print."""
        key = line.split("\n", 1)[0][:4000]
        if len(self._log_counts) > 1000 and key not in self._log_counts:
            self._log_counts.clear()
        n = self._log_counts.get(key, 0) + 1
        self._log_counts[key] = n
        if n == 1:
            self.log(line)
        elif n >= 10 and str(n).strip("0") == "1":
            self.log(f"{key} (seen {n} times)")

    # ------------------------------------------------------------------ routing table
    def _routes(self) -> dict[str, Route]:
        routes: dict[str, Route] = {}
        for robot_name, robot in self.sim.robots.items():
            # a device's services are its kind's (schemas/devices.py); the handler is named after the item
            for dev_name, dev in robot.devices.items():
                path = f"{robot_name}/{dev_name}"
                for item in KINDS[dev.kind].services:
                    routes[f"/{robot_name}/{dev_name}/{item}"] = Route(
                        S.spec("device", item), getattr(self, f"_dev_{item}"), robot_name, path)
            for motor_name in robot.motors:
                for item in KINDS[MOTOR].services:
                    routes[f"/{robot_name}/{motor_name}/{item}"] = Route(
                        S.spec("device", item), getattr(self, f"_motor_{item}"), robot_name, None, motor_name)
            for spec in S.SERVICES:
                if spec.scope == "robot":
                    handler = (partial(self._supervisor, spec.item)
                               if spec.supervisor and not hasattr(self, f"_robot_{spec.item}")
                               else getattr(self, f"_robot_{spec.item}"))
                    routes[f"/{robot_name}/robot/{spec.item}"] = Route(spec, handler, robot_name, None)
        for spec in S.SERVICES:
            if spec.scope == "server":
                routes[spec.item] = Route(spec, getattr(self, f"_srv_{spec.item}"), None, None)
        return routes

    def _unknown(self, service: str) -> ServiceError:
        """The most precise error for a name that is no service: robot, device or item unknown."""
        if not service.startswith("/"):
            return ServiceError(ErrorCode.UNKNOWN_SERVICE, f"no service {service!r}")
        robots = sorted((r for r in self.sim.robots if service.startswith(f"/{r}/")), key=len, reverse=True)
        if not robots:
            name = service[1:].split("/", 1)[0]
            return ServiceError(ErrorCode.UNKNOWN_ROBOT,
                                f"no robot {name!r} (robots: {', '.join(self.sim.robots) or 'none'})"
                                f"{self._dropped_note(name)}")
        robot = robots[0]
        rest = service[len(robot) + 2:]
        devices = self._device_kinds(robot)
        if rest.startswith("robot/"):
            return ServiceError(ErrorCode.UNKNOWN_SERVICE, f"no robot service {rest[6:]!r}")
        for dev in sorted(devices, key=len, reverse=True):
            if rest.startswith(dev + "/"):
                return ServiceError(ErrorCode.UNKNOWN_DEVICE,
                                    f"{devices[dev]} {robot}/{dev} has no service {rest[len(dev) + 1:]!r}")
        dev = rest.split("/", 1)[0]
        return ServiceError(ErrorCode.UNKNOWN_DEVICE,
                            f"robot {robot!r} has no device {dev!r} (devices: {', '.join(devices) or 'none'})")

    # ------------------------------------------------------------------ requests
    def handle(self, frames: Frames, now: float) -> list[Frames]:
        """One ROUTER message ``[identity, (envelope frames...), body]`` → replies to send now."""
        return self._serve(frames[:-1], frames[0] if len(frames) > 1 else b"", frames[-1], None, now)

    def handle_step(self, slot: int, identity: bytes, rid: int, duration: int | None, now: float) -> list[Frames]:
        """What :meth:`handle` returns for ``[identity, body]`` when ``body`` is the plain step request
        ``{"id": rid, "service": "/<robot>/robot/step", "args": {} or {"duration": duration}}`` of the
        robot with index ``slot``, already parsed by the transport's C step path (steppath.py); the
        same checks and handler run, only the decoding and validation of those bytes are skipped."""
        return self.handle_steps(((slot, identity, rid, duration),), now)

    def handle_steps(self, steps: Any, now: float) -> list[Frames]:
        """:meth:`handle_step` for each ``(slot, identity, rid, duration)`` of ``steps``, in order (the
        C step path's batch, up to the lockstep barrier): the replies to send now, in one call.

        The common case (the caller is the robot's attached socket, no step pending, not a repeated
        id, not quitting) is the handler's own outcome done directly: the step is queued, nothing is
        answered yet. Anything else goes the general way (:meth:`_serve`)."""
        ls = self.lockstep
        session_at, heard, request_step = ls.session_at, ls.heard, ls.request_step
        out: list[Frames] = []
        for slot, identity, rid, duration in steps:
            s = session_at(slot)
            if s is None or s.peer != identity or s.pending is not None or ls.shutting_down \
                    or (s.last_step is not None and s.last_step[0] == rid):
                out += self._serve([identity], identity, None, (slot, rid, duration), now)
                continue
            heard(identity, now)
            request_step(s, ([identity], rid), duration, now)
        return out

    def step_peers(self) -> list[tuple[bytes, bytes, int]]:
        """(identity, step service, slot) of every attached controller: the step requests the C step
        path may recognise (the caller's socket must be the attached one, as :meth:`handle` checks)."""
        return [(s.peer, self._step_services[s.slot], s.slot) for s in self.lockstep.sessions
                if isinstance(s.peer, bytes)]

    def _serve(self, envelope: Frames, peer: bytes, body: bytes | None, step: tuple[int, int, int | None] | None,
               now: float) -> list[Frames]:
        self.lockstep.heard(peer, now)
        rid: int | None = None
        try:
            if step is None:
                assert body is not None
                size = len(body) if len(envelope) == 1 else len(body) + sum(len(f) for f in envelope[1:])
                if size > self.max_request:
                    raise RequestError(ErrorCode.TOO_LARGE, f"request of {size} bytes exceeds the limit of {self.max_request} bytes")
                req = parse_request(body, self.max_request)
                rid = req.id
                service = req.service
                route = self.routes.get(service)
                if route is None:
                    raise self._unknown(service)
                args = self._validated(route.spec.args, service, req.args)
            else:
                slot, rid, duration = step
                service = self._step_service_names[slot]
                route = self.routes[service]
                args = self._validated(route.spec.args, service, {} if duration is None else {"duration": duration})
            s = None
            if route.spec.attached:
                s = self.lockstep.session_for(route.robot) if route.robot else None
                if s is None or s.peer != peer:
                    raise ServiceError(ErrorCode.NOT_ATTACHED,
                                       f"{service} needs the caller to be {route.robot!r}'s attached controller"
                                       + ("" if s is None else " (another socket is)"))
            if route.spec.supervisor and not getattr(self.sim.robots[route.robot], "supervisor", False):
                raise ServiceError(ErrorCode.NOT_SUPERVISOR,
                                   f"{service}: robot {route.robot!r} is not a supervisor "
                                   f"(set 'supervisor: true' on it in the world file)")
            if route.spec.item in roles.WORLD_CONTROLS and route.spec.scope != "device" and not self.open_controls \
                    and not roles.has_supervisor_role(self.sim, self.lockstep, peer):
                raise ServiceError(ErrorCode.NOT_SUPERVISOR, roles.denied(service))
            ctl = self.topics.controls[route.device] if route.device else None
            motor = self.sim.robots[route.robot].motors[route.motor] if route.motor else None
            call = Call(envelope, peer, rid, args, route.robot or "", cast(Control, ctl), motor, now, [], s)
            result = route.handler(call)
            if result is _DEFERRED:
                return call.extra
            return call.extra + [envelope + [self._bounded_reply(rid, result)]]
        except RequestError as exc:
            return [envelope + [error_reply(exc.id if exc.id is not None else rid, exc.code, exc.message)]]
        except (ServiceError, LockstepError) as exc:
            return [envelope + [error_reply(rid, exc.code, exc.message)]]
        except Exception as exc:  # noqa: BLE001 - a bug must not stop the server
            self.errors += 1
            self.log_error(f"internal error: {type(exc).__name__}: {exc}\n{traceback.format_exc()}")
            return [envelope + [error_reply(rid, ErrorCode.INTERNAL, f"{type(exc).__name__}: {exc}")]]

    def _bounded_reply(self, rid: int | None, result: dict) -> bytes:
        """``ok_reply``, or ``TOO_LARGE`` when it would exceed :data:`MAX_REPLY` (a client may refuse
        longer messages: the C client's libzmq drops the connection, and a step would never return)."""
        body = ok_reply(rid, result)
        if len(body) > MAX_REPLY:
            return error_reply(rid, ErrorCode.TOO_LARGE, f"the reply of {len(body):,} bytes exceeds the limit of "
                                                         f"{MAX_REPLY:,} bytes{self._reply_hint(result)}")
        return body

    @staticmethod
    def _reply_hint(result: dict) -> str:
        values = result.get("values") if isinstance(result, dict) else None
        if not isinstance(values, dict) or not values:
            return ""
        big = sorted(values, key=lambda name: -len(pack(values[name])))[:3]
        return (f" (largest values: {', '.join(big)}; read them from their topics, or enable fewer or smaller "
                f"devices or point clouds)")

    def _validated(self, model: type, service: str, raw: dict) -> Any:
        """``raw`` validated by the service's pydantic ``model`` (frozen): TOO_LARGE / INVALID_ARGUMENT
        otherwise. Flat maps of exact ``int``/``str`` values (a step's ``{"duration": 32}``, a ping's
        session) validate to the same model every time, so the model is kept and reused: equal keys
        mean equal values of the same types, so no check is skipped (bool, float and nested values
        are validated every time)."""
        key = None
        if len(raw) <= ARG_CACHE_KEYS:
            items = tuple(raw.items())
            for _, v in items:
                if type(v) is not int and type(v) is not str:
                    break
            else:
                key = (model, items)
                hit = self._arg_cache.get(key)
                if hit is not None:
                    return hit
        too_big = check_args_shape(raw)
        if too_big is not None:
            raise ServiceError(ErrorCode.TOO_LARGE, f"{service}: {too_big}")
        try:
            args = model.model_validate(raw)  # type: ignore[attr-defined]
        except ValidationError as exc:
            raise ServiceError(ErrorCode.INVALID_ARGUMENT, f"{service}: {_arg_errors(exc, model)}") from None
        if key is not None:
            if len(self._arg_cache) >= ARG_CACHE_SIZE:
                self._arg_cache.clear()               # bounded: a client varying its values only evicts
            self._arg_cache[key] = args
        return args

    def subscription(self, event: bytes) -> None:
        """An XPUB subscription event."""
        self.topics.subscription(event)

    # ------------------------------------------------------------------ stepping
    def next_advance(self, now: float) -> float | None:
        t = self.lockstep.next_advance(now)
        # (both announcements need no synchronous controller attached: skip the scan while one is)
        if not self._announced and not self.lockstep.synchronous_attached:
            self._announce()
        return t

    def _announce(self) -> None:
        """Say once (and again after the last controller left) what the world waits for."""
        ls = self.lockstep
        if self.launcher is not None:     # `sensorium run` starts the controllers and says when one ends
            self._announced = True
            return
        waiting = ls.waiting_for()
        if waiting:
            names = " or ".join(repr(r) for r in waiting)
            self.log(f"waiting for a controller to attach to robot {names} (controller \"<extern>\", "
                     f"synchronization true): the world steps when attached controllers ask it to; "
                     f"give robots nobody controls controller: \"<none>\" in the world file")
            self._announced = True
        elif ls.free_running and not ls.sessions:
            self.log(f"no robot waits for a controller (each has controller \"<none>\" or synchronization false): "
                     f"the world steps by itself in {ls.mode} mode")
            self._announced = True

    def next_deadline(self, now: float) -> float | None:
        return self.lockstep.next_deadline(now)

    def step_once(self, now: float) -> tuple[list[Frames], list[Frames]]:
        """Run one basic step: (step replies, topic messages). The caller checked
        :meth:`next_advance`. Publications come before replies (PROTOCOL §3.7)."""
        replies, pubs = self.step_once_compact(now)
        return [r if type(r) is list else self.plain_step_frames(r) for r in replies], pubs

    def step_once_compact(self, now: float) -> tuple[list[Any], list[Frames]]:
        """:meth:`step_once` with the common step reply (no new value) left as ``(envelope, rid,
        status, time_ms)``: the transport's gate packs it from :data:`STEP_REPLY_PIECES` (C: once per
        world step for every controller, without Python per reply). :meth:`plain_step_frames` turns
        one into the frames :meth:`step_once` returns; every other reply is its frames already."""
        try:
            self.sim.step()
        except Exception as exc:  # noqa: BLE001
            self.errors += 1
            self.log(f"the world failed to step; pausing: {type(exc).__name__}: {exc}\n{traceback.format_exc()}")
            self.lockstep.set_mode("pause")
            return [self._reply_error(d, ErrorCode.INTERNAL, f"the world failed to step: {exc}")
                    for d in self.lockstep.cancel_pending()], []
        if getattr(self.sim, "_movie", None) is not None:     # only a recording world renders frames
            supervisor.movie_after_step(self.sim)
        done = self.lockstep.advanced(now)
        if self.sim.time_ms != self.lockstep.time_ms:
            raise RuntimeError(f"clock mismatch: simulation {self.sim.time_ms} ms, lockstep {self.lockstep.time_ms} ms")
        try:
            pubs = self.topics.publish(self.sim.time_ms)
        except Exception as exc:  # noqa: BLE001 - a publishing bug must not stop the lockstep
            self.errors += 1
            if self.errors <= 10:
                self.log(f"internal error while publishing: {type(exc).__name__}: {exc}\n{traceback.format_exc()}")
            pubs = []
        answer = self._step_answer
        return [answer(d) for d in done], pubs

    @staticmethod
    def plain_step_frames(reply: tuple[Frames, int, int, int]) -> Frames:
        """``(envelope, rid, status, time_ms)`` → the frames of that step reply without new values:
        ``ok_reply(rid, {"status": status, "time_ms": time_ms, "values": {}})`` from its pieces."""
        envelope, rid, status, time_ms = reply
        return envelope + [b"".join((_STEP_HEAD, pack(rid), _STEP_STATUS, pack(status), _STEP_TIME, pack(time_ms),
                                     _STEP_NO_VALUES))]

    def unheard(self, seconds: float, now: float) -> None:
        """The transport read no requests for ``seconds``: not the sessions' silence (Lockstep.unheard)."""
        self.lockstep.unheard(seconds, now)

    def expire(self, now: float) -> None:
        if self.lockstep.exited:
            for s in self.lockstep.exited_sessions(now):
                self._released(s)
                self.log(f"controller of {s.robot!r} ended without detaching: session dropped, robot released")
        for s in self.lockstep.expire(now):
            self._released(s)
            self.log(f"controller of {s.robot!r} silent for {self.lockstep.liveness_s:g} s: session dropped, robot released")

    def shutdown(self) -> list[Frames]:
        """Quit: answer every pending step with status -1 (later steps too)."""
        return [self._step_reply(d) for d in self.lockstep.shutdown()]

    def _released(self, s: Session) -> None:
        self._seen.pop(s.token, None)
        self._custom_sent.pop(s.token, None)
        self.topics.release_robot(s.robot)
        supervisor.movie_released(self.sim, s.robot)
        robot = self.sim.robots[s.robot]          # the next controller starts with its battery sensor off
        self.sim.enable_battery_sensor(robot, 0)
        robot.battery_value = math.nan
        # a robot without a controller stops: with no collision response it would otherwise
        # drive through walls while the world steps for the others (Webots keeps the commands)
        for motor in self.sim.robots[s.robot].motors.values():
            motor.hold()

    def _step_reply(self, d: StepDone) -> Frames:
        r = self._step_answer(d)
        return r if isinstance(r, list) else self.plain_step_frames(r)

    def _step_answer(self, d: StepDone) -> Frames | tuple[Frames, int, int, int]:
        """The reply to a step done: its frames, or ``(envelope, rid, status, time_ms)`` for the
        common step reply without new values (:meth:`plain_step_frames`)."""
        envelope, rid = d.step.reply_to
        if d.step.kind == "time_step":
            body = ok_reply(rid, {"success": d.status != -1})
        else:
            values: dict[str, dict] = {}
            if d.status != -1 and d.session.alive and self._controls_by_robot[d.session.robot]:
                values = self._new_values(d.session)
            data = None                           # (an empty set: one test a reply)
            if self._custom_news and d.session.robot in self._custom_news and d.status != -1 and d.session.alive:
                data = self._custom_data_news(d.session)
            texts = None
            if self._window_news and d.session.robot in self._window_news and d.status != -1 and d.session.alive:
                texts = self._window_texts(d.session.robot)
            if not values and data is None and texts is None:   # most replies: no new value; the gate packs them
                plain = (envelope, rid, d.status, d.time_ms)
                d.session.last_step = (rid, plain)   # kept for a retry of a reply lost in transit
                return plain
            result: dict[str, Any] = {"status": d.status, "time_ms": d.time_ms, "values": values}
            if data is not None:
                result["custom_data"] = data
            if texts is not None:
                result["robot_window"] = texts
            body = self._bounded_reply(rid, result)
        d.session.last_step = (rid, body)         # kept for a retry of a reply lost in transit
        return envelope + [body]

    def _custom_data_news(self, session: Session) -> str | None:
        """The robot's customData when a Supervisor (or a reset) changed it since its controller last
        had it, else None: Webots sends it with the step's answer (WbRobot::updateData)."""
        self._custom_news.discard(session.robot)
        self._custom_news_ms.pop(session.robot, None)
        data = self.sim.robots[session.robot].custom_data
        if self._custom_sent.get(session.token) == data:
            return None
        self._custom_sent[session.token] = data
        return data

    def _window_texts(self, robot: str) -> list[str]:
        """The texts waiting for the robot's controller, oldest first; the queue is emptied."""
        self._window_news.discard(robot)
        q = self._window_inbox[robot]
        texts = list(q)
        q.clear()
        self._window_chars[robot] = 0
        return texts

    def _new_values(self, session: Session) -> dict[str, dict]:
        """The readings of the session's enabled devices that it has not received yet."""
        values: dict[str, dict] = {}
        seen = self._seen.setdefault(session.token, {})
        for ctl in self._robot_controls(session.robot):
            # a camera's recognition has its own period (the controller enabled it with its own service)
            rec = getattr(ctl.device, "recognition_schedule", None)
            if (ctl.controller_period > 0 or (rec is not None and rec.period_ms > 0)
                    or getattr(ctl.device, "reports_unasked", False)):     # a Speaker's state: no enable
                m = ctl.device.measurements
                if seen.get(ctl.path, 0) != m:
                    seen[ctl.path] = m
                    values[ctl.device.name] = self.topics.reading(ctl)
        return values

    def _reply_error(self, d: StepDone, code: ErrorCode, message: str) -> Frames:
        envelope, rid = d.step.reply_to
        return envelope + [error_reply(rid, code, message)]

    def _robot_controls(self, robot: str) -> list[Control]:
        return self._controls_by_robot[robot]

    def _device_kinds(self, robot: str) -> dict[str, str]:
        """Every device of a robot → its type, in Webots' tree order (unsimulated devices too)."""
        return {e.name: e.type for e in self._device_entries(robot)}

    def _device_entries(self, robot: str) -> list:
        r = self.sim.robots[robot]
        entries = getattr(r, "device_list", None)
        if entries is None:           # a stand-in simulation (tests): its devices, then its motors
            names = [(n, d.kind) for n, d in r.devices.items()] + [(n, MOTOR) for n in r.motors]
            entries = [DeviceEntry(i, k, n, "", True) for i, (n, k) in enumerate(names)]
        return entries

    # ------------------------------------------------------------------ server services
    def _srv_get_info(self, c: Call) -> dict:
        return {
            "protocol": S.PROTOCOL_VERSION,
            "version": self.version,
            "world": self.world_name,
            "basic_time_step": self.sim.basic_time_step,
            "time_ms": self.sim.time_ms,
            "mode": self.lockstep.mode,
            "real_time_factor": self.lockstep.real_time_factor(c.now),
            "pub_endpoint": self.pub_endpoint,
            "robots": [{"name": name, "controller": getattr(r, "controller", "<extern>"),
                        "synchronization": bool(r.synchronization),
                        "attached": self.lockstep.session_for(name) is not None,
                        "devices": [{"name": e.name, "type": e.type, "model": e.model, "index": e.index,
                                     "simulated": e.simulated} for e in self._device_entries(name)]}
                       for name, r in self.sim.robots.items()],
            "topics": [{"name": t.name, "type": t.type} for t in self.topics.topics],
        }

    def _dropped_note(self, robot: str) -> str:
        """Why ``robot`` is missing when the world lost it (or nodes that may have been it) at load."""
        from sensorium.server.world.report import dropped_robot_note

        loaded = getattr(self.sim, "loaded", None)
        return dropped_robot_note(getattr(loaded, "report", None), robot)

    def _srv_attach(self, c: Call) -> dict:
        if c.args.robot not in self.lockstep.robots:     # told why when the world lost it at load
            raise LockstepError(ErrorCode.UNKNOWN_ROBOT, f"no robot {c.args.robot!r} (robots: "
                                f"{', '.join(self.lockstep.robots) or 'none'}){self._dropped_note(c.args.robot)}")
        s = self.lockstep.attach(c.args.robot, c.peer, c.now)
        self._announced = False                     # say it again once the world waits again
        self.topics.release_robot(s.robot)          # a new controller starts from scratch
        # readings taken before it attached (a previous controller's) are not its own: never sent
        self._seen[s.token] = {ctl.path: getattr(ctl.device, "measurements", 0)
                               for ctl in self._robot_controls(s.robot)}
        robot = self.sim.robots[s.robot]
        self._custom_sent[s.token] = str(getattr(robot, "custom_data", ""))
        return {"session": s.token, "robot": s.robot, "basic_time_step": self.sim.basic_time_step,
                "time_ms": self.sim.time_ms, "synchronization": bool(robot.synchronization),
                "heartbeat_ms": self.lockstep.heartbeat_ms, "supervisor": bool(getattr(robot, "supervisor", False)),
                "model": str(getattr(getattr(robot, "model", None), "model", "")),
                "custom_data": str(getattr(robot, "custom_data", "")),
                "ackermann_drive": _ackermann(robot),
                "devices": self._describe_robot(s.robot)}

    def _srv_detach(self, c: Call) -> dict:
        s, done = self.lockstep.detach(c.args.session)
        self._released(s)
        if done is not None:
            c.extra.append(self._step_reply(done))
        return {}

    def _srv_ping(self, c: Call) -> dict:
        self.lockstep.ping(c.args.session, c.now)
        return {"time_ms": self.sim.time_ms}

    def _srv_set_mode(self, c: Call) -> dict:
        return {"mode": self.lockstep.set_mode(c.args.mode)}

    def _srv_get_counters(self, c: Call) -> dict:
        counters = dict(self.sim.counters)
        counters.update(self.topics.work)
        counters.setdefault("poses_built", 0)
        return {"time_ms": self.sim.time_ms, "steps": self.lockstep.steps,
                "counters": {k: int(v) for k, v in sorted(counters.items())},
                "measurements": {p: int(ctl.device.measurements) for p, ctl in self.topics.controls.items()},
                "demanded": sorted(self.topics.demanded),
                "subscriptions": sorted(self.topics.prefixes)}

    def _srv_get_services(self, c: Call) -> dict:
        kinds = {r: self._device_kinds(r) for r in self.sim.robots}
        out = []
        for name, route in sorted(self.routes.items(), key=lambda kv: kv[1].robot is not None):
            device = route.device.split("/", 1)[1] if route.device else route.motor
            out.append({"name": name, "scope": route.spec.scope, "robot": route.robot, "device": device,
                        "device_type": kinds[route.robot][device] if device else None,
                        "attached": route.spec.attached, "supervisor": route.spec.supervisor,
                        "simulated": True, "args": S.arg_types(route.spec.args)})
        for robot in self.sim.robots:           # listed devices: the client answers Webots' "no value"
            for e in self._device_entries(robot):
                if not e.simulated:
                    out.append({"name": f"/{robot}/{e.name}/*", "scope": "device", "robot": robot, "device": e.name,
                                "device_type": e.type, "attached": False, "supervisor": False,
                                "simulated": False, "args": {}})
        return {"services": out}

    # ------------------------------------------------------------------ robot services
    def _session(self, c: Call) -> Session:
        if c.session is not None:
            return c.session                                 # found by handle()
        s = self.lockstep.session_for(c.robot)
        assert s is not None and s.peer == c.peer          # checked by handle()
        return s

    def _retried_step(self, c: Call) -> bool:
        """A step request repeated with the same id (the client re-sends it when its reply may
        have been lost with a dropped connection, PROTOCOL.md): a pending one is answered on the
        caller's current route; an answered one gets its reply again. Never steps twice."""
        s = self._session(c)
        p = s.pending
        if p is not None and p.reply_to[1] == c.id:
            p.reply_to = (c.envelope, c.id)
            return True
        if p is None and s.last_step is not None and s.last_step[0] == c.id:
            body = s.last_step[1]
            if isinstance(body, tuple):                      # a reply the gate packed: the same bytes
                body = self.plain_step_frames(body)[-1]
            c.extra.append(c.envelope + [body])
            return True
        return False

    def _robot_step(self, c: Call) -> dict | None:
        if self._retried_step(c):
            return _DEFERRED
        commands = self._motor_commands(c.robot, c.args.motors) if c.args.motors else []
        packets = self._emitter_packets(c.robot, c.args.emitters) if c.args.emitters else []
        drawings = self._display_commands(c.robot, c.args.displays) if c.args.displays else []
        if c.args.duration == 0:
            # Webots' step(0): deliver the commands and the values not yet read, time stands still
            s = self._session(c)
            if s.pending is not None:
                raise ServiceError(ErrorCode.WRONG_STATE, f"robot {c.robot!r} already has a step pending")
            self._apply_motor_commands(commands)
            self._queue_packets(packets)
            self._draw(drawings)
            now: dict[str, Any] = {"status": 0, "time_ms": self.sim.time_ms, "values": self._new_values(s)}
            # Webots applies a Supervisor's field set at the next physics step: a step(0) before it carries nothing
            data = self._custom_data_news(s) if c.robot in self._custom_news \
                and self._custom_news_ms.get(c.robot, -1) < self.sim.time_ms else None
            if data is not None:
                now["custom_data"] = data
            if c.robot in self._window_news:
                now["robot_window"] = self._window_texts(c.robot)
            return now
        done = self.lockstep.request_step(self._session(c), (c.envelope, c.id), c.args.duration, c.now)
        if done is not None:                                 # quitting: -1 at once
            return {"status": done.status, "time_ms": done.time_ms, "values": {}}
        # the world has not advanced since the request arrived: Webots' "at the start of the step"
        self._apply_motor_commands(commands)
        self._queue_packets(packets)
        self._draw(drawings)
        return _DEFERRED

    def _step_device(self, robot: str, field: str, name: str, kind: str, noun: str) -> Any:
        """The device a step request's ``field`` names: of the robot and of ``kind``, else the request's error."""
        dev = self.sim.robots[robot].devices.get(name)
        if dev is None or dev.kind != kind:
            what = f"is a {dev.kind}, not {noun}" if dev is not None else "is no device of the robot"
            raise ServiceError(ErrorCode.UNKNOWN_DEVICE, f"step: {field}: {robot}/{name} {what}")
        return dev

    def _display_commands(self, robot: str, displays: dict[str, Any]) -> list[tuple[Any, Any]]:
        """(display, checked commands) of a step request; every display and command checked first,
        so that a bad one draws none of them."""
        out = []
        for name, commands in displays.items():
            dev = self._step_device(robot, "displays", name, "Display", "a display")
            try:
                out.append((dev, dev.check(commands)))
            except ValueError as exc:
                raise ServiceError(ErrorCode.INVALID_ARGUMENT, f"step: displays: {robot}/{name}: {exc}") from None
        return out

    def _draw(self, drawings: list[tuple[Any, Any]]) -> None:
        for dev, commands in drawings:
            dev.apply(commands, self.sim.time_ms)

    def _emitter_packets(self, robot: str, emitters: dict[str, Any]) -> list[tuple[Any, Any]]:
        """(emitter device, packets) of a step request; every name resolved first, so that a bad
        one queues none of them."""
        out = []
        for name, packets in emitters.items():
            dev = self._step_device(robot, "emitters", name, "Emitter", "an emitter")
            allowed = dev.config.allowed_channels
            for p in packets:
                if allowed and p.channel not in allowed:
                    raise ServiceError(ErrorCode.INVALID_ARGUMENT, f"step: emitters: {robot}/{name}: channel "
                                                                   f"{p.channel} is not one of allowed_channels {list(allowed)}")
            out.append((dev, packets))
        return out

    @staticmethod
    def _queue_packets(packets: list[tuple[Any, Any]]) -> None:
        # the emitter takes each packet's channel and range, as Webots' emitter node does
        for dev, items in packets:
            for p in items:
                dev.send(p.data, channel=p.channel, range_m=p.range)

    @staticmethod
    def _apply_motor_commands(commands: list[tuple[Any, Any]]) -> None:
        for motor, cmd in commands:
            if isinstance(motor, JointMotor):         # (the client printed Webots' warnings)
                motor.command(cmd.position, cmd.velocity, cmd.acceleration, cmd.available_force)
                continue
            if cmd.position is not None:
                motor.set_position(cmd.position)
            if cmd.velocity is not None:
                motor.command_velocity(cmd.velocity)

    def _motor_commands(self, robot: str, motors: dict[str, Any]) -> list[tuple[Any, Any]]:
        """Resolve every named motor first, so that a bad name applies none of the commands."""
        r = self.sim.robots[robot]
        out = []
        for name, cmd in motors.items():
            motor = r.motors.get(name)
            if motor is None:
                if name in r.devices:
                    raise ServiceError(ErrorCode.UNKNOWN_DEVICE, f"step: {robot}/{name} is a "
                                                                 f"{r.devices[name].config.device}, not a motor")
                raise ServiceError(ErrorCode.UNKNOWN_DEVICE, f"step: robot {robot!r} has no motor {name!r} "
                                                             f"(motors: {', '.join(r.motors) or 'none'})")
            out.append((motor, cmd))
        return out

    def _robot_time_step(self, c: Call) -> dict | None:
        if self._retried_step(c):
            return _DEFERRED
        done = self.lockstep.request_step(self._session(c), (c.envelope, c.id), c.args.value, c.now, kind="time_step")
        if done is not None:
            return {"success": False}
        return _DEFERRED

    def _robot_get_time(self, c: Call) -> dict:
        return {"value": self.sim.time_ms / 1000.0}

    def _robot_get_basic_time_step(self, c: Call) -> dict:
        return {"value": float(self.sim.basic_time_step)}

    def _robot_get_device_list(self, c: Call) -> dict:
        return {"list": list(self._device_kinds(c.robot))}

    def _robot_get_number_of_devices(self, c: Call) -> dict:
        return {"value": len(self._device_kinds(c.robot))}

    def _robot_set_pose(self, c: Call) -> dict:
        a = c.args
        if a.rotation is not None and a.quaternion is not None:
            raise ServiceError(ErrorCode.INVALID_ARGUMENT, "give either 'rotation' (axis-angle) or 'quaternion', not both")
        try:
            roles.check_pose(a.translation, a.rotation, a.quaternion)
            self.sim.robots[c.robot].set_pose(a.translation, a.rotation, a.quaternion)
        except (ValueError, ArithmeticError) as exc:
            raise ServiceError(ErrorCode.INVALID_ARGUMENT, f"set_pose: {exc}") from None
        return {"success": True}

    def _robot_get_pose(self, c: Call) -> dict:
        pose = self.sim.robots[c.robot].pose
        return {"translation": [float(v) for v in pose.translation], "quaternion": pose_quaternion(pose)}

    def _robot_get_custom_data(self, c: Call) -> dict:
        return {"value": self.sim.robots[c.robot].custom_data}

    def _robot_set_custom_data(self, c: Call) -> dict:
        self._custom_sent[self._session(c).token] = c.args.value     # its controller has it (the field too)
        if c.robot in self._custom_news and self._custom_news_ms.get(c.robot) == self.sim.time_ms:
            # a Supervisor's set (or a reset) since the world last stepped: Webots applies it at the start of
            # the next step, after this request's value, so it wins and reaches the controller with that step
            return {"success": True}
        self.sim.robots[c.robot].custom_data = c.args.value
        return {"success": True}

    def _robot_battery_sensor_enable(self, c: Call) -> dict:
        """Webots' wb_robot_battery_sensor_enable: its value (J) every period from now (NaN until the
        first; -1 without a battery, as Webots); 0 disables it (the last value stays)."""
        self.sim.enable_battery_sensor(self.sim.robots[c.robot], c.args.value)
        return {"success": True}

    def _robot_battery_sensor_get_sampling_period(self, c: Call) -> dict:
        return {"value": self.sim.robots[c.robot].battery_schedule.period_ms}

    def _robot_battery_sensor_get_value(self, c: Call) -> dict:
        return {"value": self.sim.robots[c.robot].battery_value}

    def _robot_get_model(self, c: Call) -> dict:
        return {"value": self.sim.robots[c.robot].model.model}

    def _robot_get_urdf(self, c: Call) -> dict:
        """Webots' wb_robot_get_urdf: the robot's URDF from its nodes as the world loads (world/urdf.py)."""
        robot = self.sim.robots[c.robot]
        return {"value": robot_urdf(robot.model, robot_entries(robot), c.args.prefix)}

    def _robot_wwi_send(self, c: Call) -> dict:
        """Webots' wb_robot_wwi_send_text: the controller's text for its robot window, published on
        ``/<robot>/robot_window`` now (an immediate request in Webots too), stamped with the time."""
        self.topics.robot_window(c.robot, c.args.text, self.sim.time_ms)
        return {"success": True}

    def _robot_window_send(self, c: Call) -> dict:
        """What a robot window's page sends its controller: queued for the controller's next step
        reply (wwiReceiveText reads them one per call), at most MAX_WINDOW_QUEUE texts and
        MAX_WINDOW_QUEUE_CHARS characters waiting; published on ``/<robot>/robot_window/to_controller``
        when queued (a refused one is not), stamped with the time then, so a recording has both sides."""
        q = self._window_inbox[c.robot]
        chars = self._window_chars[c.robot] + len(c.args.text)
        if len(q) >= S.MAX_WINDOW_QUEUE or chars > S.MAX_WINDOW_QUEUE_CHARS:
            raise ServiceError(ErrorCode.WRONG_STATE,
                               f"window_send: robot {c.robot!r}'s window queue is full ({len(q)} texts, "
                               f"{self._window_chars[c.robot]:,} characters waiting; at most {S.MAX_WINDOW_QUEUE} "
                               f"texts and {S.MAX_WINDOW_QUEUE_CHARS:,} characters): its controller takes them "
                               f"with its steps")
        q.append(c.args.text)
        self._window_chars[c.robot] = chars
        self._window_news.add(c.robot)
        self.topics.robot_window(c.robot, c.args.text, self.sim.time_ms, to_controller=True)
        return {"queued": len(q)}

    # ------------------------------------------------------------------ supervisor services
    def _robot_restart_controller(self, c: Call) -> dict:
        """Webots' restartController: the robot's controller ends (a pending step answers -1, the
        world waits for it no more) and the launcher (``sensorium run``) starts it again."""
        if self.launcher is None:
            raise ServiceError(ErrorCode.WRONG_STATE, "restart_controller: only `sensorium run` starts controllers; "
                                                      "an <extern> controller is restarted by whoever started it")
        try:
            target = supervisor.robot_of_node(self.sim, c.args.node)
        except ValueError as exc:
            raise ServiceError(ErrorCode.INVALID_ARGUMENT, f"restart_controller: {exc}") from None
        self._end_controller(target, c)
        self.launcher.restart(target)
        return {"success": True}

    def _end_controller(self, robot: str, c: Call) -> None:
        """The robot's controller session ends: a pending step answers -1 (sent with ``c``'s reply) and the
        world waits for it no more (restartController, a Supervisor's controller field set)."""
        ended = self.lockstep.end_controller(robot)
        if ended is not None:
            s, done = ended
            self._released(s)
            if done is not None:
                c.extra.append(self._step_reply(done))

    def _robot_world_reload(self, c: Call) -> dict:
        """Webots' worldReload: ``sensorium run`` stops this simulation (every step answers -1), loads
        the world file again (time 0) and starts every controller again."""
        if self.launcher is None:
            raise ServiceError(ErrorCode.WRONG_STATE, "world_reload: only `sensorium run` reloads a world (it "
                                                      "starts the controllers again)")
        self.launcher.reload()
        return {"success": True}

    def _robot_world_load(self, c: Call) -> dict:
        """Webots' worldLoad: ``sensorium run`` stops this simulation (every step answers -1), loads the
        named world (or says in one line why it cannot and ends) and starts its controllers."""
        if self.launcher is None:
            raise ServiceError(ErrorCode.WRONG_STATE, "world_load: only `sensorium run` loads another world (it "
                                                      "starts the new world's controllers)")
        self.launcher.load(c.robot, c.args.filename)
        return {"success": True}

    def _robot_simulation_quit(self, c: Call) -> dict:
        """Webots' simulationQuit: Webots quits, for every controller, extern ones too: the server
        stops (every step answers -1; ``sensorium run`` ends every controller after its grace) and
        ``run``/``serve`` exit with ``status``. A second call changes nothing."""
        if self.quit_status is None:
            self.quit_status = int(c.args.status)
            self.log(f"robot {c.robot!r} quit the simulation (simulationQuit({self.quit_status})) at "
                     f"{self.sim.time_ms} ms: every controller ends")
            if self.launcher is not None:
                self.launcher.quit()
            self.request_stop()
        return {"success": True}

    def _supervisor(self, item: str, c: Call) -> dict:
        """Every Supervisor service: :data:`supervisor.HANDLERS` (ValueError → INVALID_ARGUMENT)."""
        # what a set field, a reset or a loaded state may change: a robot's controller, its customData
        fields = {name: (r.controller, r.custom_data) for name, r in self.sim.robots.items()} \
            if item in ("set_field", "simulation_reset", "load_node_state") else {}
        try:
            out = supervisor.HANDLERS[item](self.sim, self.lockstep, c.robot, c.args)
        except ValueError as exc:
            raise ServiceError(ErrorCode.INVALID_ARGUMENT, f"{item}: {exc}") from None
        for line in out.pop(supervisor.LOG, ()):
            self.log_error(f"robot {c.robot!r}: {item}: {line}")
        for name, (controller, data) in fields.items():     # (through a PROTO's field too)
            robot = self.sim.robots[name]
            if robot.custom_data != data:
                self._custom_news.add(name)               # its controller gets it with its next step reply
                self._custom_news_ms[name] = self.sim.time_ms
            if robot.controller != controller:
                self._controller_changed(name, c)
        return out

    def _controller_changed(self, robot: str, c: Call) -> None:
        """Webots' WbRobot::updateControllerDir: the robot's running controller ends (a pending step
        answers -1, as restartController's) and ``sensorium run``'s launcher starts the one now named
        (``<extern>``: the robot waits for one to attach; ``""``/``<none>``: none). Under plain
        ``serve`` every controller is the user's: the value changes, nothing ends or starts (one line)."""
        name = self.sim.robots[robot].controller
        ls = self.lockstep        # "<none>": no controller attaches (as one named so in the world file)
        ls.uncontrolled = ls.uncontrolled | {robot} if name == "<none>" else ls.uncontrolled - {robot}
        if name == "<none>" and robot in ls.extern_synchronous:
            ls.extern_synchronous.remove(robot)
        if self.launcher is None:
            self.log_error(f"robot {c.robot!r}: set_field: robot {robot!r}'s controller is now {name!r}; nothing "
                           "is ended or started: only `sensorium run` starts controllers")
            return
        self._end_controller(robot, c)
        self.launcher.switch(robot, name, bool(self.sim.robots[robot].synchronization))


def _ackermann(robot: Any) -> dict | None:
    """A car-like robot's drive as ``attach`` describes it (its world entry's fields that
    ``AckermannDescription`` declares: a world-only field such as ``wheel_bottom`` stays home), else None."""
    drive = getattr(getattr(robot, "model", None), "ackermann_drive", None)
    return drive.model_dump(include=set(S.AckermannDescription.model_fields)) if drive is not None else None
