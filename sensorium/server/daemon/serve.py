"""The serve loop as a library: world file → simulation → core → bound transport → run.

``sensorium serve`` (:mod:`sensorium.cli.serve`) is the argparse shell over this module; tests and
embedding programs can use :func:`build` and :class:`Server` directly. A recorder (``serve
--record``) is passed in by the caller (:func:`sensorium.server.recording.writer.recorder_for_server`
builds one): the daemon never imports the recording package.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sensorium.server.daemon.roles import CONTROLS, open_controls
from sensorium.server.daemon.services import Core
from sensorium.server.daemon.steppath import chosen_gate_class
from sensorium.server.daemon.transport import (
    DEFAULT_PUB,
    DEFAULT_RPC,
    Transport,
    check_cpu,
    check_endpoints,
    load_curve_keys,
)
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.limits import WorldLimits
from sensorium.server.world.loader import LoadedWorld, Problem, WorldError, default_world_path, load_world

__all__ = ["ServeOptions", "Server", "build"]


@dataclass
class ServeOptions:
    """What ``sensorium serve`` takes besides the world file (same names as its options)."""

    rpc: str = DEFAULT_RPC
    pub: str = DEFAULT_PUB
    mode: str = "fast"                # fast | realtime | pause
    precision: str = "exact"          # ray engine precision: fast | exact
    heartbeat_ms: int = 1000          # controllers not heard from for 3 × this are released
    until: int | None = None          # quit when the simulated time reaches this many ms
    contact: bool | None = None       # kinematic contact; None: the world's world_info.contact
    allow_large: bool = False         # raise the world limits (WorldLimits.large())
    allow_outside_meshes: bool = False  # mesh urls may leave the world's folder
    controls: str = "auto"            # world-wide controls: auto | open | supervisor (daemon/roles.py)
    curve_keys: str | None = None     # DIR with server.key_secret: CURVE on both sockets
    watch: list[str] | None = None    # run these "<extern>" robots ([] = every one) as "<none>" (serve --watch)
    allow_skipped: bool = False       # serve a world whose robots were all dropped when it loaded
    cpu: int | None = None            # run the loop and ZeroMQ's I/O threads on this CPU (serve --cpu)

    def check(self) -> None:
        """Raise ValueError naming the first bad option."""
        check_endpoints(("--rpc", self.rpc), ("--pub", self.pub))
        if self.heartbeat_ms <= 0:
            raise ValueError("--heartbeat-ms must be > 0")
        if self.until is not None and self.until < 0:     # it stopped at once, with exit 0
            raise ValueError(f"--until must be a simulated time >= 0 ms, got {self.until}")
        if self.controls not in CONTROLS:
            raise ValueError(f"--controls must be one of {', '.join(CONTROLS)}, got {self.controls!r}")
        if self.curve_keys:
            load_curve_keys(self.curve_keys)
        if self.cpu is not None:
            check_cpu(self.cpu)
        chosen_gate_class()             # SENSORIUM_STEP_PATH: an unknown value, or c without the extension


def build(world: str | Path | None, options: ServeOptions | None = None) -> tuple[Core, Transport]:
    """World → simulation → core → bound transport. Raises ``WorldError`` on a bad world and
    ``OSError`` (``zmq.ZMQError``) when an endpoint cannot be bound. ``world=None`` is the
    embedded arena world."""
    opts = options or ServeOptions()
    opts.check()
    secret = load_curve_keys(opts.curve_keys)[1] if opts.curve_keys else None
    path = Path(world) if world else default_world_path()
    limits = WorldLimits.large() if opts.allow_large else WorldLimits()
    loaded = load_world(path, limits=limits, allow_outside_meshes=opts.allow_outside_meshes)
    if not opts.allow_skipped:
        refuse_robotless(loaded)
    if opts.watch is not None:
        loaded = watched(loaded, opts.watch)
    sim = Simulation(loaded, opts.precision, contact=opts.contact, limits=limits,   # imports: the same bounds
                     allow_outside_meshes=opts.allow_outside_meshes)
    core = Core(sim, heartbeat_ms=opts.heartbeat_ms, mode=opts.mode,
                open_controls=open_controls(opts.controls, opts.rpc))
    return core, Transport(core, opts.rpc, opts.pub, stop_at_ms=opts.until, curve_secret=secret, cpu=opts.cpu)


def refuse_robotless(loaded: LoadedWorld) -> None:
    """A world that wrote robots but lost every one when it loaded is not served (it would run by
    itself with nothing to control): ``WorldError`` naming each, unless ``--allow-skipped``."""
    dropped = loaded.report.dropped_robots()
    if loaded.world.robots or not dropped:
        return
    robots = sum(loss.kind == "robot" for loss in dropped)
    what = ", ".join(part for part in (f"{robots} robot{'s' if robots != 1 else ''}" if robots else "",
                                       f"{len(dropped) - robots} unknown node{'s' if len(dropped) - robots != 1 else ''} "
                                       "that may have been one" if len(dropped) > robots else "") if part)
    lines = [f"every robot of this world was lost when it loaded ({what}); nothing to control "
             "(--allow-skipped serves it anyway):", *(f"  lost {loss.label()}: {loss.text}" for loss in dropped)]
    problems = [Problem("", "\n".join(lines))]
    raise WorldError(loaded.source, problems)


def watched(loaded: LoadedWorld, robots: list[str]) -> LoadedWorld:
    """``serve --watch``: the named ``"<extern>"`` robots (every one when ``robots`` is empty) as
    ``"<none>"``, so the world steps by itself and a viewer sees their sensors with no controller.
    Raises ``WorldError`` naming a robot the world does not have."""
    names = [r.name for r in loaded.world.robots]
    unknown = [r for r in robots if r not in names]
    if unknown:
        raise WorldError(loaded.source, [Problem("", f"--watch: no robot {unknown[0]!r} (robots: {', '.join(names)})")])
    pick = set(robots) or set(names)
    new = [r.model_copy(update={"controller": "<none>"}) if r.name in pick and r.controller == "<extern>" else r
           for r in loaded.world.robots]
    return dataclasses.replace(loaded, world=loaded.world.model_copy(update={"robots": new}))


class Server:
    """A built server: ``Server.open(world, options)``, optionally ``attach_recorder(rec)``, then
    ``run()`` (blocks until SIGINT/SIGTERM or ``stop()`` or ``until``; closes the recorder)."""

    def __init__(self, core: Core, transport: Transport):
        self.core = core
        self.transport = transport
        self.recorder: Any = None
        core.request_stop = transport.stop         # simulationQuit

    @classmethod
    def open(cls, world: str | Path | None, options: ServeOptions | None = None) -> Server:
        core, transport = build(world, options)
        return cls(core, transport)

    @property
    def ready_line(self) -> str:
        """The line printed when ready, with the endpoints actually bound (scripts wait for it)."""
        t = self.transport
        return f"sensorium: serving world '{self.core.world_name}' rpc={t.rpc_endpoint} pub={t.pub_endpoint}"

    def attach_recorder(self, recorder: Any) -> None:
        """Record from inside the step loop: ``recorder`` gets every published message (see
        :meth:`sensorium.server.daemon.topics.Topics.set_recorder`); it is closed by :meth:`run`."""
        self.recorder = recorder
        self.core.topics.set_recorder(recorder)

    def stop(self) -> None:
        self.transport.stop()

    def run(self, *, signals: bool = True) -> None:
        """Serve until stopped. ``signals``: SIGINT/SIGTERM stop the loop (main thread only)."""
        if signals:
            self.transport.install_signal_handlers()
        try:
            self.transport.run()
        finally:
            if self.recorder is not None:
                self.recorder.close()

    def close(self) -> None:
        """Release the sockets of a server that was built but not run."""
        self.transport.close()
        if self.recorder is not None:
            self.recorder.close()
