"""The sans-IO lockstep machine, table-driven: scripted controllers in, replies out."""

from __future__ import annotations

import itertools

import pytest

from sensorium.schemas.wire import ErrorCode
from sensorium.server.daemon.lockstep import Lockstep, LockstepError

BASIC = 32


def machine(robots=None, **kw) -> Lockstep:
    counter = itertools.count()
    return Lockstep(robots or {"a": True, "b": True, "c": False}, BASIC,
                    new_token=lambda: f"t{next(counter)}", **kw)


def run(ls: Lockstep, now: float = 0.0, limit: int = 1000) -> list[tuple[int, str, int]]:
    """Advance while allowed (fast mode): [(time_ms, robot, status)] of the answered steps."""
    out = []
    for _ in range(limit):
        t = ls.next_advance(now)
        if t is None or t > now:
            break
        out += [(d.time_ms, d.session.robot, d.status) for d in ls.advanced(now)]
    return out


# ---------------------------------------------------------------------- scripted interleavings

@pytest.mark.parametrize("durations, until, expected", [
    # one synchronous controller, basic steps
    ({"a": 32}, 96, [(32, "a"), (64, "a"), (96, "a")]),
    # one controller, 3 basic steps per control step
    ({"a": 96}, 192, [(96, "a"), (192, "a")]),
    # two synchronous controllers with different durations interleave (Webots)
    ({"a": 32, "b": 64}, 128, [(32, "a"), (64, "a"), (64, "b"), (96, "a"), (128, "a"), (128, "b")]),
    ({"a": 64, "b": 96}, 192, [(64, "a"), (96, "b"), (128, "a"), (192, "a"), (192, "b")]),
    # an asynchronous controller alone runs the world
    ({"c": 32}, 64, [(32, "c"), (64, "c")]),
])
def test_interleaving(durations, until, expected):
    ls = machine()
    sessions = {r: ls.attach(r, peer=r.encode(), now=0.0) for r in durations}
    for r, s in sessions.items():
        assert ls.request_step(s, reply_to=r, duration=durations[r], now=0.0) is None
    got = []
    while ls.time_ms < until:
        assert ls.next_advance(0.0) == 0.0
        for d in ls.advanced(0.0):
            got.append((d.time_ms, d.session.robot))
            assert d.status == 0 and d.step.reply_to == d.session.robot
            ls.request_step(d.session, d.session.robot, durations[d.session.robot], now=0.0)  # re-request at once
    assert got == expected


@pytest.mark.parametrize("pending, attached, can", [
    ({}, {"a"}, False),                    # nothing pending: never advance
    ({"a"}, {"a"}, True),
    ({"a"}, {"a", "b"}, False),            # b is synchronous and has no step pending
    ({"a", "b"}, {"a", "b"}, True),
    ({"c"}, {"a", "c"}, False),            # asynchronous pending does not override a waiting sync robot
    ({"a"}, {"a", "c"}, True),             # asynchronous robots are never waited for
    ({"c"}, {"c"}, True),
    ({}, set(), False),
])
def test_advance_rule(pending, attached, can):
    ls = machine()
    sessions = {r: ls.attach(r, r.encode(), 0.0) for r in sorted(attached)}
    for r in pending:
        ls.request_step(sessions[r], r, None, 0.0)
    assert ls.can_advance() is can
    assert (ls.next_advance(0.0) is not None) is can
    assert sorted(ls.blocking()) == sorted(r for r in attached if r != "c" and r not in pending)


# ---------------------------------------------------------------------- request validation

@pytest.mark.parametrize("duration, kind, ok", [
    (None, "step", BASIC), (32, "step", 32), (96, "step", 96),
    (0, "step", None), (-32, "step", None), (33, "step", 64), (16, "step", 32), (1, "step", 32),
    (True, "step", None), (32.0, "step", None), ("32", "step", None),
    (0, "time_step", BASIC), (64, "time_step", 64), (48, "time_step", 64),   # rounded up, as Webots
])
def test_durations(duration, kind, ok):
    ls = machine()
    if ok is None:
        with pytest.raises(LockstepError) as e:
            ls.check_duration(duration, kind)
        assert e.value.code == ErrorCode.INVALID_ARGUMENT
    else:
        assert ls.check_duration(duration, kind) == ok


