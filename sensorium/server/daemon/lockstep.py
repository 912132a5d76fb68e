"""Webots lockstep as a pure state machine (PROTOCOL.md §3.3, §3.7; wire.md §2.2, §5.3).

No sockets, no clock: the driver passes wall time (``now``, seconds, monotonic) into every call
that needs it and does the I/O. The machine decides:

* who is attached to which robot, and who is still alive (last heard + 3 heartbeats, not counting
  the time the server itself did not read requests: :meth:`Lockstep.unheard`);
* whether the world may advance one basic step now (every attached synchronous controller has a
  step pending, at least one step is pending, the mode allows it, real-time pacing allows it) - or
  runs by itself: when no synchronous controller is attached and no robot waits for one (every
  robot's controller is ``"<none>"`` or asynchronous), as Webots runs robots without a controller;
* which pending steps are answered after a basic step (wake time reached), and with which status
  (0; -1 on shutdown; the lateness ``dt`` for asynchronous robots).

    ls = Lockstep({"epuck": True}, basic_time_step=32)
    s = ls.attach("epuck", peer=b"A", now=0.0)
    ls.request_step(s, reply_to="r1", duration=64, now=0.0)
    while ls.next_advance(now) is not None and ls.next_advance(now) <= now:
        sim.step(); done = ls.advanced(now)     # -> [StepDone(...)] once 64 ms have passed
"""

from __future__ import annotations

import secrets
from collections import deque
from collections.abc import Callable, Hashable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from sensorium.schemas.wire import ErrorCode

__all__ = ["Lockstep", "LockstepError", "Session", "PendingStep", "StepDone", "MODES"]

MODES = ("fast", "realtime", "pause")
STATUS_QUIT = -1
REST_MAX_S = 60.0      # longest rest of a robot whose controllers keep vanishing
ENDED_KEPT = 1024       # tokens of ended controllers remembered (their late requests answer SHUTTING_DOWN)
REST_CLEAR_S = 60.0    # a session heard from for this long after attaching is no vanishing one: the count restarts
RTF_WINDOW_S = 1.0


class LockstepError(Exception):
    """A request the machine refuses; ``code`` is the protocol error code to answer with."""

    def __init__(self, code: ErrorCode, message: str):
        super().__init__(f"{code.name}: {message}")
        self.code = code
        self.message = message


@dataclass(slots=True)
class PendingStep:
    reply_to: Any            # opaque to the machine: what the driver needs to answer
    kind: str                # "step" or "time_step"
    duration_ms: int
    requested_ms: int        # simulated time when the request arrived
    wake_ms: int             # requested_ms + duration_ms


@dataclass(slots=True, eq=False)
class Session:
    token: str
    robot: str
    peer: Hashable           # the ROUTER identity of the attached socket
    synchronous: bool
    last_heard: float
    pending: PendingStep | None = None
    last_reply_ms: int | None = None     # simulated time of the previous step reply (async dt)
    alive: bool = True
    # (request id, reply body) of the last answered step; the body as (envelope, rid, status, time_ms)
    # for a step reply without new values (services.Core.plain_step_frames makes its bytes)
    last_step: tuple[Any, bytes | tuple] | None = None
    stepped: bool = False                # asked for a step at least once
    attached_at: float = 0.0             # wall time of the attach
    slot: int = 0                        # the robot's index in the world (the transport's step path names it so)

    @property
    def lived_s(self) -> float:
        """How long the controller was heard from after attaching (wall seconds)."""
        return self.last_heard - self.attached_at


@dataclass(slots=True)
class StepDone:
    """A pending step to answer now: ``status`` 0, -1 (quit) or the asynchronous lateness."""

    session: Session
    step: PendingStep
    status: int
    time_ms: int


