"""``sensorium serve --cpu N``: the loop thread and ZeroMQ's I/O threads run on CPU N (read back
from /proc), the lockstep works as before, the ray engine's block workers keep every CPU, and a CPU
the process may not use is refused with one line."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
from pathlib import Path

import pytest
import zmq
from _serve import child_env, sensorium, serve

from sensorium.server.raycast import blocks

WORLD = Path(__file__).parent / "worlds" / "server.yaml"

linux_cpus = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
needs_two = pytest.mark.skipif(len(linux_cpus) < 2, reason="pinning needs Linux and two CPUs to tell apart")


def _threads(pid: int) -> dict[str, list[str]]:
    """Thread name → the CPU lists (Cpus_allowed_list) of the threads of that name."""
    out: dict[str, list[str]] = {}
    for tid in os.listdir(f"/proc/{pid}/task"):
        base = f"/proc/{pid}/task/{tid}"
        name = Path(f"{base}/comm").read_text().strip()
        status = Path(f"{base}/status").read_text()
        cpus = status.split("Cpus_allowed_list:", 1)[1].split()[0]
        out.setdefault("main" if tid == str(pid) else name, []).append(cpus)
    return out


@needs_two
def test_serve_cpu_pins_the_loop_and_io_threads_and_steps():
    cpu = linux_cpus[-1]
    with serve(WORLD, "--precision", "fast", "--cpu", str(cpu)) as s:
        conn = s.conn
        session = conn.call("attach", {"robot": "bot"})["session"]
        times = [conn.call("/bot/robot/step", {})["time_ms"] for _ in range(5)]
        assert times == sorted(times) and times[0] > 0 and len(set(times)) == 5
        threads = _threads(s.p.pid)
        conn.call("detach", {"session": session})
    assert threads["main"] == [str(cpu)], threads               # the loop thread
    io = [c for name, cs in threads.items() if name.startswith("ZMQbg/IO") for c in cs]
    assert io and all(c == str(cpu) for c in io), threads


@needs_two
def test_serve_without_cpu_leaves_threads_free():
    with serve(WORLD, "--precision", "fast") as s:
        threads = _threads(s.p.pid)
    assert "-" in threads["main"][0] or "," in threads["main"][0], threads


def test_serve_cpu_outside_the_process_is_one_line_and_exit_2():
    bad = max(linux_cpus, default=0) + 64
    p = subprocess.run(sensorium("serve", str(WORLD), "--rpc", "tcp://127.0.0.1:0", "--pub", "tcp://127.0.0.1:0",
                                 "--cpu", str(bad)),
                       capture_output=True, text=True, env=child_env(), timeout=120)
    assert p.returncode == 2, p.stderr
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and f"--cpu {bad}" in lines[0] and "Traceback" not in p.stderr, p.stderr
    assert lines[0].startswith("sensorium serve: ")


def test_transport_cpu_needs_its_own_context():
    from sensorium.server.daemon.serve import ServeOptions, build

    ctx = zmq.Context()
    try:
        core, transport = build(WORLD, ServeOptions(rpc="tcp://127.0.0.1:0", pub="tcp://127.0.0.1:0"))
        transport.close()
        from sensorium.server.daemon.transport import Transport

        with pytest.raises(ValueError, match="own context"):
            Transport(core, "tcp://127.0.0.1:0", "tcp://127.0.0.1:0", context=ctx, cpu=linux_cpus[0] if linux_cpus else 0)
    finally:
        ctx.term()


@needs_two
def test_block_workers_started_from_a_pinned_thread_use_every_cpu(monkeypatch):
    """The server's loop (pinned by --cpu) starts the ray engine's pool at its first large cast:
    the workers must not inherit the pin, or a split cast would run on one core."""
    monkeypatch.setattr(blocks, "_pool", None)
    monkeypatch.setattr(blocks, "_workers", 0)
    seen: dict[str, set[int]] = {}

    def pinned_caller() -> None:
        os.sched_setaffinity(0, {linux_cpus[-1]})
        seen["caller"] = os.sched_getaffinity(0)
        seen["worker"] = blocks._executor(1).submit(os.sched_getaffinity, 0).result(timeout=60)

    t = threading.Thread(target=pinned_caller)
    t.start()
    t.join(60)
    pool = blocks._pool
    if pool is not None:
        pool.shutdown(wait=True)
    assert seen["caller"] == {linux_cpus[-1]}
    assert seen["worker"] == set(linux_cpus)


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-v"]))


@needs_two
def test_the_packet_helpers_threads_keep_every_cpu_of_a_pinned_caller():
    """A thread pinned to one CPU (the loop of `serve --cpu`) that starts a FAST pass on several
    threads: the pass's threads run on every CPU the process started with, as the block workers do
    (read back from a thread the helper starts the same way)."""
    from sensorium.server.raycast import packets

    if packets.library() is None:
        pytest.skip(f"packet path off: {packets.status()}")
    seen: dict[str, int] = {}

    def pinned() -> None:
        os.sched_setaffinity(0, {linux_cpus[-1]})
        seen["caller"] = len(os.sched_getaffinity(0))
        seen["pass"] = packets.library().sp_probe_worker_cpus()

    t = threading.Thread(target=pinned)
    t.start()
    t.join(timeout=60)
    assert seen == {"caller": 1, "pass": len(blocks.process_cpus())}
    assert len(blocks.process_cpus()) == len(linux_cpus) >= 2
