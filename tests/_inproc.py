"""A real server (core + ZeroMQ transport) in a thread of the test process, on loopback free ports."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from sensorium.server.daemon.services import Core
from sensorium.server.daemon.transport import Transport
from sensorium.server.sim.simulation import Simulation

WORLD = Path(__file__).parent / "worlds" / "server.yaml"


@contextmanager
def inproc_server(heartbeat_ms: int, world: Path = WORLD) -> Iterator[tuple[Core, Transport]]:
    core = Core(Simulation.from_file(world, precision="fast"), heartbeat_ms=heartbeat_ms)
    transport = Transport(core, "tcp://127.0.0.1:0", "tcp://127.0.0.1:0")
    thread = threading.Thread(target=transport.run, daemon=True)
    thread.start()
    try:
        yield core, transport
    finally:
        transport.stop()
        thread.join(timeout=30)
