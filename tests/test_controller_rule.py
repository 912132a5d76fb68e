"""The "no controller attached" rule (PROTOCOL.md §3.7): a robot's world-file ``controller`` is
"<extern>" (default: the world waits for its synchronous controller while none is attached) or
"<none>" (never controlled, never waited for); with nobody to wait for, the world runs by itself."""

from __future__ import annotations

import itertools

import pytest
from pydantic import ValidationError
from server_fakes import FakeSim, small_world

from sensorium.schemas import world as wm
from sensorium.schemas.wire import ErrorCode
from sensorium.server.daemon.lockstep import Lockstep, LockstepError
from sensorium.server.daemon.services import Core

BASIC = 32


def machine(robots, **kw) -> Lockstep:
    counter = itertools.count()
    return Lockstep(robots, BASIC, new_token=lambda: f"t{next(counter)}", **kw)


def steps_run(ls: Lockstep, now: float = 0.0, limit: int = 10) -> int:
    n = 0
    while n < limit and (t := ls.next_advance(now)) is not None and t <= now:
        ls.advanced(now)
        n += 1
    return n


def test_world_waits_for_an_extern_synchronous_robot_until_its_controller_steps():
    ls = machine({"a": True, "b": False})
    assert ls.waiting_for() == ["a"] and not ls.free_running
    assert steps_run(ls) == 0 and ls.time_ms == 0
    s = ls.attach("a", peer=b"A", now=0.0)
    assert ls.waiting_for() == []                      # attached: ordinary lockstep from now on
    assert steps_run(ls) == 0                          # ... which waits for its step request
    ls.request_step(s, "r", 64, now=0.0)
    assert steps_run(ls) == 2 and ls.time_ms == 64
    ls.detach(s.token)
    assert ls.waiting_for() == ["a"] and steps_run(ls) == 0      # waits again once it left


def test_world_without_anyone_to_wait_for_runs_by_itself_in_fast_and_realtime_not_in_pause():
    ls = machine({"a": True, "b": False}, uncontrolled=["a"])
    assert ls.free_running and ls.waiting_for() == []
    assert steps_run(ls, limit=5) == 5 and ls.time_ms == 5 * BASIC
    ls.set_mode("pause")
    assert steps_run(ls) == 0
    ls.set_mode("realtime")
    assert ls.next_advance(10.0) == 10.0               # one step now, the next a basic step later
    ls.advanced(10.0)
    assert ls.next_advance(10.0) == pytest.approx(10.0 + BASIC / 1000)


def test_an_asynchronous_controller_does_not_hold_a_free_running_world():
    ls = machine({"b": False})
    s = ls.attach("b", peer=b"B", now=0.0)
    assert ls.free_running and steps_run(ls, limit=3) == 3           # Webots: asynchronous robots never block
    ls.request_step(s, "r", 32, now=0.0)
    done = ls.advanced(0.0)
    assert [d.session.robot for d in done] == ["b"]


def test_an_asynchronous_controller_steps_a_world_that_waits_for_others():
    ls = machine({"a": True, "b": False})
    s = ls.attach("b", peer=b"B", now=0.0)
    assert ls.waiting_for() == ["a"] and steps_run(ls) == 0
    ls.request_step(s, "r", 32, now=0.0)               # the old rule: a pending step advances the world
    assert ls.waiting_for() == [] and steps_run(ls) == 1


def test_a_robot_without_controller_refuses_to_be_attached():
    ls = machine({"a": True}, uncontrolled=["a"])
    with pytest.raises(LockstepError) as e:
        ls.attach("a", peer=b"A", now=0.0)
    assert e.value.code == ErrorCode.WRONG_STATE and '"<none>"' in e.value.message


def test_world_file_field_defaults_to_extern_and_rejects_other_values():
    world = small_world()
    assert [r.controller for r in world.robots] == ["<extern>", "<extern>"]
    assert small_world(controller="<none>").robots[0].controller == "<none>"
    # a controller's name (`sensorium run` starts controllers/NAME/; `serve` waits for it as <extern>)
    assert small_world(controller="my_controller").robots[0].controller == "my_controller"
    for bad in ("<other>", "../up", "a/b", ".."):
        with pytest.raises(ValidationError, match="controller"):
            small_world(controller=bad)


