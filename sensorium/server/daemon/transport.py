"""The server's only ZeroMQ module: ROUTER + XPUB, the poll loop, signals.

A thin adapter around :class:`sensorium.server.daemon.services.Core` (sans-IO): frames in, frames out.

* ``ROUTER`` (RPC) with ``ZMQ_MAXMSGSIZE`` as the hard cap (libzmq drops the connection of a peer
  that sends more); the 1 MiB soft limit is the core's and is answered with ``TOO_LARGE``. ZMTP
  heartbeats detect silently dead TCP peers; session liveness is the lockstep's (heartbeat × 3).
  Requests are read and replies sent by the step path's gate (steppath.py: C when built, else
  pyzmq), in batches that end wherever the world might step.
* ``XPUB`` (topics): subscription events feed the demand; a small ``SNDHWM`` bounds the memory a
  slow subscriber costs (PUB semantics: excess messages are dropped, ``seq`` shows the gap).
* Run modes ``fast``/``realtime``/``pause`` are decided by the lockstep; this loop only sleeps
  until the next event or deadline.
* ``hooks``: callables run by the loop thread once per loop pass, before stepping (the Foxglove
  viewer applies its subscriptions there); another thread calls :meth:`wake` to get a pass soon.
* SIGINT/SIGTERM: every pending (and later) step is answered with status -1, requests are still
  served for ``grace_s`` so controllers can clean up, then both sockets close.
"""

from __future__ import annotations

import errno
import os
import signal
import socket
import time
from collections.abc import Callable
from pathlib import Path

import zmq
import zmq.auth
import zmq.utils.z85

from sensorium.schemas.services import MAX_PERIOD_MS
from sensorium.schemas.wire import HARD_LIMIT, ErrorCode, error_reply
from sensorium.server.daemon.services import STEP_REPLY_PIECES, Core
from sensorium.server.daemon.steppath import gate_for

__all__ = ["Transport", "DEFAULT_RPC", "DEFAULT_PUB", "generate_curve_keys", "load_curve_keys", "curve_server",
           "curve_client_from_env", "check_cpu", "check_endpoints", "endpoint_problem"]

DEFAULT_RPC = "tcp://127.0.0.1:5560"
DEFAULT_PUB = "tcp://127.0.0.1:5561"
STEP_BUDGET_S = 0.005          # at most this long stepping before looking at the sockets again
MAX_IDLE_WAIT_S = 1.0
BIND_ERRORS: tuple[type[Exception], ...] = (OSError, zmq.ZMQError)
"""What opening a server's sockets raises for an address in use or a bad endpoint (callers that do not
import zmq catch these)."""


def bind_problem(exc: BaseException) -> str:
    """One line for a socket that could not be bound, with what to do about it."""
    text = str(exc)
    addr = text.split("addr=", 1)[1].strip("')") if "addr=" in text else ""
    what = text.split(" (addr=")[0]
    hint = ""
    if getattr(exc, "errno", None) == errno.EADDRINUSE or "in use" in text:
        hint = " (another server? choose other --rpc/--pub ports, or port 0 for free ones)"
    return f"cannot bind {addr or 'the endpoint'}: {what}{hint}"
MAX_IDLE_WAIT_MS = int(MAX_IDLE_WAIT_S * 1000)
EXPIRE_EVERY_S = 0.01           # session expiry scan (and, while busy, a look at XPUB + wake) this often
HOT_S = 0.01                    # busy: a request arrived this recently; wait in the ROUTER's recv alone
HOT_WAIT_MS = 10                # longest such wait (then XPUB, wake and deadlines are looked at)
REQUESTS_PER_TURN = 64          # requests in one batch of the step path (the world may step after each but steps)
MAX_FRAMES = 16                 # frames in one request message (identity, REQ envelope, body)
DISCARD_PER_TURN = 1 << 16      # frames of an over-long message dropped per loop pass (C: ~3 ms, Python: ~45 ms)
STALL_S = 0.05                  # a longer stretch without reading requests is not the sessions' silence
TOO_MANY_FRAMES = error_reply(None, ErrorCode.TOO_LARGE, f"a request has at most {MAX_FRAMES} frames")
SUB_LIMIT = 1024                # bytes of one subscription message (topic names are short)
ROUTER_SNDHWM = 256             # replies queued for one peer that does not read them


