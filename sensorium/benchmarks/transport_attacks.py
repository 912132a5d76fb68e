"""The README's figures for "one client cannot freeze or fill the server" (issue 28), reproducible:

    python -m sensorium.benchmarks.transport_attacks frames [FRAMES] [c|python]
    python -m sensorium.benchmarks.transport_attacks vanish [SECONDS] [attach|step]

``frames``: a controller steps robot c0 (heartbeat 1 s) while another client sends one message of
FRAMES empty frames (default 10⁶); prints the longest pause of the controller's steps once the
message was complete, whether it kept its session, and the server's memory before and at peak.
``vanish``: a controller steps c0 while another client, again and again, attaches c1 (and steps
it once, ``step``) and disappears without detaching; prints the fraction of SECONDS (default
120) in which c0's steps waited more than 0.1 s. Each party is its own process (the server is
``sensorium serve``); loopback only.
"""

from __future__ import annotations

import sys
import tempfile
import threading
import time
from pathlib import Path

import msgpack
import numpy as np
import zmq

from sensorium.client.connection import Connection, SensoriumError

from .transport import Server, _robots_world


def _status_kib(pid: int, key: str) -> int:
    return int(Path(f"/proc/{pid}/status").read_text().split(key + ":")[1].split()[0])


class _Stepper(threading.Thread):
    """The innocent controller: steps c0 as fast as the lockstep allows, records when each step returned."""

    def __init__(self, rpc: str):
        super().__init__(daemon=True)
        self.conn = Connection(rpc, timeout=120)
        reply = self.conn.call("attach", {"robot": "c0"})
        self.conn.start_heartbeat(reply["session"], reply["heartbeat_ms"])
        self.times: list[float] = []
        self.errors: list[str] = []
        self.halt = threading.Event()

    def run(self) -> None:
        try:
            while not self.halt.is_set():
                self.conn.call("/c0/robot/step", {})
                self.times.append(time.monotonic())
        except SensoriumError as exc:
            self.errors.append(str(exc))

    def finish(self) -> None:
        self.halt.set()
        self.join(60)
        self.conn.close()


def frames(count: int = 1_000_000, step_path: str = "auto") -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        server = Server(_robots_world(2), Path(tmp), step_path=step_path)
        try:
            good = _Stepper(server.rpc)
            good.start()
            time.sleep(1.0)
            pid = server.proc.p.pid
            rss0 = _status_kib(pid, "VmRSS")
            ctx = zmq.Context()
            bad = ctx.socket(zmq.DEALER)
            bad.setsockopt(zmq.LINGER, 0)
            bad.connect(server.rpc)
            bad.send_multipart([b""] * count + [msgpack.packb({"id": 1, "service": "get_info", "args": {}})])
            sent = time.monotonic()
            if not bad.poll(120_000):
                raise RuntimeError("no reply to the over-long message")
            reply = msgpack.unpackb(bad.recv())
            replied = time.monotonic()
            time.sleep(3.0)
            good.finish()
            peak = _status_kib(pid, "VmHWM")
            bad.close()
            ctx.term()
        finally:
            server.stop()
    after = [b - a for a, b in zip(good.times, good.times[1:]) if b > sent - 0.5]
    return {"frames": count, "reply": reply.get("error", {}).get("message"), "reply_after_s": replied - sent,
            "longest_pause_s": max(after) if after else float("nan"), "kept_session": not good.errors,
            "errors": good.errors, "rss_mib": rss0 / 1024, "peak_mib": peak / 1024}


def vanish(seconds: float = 120.0, mode: str = "step") -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        server = Server(_robots_world(2), Path(tmp))
        try:
            good = _Stepper(server.rpc)
            good.start()
            t0 = time.monotonic()
            attaches = refused = 0
            while time.monotonic() - t0 < seconds:
                c = Connection(server.rpc, timeout=10)
                try:
                    c.call("attach", {"robot": "c1"})
                    attaches += 1
                    if mode == "step":
                        c.send("/c1/robot/step", {})
                        time.sleep(0.05)
                except SensoriumError:
                    refused += 1
                c.close()                          # gone, without detaching (its heartbeat never started)
                time.sleep(0.1)
            good.finish()
        finally:
            server.stop()
    ts = np.asarray([t for t in good.times if t0 <= t <= t0 + seconds])
    gaps = np.diff(ts)
    return {"seconds": seconds, "mode": mode, "attaches": attaches, "refused": refused, "steps": len(ts),
            "waiting_fraction": float(gaps[gaps > 0.1].sum() / seconds), "errors": good.errors}


def main(argv: list[str]) -> None:
    if not argv or argv[0] not in ("frames", "vanish"):
        print(__doc__.strip().split("\n\n")[1], file=sys.stderr)
        raise SystemExit(2)
    if argv[0] == "frames":
        r = frames(int(argv[1]) if len(argv) > 1 else 1_000_000, argv[2] if len(argv) > 2 else "auto")
        print(f"{r['frames']:,} empty frames: answered '{r['reply']}' {r['reply_after_s']:.3f} s after sending; the "
              f"controller's longest pause {r['longest_pause_s'] * 1000:.0f} ms; kept its session: {r['kept_session']} "
              f"{r['errors'] or ''}; server memory {r['rss_mib']:.0f} MiB, peak {r['peak_mib']:.0f} MiB")
    else:
        r = vanish(float(argv[1]) if len(argv) > 1 else 120.0, argv[2] if len(argv) > 2 else "step")
        print(f"attach-{'step-' if r['mode'] == 'step' else ''}vanish loop for {r['seconds']:g} s: {r['attaches']} "
              f"attaches, {r['refused']} refused; the world waited {r['waiting_fraction']:.0%} of the time "
              f"({r['steps']:,} steps of the other controller) {r['errors'] or ''}")


if __name__ == "__main__":
    main(sys.argv[1:])
