"""The conformance vectors (sensorium/schemas/conformance/) are current, the server answers every
request vector as PROTOCOL.md says, and the Python client replays them: the request cases over a
raw DEALER socket (as a client in any language would) and through ``Connection``, the scripted
lockstep session through the flat wb_* API (tests/controllers/script.py). The C client replays the
session in tests/test_c_client.py.
"""

from __future__ import annotations

import json
import math
import os
import struct
import subprocess
import sys
from pathlib import Path
from typing import Any

import msgpack
import pytest
import zmq
from _serve import serve

from sensorium.client.connection import Connection, SensoriumError
from sensorium.server.sim import conformance

REPO = Path(__file__).resolve().parents[1]
VECTORS = REPO / "sensorium" / "schemas" / "conformance"
SCRIPT_PY = REPO / "tests" / "controllers" / "script.py"


def load(name: str) -> dict:
    return json.loads((VECTORS / name).read_text())


@pytest.fixture
def server():
    with serve(VECTORS / "world.yaml") as s:
        yield s


def _path(result: Any, dotted: str) -> bool:
    for part in dotted.split("."):
        if not isinstance(result, dict) or part not in result:
            return False
        result = result[part]
    return True


def _same(got: Any, want: Any) -> bool:
    if isinstance(want, dict):
        return isinstance(got, dict) and all(k in got and _same(got[k], v) for k, v in want.items())
    if isinstance(want, float) and math.isnan(want):
        return isinstance(got, float) and math.isnan(got)
    return got == want and type(got) is not bool or got is want


def check_result(case: dict, result: Any) -> None:
    expect = case["expect"]
    want = conformance.decode_value(expect.get("result", {}))
    assert _same(result, want), f"{case['name']}: {result!r} lacks {want!r}"
    for dotted in expect.get("result_has", []):
        assert _path(result, dotted), f"{case['name']}: no {dotted} in {result!r}"


def test_vector_files_are_current():
    assert conformance.main([]) == 0     # session.json from the simulation, requests.json from CASES


def test_request_vectors_over_a_raw_dealer_socket(server):
    """What a client in any language does: send the bytes, read one reply, compare."""
    sock = zmq.Context.instance().socket(zmq.DEALER)
    sock.setsockopt(zmq.LINGER, 0)
    sock.setsockopt(zmq.RCVTIMEO, 20_000)
    sock.connect(server.rpc)
    saved: dict[str, str] = {}
    cases = load("requests.json")["cases"]
    assert len(cases) >= 30
    try:
        for case in cases:
            if "request_hex" in case:
                data = bytes.fromhex(case["request_hex"])
                if "request" in case:       # the bytes are the canonical encoding of the JSON form
                    assert msgpack.packb(conformance.decode_value(case["request"]), use_bin_type=True) == data
            else:
                data = msgpack.packb(conformance.decode_value(case["request"], saved), use_bin_type=True)
            sock.send(data)
            reply = msgpack.unpackb(sock.recv(), raw=False)
            expect = case["expect"]
            want_id = None if "id" in expect else case["request"]["id"]
            assert reply["id"] == want_id and reply["ok"] is expect["ok"], (case["name"], reply)
            if expect["ok"]:
                check_result(case, reply["result"])
                if "save" in expect:
                    saved[expect["save"]] = reply["result"][expect["save"]]
            else:
                assert reply["error"]["code"] == expect["code"], (case["name"], reply)
                assert expect.get("message_has", "") in reply["error"]["message"], (case["name"], reply)
    finally:
        sock.close()


def test_request_vectors_through_the_python_client(server):
    """The same cases through ``Connection.call`` (its own ids): results, or SensoriumError codes."""
    saved: dict[str, str] = {}
    done = 0
    with Connection(server.rpc, timeout=20.0) as conn:
        for case in load("requests.json")["cases"]:
            request = case.get("request")
            if not isinstance(request, dict) or "args" not in request:
                continue                                      # raw-bytes cases: the client cannot send them
            args = conformance.decode_value(request["args"], saved)
            expect = case["expect"]
            if expect["ok"]:
                result = conn.call(request["service"], args)
                check_result(case, result)
                if "save" in expect:
                    saved[expect["save"]] = result[expect["save"]]
            else:
                with pytest.raises(SensoriumError) as err:
                    conn.call(request["service"], args)
                assert err.value.code == expect["code"], case["name"]
            done += 1
    assert done >= 25