def _bindable(url: str) -> str:
    """``tcp://host:0`` → ``tcp://host:*`` (an ephemeral port, like the ``*`` form)."""
    if url.startswith("tcp://") and url.endswith(":0"):
        return url[:-2] + ":*"
    return url


def endpoint_problem(url: str) -> str | None:
    """Why an endpoint cannot be bound as asked, else None: a ``tcp://`` port out of range (libzmq
    would take port 99999 as 34463 and -1 as 65535, silently binding another port than asked), an
    ``ipc://`` path that is a file but no socket, or a socket another process listens on (libzmq
    unlinks whatever is at the path before it binds: the file would be deleted, the other server
    cut off from its clients)."""
    if url.startswith("ipc://"):
        return _ipc_problem(url, url[len("ipc://"):])
    if not url.startswith("tcp://"):
        return None
    _host, sep, port = url[len("tcp://"):].rpartition(":")
    if not sep or port.endswith("]"):
        return f"{url}: no port (tcp://HOST:PORT; 0 or * for a free one)"
    if port == "*" or (port.isdigit() and int(port) <= 65535):
        return None
    return f"{url}: the port must be 0 to 65535 (0 or * for a free one), got {port!r}"


def check_endpoints(*endpoints: tuple[str, str | None]) -> None:
    """ValueError naming the first of the (flag, url) endpoints to bind that cannot be bound as asked
    (:func:`endpoint_problem`; a None url is not bound), or two of them that are the same (on ipc the
    second bind would take the path from the first)."""
    for flag, url in endpoints:
        problem = endpoint_problem(url) if url else None
        if problem:
            raise ValueError(f"{flag} {problem}")
    urls = [url for _, url in endpoints if url and not url.endswith((":0", ":*"))]
    for i, url in enumerate(urls):
        if url in urls[:i]:
            raise ValueError(f"--rpc and --pub are the same endpoint {url}: give each its own")


def _ipc_problem(url: str, path: str) -> str | None:
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return None                             # nothing there (or not reachable: bind says why)
    import stat

    if not stat.S_ISSOCK(mode):
        return f"{url}: {path} exists and is not a socket: not replacing it"
    probe = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    probe.settimeout(1.0)
    try:
        probe.connect(path)
    except OSError:
        return None                             # a socket file nobody listens on: left by a server that died
    finally:
        probe.close()
    return f"{url}: another process listens there (another server?); choose another path"


def check_cpu(cpu: int) -> None:
    """ValueError unless this process may run on CPU ``cpu`` and can pin threads (Linux)."""
    if not hasattr(os, "sched_setaffinity"):
        raise ValueError("--cpu: pinning threads to a CPU needs Linux")
    allowed = sorted(os.sched_getaffinity(0))
    if cpu not in allowed:
        raise ValueError(f"--cpu {cpu}: this process may run on CPUs {', '.join(map(str, allowed))} only")


# ---------------------------------------------------------------------- CURVE (serve --curve-keys DIR)
CURVE_NAME = "server"          # DIR/server.key (public) and DIR/server.key_secret (ZeroMQ certificate files)


def generate_curve_keys(directory: str | Path, *, overwrite: bool = False) -> bytes:
    """Write a fresh server key pair (``zmq.curve_keypair``) to DIR/server.key and
    DIR/server.key_secret (owner-only); return the public key (Z85) clients need."""
    d = Path(directory)
    paths = [d / f"{CURVE_NAME}.key", d / f"{CURVE_NAME}.key_secret"]
    if not overwrite and any(p.exists() for p in paths):
        raise FileExistsError(f"{d}: a key pair exists already (--force to replace it)")
    d.mkdir(parents=True, exist_ok=True)
    old = os.umask(0o077)
    try:
        zmq.auth.create_certificates(d, CURVE_NAME)
    finally:
        os.umask(old)
    os.chmod(paths[1], 0o600)
    return load_curve_keys(d)[0]