def test_second_step_while_pending_is_wrong_state():
    ls = machine()
    s = ls.attach("a", b"A", 0.0)
    ls.request_step(s, 1, 64, 0.0)
    with pytest.raises(LockstepError) as e:
        ls.request_step(s, 2, 32, 0.0)
    assert e.value.code == ErrorCode.WRONG_STATE
    assert run(ls) == [(64, "a", 0)]


@pytest.mark.parametrize("robot, code", [("zz", ErrorCode.UNKNOWN_ROBOT), ("a", ErrorCode.ROBOT_TAKEN)])
def test_attach_errors(robot, code):
    ls = machine()
    ls.attach("a", b"A", 0.0)
    with pytest.raises(LockstepError) as e:
        ls.attach(robot, b"B", 0.5)
    assert e.value.code == code


# ---------------------------------------------------------------------- liveness

def test_silent_controller_is_dropped_and_world_goes_on():
    ls = machine(heartbeat_ms=100)                  # dropped after 0.3 s of silence
    a, b = ls.attach("a", b"A", 0.0), ls.attach("b", b"B", 0.0)
    ls.request_step(a, "ra", None, 0.0)
    assert run(ls) == []                            # b has no step pending: world waits
    assert ls.expire(0.25) == []
    ls.heard(b"A", 0.25)                            # any request from a's socket keeps it alive
    assert [s.robot for s in ls.expire(0.31)] == ["b"]
    assert not b.alive and ls.session_for("b") is None
    assert run(ls, 0.31) == [(32, "a", 0)]
    with pytest.raises(LockstepError) as e:         # b's session token is gone
        ls.ping(b.token, 0.4)
    assert e.value.code == ErrorCode.NOT_ATTACHED
    assert ls.attach("b", b"B2", 0.4).robot == "b"  # and the robot is free again


def test_ping_keeps_alive_and_dead_session_can_be_replaced():
    ls = machine(heartbeat_ms=100)
    a = ls.attach("a", b"A", 0.0)
    ls.ping(a.token, 0.2)
    assert ls.expire(0.45) == []
    assert ls.next_deadline(0.45) == pytest.approx(0.5)
    # not yet collected, but dead: a newcomer takes the robot over
    b = ls.attach("a", b"B", 0.6)
    assert b.token != a.token and not a.alive


def test_dropped_pending_step_is_discarded():
    ls = machine(heartbeat_ms=100)
    a, c = ls.attach("a", b"A", 0.0), ls.attach("c", b"C", 0.0)
    ls.request_step(a, "ra", 64, 0.0)
    ls.request_step(c, "rc", 128, 0.0)
    run(ls)                                         # 64: a answered, a silent afterwards
    ls.ping(c.token, 0.5)
    assert [s.robot for s in ls.expire(0.5)] == ["a"]
    assert run(ls, 0.5) == [(128, "c", 0)]


def test_detach_answers_pending_step_with_minus_one():
    ls = machine()
    a = ls.attach("a", b"A", 0.0)
    ls.request_step(a, "ra", 64, 0.0)
    s, done = ls.detach(a.token)
    assert done.status == -1 and done.step.reply_to == "ra"
    assert ls.session_for("a") is None and not ls.can_advance()


# ---------------------------------------------------------------------- asynchronous status

def test_async_status_is_lateness():
    ls = machine()
    a, c = ls.attach("a", b"A", 0.0), ls.attach("c", b"C", 0.0)
    ls.request_step(c, "c1", 32, 0.0)
    ls.request_step(a, "a1", 96, 0.0)
    assert run(ls) == [(32, "c", 0), (96, "a", 0)]   # first step: dt 0
    ls.request_step(c, "c2", 32, 0.0)                # requested at 96, previous reply at 32: 64 ms late
    ls.request_step(a, "a2", 32, 0.0)
    assert run(ls) == [(128, "a", 0), (128, "c", 64)]


# ---------------------------------------------------------------------- shutdown, modes, pacing

