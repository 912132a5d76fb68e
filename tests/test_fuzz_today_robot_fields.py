"""Hypothesis fuzz of a Supervisor's customData and controller sets (services.py, through the
sans-IO core on tests/worlds/webots_api.yaml, a launcher standing in for ``sensorium run``'s):
random sequences of the supervisor setting the rover's customData (any text, at and past the
world's limit, not a string) and controller (another name, the same, ``<extern>``, ``<none>``, ''),
the rover's controller setting its own data, stepping, detaching, attaching again, restartController
and a simulation reset. Every request gets one reply, never INTERNAL; a refusal is one line and
changes nothing; the rover's controller, after each of its steps (and at attach), has the robot's
customData as it is now; the launcher is asked only when the controller's name changes; the core's
per-session tables do not outlive the sessions."""

from __future__ import annotations

import msgpack
import pytest
from _fuzz import example_counts
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS
from test_supervisor_robot_fields import A, B, Logged, Switches

from sensorium.schemas.wire import ErrorCode
from sensorium.server.world.limits import custom_data_chars

texts = (st.text(max_size=12) | st.sampled_from(["", "gain=2", "é\x00\n", "x" * 4096, "x" * 4097]) | st.integers(0, 3)
         | st.none())
names = st.sampled_from(["wanderer", "other", "<extern>", "<none>", "", "rover_ctl", "x" * 300])
ops = st.one_of(st.tuples(st.just("sup_cd"), texts), st.tuples(st.just("own_cd"), st.text(max_size=8)),
                st.tuples(st.just("ctrl"), names), st.tuples(st.sampled_from(
                    ["step", "step", "step", "step", "detach", "attach", "attach", "restart", "reset"]), st.none()))


@pytest.mark.parametrize("examples", example_counts(200))
def test_custom_data_and_controller_sets_interleaved(examples: int):
    @settings(SETTINGS, max_examples=examples)
    @given(st.lists(ops, min_size=1, max_size=16))
    def run(seq):
        _interleaved(seq)

    run()


def _interleaved(seq) -> None:
    live = Logged()
    launcher = Switches()
    live.core.launcher = launcher
    live.core.launcher.restart = lambda robot: launcher.calls.append((robot, "restart", True))
    live.ok(A, "attach", {"robot": "pioneer"})
    first = live.ok(B, "attach", {"robot": "rover"})
    has, session = first["custom_data"], first["session"]      # what the rover's controller has
    attached = True
    rover = live.ok(A, "/pioneer/robot/get_from_def", {"name": "rover"})["node"]
    robot = live.sim.robots["rover"]
    limit = min(custom_data_chars(live.sim.limits), 4096)      # (setSFString's 4096: README)
    controller = live.ok(A, "/pioneer/robot/get_field", {"node": rover, "field": "controller"})["value"]

    def check(reply: dict) -> None:
        assert reply["ok"] or reply["error"]["code"] != ErrorCode.INTERNAL, reply
        if not reply["ok"]:
            assert "\n" not in reply["error"]["message"] and "Traceback" not in reply["error"]["message"]

    for op, arg in seq:
        before = (robot.custom_data, controller, len(launcher.calls))
        if op == "sup_cd":
            r = live.call(A, "/pioneer/robot/set_field", {"node": rover, "field": "customData", "value": arg})
            check(r)
            assert r["ok"] == (isinstance(arg, str) and len(arg) <= limit), (arg, r)
            if not r["ok"]:
                assert (robot.custom_data, controller, len(launcher.calls)) == before
        elif op == "own_cd" and attached:
            live.ok(B, "/rover/robot/set_custom_data", {"value": arg})
            has = arg
        elif op == "ctrl":
            r = live.call(A, "/pioneer/robot/set_field", {"node": rover, "field": "controller", "value": arg})
            check(r)
            if r["ok"]:
                changed = arg != controller
                assert len(launcher.calls) == before[2] + changed, (arg, controller, launcher.calls)
                if changed:
                    assert launcher.calls[-1] == ("rover", arg, True)
                    attached = False               # its controller was ended
                controller = arg
            assert live.ok(A, "/pioneer/robot/get_field", {"node": rover, "field": "controller"})["value"] == controller
        elif op == "step":
            if attached:
                rid = live.send(B, "/rover/robot/step", {"duration": 32})
            reply = live.step(A, "pioneer", {"duration": 32})
            assert reply["status"] == 0
            if attached:
                while rid not in live.pending:
                    for frames in live.core.step_once(0.0)[0]:
                        got = msgpack.unpackb(frames[-1])
                        live.pending[got["id"]] = got
                r = live.pending.pop(rid)
                check(r)
                if r["ok"] and r["result"]["status"] == 0:
                    has = r["result"].get("custom_data", has)
                    assert has == robot.custom_data, (seq, has, robot.custom_data)
        elif op == "detach" and attached:
            live.ok(B, "detach", {"session": session})
            attached = False
        elif op == "attach" and not attached:
            r = live.call(B, "attach", {"robot": "rover"})
            check(r)
            assert r["ok"] == (controller != "<none>"), (controller, r)
            if r["ok"]:
                has, session = r["result"]["custom_data"], r["result"]["session"]
                assert has == robot.custom_data
                attached = True
        elif op == "restart":
            r = live.call(A, "/pioneer/robot/restart_controller", {"node": rover})
            check(r)
            assert r["ok"] and launcher.calls[-1] == ("rover", "restart", True)
            attached = False
        elif op == "reset":
            live.ok(A, "/pioneer/robot/simulation_reset")
        # the core keeps per-session data only for live sessions
        assert len(live.core._custom_sent) <= 2 and len(live.core._seen) <= 2, (live.core._custom_sent, live.core._seen)
    live.step(A, "pioneer", {"duration": 32})