def load_curve_keys(directory: str | Path) -> tuple[bytes, bytes]:
    """(public, secret) Z85 keys from DIR/server.key_secret; ValueError naming the problem."""
    path = Path(directory) / f"{CURVE_NAME}.key_secret"
    if not path.is_file():
        raise ValueError(f"--curve-keys: {path} not found (create a key pair with: sensorium keys {directory})")
    try:
        public, secret = zmq.auth.load_certificate(path)
    except (OSError, ValueError) as exc:
        raise ValueError(f"--curve-keys: {path}: {exc}") from None
    if secret is None:
        raise ValueError(f"--curve-keys: {path} has no secret key")
    return public, secret


def curve_server(sock: zmq.Socket, secret: bytes | None) -> None:
    """Make ``sock`` a CURVE server (before bind): every connection is encrypted, and only clients
    that know the server's public key complete the handshake."""
    if secret is None:
        return
    sock.setsockopt(zmq.CURVE_SERVER, 1)
    sock.setsockopt(zmq.CURVE_SECRETKEY, secret)


def curve_client_from_env(sock: zmq.Socket, environ: dict[str, str] | None = None) -> None:
    """For the server package's own client sockets (``record --connect``): CURVE with the server
    key ``SENSORIUM_CURVE_SERVERKEY`` (Z85 or hex) and a fresh key pair, like the client library."""
    key = (os.environ if environ is None else environ).get("SENSORIUM_CURVE_SERVERKEY", "").strip()
    if not key:
        return
    try:
        z85 = zmq.utils.z85.encode(bytes.fromhex(key)) if len(key) == 64 else key.encode("ascii")
        zmq.utils.z85.decode(z85)
    except (ValueError, UnicodeEncodeError, KeyError):
        raise ValueError("SENSORIUM_CURVE_SERVERKEY: a CURVE key is 40 Z85 or 64 hex characters") from None
    if len(z85) != 40:
        raise ValueError("SENSORIUM_CURVE_SERVERKEY: a CURVE key is 40 Z85 or 64 hex characters")
    public, secret = zmq.curve_keypair()
    sock.setsockopt(zmq.CURVE_SERVERKEY, z85)
    sock.setsockopt(zmq.CURVE_PUBLICKEY, public)
    sock.setsockopt(zmq.CURVE_SECRETKEY, secret)