def test_session_vector_replayed_by_the_python_client(server):
    session = load("session.json")
    done = subprocess.run([sys.executable, "-m", "sensorium", "controller", "--url", f"{server.rpc}/{session['robot']}",
                           str(SCRIPT_PY), *session["script"]], capture_output=True, text=True, timeout=120,
                          cwd=str(REPO), env={**os.environ, "PYTHONUNBUFFERED": "1"})
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == session["lines"]
    # the session is not vacuous: values appear, change, stay after a disable, the cloud comes and goes
    rows = [line.split(" ") for line in session["lines"]]
    assert any("7ff8000000000000" in r for line in session["lines"] for r in line.split())
    assert len({r[2] for r in rows}) == len(rows)                       # ir: a new noisy value every step
    assert sum("lidar.cloud=" in line for line in session["lines"]) < len(rows)


def replay_radio(server, runners: dict[str, list[str]]) -> dict[str, list[str]]:
    """radio.json's scripts, one controller process per robot (``runners[robot]``: the argv before
    the script's ops) stepping together on one server started in pause mode: the world runs once
    every controller is attached (else the first would step alone); each robot's printed lines."""
    session = load("radio.json")
    rpc = server.rpc
    procs = {robot: subprocess.Popen([*runners[robot], *session["scripts"][robot]], stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, text=True, cwd=str(REPO),
                                     env={**os.environ, "PYTHONUNBUFFERED": "1", "SENSORIUM_CONTROLLER_URL": f"{rpc}/{robot}",
                                          "ASAN_OPTIONS": "detect_leaks=1:exitcode=86",
                                          "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"})
             for robot in session["scripts"]}
    server.wait_attached(set(procs))
    assert server.conn.call("set_mode", {"mode": "fast"})["mode"] == "fast"
    out = {}
    for robot, p in procs.items():
        try:
            stdout, stderr = p.communicate(timeout=180)
        finally:
            for q in procs.values():
                if q.poll() is None and q is not p and p.returncode is None:
                    q.kill()
        assert p.returncode == 0, f"{robot}: {stderr}"
        assert "Sanitizer" not in stderr and "runtime error" not in stderr, stderr
        out[robot] = stdout.splitlines()
    return out


def python_runner() -> list[str]:
    return [sys.executable, "-m", "sensorium", "controller", str(SCRIPT_PY)]


@pytest.fixture
def paused_server():
    with serve(VECTORS / "world.yaml", "--mode", "pause") as s:
        yield s


def test_radio_session_two_python_controllers(paused_server):
    """Two controllers of one world talking by radio (sensorium/schemas/conformance/radio.json): the
    exact packets, signal strengths and directions each receives, what each emitter's buffer and
    baud rate let through, channels, ranges, broadcast; computed from the simulation alone."""
    session = load("radio.json")
    got = replay_radio(paused_server, {"rover": python_runner(), "buddy": python_runner()})
    assert got == session["lines"]
    rover, buddy = session["lines"]["rover"], session["lines"]["buddy"]
    # not vacuous: packets arrive both ways, the rover's buffer refuses one, the buddy's noisy receiver
    # reads a direction of unit length, a packet sent out of range never arrives
    assert rover[0].endswith("radio out.sent=1110") and "radio in=1:6275646479/" in rover[0]
    assert "radio in=1:68656c6c6f/" in buddy[1]
    assert not any(":0d/" in line for line in buddy) and any(":0e/" in line for line in buddy)
    assert not any(":" + "ff" * 30 in line for line in buddy)          # larger than the buddy's buffer
    head = buddy[1].split("radio in=1:")[1].split(" ")[0]
    x, y, z = (struct.unpack("<d", struct.pack("<Q", int(h, 16)))[0] for h in head.split("/")[2].split(","))
    assert abs(math.hypot(x, y, z) - 1.0) < 1e-12