def test_shutdown():
    ls = machine()
    a, b = ls.attach("a", b"A", 0.0), ls.attach("b", b"B", 0.0)
    ls.request_step(a, "ra", 64, 0.0)
    done = ls.shutdown()
    assert [(d.session.robot, d.status, d.step.reply_to) for d in done] == [("a", -1, "ra")]
    late = ls.request_step(b, "rb", 32, 0.0)         # later steps: -1 at once
    assert late is not None and late.status == -1
    assert not ls.can_advance() and ls.next_advance(0.0) is None
    with pytest.raises(LockstepError) as e:
        ls.attach("c", b"C", 0.0)
    assert e.value.code == ErrorCode.SHUTTING_DOWN


def test_pause_and_modes():
    ls = machine()
    a = ls.attach("a", b"A", 0.0)
    ls.request_step(a, 1, None, 0.0)
    ls.set_mode("pause")
    assert ls.next_advance(0.0) is None and ls.can_advance()
    ls.set_mode("fast")
    assert ls.next_advance(5.0) == 5.0
    with pytest.raises(LockstepError) as e:
        ls.set_mode("slow")
    assert e.value.code == ErrorCode.INVALID_ARGUMENT


def test_realtime_pacing():
    ls = machine(mode="realtime")
    a = ls.attach("a", b"A", 0.0)
    now = 10.0
    times = []
    for _ in range(3):
        ls.request_step(a, 1, None, now)
        t = ls.next_advance(now)
        times.append(round(t - 10.0, 6))
        now = max(now, t)
        ls.advanced(now)
    assert times == [0.0, 0.032, 0.064]             # one basic step per 32 ms of wall time
    # a controller late by seconds does not cause a burst of catch-up steps
    ls.request_step(a, 1, None, 20.0)
    assert ls.next_advance(20.0) == 20.0
    ls.advanced(20.0)
    ls.request_step(a, 1, None, 20.0)
    assert ls.next_advance(20.0) == pytest.approx(20.032)


def test_real_time_factor():
    ls = machine()
    a = ls.attach("a", b"A", 0.0)
    assert ls.real_time_factor(0.0) == 0.0
    for i in range(1, 11):                           # 10 steps of 32 ms in 0.16 s: RTF 2
        ls.request_step(a, i, None, i * 0.016)
        ls.advanced(i * 0.016)
    assert ls.real_time_factor(0.16) == pytest.approx(2.0, rel=0.12)
    assert ls.real_time_factor(5.0) == 0.0           # idle


def test_deterministic_answer_order():
    """Replies after a step come in attach order whatever the request order."""
    ls = machine()
    a, b, c = (ls.attach(r, r.encode(), 0.0) for r in "abc")
    for s in (c, b, a):
        ls.request_step(s, s.robot, None, 0.0)
    assert run(ls) == [(32, "a", 0), (32, "b", 0), (32, "c", 0)]


def test_a_robot_whose_controllers_vanish_before_stepping_rests():
    """A client that attaches a free robot and disconnects, again and again, held the world for
    3 heartbeats each time. From the second such vanishing the robot rests 1, 2, 4 … s (at most
    60) before it can be attached again, so the world mostly steps; a controller that steps clears it."""
    from sensorium.server.daemon.lockstep import Lockstep, LockstepError

    ls = Lockstep({"a": True, "b": True}, basic_time_step=32, heartbeat_ms=1000)
    stepper = ls.attach("b", peer=b"B", now=0.0)
    blocked = 0.0
    t = 0.0
    while t < 120.0:                            # the attacker tries every 0.5 s; b steps and pings
        ls.ping(stepper.token, t)
        try:
            ls.attach("a", peer=b"X%d" % int(t * 2), now=t)
        except LockstepError as exc:
            assert exc.code in (ErrorCode.ROBOT_TAKEN,)
        ls.expire(t)
        if ls.session_for("a") is not None:
            blocked += 0.5                      # a attached and silent: the world waits for it
        t += 0.5
    assert blocked / 120.0 < 0.3, blocked       # 0.23 with the rest; without it 1.0 (always waiting)
    vanished, until = ls._rest["a"]
    assert vanished >= 5 and until - 120.0 <= 60.0
    with pytest.raises(LockstepError) as e:
        ls.attach("a", peer=b"late", now=until - 0.1)
    assert "went silent before their first step" in e.value.message
    s = ls.attach("a", peer=b"good", now=until)          # after the rest: a real controller
    ls.request_step(s, "r", None, now=until)
    assert "a" not in ls._rest                            # it stepped: the rest is forgotten