class Transport:
    """Bind, serve until stopped, close. ``run()`` blocks; ``stop()`` may be called from a signal
    handler or another thread."""

    def __init__(self, core: Core, rpc: str = DEFAULT_RPC, pub: str = DEFAULT_PUB, *,
                 hard_limit: int = HARD_LIMIT, pub_hwm: int = 100, grace_s: float = 0.5,
                 context: zmq.Context | None = None, clock: Callable[[], float] = time.monotonic,
                 stop_at_ms: int | None = None, curve_secret: bytes | None = None, step_path: str | None = None,
                 cpu: int | None = None):
        self.core = core
        self.stop_at_ms = stop_at_ms          # quit (steps answer -1) once simulated time reaches it
        self.clock = clock
        self.grace_s = grace_s
        self._own_context = context is None
        self.ctx = context or zmq.Context()
        # --cpu: the loop thread (pinned in run) and ZeroMQ's I/O threads on one core: a request's
        # hand-over from the I/O thread to the loop and the reply's way back are then wake-ups on
        # that core, not across cores (the lockstep round trip's cost on a VM; bench transport
        # section). Set before the first socket starts the I/O threads of a context of our own.
        if cpu is not None:
            check_cpu(cpu)
            if context is not None:
                raise ValueError("Transport(cpu=...) pins the I/O threads of its own context: pass no context")
            self.ctx.set(zmq.THREAD_AFFINITY_CPU_ADD, cpu)
        self.cpu = cpu
        self.router = self.ctx.socket(zmq.ROUTER)
        self.xpub = self.ctx.socket(zmq.XPUB)
        hb = max(1, core.lockstep.heartbeat_ms)
        for s in (self.router, self.xpub):
            s.setsockopt(zmq.LINGER, 1000)
            s.setsockopt(zmq.HEARTBEAT_IVL, hb)
            s.setsockopt(zmq.HEARTBEAT_TIMEOUT, 3 * hb)
        self.router.setsockopt(zmq.MAXMSGSIZE, hard_limit)
        self.router.setsockopt(zmq.SNDHWM, ROUTER_SNDHWM)
        self.router.setsockopt(zmq.RCVHWM, 10_000)
        # a controller whose TCP connection was reset reconnects with the same routing id (the
        # client sets a random one): the new connection takes the identity over, so the session
        # and its pending step follow it (PROTOCOL.md, "Connections that drop")
        self.router.setsockopt(zmq.ROUTER_HANDOVER, 1)
        self.xpub.setsockopt(zmq.SNDHWM, pub_hwm)
        self.xpub.setsockopt(zmq.MAXMSGSIZE, SUB_LIMIT)       # subscription messages only
        # subscriptions are applied by us, only for prefixes that match a topic: a peer cannot
        # make libzmq hold arbitrary prefixes (memory), and each is released when its peer goes
        self.xpub.setsockopt(zmq.XPUB_MANUAL, 1)
        self.curve = curve_secret is not None
        for s in (self.router, self.xpub):
            curve_server(s, curve_secret)
        try:
            self.router.bind(_bindable(rpc))
            self.xpub.bind(_bindable(pub))
        except zmq.ZMQError:
            self._close_sockets()
            raise
        try:
            # requests in, replies out: C when built (steppath.py), else pyzmq; step_path or
            # SENSORIUM_STEP_PATH chooses
            self.gate = gate_for(self.router, max_frames=MAX_FRAMES, max_request=core.max_request,
                                 max_duration=MAX_PERIOD_MS, discard_budget=DISCARD_PER_TURN, step_path=step_path)
        except ValueError:
            self._close_sockets()
            raise
        self.rpc_endpoint = self.router.getsockopt_string(zmq.LAST_ENDPOINT)
        self.pub_endpoint = self.xpub.getsockopt_string(zmq.LAST_ENDPOINT)
        core.pub_endpoint = self.pub_endpoint
        self._stop_requested = False
        self._wake_r, self._wake_w = socket.socketpair()
        self._wake_r.setblocking(False)
        self._wake_w.setblocking(False)
        self.poller = zmq.Poller()
        self.poller.register(self.router, zmq.POLLIN)
        self.poller.register(self.xpub, zmq.POLLIN)
        self.poller.register(self._wake_r.fileno(), zmq.POLLIN)
        self.hooks: list[Callable[[], None]] = []
        # step replies of the last world steps, sent by the next receive (gate.exchange) or _flush
        self._outbox: list = []
        self.closed = False

    # ------------------------------------------------------------------ control
    def stop(self) -> None:
        """Ask the loop to shut down (signal-safe, thread-safe)."""
        self._stop_requested = True
        try:
            self._wake_w.send(b"\0")
        except OSError:
            pass

    def wake(self) -> None:
        """Make the loop pass soon (thread-safe): it runs :attr:`hooks` then."""
        try:
            self._wake_w.send(b"\1")
        except OSError:
            pass

    def install_signal_handlers(self) -> None:
        """SIGINT/SIGTERM → :meth:`stop` (main thread only)."""
        def handler(signum, frame):  # noqa: ARG001
            self.stop()

        signal.signal(signal.SIGINT, handler)
        signal.signal(signal.SIGTERM, handler)

    # ------------------------------------------------------------------ loop
    def run(self) -> None:
        """Serve until stopped. Two ways to wait:

        * *busy* (a request arrived within the last :data:`HOT_S`): block in the ROUTER's own
          receive (the step path's gate, ``RCVTIMEO`` ≤ :data:`HOT_WAIT_MS`). That is the
          lockstep's hot path: libzmq wakes this thread through the socket's mailbox alone,
          without the readiness checks of ``zmq_poll`` over three sockets (each ``ZMQ_EVENTS``
          query is a ``poll`` and a ``getpid``). The C gate reads on while the world waits for
          more controllers' steps (steppath.py), so this loop runs once per world step. The XPUB
          and the wake socket are looked at every :data:`EXPIRE_EVERY_S` (a zero-timeout poll),
          and a wait that times out drops to idle.
        * *idle*: ``zmq_poll`` on ROUTER, XPUB and the wake socket until the next deadline; a
          request makes the loop busy.

        A stretch of more than :data:`STALL_S` in which the loop read no request (a long world
        step, a long request, an over-long message being dropped) is credited to every session
        (``Core.unheard``): requests waited in the socket meanwhile, so that is not their silence.
        """
        core = self.core
        clock = self.clock
        gate = self.gate
        poll = self.poller.poll
        lockstep = core.lockstep
        quit_at: float | None = None
        next_expire = 0.0
        busy_until = 0.0
        next_step: float | None = None               # when the world may step next (None: not by itself)
        deaf_since = clock()                         # the loop last listened to the ROUTER then
        peers_generation = -1
        pinned = self._pin()
        try:
            while True:
                if self._stop_requested and quit_at is None:
                    self._flush()
                    gate.send(core.shutdown())
                    quit_at = clock() + self.grace_s
                now = clock()
                if quit_at is not None and now >= quit_at:
                    break
                timed_out = False
                if gate.discarding:
                    # the rest of an over-long message: nobody else's request can be read meanwhile
                    self._flush()
                    gate.discard()
                    busy_until = now + HOT_S
                elif now < busy_until:
                    t = next_step                        # the world may step by itself: wait no longer
                    wait_ms = HOT_WAIT_MS if t is None else max(0, min(HOT_WAIT_MS, int((t - now) * 1000 + 0.999)))
                    if lockstep.generation != peers_generation:
                        gate.set_peers(core.step_peers())
                        peers_generation = lockstep.generation
                    if now - deaf_since > STALL_S:      # a long stretch without reading: not their silence
                        core.unheard(now - deaf_since, now)
                    # the last world step's replies, then straight to waiting for the next requests:
                    # everything the loop does per step is done before the replies leave
                    replies, self._outbox = self._outbox, []
                    batch = gate.exchange(replies, STEP_REPLY_PIECES, wait_ms, lockstep.waiting_slots(),
                                          REQUESTS_PER_TURN)
                    now = deaf_since = clock()
                    if batch is not None:
                        self._serve(batch, now)
                        busy_until = now + HOT_S
                    elif wait_ms:
                        busy_until = 0.0                 # nothing for a while: wait on every socket
                        timed_out = True
                else:
                    self._flush()
                    if now - deaf_since > STALL_S:
                        core.unheard(now - deaf_since, now)
                    events = poll(self._timeout(now, quit_at))
                    now = deaf_since = clock()
                    timed_out = not events
                    for sock, _ in events:
                        if sock is self.router:
                            busy_until = now + HOT_S     # read by the busy branch, right away
                        elif sock is self.xpub:
                            self._drain_xpub()
                        else:
                            self._drain_wake()
                    now = clock()
                if quit_at is not None and now >= quit_at:
                    break
                # session expiry (and, while busy, the other sockets): when a deadline woke us,
                # else at most every EXPIRE_EVERY_S
                if timed_out or now >= next_expire:
                    if now - deaf_since > STALL_S:          # not listening since (dropping frames): credit it first
                        core.unheard(now - deaf_since, now)
                        deaf_since = now
                    core.expire(now)
                    next_expire = now + EXPIRE_EVERY_S
                    if busy_until:
                        self._look_around()
                for hook in self.hooks:
                    hook()
                next_step = self._run_steps(now)
        finally:
            if pinned is not None:
                os.sched_setaffinity(0, pinned)
            if not self.router.closed:
                self._flush()
            self.close()

    def _pin(self) -> set[int] | None:
        """With ``cpu``: run this (the loop's) thread on it until :meth:`run` ends; the CPUs it
        had before (threads the loop starts meanwhile inherit the pin; the ray engine's block
        workers widen theirs back, raycast/blocks.py)."""
        if self.cpu is None:
            return None
        before = os.sched_getaffinity(0)
        os.sched_setaffinity(0, {self.cpu})
        return before

    def _serve(self, batch: list, now: float) -> None:
        """Answer one batch from the gate: recognised steps, other messages, over-long messages.
        Only the last item can be other than a recognised step (the gate ends a batch there), so a
        batch of steps up to the barrier goes to the core in one call."""
        core = self.core
        if type(batch[-1]) is tuple:
            replies = core.handle_steps(batch, now)
        else:
            replies = []
            for item in batch:
                kind = type(item)
                if kind is tuple:
                    replies += core.handle_step(item[0], item[1], item[2], item[3], now)
                elif kind is list:
                    replies += core.handle(item, now)
                else:                                    # the identity of a message with too many frames
                    replies.append([item, TOO_MANY_FRAMES])
        if replies:
            self.gate.send(replies)
        said = core.topics.outbox                       # robot-window texts the requests published
        if said:
            core.topics.outbox = []
            for frames in said:
                self.xpub.send_multipart(frames, copy=False)

    def _flush(self) -> None:
        """Send the step replies still in the outbox (before anything but the busy receive)."""
        if self._outbox:
            replies, self._outbox = self._outbox, []
            self.gate.send_steps(replies, STEP_REPLY_PIECES)

    def _look_around(self) -> None:
        """While busy: serve the XPUB and the wake socket if they have something (no waiting)."""
        for sock, _ in self.poller.poll(0):
            if sock is self.xpub:
                self._drain_xpub()
            elif sock is not self.router:
                self._drain_wake()

    def _timeout(self, now: float, quit_at: float | None) -> int:
        deadline = self.core.next_deadline(now)
        if quit_at is not None:
            deadline = quit_at if deadline is None else min(deadline, quit_at)
        if deadline is None:
            return MAX_IDLE_WAIT_MS
        return max(0, min(MAX_IDLE_WAIT_MS, int((deadline - now) * 1000 + 0.999)))

    def _drain_xpub(self, limit: int = 1000) -> None:
        xpub = self.xpub
        for _ in range(limit):
            if not xpub.getsockopt(zmq.EVENTS) & zmq.POLLIN:
                return
            try:
                event = xpub.recv(zmq.NOBLOCK)
            except zmq.Again:
                return
            if not event or event[0] not in (0, 1):
                continue
            prefix = event[1:]
            if event[0] == 1:
                if not self.core.topics.accepts(prefix):
                    continue                              # matches no topic: not kept
                xpub.setsockopt(zmq.SUBSCRIBE, prefix)    # applies to the pipe it came from
            else:
                xpub.setsockopt(zmq.UNSUBSCRIBE, prefix)
            self.core.subscription(event)

    def _drain_wake(self) -> None:
        try:
            while self._wake_r.recv(64):
                pass
        except (BlockingIOError, OSError):
            pass

    def _run_steps(self, now: float | None = None) -> float | None:
        """Step while the lockstep allows it (at most :data:`STEP_BUDGET_S`); return when the world
        may step next (wall time; ``None``: when a request or deadline allows it)."""
        core, clock = self.core, self.clock
        start = now = clock() if now is None else now
        while True:
            t = core.next_advance(now)
            if t is None or t > now:
                return t
            self._flush()                               # a world stepping on: the earlier step's replies now
            # the step replies without new values stay (envelope, rid, status, time_ms): the gate packs
            # them; they leave with the loop's next receive (gate.exchange), publications first
            replies, pubs = core.step_once_compact(now)
            for frames in pubs:
                self.xpub.send_multipart(frames, copy=False)
            self._outbox += replies
            if self.stop_at_ms is not None and core.sim.time_ms >= self.stop_at_ms:
                self.stop()
                return None
            now = clock()
            if now - start > STEP_BUDGET_S:
                return now                              # let the sockets be served, then step on

    # ------------------------------------------------------------------ close
    def _close_sockets(self) -> None:
        gate = getattr(self, "gate", None)
        if gate is not None:
            gate.close()                      # before the socket goes: the C gate holds its raw handle
        for s in (self.router, self.xpub):
            if not s.closed:
                s.close()

    def close(self) -> None:
        if self.closed:
            return
        self.closed = True
        self._close_sockets()
        for s in (getattr(self, "_wake_r", None), getattr(self, "_wake_w", None)):
            if s is not None:
                s.close()
        if self._own_context:
            self.ctx.term()

