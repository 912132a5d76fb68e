"""Hypothesis fuzz of the Python client's Supervisor ``setVelocity`` (sensorium/client/wb_supervisor.py) without
a server: velocities of every shape (lists and tuples of 0..8 items, NaN, infinities, -0.0, denormals, ints past
a double, strings, None, nested lists, numpy arrays) on node ids valid and not. Each call returns None and
prints at most one line; six finite zeros on a node other than the root ask the server ``reset_physics`` of
that node and print nothing; on the root (no Solid) they print Webots' warning and ask nothing (the root's
``reset_physics`` would stop every falling solid); any other velocity asks nothing (but the node's type)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from _fuzz import example_counts
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS
from test_movie import _FakeSupervisor

from sensorium.client import wb_supervisor as ws

FUNC = "wb_supervisor_node_set_velocity"
number = (st.floats(allow_nan=True, allow_infinity=True) | st.sampled_from([0, -0.0, 0.0, 5e-324, 1 << 2000, True])
          | st.integers(-(1 << 70), 1 << 70))
item = number | st.sampled_from(["0", "x", None, [0.0], b"\0"])
velocity = (st.lists(number, min_size=0, max_size=8) | st.lists(item, min_size=6, max_size=6)
            | st.lists(number, min_size=6, max_size=6).map(tuple)
            | st.lists(st.floats(-1e3, 1e3), min_size=6, max_size=6).map(np.array)
            | st.sampled_from([None, "000000", "123456", 0, 0.0, {}, [[0.0] * 6], np.zeros(6), np.zeros((2, 3))]))
node = st.sampled_from([0, 7, 7, 7, 1 << 24, -1, None, True, 1 << 31, 2.0, "7"])


def _six_finite_zeros(v) -> bool:
    if isinstance(v, str):
        return False
    try:
        wire = [float(x) for x in v]
    except (TypeError, ValueError, OverflowError):
        return False
    return len(wire) == 6 and all(math.isfinite(x) and x == 0.0 for x in wire)


@pytest.mark.parametrize("examples", example_counts(600))
def test_set_velocity_answers_each_call_with_at_most_one_line(monkeypatch, capsys, examples: int) -> None:
    fake = _FakeSupervisor()
    monkeypatch.setattr(ws, "_supervisor", lambda func: fake)

    @settings(SETTINGS, max_examples=examples)
    @given(n=node, v=velocity)
    def run(n, v) -> None:
        ws._set_velocity_warned.clear()          # (each example: the warning not yet printed)
        fake.calls.clear()
        assert ws.wb_supervisor_node_set_velocity(n, v) is None
        err = capsys.readouterr().err
        asked = [c for c in fake.calls if not c.endswith("/get_from_id")]      # (the node's type: a question only)
        assert err.count("\n") <= 1 and (err == "" or err.endswith("\n")), err
        valid_node = isinstance(n, int) and not isinstance(n, bool) and 0 <= n < 1 << 31
        if valid_node and _six_finite_zeros(v) and n != 0:
            assert asked == ["/boss/robot/reset_physics"] and err == ""
        else:
            assert asked == [], (n, v)
            assert err.startswith(("Error: ", "Warning: ")) and FUNC in err, (n, v, err)
        if valid_node and n == 0 and _six_finite_zeros(v):
            assert err == f"Warning: {FUNC}() can exclusively be used with a Solid.\n"
    run()


def test_set_velocity_of_the_root_or_of_characters_asks_nothing(monkeypatch, capsys) -> None:
    """Regressions: six zeros on the root asked the root's reset_physics (every falling solid stopped;
    Webots warns that setVelocity takes a Solid and sets nothing); a string of six digits was six numbers;
    an int past a double raised OverflowError out of the call; an endless iterator never returned; a long
    list of non-numbers was written whole in the line."""
    fake = _FakeSupervisor()
    monkeypatch.setattr(ws, "_supervisor", lambda func: fake)
    monkeypatch.setattr(ws, "_set_velocity_warned", [])
    ws.wb_supervisor_node_set_velocity(0, [0.0] * 6)
    assert capsys.readouterr().err == f"Warning: {FUNC}() can exclusively be used with a Solid.\n"
    ws.wb_supervisor_node_set_velocity(7, "000000")
    assert capsys.readouterr().err == f"Error: {FUNC}(): expected 6 numbers, got '000000'.\n"
    ws.wb_supervisor_node_set_velocity(7, [1 << 1100] + [0] * 5)
    assert capsys.readouterr().err.startswith(f"Error: {FUNC}(): expected 6 numbers, got [")
    assert fake.calls == []
    ws.wb_supervisor_node_set_velocity(7, itertools.repeat(0.0))            # endless: 7 read, refused
    assert capsys.readouterr().err == f"Error: {FUNC}(): expected 6 numbers, got more than 6.\n"
    ws.wb_supervisor_node_set_velocity(7, (0.0 for _ in range(6)))          # a generator of six zeros: served
    ws.wb_supervisor_node_set_velocity(7, [0.0] * 100)
    assert capsys.readouterr().err == f"Error: {FUNC}(): expected 6 numbers, got 100.\n"
    ws.wb_supervisor_node_set_velocity(7, ["x"] * 100_000)                  # its line stays short
    assert len(capsys.readouterr().err) < 200
    assert fake.calls == ["/boss/robot/get_from_id", "/boss/robot/reset_physics"]
    ws.wb_supervisor_node_set_velocity(7, np.zeros(6))
    assert fake.calls == ["/boss/robot/get_from_id", "/boss/robot/reset_physics"] * 2 and capsys.readouterr().err == ""


class _TypedSupervisor(_FakeSupervisor):
    """The fake, its get_from_id answering a node of type ``kind``."""

    kind = "Solid"

    def call(self, service: str, args: dict | None = None) -> dict:
        super().call(service, args)
        return {"type": self.kind, "id": 7} if service.endswith("/get_from_id") else {}


@pytest.mark.parametrize(("kind", "solid"), [
    ("Solid", True), ("Robot", True), ("Charger", True), ("Track", True), ("Camera", True), ("Connector", True),
    ("Pose", False), ("Transform", False), ("Group", False), ("Shape", False), ("HingeJoint", False),
    ("RotationalMotor", False), ("PositionSensor", False), ("Propeller", False), ("Skin", False)])
def test_set_velocity_of_a_node_that_is_no_solid_is_webots_warning_and_asks_no_change(
        monkeypatch, capsys, kind: str, solid: bool) -> None:
    """Webots' Solid and the nodes derived from it (Robot, Charger, Track, the devices that are Solids) take
    setVelocity (zeros: ``reset_physics``); any other node, whatever the velocity, is Webots' warning each call
    and no request but its type."""
    fake = _TypedSupervisor()
    fake.kind = kind
    monkeypatch.setattr(ws, "_supervisor", lambda func: fake)
    monkeypatch.setattr(ws, "_set_velocity_warned", [])
    for velocity in ([0.0] * 6, [0.0] * 6, [1.0] + [0.0] * 5):
        ws.wb_supervisor_node_set_velocity(7, velocity)
    err = capsys.readouterr().err
    if solid:
        assert fake.calls == ["/boss/robot/get_from_id", "/boss/robot/reset_physics"] * 2 + ["/boss/robot/get_from_id"]
        assert err.startswith(f"Warning: {FUNC}(): a velocity other than zero is ignored") and err.count("\n") == 1
    else:
        assert fake.calls == ["/boss/robot/get_from_id"] * 3
        assert err == f"Warning: {FUNC}() can exclusively be used with a Solid.\n" * 3


@pytest.mark.slow
def test_a_c_supervisors_hostile_set_velocity_calls_are_one_line_each(tmp_path_factory) -> None:
    """tests/c/set_velocity_bad.c, built with sanitizers, through ``sensorium serve`` on tests/worlds/
    reset_falls.wbt: a NULL node, a NULL velocity, NaN and infinities at each of the six places are Webots'
    lines; zeros on the root and on the box's Shape are its warning each and stop nothing (the box lifted to 1 m still falls at
    −g·t, t = 4 steps of 16 ms); a denormal is the one warning; zeros with -0.0 stop the box."""
    import json
    from pathlib import Path

    from test_c_client import sanitized_run

    repo = Path(__file__).resolve().parents[1]
    code, out, err = sanitized_run(tmp_path_factory, repo / "tests" / "c" / "set_velocity_bad.c",
                                   repo / "tests" / "worlds" / "reset_falls.wbt", "boss")
    assert code == 0, err
    got = json.loads(out[-1])
    g, t = 9.81, 4 * 0.016
    assert got["z"] == pytest.approx(1.0 - g * t * t / 2.0, abs=1e-12)
    assert got["falling"] == pytest.approx(-g * t, abs=1e-12) and got["stopped"] == 0.0
    assert [line for line in err.splitlines() if FUNC in line] == [
        f"Error: {FUNC}() called with a NULL or invalid 'node' argument.",
        f"Error: {FUNC}() called with NULL argument.",
        *[f"Error: {FUNC}() called with a NaN or infinite value."] * 6,
        *[f"Warning: {FUNC}() can exclusively be used with a Solid."] * 2,
        f"Warning: {FUNC}(): a velocity other than zero is ignored: Sensorium has no physics engine (robots move by "
        "their wheels' commands, solids only fall straight down from rest)."]
