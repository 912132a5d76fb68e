"""A server whose world step blocks while a file exists: a long step on demand, for
tests/test_long_step.py (a 1920x1080 anti-aliased camera's first frame took 13-26 s here).

    python tests/_slow_server.py WORLD HEARTBEAT_MS RPC HOLD [CURVE_KEYS_DIR]

Serves WORLD on RPC (pub on a free loopback port) and prints ``ready rpc=ENDPOINT``. While the file
HOLD exists, a world step touches ``HOLD.holding`` (once per step) and waits until HOLD is removed:
the server's Python loop computes, its ZeroMQ I/O threads run on. With CURVE_KEYS_DIR the RPC
socket uses the key pair there (``sensorium keys``)."""

from __future__ import annotations

import sys
import time
from pathlib import Path

from sensorium.server.daemon.services import Core
from sensorium.server.daemon.transport import Transport, load_curve_keys
from sensorium.server.sim.simulation import Simulation


def main() -> None:
    world, heartbeat_ms, rpc, hold_path = sys.argv[1:5]
    hold = Path(hold_path)
    holding = Path(hold_path + ".holding")
    real_step = Simulation.step

    def step(self: Simulation):  # type: ignore[no-untyped-def]
        if hold.exists():
            holding.touch()
            while hold.exists():
                time.sleep(0.01)
        return real_step(self)

    Simulation.step = step  # type: ignore[method-assign]
    secret = load_curve_keys(sys.argv[5])[1] if len(sys.argv) > 5 else None
    core = Core(Simulation.from_file(world, precision="fast"), heartbeat_ms=int(heartbeat_ms))
    transport = Transport(core, rpc, "tcp://127.0.0.1:0", curve_secret=secret)
    print(f"ready rpc={transport.rpc_endpoint}", flush=True)
    transport.run()


if __name__ == "__main__":
    main()