def test_core_says_once_what_it_waits_for_and_again_after_the_last_controller_left():
    lines: list[str] = []
    core = Core(FakeSim(small_world()), log=lines.append)
    for now in (0.0, 0.1, 0.2):
        assert core.next_advance(now) is None
    assert len(lines) == 1 and "'bot'" in lines[0] and '"<none>"' in lines[0] and "'free'" not in lines[0]
    # a controller attaches and leaves: the world waits again, said once more
    s = core.lockstep.attach("bot", peer=b"A", now=0.3)
    core._announced = False                            # what the attach service does
    assert core.next_advance(0.3) is None and len(lines) == 1
    core.lockstep.detach(s.token)
    core.next_advance(0.4)
    core.next_advance(0.5)
    assert len(lines) == 2


def test_core_runs_a_world_of_uncontrolled_robots_and_says_so_once():
    lines: list[str] = []
    core = Core(FakeSim(small_world(controller="<none>")), log=lines.append)
    for now in (0.0, 0.1):
        assert core.next_advance(now) == now
        core.step_once(now)
    assert core.sim.time_ms == 2 * BASIC
    assert len(lines) == 1 and "steps by itself" in lines[0]
    info = {r["name"]: r for r in core._srv_get_info(type("C", (), {"now": 0.2})())["robots"]}
    assert info["bot"]["controller"] == "<none>" and info["free"]["controller"] == "<extern>"


def test_robot_model_rejects_unknown_controller_value_with_its_path():
    with pytest.raises(ValidationError) as e:
        wm.World.model_validate({"robots": [{"name": "r", "controller": ""}]})
    assert "controller" in str(e.value)


def test_wbt_controllers_keep_their_name_or_map_to_extern_or_none(tmp_path):
    from sensorium.server.world.loader import load_world

    wbt = tmp_path / "w.wbt"
    wbt.write_text('#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 32 }\n'
                   'Robot { name "a" controller "e-puck_avoid" }\nRobot { name "b" controller "<none>" }\n'
                   'Robot { name "c" controller "" }\nRobot { name "d" }\n')
    loaded = load_world(wbt)
    assert [r.controller for r in loaded.world.robots] == ["e-puck_avoid", "<none>", "<none>", "<extern>"]
    assert not any("e-puck_avoid" in w for w in loaded.warnings)


def test_the_world_waits_for_controllers_being_started_and_an_ended_one_gets_minus_one():
    """`sensorium run`: a robot in ``starting`` holds the world until its controller attaches;
    ``end_controller`` (restartController) answers its pending step -1, releases it at once, and its
    later requests are SHUTTING_DOWN (the client's step returns -1)."""
    ls = machine({"a": True, "b": True})
    a = ls.attach("a", peer=b"A", now=0.0)
    ls.starting.add("b")
    ls.request_step(a, "ra", BASIC, now=0.0)
    assert steps_run(ls) == 0                          # b's controller is starting: the world waits
    b = ls.attach("b", peer=b"B", now=0.0)
    assert not ls.starting
    ls.request_step(b, "rb", BASIC, now=0.0)
    assert steps_run(ls, limit=1) == 1
    ls.request_step(b, "rb2", BASIC, now=0.0)
    session, done = ls.end_controller("b")
    assert session is b and done is not None and (done.status, done.step.reply_to) == (-1, "rb2")
    assert ls.session_for("b") is None and ls.end_controller("b") is None
    with pytest.raises(LockstepError) as e:
        ls.session(b.token)
    assert e.value.code == ErrorCode.SHUTTING_DOWN and "restartController" in e.value.message
    ls.request_step(a, "ra2", BASIC, now=0.0)
    assert steps_run(ls, limit=1) == 1                 # the world no longer waits for b