class Lockstep:
    """Sessions, pending steps, run mode and pacing of one world.

    ``robots`` maps each robot name to its ``synchronization`` flag; ``uncontrolled`` names the
    robots whose world-file ``controller`` is ``"<none>"`` (never attached, never waited for).
    ``new_token`` makes session tokens (default: 16 random hex digits); tests inject a
    deterministic one."""

    def __init__(self, robots: Mapping[str, bool], basic_time_step: int, *, heartbeat_ms: int = 1000,
                 mode: str = "fast", time_ms: int = 0, new_token: Callable[[], str] | None = None,
                 uncontrolled: Iterable[str] = ()):
        if basic_time_step <= 0:
            raise ValueError("basic_time_step must be > 0")
        if heartbeat_ms <= 0:
            raise ValueError("heartbeat_ms must be > 0")
        self.robots = dict(robots)
        self._slots = {name: i for i, name in enumerate(self.robots)}
        self._by_slot: list[Session | None] = [None] * len(self.robots)
        self.generation = 0                          # changes whenever a session comes or goes
        self.uncontrolled = frozenset(uncontrolled)
        # robots with an "<extern>" synchronous controller: while none of them is attached, the
        # world waits for one (Webots waits for a synchronous extern controller to connect)
        self.extern_synchronous = [r for r, sync in self.robots.items() if sync and r not in self.uncontrolled]
        self.basic_time_step = int(basic_time_step)
        self.heartbeat_ms = int(heartbeat_ms)
        self.time_ms = int(time_ms)
        self.steps = 0
        self.mode = self._check_mode(mode)
        self.shutting_down = False
        self._new_token = new_token or (lambda: secrets.token_hex(8))
        self._by_robot: dict[str, Session] = {}
        self.synchronous_attached = 0                # attached sessions with synchronization true
        self._by_token: dict[str, Session] = {}
        self._by_peer: dict[Hashable, list[Session]] = {}
        # robot -> (controllers in a row that vanished within REST_CLEAR_S of attaching, no attach before this time)
        self._rest: dict[str, tuple[int, float]] = {}
        self._rt_next: float | None = None          # realtime: earliest wall time of the next step
        self._rtf: deque[tuple[float, int]] = deque()
        self._ended: dict[str, str] = {}             # token -> robot of controllers ended (end_controller)
        # robots whose controller `sensorium run` started and that have not attached yet: the world waits
        # for them, as Webots waits for the controllers it starts (set by the launcher's thread: one add/discard)
        self.starting: set[str] = set()
        # robots whose controller process, started by `sensorium run`, ended by itself (a crash: no detach), and
        # the wall time it was seen to end (the transport's clock): a session attached before then is that
        # process's and is dropped at once, not after liveness_s of silence (set by the launcher's thread)
        self.exited: dict[str, float] = {}

    # ------------------------------------------------------------------ sessions
    @property
    def liveness_s(self) -> float:
        """A session not heard from for longer than this is dropped (3 heartbeats)."""
        return 3 * self.heartbeat_ms / 1000.0

    @property
    def sessions(self) -> list[Session]:
        return list(self._by_robot.values())

    def session_for(self, robot: str) -> Session | None:
        return self._by_robot.get(robot)

    def session_at(self, slot: int) -> Session | None:
        """The session of the robot with index ``slot`` (:attr:`Session.slot`)."""
        return self._by_slot[slot]

    def session(self, token: str) -> Session:
        s = self._by_token.get(token)
        if s is None:
            robot = self._ended.get(token)
            if robot is not None:         # its controller was ended: its steps answer -1, as when quitting
                raise LockstepError(ErrorCode.SHUTTING_DOWN, f"the controller of robot {robot!r} was ended "
                                                             "(restartController)")
            raise LockstepError(ErrorCode.NOT_ATTACHED, "no such session (detached, dropped after missing "
                                                        "heartbeats, or never attached)")
        return s

    def attach(self, robot: str, peer: Hashable, now: float) -> Session:
        if self.shutting_down:
            raise LockstepError(ErrorCode.SHUTTING_DOWN, "the server is quitting")
        if robot not in self.robots:
            raise LockstepError(ErrorCode.UNKNOWN_ROBOT, f"no robot {robot!r} (robots: {', '.join(self.robots) or 'none'})")
        if robot in self.uncontrolled:
            raise LockstepError(ErrorCode.WRONG_STATE, f"robot {robot!r} has controller \"<none>\" (its world file's or a "
                                                       "Supervisor's): it takes no controller (set controller: "
                                                       "\"<extern>\")")
        current = self._by_robot.get(robot)
        if current is not None and now - current.last_heard > self.liveness_s:
            self._drop(current, now)              # dead but not yet collected
        vanished, until = self._rest.get(robot, (0, 0.0))
        if now < until:
            raise LockstepError(ErrorCode.ROBOT_TAKEN,
                                f"robot {robot!r} takes no controller for another {until - now:.1f} s: the last "
                                f"{vanished} controllers that attached to it went silent without detaching, each "
                                f"within {REST_CLEAR_S:g} s (PROTOCOL.md, 'Sessions and liveness')")
        if self._by_robot.get(robot) is not None:
            raise LockstepError(ErrorCode.ROBOT_TAKEN, f"robot {robot!r} already has a live controller attached")
        token = self._new_token()
        while token in self._by_token:
            token = self._new_token()
        s = Session(token, robot, peer, self.robots[robot], now, attached_at=now, slot=self._slots[robot])
        self.starting.discard(robot)
        self.generation += 1
        self._by_robot[robot] = s
        self._by_slot[s.slot] = s
        self.synchronous_attached += s.synchronous
        self._by_token[token] = s
        self._by_peer.setdefault(peer, []).append(s)
        return s

    def end_controller(self, robot: str) -> tuple[Session, StepDone | None] | None:
        """End the controller attached to ``robot`` (Webots' restartController): its session is
        released at once, so the world waits for it no more; a pending step is answered with -1 and
        its later requests with ``SHUTTING_DOWN`` (the client's steps return -1). None if no
        controller is attached."""
        s = self._by_robot.get(robot)
        if s is None:
            return None
        done = StepDone(s, s.pending, STATUS_QUIT, self.time_ms) if s.pending is not None else None
        self._remove(s)
        self._ended[s.token] = robot
        if len(self._ended) > ENDED_KEPT:                # the oldest ones have long gone
            del self._ended[next(iter(self._ended))]
        return s, done

    def detach(self, token: str) -> tuple[Session, StepDone | None]:
        """Release a robot; a pending step is answered with -1 (the controller is leaving)."""
        s = self.session(token)
        done = None
        if s.pending is not None:
            done = StepDone(s, s.pending, STATUS_QUIT, self.time_ms)
        self._remove(s)
        if s.lived_s >= REST_CLEAR_S:
            self._rest.pop(s.robot, None)           # a controller that lived and said goodbye
        return s, done

    def heard(self, peer: Hashable, now: float) -> None:
        """Any request arrived from ``peer``: its sessions are alive."""
        sessions = self._by_peer.get(peer)
        if sessions:
            for s in sessions:
                s.last_heard = now

    def unheard(self, seconds: float, now: float) -> None:
        """The server read no requests for ``seconds`` (a long step, a long request, an over-long
        message dropped frame by frame): requests that came meanwhile waited in the socket, so that
        time does not count toward any session's silence (never blame a peer for the server's stall)."""
        if seconds <= 0:
            return
        for s in self._by_robot.values():
            s.last_heard = min(s.last_heard + seconds, now)

    def ping(self, token: str, now: float) -> Session:
        s = self.session(token)
        s.last_heard = now
        return s

    def exited_sessions(self, now: float) -> list[Session]:
        """Drop the sessions of the processes in :attr:`exited` (each as a silent one is dropped)."""
        dead = []
        for robot in list(self.exited):
            ended_at = self.exited.pop(robot)
            s = self._by_robot.get(robot)
            if s is not None and s.attached_at <= ended_at:      # not a controller that attached since
                self._drop(s, now)
                dead.append(s)
        return dead

    def expire(self, now: float) -> list[Session]:
        """Drop sessions not heard from for :attr:`liveness_s`; their pending steps are discarded."""
        dead = [s for s in self._by_robot.values() if now - s.last_heard > self.liveness_s]
        for s in dead:
            self._drop(s, now)
        return dead

    def _drop(self, s: Session, now: float) -> None:
        """Remove a session that went silent.

        Its robot's wait cost the world up to :attr:`liveness_s`. A client that attaches (and
        perhaps steps) and vanishes, in a loop, would hold every other robot most of the time; so
        vanishings in a row of sessions that lived less than :data:`REST_CLEAR_S` are counted per
        robot, and from the second one the robot rests 1, 2, 4 … 60 s before it may be attached
        again: the world then waits at most ``liveness_s`` per ``liveness_s`` + 60 s for that
        robot (~5 % with the default heartbeat). A session that lived longer restarts the count."""
        self._remove(s)
        vanished = 1 if s.lived_s >= REST_CLEAR_S else self._rest.get(s.robot, (0, 0.0))[0] + 1
        rest = 0.0 if vanished == 1 else min(REST_MAX_S, 2.0 ** (vanished - 2))
        self._rest[s.robot] = (vanished, now + rest)

    def _remove(self, s: Session) -> None:
        self.generation += 1
        s.alive = False
        s.pending = None
        if self._by_robot.get(s.robot) is s:
            self.synchronous_attached -= s.synchronous
            self._by_robot.pop(s.robot, None)
            self._by_slot[s.slot] = None
        self._by_token.pop(s.token, None)
        peers = self._by_peer.get(s.peer)
        if peers is not None:
            if s in peers:
                peers.remove(s)
            if not peers:
                del self._by_peer[s.peer]

    # ------------------------------------------------------------------ steps
    def check_duration(self, duration: int | None, kind: str = "step") -> int:
        """The step duration in ms: ``None`` (and 0 for ``time_step``) is one basic step; otherwise a
        positive integer, rounded up to a multiple of the basic time step as Webots does (the
        controller wakes at the first basic step that ends at or after the requested time), else
        :class:`LockstepError` INVALID_ARGUMENT."""
        if duration is None or (kind == "time_step" and duration == 0):
            return self.basic_time_step
        if type(duration) is int and duration > 0:          # the common case, checked by type alone
            return -(-duration // self.basic_time_step) * self.basic_time_step
        if isinstance(duration, bool) or not isinstance(duration, int) or duration <= 0:
            raise LockstepError(ErrorCode.INVALID_ARGUMENT, f"duration must be a positive integer (ms), got {duration!r}")
        return -(-duration // self.basic_time_step) * self.basic_time_step

    def request_step(self, session: Session, reply_to: Any, duration: int | None, now: float,
                     kind: str = "step") -> StepDone | None:
        """Queue a step; returns a :class:`StepDone` to answer at once (status -1 while quitting),
        else ``None`` (answered by a later :meth:`advanced`)."""
        if not session.alive:
            raise LockstepError(ErrorCode.NOT_ATTACHED, f"session for robot {session.robot!r} was dropped")
        d = self.check_duration(duration, kind)
        if session.pending is not None:
            raise LockstepError(ErrorCode.WRONG_STATE, f"robot {session.robot!r} already has a step pending "
                                                       f"(wake at {session.pending.wake_ms} ms)")
        session.last_heard = now
        session.stepped = True
        step = PendingStep(reply_to, kind, d, self.time_ms, self.time_ms + d)
        if self.shutting_down:
            return StepDone(session, step, STATUS_QUIT, self.time_ms)
        session.pending = step
        return None

    def blocking(self) -> list[str]:
        """Attached synchronous robots without a pending step (the world waits for them)."""
        return [s.robot for s in self._by_robot.values() if s.synchronous and s.pending is None]

    def waiting_slots(self) -> list[int]:
        """The :attr:`Session.slot` of every attached synchronous robot without a pending step."""
        return [s.slot for s in self._by_robot.values() if s.synchronous and s.pending is None]

    def can_advance(self) -> bool:
        """Lockstep rule alone (no mode, no pacing): no attached synchronous controller without a
        step pending, and either some step pending or nobody to wait for (:attr:`free_running`)."""
        if self.shutting_down or self.starting:
            return False
        any_pending = False
        any_synchronous = False
        for s in self._by_robot.values():
            if s.synchronous:
                any_synchronous = True
                if s.pending is None:
                    return False
            if s.pending is not None:
                any_pending = True
        return any_pending or (not any_synchronous and not self.extern_synchronous)

    @property
    def free_running(self) -> bool:
        """The world steps by itself (mode permitting): no synchronous controller is attached and
        no robot waits for one."""
        return not self.extern_synchronous and not any(s.synchronous for s in self._by_robot.values())

    def waiting_for(self) -> list[str]:
        """The robots whose controller the world waits for before it can step again: every
        ``"<extern>"`` synchronous robot while no controller at all has a step pending and no
        synchronous one is attached (empty otherwise)."""
        if self.shutting_down or any(s.synchronous or s.pending is not None for s in self._by_robot.values()):
            return []
        return list(self.extern_synchronous)

    def next_advance(self, now: float) -> float | None:
        """Wall time at which the next basic step may run (``<= now``: run it now), or ``None``
        while blocked or paused."""
        if self.mode == "pause" or not self.can_advance():
            return None
        if self.mode == "fast":
            return now
        dt = self.basic_time_step / 1000.0
        if self._rt_next is None or self._rt_next < now - dt:
            self._rt_next = now                     # idle or late by more than a step: no catch-up burst
        return self._rt_next

    def advanced(self, now: float) -> list[StepDone]:
        """The driver ran one basic step: advance the clock, return the steps to answer now (in
        attach order, deterministic)."""
        self.time_ms += self.basic_time_step
        self.steps += 1
        if self.mode == "realtime":
            base = self._rt_next if self._rt_next is not None else now
            self._rt_next = base + self.basic_time_step / 1000.0
        self._rtf.append((now, self.time_ms))
        while len(self._rtf) > 2 and self._rtf[1][0] < now - RTF_WINDOW_S:
            self._rtf.popleft()
        done = []
        for s in self._by_robot.values():
            p = s.pending
            if p is not None and p.wake_ms <= self.time_ms:
                done.append(StepDone(s, p, self._status(s, p), self.time_ms))
                s.pending = None
                s.last_reply_ms = self.time_ms
        return done

    def _status(self, s: Session, p: PendingStep) -> int:
        if s.synchronous:
            return 0
        # asynchronous: simulated ms that passed between the previous reply and this request
        return 0 if s.last_reply_ms is None else max(0, p.requested_ms - s.last_reply_ms)

    # ------------------------------------------------------------------ mode, shutdown, timing
    @staticmethod
    def _check_mode(mode: str) -> str:
        if mode not in MODES:
            raise LockstepError(ErrorCode.INVALID_ARGUMENT, f"mode must be one of {', '.join(MODES)}, got {mode!r}")
        return mode

    def set_mode(self, mode: str) -> str:
        self.mode = self._check_mode(mode)
        self._rt_next = None
        return self.mode

    def shutdown(self) -> list[StepDone]:
        """Quit: every pending step is answered with -1; later steps too (:meth:`request_step`)."""
        self.shutting_down = True
        done = []
        for s in self._by_robot.values():
            if s.pending is not None:
                done.append(StepDone(s, s.pending, STATUS_QUIT, self.time_ms))
                s.pending = None
        return done

    def cancel_pending(self) -> list[StepDone]:
        """Take every pending step out (the driver answers them with an error), e.g. after the
        world failed to step. Status is -1."""
        done = []
        for s in self._by_robot.values():
            if s.pending is not None:
                done.append(StepDone(s, s.pending, STATUS_QUIT, self.time_ms))
                s.pending = None
        return done

    def real_time_factor(self, now: float) -> float:
        """Simulated seconds per wall second over about the last second (0 when no step ran)."""
        while len(self._rtf) > 1 and self._rtf[1][0] < now - RTF_WINDOW_S:
            self._rtf.popleft()
        if not self._rtf or now - self._rtf[-1][0] > RTF_WINDOW_S:
            return 0.0
        wall0, sim0 = self._rtf[0]
        if now <= wall0:
            return 0.0
        return (self.time_ms - sim0) / 1000.0 / (now - wall0)

    def next_deadline(self, now: float) -> float | None:
        """The next wall time at which something happens without a new message: a session expiry
        or a paced step. ``None``: nothing scheduled."""
        times: Iterable[float] = [s.last_heard + self.liveness_s for s in self._by_robot.values()]
        t = min(times, default=None)
        nxt = self.next_advance(now)
        if nxt is not None:
            t = nxt if t is None else min(t, nxt)
        return t
