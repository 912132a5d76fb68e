"""CURVE on tcp (issue 16): ``sensorium keys DIR`` + ``serve --curve-keys DIR``; a client that knows
the server's public key (environment or URL query) is served, on RPC and topics; one that does not
(no key, a wrong key) gets nothing. Servers on 127.0.0.1, port 0."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time

import pytest
import zmq
import zmq.utils.z85
from _serve import Proc, sensorium, serve

from sensorium.client.connection import (
    ENV_CURVE_SERVERKEY,
    Connection,
    ErrorCode,
    SensoriumError,
    SubSocket,
    split_curve,
)

PY = sys.executable


@pytest.fixture(scope="module")
def curve_server(tmp_path_factory):
    keys = tmp_path_factory.mktemp("keys")
    out = subprocess.run([PY, "-m", "sensorium", "keys", str(keys)], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    hexkey = re.search(r"SENSORIUM_CURVE_SERVERKEY=([0-9a-f]{64})", out.stdout).group(1)
    assert oct((keys / "server.key_secret").stat().st_mode & 0o777) == "0o600"
    no_key = {k: None for k in os.environ if k.startswith("SENSORIUM_CURVE")}
    with serve(None, "--curve-keys", str(keys), "--mode", "realtime", env=no_key, stop_signal=signal.SIGTERM) as s:
        yield s.rpc, s.pub, hexkey


def _no_curve_env(monkeypatch):
    for k in list(os.environ):
        if k.startswith("SENSORIUM_CURVE"):
            monkeypatch.delenv(k)


def test_a_client_with_the_key_is_served_one_without_is_not(curve_server, monkeypatch):
    rpc, _pub, key = curve_server
    _no_curve_env(monkeypatch)
    ctx = zmq.Context()
    try:
        # with the key in the URL query (hex or Z85)
        with Connection(f"{rpc}?serverkey={key}", timeout=30, context=ctx) as c:
            assert c.call("get_info")["protocol"] == 1
        z85 = zmq.utils.z85.encode(bytes.fromhex(key)).decode()
        with Connection(f"{rpc}?serverkey={z85}", timeout=30, context=ctx) as c:
            assert c.call("get_info")["protocol"] == 1
        # with the key in the environment
        monkeypatch.setenv(ENV_CURVE_SERVERKEY, key)
        with Connection(rpc, timeout=30, context=ctx) as c:
            assert c.call("get_info")["protocol"] == 1
        # a wrong key, and no key: the handshake never completes, no service
        monkeypatch.setenv(ENV_CURVE_SERVERKEY, zmq.curve_keypair()[0].decode())
        with Connection(rpc, timeout=1.5, context=ctx) as c, pytest.raises(SensoriumError) as exc:
            c.call("get_info")
        assert exc.value.code == ErrorCode.TIMEOUT
        # ... and the timeout says why (issue 26: it asked "is `sensorium serve` running there?")
        assert "server key" in str(exc.value) and "is wrong" in str(exc.value), exc.value
        assert "running there" not in str(exc.value)
        monkeypatch.delenv(ENV_CURVE_SERVERKEY)
        with Connection(rpc, timeout=1.5, context=ctx) as c, pytest.raises(SensoriumError) as exc:
            c.call("get_info")
        assert exc.value.code == ErrorCode.TIMEOUT
        assert "uses CURVE encryption and this client has no key" in str(exc.value), exc.value
        assert ENV_CURVE_SERVERKEY in str(exc.value) and "running there" not in str(exc.value)
        # a server that is not there is still "is `sensorium serve` running there?"
        with Connection("tcp://127.0.0.1:1", timeout=0.5, context=ctx) as c, pytest.raises(SensoriumError) as exc:
            c.call("get_info")
        assert "running there" in str(exc.value)
    finally:
        ctx.destroy(linger=0)


def _first_message(sub: SubSocket, within_s: float) -> list[bytes] | None:
    deadline = time.monotonic() + within_s
    while time.monotonic() < deadline:
        if sub.poll(100):
            return sub.recv_frames()
    return None


def test_topics_need_the_key_too(curve_server, monkeypatch):
    """The world steps only with a step pending (PROTOCOL §3.7): a keyed controller drives it."""
    rpc, pub, key = curve_server
    _no_curve_env(monkeypatch)
    ctx = zmq.Context()
    try:
        good = SubSocket(f"{pub}?serverkey={key}", context=ctx)
        bad = SubSocket(pub, context=ctx)
        for s in (good, bad):
            s.subscribe(b"/clock")
        with Connection(f"{rpc}?serverkey={key}", timeout=30, context=ctx) as c:
            info = c.call("get_info")
            robot = info["robots"][0]["name"]
            session = c.call("attach", {"robot": robot})["session"]
            frames = None
            deadline = time.monotonic() + 30
            while frames is None and time.monotonic() < deadline:   # until the subscription has arrived
                c.call(f"/{robot}/robot/step", {"duration": info["basic_time_step"]})
                frames = _first_message(good, 0.05)
            assert frames is not None and frames[0] == b"/clock\0"
            for _ in range(20):
                c.call(f"/{robot}/robot/step", {"duration": info["basic_time_step"]})
            assert _first_message(good, 5) is not None
            assert _first_message(bad, 1.5) is None
            c.call("detach", {"session": session})
        good.close()
        bad.close()
    finally:
        ctx.destroy(linger=0)


def test_curve_keys_in_urls_and_environment_are_checked():
    key = "ab" * 32
    assert split_curve(f"tcp://127.0.0.1:5560?serverkey={key}", {}) == (
        "tcp://127.0.0.1:5560", zmq.utils.z85.encode(bytes.fromhex(key)))
    assert split_curve("tcp://127.0.0.1:5560", {}) == ("tcp://127.0.0.1:5560", None)
    assert split_curve("tcp://127.0.0.1:5560", {ENV_CURVE_SERVERKEY: key})[1] is not None
    for bad in ("tcp://h:1?serverkey=short", "tcp://h:1?key=" + key, "tcp://h:1?serverkey=" + "zz" * 32):
        with pytest.raises(SensoriumError) as exc:
            split_curve(bad, {})
        assert exc.value.code == ErrorCode.BAD_URL and "key" in str(exc.value)


def test_serve_refuses_a_missing_key_directory(tmp_path):
    r = subprocess.run([PY, "-m", "sensorium", "serve", "--curve-keys", str(tmp_path / "none"), "--rpc",
                        "tcp://127.0.0.1:0", "--pub", "tcp://127.0.0.1:0"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "sensorium keys" in r.stderr and r.stderr.count("\n") == 1
    r = subprocess.run([PY, "-m", "sensorium", "keys", str(tmp_path)], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0
    before = (tmp_path / "server.key_secret").read_bytes()
    r = subprocess.run([PY, "-m", "sensorium", "keys", str(tmp_path)], capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and "exists" in r.stderr and (tmp_path / "server.key_secret").read_bytes() == before


def test_controller_urls_carry_the_server_key():
    from sensorium.client.connection import parse_controller_url

    key = "cd" * 32
    u = parse_controller_url(f"tcp://127.0.0.1:5560/epuck?serverkey={key}")
    assert u.robot == "epuck" and u.endpoint == f"tcp://127.0.0.1:5560?serverkey={key}"
    assert str(u) == f"tcp://127.0.0.1:5560/epuck?serverkey={key}"
    assert parse_controller_url(str(u)) == u
    with pytest.raises(SensoriumError):
        parse_controller_url("tcp://127.0.0.1:5560/epuck?serverkey=nope")


def test_record_connect_uses_the_key_from_the_environment(curve_server, monkeypatch, tmp_path):
    rpc, _pub, key = curve_server
    _no_curve_env(monkeypatch)
    env = {k: v for k, v in os.environ.items() if not k.startswith("SENSORIUM_CURVE")}
    out = tmp_path / "curve.mcap"
    r = subprocess.run([PY, "-m", "sensorium", "record", str(out), "--url", rpc, "--duration", "1"],
                       capture_output=True, text=True, timeout=60, env=env)
    assert r.returncode == 1 and "no answer" in r.stderr and not out.exists()       # no key: no service
    rec = Proc(sensorium("record", str(out), "--url", rpc, "--topics", "/clock", "--max-messages", "5", "--json"),
               env={**{k: None for k in os.environ if k.startswith("SENSORIUM_CURVE")}, ENV_CURVE_SERVERKEY: key})
    ctx = zmq.Context()
    try:
        with Connection(f"{rpc}?serverkey={key}", timeout=30, context=ctx) as c:
            info = c.call("get_info")
            robot = next(r["name"] for r in info["robots"] if not r.get("attached"))
            session = c.call("attach", {"robot": robot})["session"]
            deadline = time.monotonic() + 60
            while rec.returncode is None:
                assert time.monotonic() < deadline, "the recorder got nothing"
                c.call(f"/{robot}/robot/step", {"duration": info["basic_time_step"]})
            c.call("detach", {"session": session})
        assert rec.wait() == 0, rec.stderr()
        assert '"received": 5' in rec.stdout()
    finally:
        rec.stop()
        ctx.destroy(linger=0)
