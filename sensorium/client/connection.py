"""The client's only ZeroMQ module: controller URLs, request/reply correlation, heartbeats.

    conn = Connection("tcp://127.0.0.1:5560")
    info = conn.call("get_info")                    # one round trip
    rid = conn.send("/epuck/robot/step", {"duration": 32})   # pipelined: send now ...
    reply = conn.wait(rid, timeout=None)            # ... read the reply later

A :class:`Connection` owns one ``DEALER`` socket (not thread-safe: use it from one thread). A
:class:`Heartbeat` thread owns a second socket and sends ``ping {session}`` every
``heartbeat_ms`` so that a controller computing for a long time between steps stays attached; it
also tells the connection when the server is gone (no answer and no live ZeroMQ connection: a
server computing a long step keeps its connection up and is waited for), so a blocked step raises
:class:`ConnectionLost` instead of hanging forever. Errors the server sends back raise
:class:`SensoriumError` with the protocol's code (PROTOCOL.md §3.2).
"""

from __future__ import annotations

import itertools
import os
import secrets
import socket
import stat
import threading
import time
from collections.abc import Mapping
from dataclasses import dataclass
from enum import IntEnum
from typing import Any
from urllib.parse import quote, unquote

import msgpack
import zmq
import zmq.utils.z85

DEFAULT_RPC_ENDPOINT = "tcp://127.0.0.1:5560"
DEFAULT_PUB_ENDPOINT = "tcp://127.0.0.1:5561"
DEFAULT_PORT = 5560
ENV_URL = "SENSORIUM_CONTROLLER_URL"
WEBOTS_ENV_URL = "WEBOTS_CONTROLLER_URL"
WEBOTS_ENV_ROBOT = "WEBOTS_ROBOT_NAME"
ENV_CURVE_SERVERKEY = "SENSORIUM_CURVE_SERVERKEY"   # the server's CURVE public key: encrypt, authenticate it
ENV_CURVE_PUBLICKEY = "SENSORIUM_CURVE_PUBLICKEY"   # this client's key pair (default: a fresh one per socket)
ENV_CURVE_SECRETKEY = "SENSORIUM_CURVE_SECRETKEY"
RETRY_S = 1.0                   # a step request unanswered this long is sent again (same id) ...
RETRY_MAX_S = 8.0               # ... then after twice as long each time, up to this (a long step)
PING_BACKLOG = 16               # unanswered pings at most (a long step): the server's queue stays short
RETRIED_SERVICES = ("/robot/step", "/robot/time_step")
DEFAULT_TIMEOUT = 10.0          # seconds for a non-step request (the server may still be starting)

_NO_TIMEOUT = object()
_NOBLOCK = int(zmq.NOBLOCK)     # a plain int: pyzmq's enum flags cost ~0.3 µs per call


class ErrorCode(IntEnum):
    """Server error codes (PROTOCOL.md §3.2) and, from 1000 up, errors found by the client itself."""

    BAD_REQUEST = 1
    UNKNOWN_SERVICE = 2
    UNKNOWN_ROBOT = 3
    UNKNOWN_DEVICE = 4
    INVALID_ARGUMENT = 5
    NOT_ATTACHED = 6
    ROBOT_TAKEN = 7
    TOO_LARGE = 8
    SHUTTING_DOWN = 9
    WRONG_STATE = 10
    NOT_SUPERVISOR = 11
    INTERNAL = 99
    # client side
    TIMEOUT = 1000
    CONNECTION_LOST = 1001
    BAD_REPLY = 1002
    BAD_URL = 1003


class SensoriumError(Exception):
    """An error reply from the server (``code`` from PROTOCOL.md §3.2) or a client-side failure."""

    def __init__(self, code: int, message: str):
        self.code = int(code)
        self.message = str(message)
        super().__init__(self.code, self.message)

    @property
    def name(self) -> str:
        try:
            return ErrorCode(self.code).name
        except ValueError:
            return f"ERROR_{self.code}"

    def __str__(self) -> str:
        return f"{self.name}: {self.message}"


class ServiceTimeout(SensoriumError, TimeoutError):
    def __init__(self, message: str):
        super().__init__(ErrorCode.TIMEOUT, message)


class ConnectionLost(SensoriumError, ConnectionError):
    def __init__(self, message: str):
        super().__init__(ErrorCode.CONNECTION_LOST, message)


# ---------------------------------------------------------------------- URLs

@dataclass(frozen=True, slots=True)
class ControllerURL:
    """Where a controller connects: the RPC ``endpoint`` (a ZeroMQ address) and the ``robot``
    (``None``: the world's only robot, like Webots' URL without a robot name)."""

    endpoint: str
    robot: str | None = None

    def __str__(self) -> str:
        if self.robot is None:
            return self.endpoint
        base, sep, query = self.endpoint.partition("?")
        return f"{base}/{quote(self.robot, safe='')}{sep}{query}"

    def with_robot(self, robot: str | None) -> ControllerURL:
        return ControllerURL(self.endpoint, robot)


def _bad_url(url: str, why: str) -> SensoriumError:
    return SensoriumError(ErrorCode.BAD_URL, f"controller URL {url!r}: {why}")


def _robot_part(url: str, part: str) -> str | None:
    part = part.strip("/")
    if not part:
        return None
    if "/" in part:
        raise _bad_url(url, f"robot name {part!r} contains '/'; percent-encode it (%2F)")
    return unquote(part)


def _is_socket(path: str) -> bool:
    try:
        return stat.S_ISSOCK(os.stat(path).st_mode)
    except OSError:
        return False


def parse_controller_url(url: str | None, default_endpoint: str = DEFAULT_RPC_ENDPOINT) -> ControllerURL:
    """Parse a controller URL, in Webots' ``WEBOTS_CONTROLLER_URL`` forms:

    ==================================  ==============================================
    unset or empty                      the only robot at ``default_endpoint``
    ``NAME``                            robot NAME at ``default_endpoint``
    ``tcp://HOST[:PORT][/NAME]``        robot NAME (or the only robot); port 5560
    ``ipc://PATH/NAME``                 robot NAME at ``ipc://PATH``
    ``ipc://PATH/``                     the only robot at ``ipc://PATH``
    ==================================  ==============================================

    Robot names are percent-decoded. For ``ipc://`` the last path component is the robot unless
    the whole path is an existing socket file.
    """
    if url is None or not url.strip():
        return ControllerURL(default_endpoint, None)
    url, sep, query = url.strip().partition("?")
    if sep:                                          # ?serverkey=KEY (CURVE): carried by the endpoint
        split_curve("tcp://x?" + query, {})          # checked now: a bad key is a bad URL
        parsed = parse_controller_url(url, default_endpoint)
        return ControllerURL(f"{parsed.endpoint}?{query}", parsed.robot)
    scheme, sep, rest = url.partition("://")
    if not sep:
        return ControllerURL(default_endpoint, _robot_part(url, url))
    scheme = scheme.lower()
    if scheme == "tcp":
        hostport, _, path = rest.partition("/")
        if not hostport:
            raise _bad_url(url, "no host")
        if hostport.startswith("["):                     # IPv6 literal: [::1]:5560
            close = hostport.find("]")
            if close < 0:
                raise _bad_url(url, "unterminated IPv6 address")
            host, port = hostport[:close + 1], hostport[close + 1:].lstrip(":")
        else:
            host, _, port = hostport.partition(":")
        if not host:
            raise _bad_url(url, "no host")
        if port:
            if not port.isdigit() or not 0 < int(port) < 65536:
                raise _bad_url(url, f"bad port {port!r}")
        else:
            port = str(DEFAULT_PORT)
        return ControllerURL(f"tcp://{host}:{port}", _robot_part(url, path))
    if scheme in ("ipc", "inproc"):
        if not rest:
            raise _bad_url(url, "no path")
        if rest.endswith("/"):
            return ControllerURL(f"{scheme}://{rest.rstrip('/')}", None)
        if scheme == "ipc" and _is_socket(rest):
            return ControllerURL(url, None)
        head, slash, tail = rest.rpartition("/")
        if not slash or not head:
            return ControllerURL(url, None)
        return ControllerURL(f"{scheme}://{head}", _robot_part(url, tail))
    raise _bad_url(url, f"unsupported scheme {scheme!r} (use tcp://, ipc:// or a robot name)")


def controller_url_from_env(environ: Mapping[str, str] | None = None) -> ControllerURL:
    """The controller URL from ``SENSORIUM_CONTROLLER_URL``, else Webots' ``WEBOTS_CONTROLLER_URL``;
    a URL that names no robot takes ``WEBOTS_ROBOT_NAME``'s (Webots sets it for each controller it
    starts, and extern controllers before R2022b chose their robot with it), literally (no
    percent-decoding: it is a name, not a URL)."""
    env = os.environ if environ is None else environ
    url = parse_controller_url(env.get(ENV_URL) or env.get(WEBOTS_ENV_URL) or None)
    name = env.get(WEBOTS_ENV_ROBOT)
    return url.with_robot(name) if url.robot is None and name else url


# ---------------------------------------------------------------------- CURVE (encryption)

def _curve_key(text: str, where: str) -> bytes:
    """A CURVE key as Z85 (40 characters) or hex (64) → Z85 bytes; SensoriumError(BAD_URL) otherwise."""
    text = text.strip()
    if len(text) == 64:
        try:
            return zmq.utils.z85.encode(bytes.fromhex(text))
        except ValueError:
            pass
    if len(text) == 40:
        try:
            zmq.utils.z85.decode(text.encode("ascii"))
            return text.encode("ascii")
        except (ValueError, UnicodeEncodeError, KeyError):
            pass
    raise SensoriumError(ErrorCode.BAD_URL, f"{where}: a CURVE key is 40 Z85 or 64 hex characters "
                                            f"(got {len(text)} characters)")


def split_curve(endpoint: str, environ: dict[str, str] | None = None) -> tuple[str, bytes | None]:
    """``tcp://HOST:PORT?serverkey=KEY`` → (``tcp://HOST:PORT``, KEY); without a query the key is
    ``SENSORIUM_CURVE_SERVERKEY`` (or None: a plain connection). KEY runs to the end of the URL."""
    env = os.environ if environ is None else environ
    base, sep, query = endpoint.partition("?")
    if sep:
        name, eq, value = query.partition("=")
        if name != "serverkey" or not eq:
            raise SensoriumError(ErrorCode.BAD_URL, f"endpoint {base!r}: the only query is ?serverkey=KEY")
        return base, _curve_key(value, f"endpoint {base!r}: serverkey")
    key = env.get(ENV_CURVE_SERVERKEY)
    return base, (_curve_key(key, ENV_CURVE_SERVERKEY) if key else None)


def curve_client(sock: zmq.Socket, serverkey: bytes | None, environ: dict[str, str] | None = None) -> None:
    """Make ``sock`` a CURVE client of the server with public key ``serverkey`` (before connect).
    Its own key pair is ``SENSORIUM_CURVE_PUBLICKEY``/``SECRETKEY``, else a fresh one."""
    if serverkey is None:
        return
    env = os.environ if environ is None else environ
    pub, sec = env.get(ENV_CURVE_PUBLICKEY), env.get(ENV_CURVE_SECRETKEY)
    if pub and sec:
        public, secret = _curve_key(pub, ENV_CURVE_PUBLICKEY), _curve_key(sec, ENV_CURVE_SECRETKEY)
    else:
        public, secret = zmq.curve_keypair()
    sock.setsockopt(zmq.CURVE_SERVERKEY, serverkey)
    sock.setsockopt(zmq.CURVE_PUBLICKEY, public)
    sock.setsockopt(zmq.CURVE_SECRETKEY, secret)


# ---------------------------------------------------------------------- encoding

def pack(obj: Any) -> bytes:
    return msgpack.packb(obj, use_bin_type=True)


def unpack(data: bytes) -> Any:
    return msgpack.unpackb(data, raw=False, strict_map_key=False)


_unpackb = msgpack.unpackb


def _error_from(reply: dict) -> SensoriumError:
    err = reply.get("error")
    if not isinstance(err, dict):
        return SensoriumError(ErrorCode.BAD_REPLY, f"error reply without an error map: {reply!r}")
    return SensoriumError(int(err.get("code", ErrorCode.INTERNAL)), str(err.get("message", "")))


# ---------------------------------------------------------------------- connection

class Connection:
    """One DEALER socket to the RPC endpoint: numbered requests, replies matched by ``id``.

    ``timeout`` (seconds, ``None`` = forever) is the default wait for a reply; ``send`` + ``wait``
    pipeline requests (a step reply may arrive after later requests' replies)."""

    def __init__(self, endpoint: str, *, timeout: float | None = DEFAULT_TIMEOUT,
                 context: zmq.Context | None = None):
        self.endpoint, self._serverkey = split_curve(endpoint)
        self.timeout = timeout
        self._context = context or zmq.Context.instance()
        self._socket = self._context.socket(zmq.DEALER)
        self._socket.setsockopt(zmq.LINGER, 0)
        # a random routing id of our own: if the TCP connection drops and libzmq reconnects, the
        # server sees the same peer (ROUTER_HANDOVER), so the session and a pending step follow
        # (a first byte of 0 is reserved by libzmq)
        self._socket.setsockopt(zmq.ROUTING_ID, b"S" + secrets.token_bytes(15))
        curve_client(self._socket, self._serverkey)
        # handshake events only (tcp): a timeout can then say "the key is missing or wrong" instead
        # of "is the server running?"; dropped after the first successful handshake
        self._monitor: zmq.Socket | None = None
        if self.endpoint.startswith("tcp://"):
            addr = f"inproc://sensorium-handshake-{secrets.token_hex(8)}"
            self._socket.monitor(addr, zmq.EVENT_HANDSHAKE_SUCCEEDED | zmq.EVENT_HANDSHAKE_FAILED_PROTOCOL
                                 | zmq.EVENT_HANDSHAKE_FAILED_NO_DETAIL | zmq.EVENT_HANDSHAKE_FAILED_AUTH)
            # libzmq sends monitor events from its I/O thread with a blocking send: a full pipe (a
            # wrong key failing every reconnect while nobody waits on a reply) would stall every
            # socket of the context. RCVHWM 0 before connecting makes the inproc pipe unbounded
            # (a few bytes per event, read and dropped at the next wait).
            self._monitor = self._context.socket(zmq.PAIR)
            self._monitor.setsockopt(zmq.RCVHWM, 0)
            self._monitor.setsockopt(zmq.LINGER, 0)
            self._monitor.connect(addr)
        self._handshake_failed = 0                   # the last failed handshake's event (0: none)
        self._socket.connect(self.endpoint)
        self._poller = zmq.Poller()                  # kept for callers that poll the socket themselves
        self._poller.register(self._socket, zmq.POLLIN)
        self._rcvtimeo: zmq.Socket | None = None     # the socket whose RCVTIMEO is _rcvtimeo_ms
        self._rcvtimeo_ms = -1
        self._ids = itertools.count(1)
        self._packer = msgpack.Packer(use_bin_type=True)   # reused: one per connection (one thread)
        self._outstanding: dict[int, str] = {}      # id -> service, for messages
        self._replies: dict[int, dict] = {}
        self._retry: dict[int, tuple[bytes, float, float]] = {}   # step requests: id -> (bytes, last sent, wait)
        self.heartbeat: Heartbeat | None = None
        self.retries = 0                            # step requests sent again (see _resend_due)
        self.closed = False

    # -- requests
    def send(self, service: str, args: dict | None = None) -> int:
        """Send a request; return its id (for :meth:`wait`)."""
        if self.closed:
            raise SensoriumError(ErrorCode.WRONG_STATE, f"connection to {self.endpoint} is closed")
        rid = next(self._ids)
        try:
            data = self._packer.pack({"id": rid, "service": service, "args": args or {}})
        except (UnicodeEncodeError, OverflowError, TypeError, ValueError) as exc:
            # a str with lone surrogates (a file name os.fsdecode made), an int beyond 64 bits, an
            # object msgpack does not know: the caller's bad argument, said in one line
            raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{service}: an argument cannot be sent: {exc}") from None
        try:
            # never blocks: a DEALER queues while (re)connecting and refuses only once ZeroMQ closed
            # its connection for good (see _resend_due) or 1000 requests wait unsent
            self._socket.send(data, _NOBLOCK)
        except zmq.Again:
            raise ConnectionLost(f"cannot send {service!r} to {self.endpoint}: ZeroMQ closed the connection for good "
                                 "or 1000 requests wait unsent") from None
        self._outstanding[rid] = service
        if service.endswith(RETRIED_SERVICES):
            self._retry[rid] = (data, time.monotonic(), RETRY_S)
        return rid

    def wait(self, rid: int, timeout: Any = _NO_TIMEOUT) -> dict:
        """The ``result`` of request ``rid``; raise :class:`SensoriumError` for an error reply,
        :class:`ServiceTimeout` after ``timeout`` seconds, :class:`ConnectionLost` if the
        heartbeat found the server gone or the session dropped."""
        reply = self._replies.pop(rid, None) if self._replies else None
        if reply is None:
            try:
                reply = self._receive(rid, self.timeout if timeout is _NO_TIMEOUT else timeout)
            except SensoriumError as exc:
                # the server's id-less refusal of a request too large to read: ours when it is the
                # only one outstanding (a controller's call), said with its service
                if exc.code != ErrorCode.TOO_LARGE or list(self._outstanding) != [rid]:
                    raise
                service = self._outstanding.pop(rid)
                self._retry.pop(rid, None)
                raise SensoriumError(exc.code, f"{service}: {exc.message}") from None
        del self._outstanding[rid]
        if self._retry:
            self._retry.pop(rid, None)
        if reply.get("ok") is True:
            result = reply.get("result")
            return result if isinstance(result, dict) else {}
        raise _error_from(reply)

    def _receive(self, rid: int, timeout: float | None) -> dict:
        """Receive until the reply to ``rid`` arrives (others are kept for their :meth:`wait`)."""
        if rid not in self._outstanding:
            raise SensoriumError(ErrorCode.WRONG_STATE, f"request {rid} is not outstanding")
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            slice_ms = 250
            if deadline is not None:
                left = deadline - time.monotonic()
                if left <= 0:
                    service = self._outstanding.pop(rid, "?")
                    self._retry.pop(rid, None)
                    problem = self.handshake_problem()
                    raise ServiceTimeout(
                        f"no reply to {service!r} from {self.endpoint} within {timeout:g} s "
                        + (f"({problem})" if problem else "(is `sensorium serve` running there?)"))
                if left < 0.25:
                    slice_ms = max(1, int(left * 1000) + 1)
            # one blocking receive (RCVTIMEO = the slice) instead of poll + non-blocking drain
            sock = self._socket
            if self._rcvtimeo is not sock or self._rcvtimeo_ms != slice_ms:
                sock.setsockopt(zmq.RCVTIMEO, slice_ms)
                self._rcvtimeo, self._rcvtimeo_ms = sock, slice_ms
            try:
                # a reply to a DEALER is one frame (PROTOCOL.md §3.1), received as bytes: the
                # cheapest form (a zero-copy frame, or a ZMQ_RCVMORE query, costs ~0.6 µs more); a
                # longer message would come apart into frames that do not decode (BAD_REPLY)
                data = sock.recv()
            except zmq.Again:
                self._resend_due(rid)
                if self._monitor is not None:
                    self._watch_handshakes()
                if self.heartbeat is not None:
                    problem = self.heartbeat.problem()
                    if problem is not None:
                        service = self._outstanding.pop(rid, "?")
                        self._retry.pop(rid, None)
                        raise ConnectionLost(f"while waiting for {service!r}: {problem}") from None
                continue
            # _decode_body inlined (the step loop's hot path): the same checks
            try:
                reply = _unpackb(data, raw=False, strict_map_key=False)
            except Exception as exc:  # noqa: BLE001 - any decoding failure is a bad reply
                raise SensoriumError(ErrorCode.BAD_REPLY, f"undecodable reply from {self.endpoint}: {exc}") from None
            if type(reply) is not dict:
                raise SensoriumError(ErrorCode.BAD_REPLY, f"reply is not a map: {reply!r}")
            got = reply.get("id")
            if got == rid:
                return reply
            if got is None and reply.get("ok") is False:
                raise _error_from(reply)
            if got in self._outstanding:
                self._replies[got] = reply
            # else: the reply to a request we gave up on (timeout, discard): drop it

    def _watch_handshakes(self) -> None:
        """Read the monitor's events (non-blocking); stop monitoring once a handshake succeeded."""
        mon = self._monitor
        while mon is not None and mon.poll(0):
            frames = mon.recv_multipart()
            event = int.from_bytes(frames[0][:2], "little")
            if event == zmq.EVENT_HANDSHAKE_SUCCEEDED:
                self._handshake_failed = 0
                self._stop_monitor()
                return
            self._handshake_failed = event

    def _stop_monitor(self) -> None:
        if self._monitor is not None:
            try:
                self._socket.disable_monitor()
            except zmq.ZMQError:
                pass
            self._monitor.close(linger=0)
            self._monitor = None

    def handshake_problem(self) -> str | None:
        """Why the server would not talk to this client, if its security handshake failed."""
        self._watch_handshakes()
        failed = self._handshake_failed
        if not failed:
            return None
        if self._serverkey is None:
            return ("the server refused the connection's handshake: it uses CURVE encryption and this client has "
                    f"no key; set {ENV_CURVE_SERVERKEY} to the key `sensorium serve --curve-keys` prints, or add "
                    "?serverkey=KEY to the URL")
        if failed == zmq.EVENT_HANDSHAKE_FAILED_PROTOCOL:
            return (f"the handshake failed: this client uses CURVE ({ENV_CURVE_SERVERKEY} or ?serverkey=) but the "
                    "server does not (started without --curve-keys?)")
        return (f"the server did not accept the CURVE handshake: the server key ({ENV_CURVE_SERVERKEY} or "
                "?serverkey=) is wrong for this server")

    def call(self, service: str, args: dict | None = None, timeout: Any = _NO_TIMEOUT) -> dict:
        """``send`` then ``wait``."""
        return self.wait(self.send(service, args), timeout)

    def _resend_due(self, rid: int) -> None:
        """Re-send a step request not answered for :data:`RETRY_S`: its reply may have been lost
        with a dropped connection. The server answers a repeated id once (PROTOCOL.md)."""
        entry = self._retry.get(rid)
        if entry is not None and time.monotonic() - entry[1] >= entry[2]:
            try:
                self._socket.send(entry[0], _NOBLOCK)
            except zmq.Again:
                # no connection left to queue on: ZeroMQ closed it for good (it does so, without
                # reconnecting, when a message breaks the protocol); a dropped network one would queue
                service = self._outstanding.pop(rid, "?")
                self._retry.pop(rid, None)
                raise ConnectionLost(f"ZeroMQ closed the connection to {self.endpoint} for good while the reply to "
                                     f"{service!r} was due (a message that is not ZeroMQ ends it)") from None
            # a step the server computes for long gets fewer copies: 1, 2, 4, 8, 8 … s apart
            self._retry[rid] = (entry[0], time.monotonic(), min(2 * entry[2], RETRY_MAX_S))
            self.retries += 1

    def discard(self, rid: int) -> None:
        """Forget an outstanding request: its reply, if it comes, is dropped."""
        self._retry.pop(rid, None)
        self._outstanding.pop(rid, None)
        self._replies.pop(rid, None)

    def _drain(self) -> None:
        """Take every reply already received (non-blocking)."""
        sock = self._socket
        while sock.getsockopt(zmq.EVENTS) & zmq.POLLIN:
            try:
                frames = sock.recv_multipart(zmq.NOBLOCK)
            except zmq.Again:
                return
            self._accept(frames)

    def _accept(self, frames: list[bytes]) -> None:
        """One received reply: keep it if its request is outstanding, else drop it."""
        reply = self._decode(frames)
        rid = reply.get("id")
        if rid in self._outstanding:
            self._replies[rid] = reply
        # else: the reply to a request we gave up on (timeout, discard): drop it

    def _decode(self, frames: list[bytes]) -> dict:
        return self._decode_body(frames[-1])

    def _decode_body(self, body: bytes) -> dict:
        """A reply's map; SensoriumError for an undecodable one, or for the server's id-less error
        reply (it could not read one of our requests)."""
        try:
            reply = unpack(body)
        except Exception as exc:  # noqa: BLE001 - any decoding failure is a bad reply
            raise SensoriumError(ErrorCode.BAD_REPLY, f"undecodable reply from {self.endpoint}: {exc}") from None
        if type(reply) is not dict:
            raise SensoriumError(ErrorCode.BAD_REPLY, f"reply is not a map: {reply!r}")
        if reply.get("id") is None and reply.get("ok") is False:
            raise _error_from(reply)
        return reply

    @property
    def outstanding(self) -> int:
        return len(self._outstanding)

    # -- lifecycle
    def start_heartbeat(self, session: str, interval_ms: int, lost_after_s: float | None = None) -> Heartbeat:
        self.stop_heartbeat()
        self.heartbeat = Heartbeat(self.endpoint, session, interval_ms, self._context, lost_after_s,
                                   serverkey=self._serverkey)
        self.heartbeat.start()
        return self.heartbeat

    def stop_heartbeat(self) -> None:
        if self.heartbeat is not None:
            self.heartbeat.stop()
            self.heartbeat = None

    def close(self) -> None:
        if self.closed:
            return
        self.stop_heartbeat()
        self.closed = True
        self._stop_monitor()
        self._socket.close(linger=0)

    def __enter__(self) -> Connection:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class Heartbeat(threading.Thread):
    """Sends ``ping {session}`` every ``interval_ms`` on its own socket and watches the replies.

    :meth:`problem` says why the connection is unusable: the server answered that the session is
    gone, or it is gone itself: no reply for ``lost_after_s`` seconds (default: 5 heartbeats, at
    least 2 s) *and* no live ZeroMQ connection to it for :attr:`down_grace` seconds. A server that
    computes a long step answers no ping, but its ZeroMQ I/O thread answers the ZMTP heartbeats this
    socket sends (``ZMQ_HEARTBEAT_IVL``/``ZMQ_HEARTBEAT_TIMEOUT``) and keeps the connection up:
    busy, not gone, so the wait goes on. A killed server closes the connection; a frozen one
    (SIGSTOP: its I/O threads stop too) lets the ZMTP heartbeats time out, which closes it."""

    def __init__(self, endpoint: str, session: str, interval_ms: int, context: zmq.Context,
                 lost_after_s: float | None = None, serverkey: bytes | None = None):
        super().__init__(name="sensorium-heartbeat", daemon=True)
        self.endpoint = endpoint
        self.serverkey = serverkey                      # CURVE: the server's public key (Z85)
        self.session = session
        self.interval = max(1, int(interval_ms)) / 1000.0
        self.lost_after = lost_after_s if lost_after_s is not None else max(2.0, 5 * self.interval)
        # ZMTP heartbeats: a PING each interval; no traffic for zmtp_timeout closes the connection
        self.zmtp_timeout = max(1.0, 3 * self.interval)
        # a connection down this long (a reconnection takes ~0.1 s) counts as no connection
        self.down_grace = max(0.5, 2 * self.interval)
        self.connected = False     # a ZeroMQ connection has passed its handshake and not closed since
        self.down_since = time.monotonic()
        self._context = context
        self._stop_event = threading.Event()
        # stop() wakes the thread through this pair: it sleeps until its next ping, not in short
        # slices (each wake-up of a Python thread takes the GIL from the stepping one)
        self._wake_r, self._wake_w = socket.socketpair()
        self._wake_w.setblocking(False)
        self._problem: str | None = None
        self.last_reply = time.monotonic()
        self.pings = 0
        self.replies = 0
        self._unanswered = 0       # pings sent since the last reply (or connection)
        self.paused_s = 0.0        # longest time this thread did not run (SIGSTOP, a stalled VM)

    def problem(self) -> str | None:
        if self._problem is not None:
            return self._problem
        now = time.monotonic()
        silent = now - self.last_reply
        if silent <= self.lost_after or self.connected:
            return None                 # answering, or busy (a long step): its connection lives
        down = now - self.down_since
        if down <= self.down_grace:
            return None
        return (f"no answer from {self.endpoint} for {silent:.1f} s and no connection to it for {down:.1f} s "
                "(server gone, or the network down)")

    def _watch(self, monitor: zmq.Socket) -> None:
        """Read the connection's events (non-blocking): up after a handshake, down when it closes."""
        while True:
            try:
                frames = monitor.recv_multipart(zmq.NOBLOCK)
            except zmq.Again:
                return
            event = int.from_bytes(frames[0][:2], "little")
            if event == zmq.EVENT_HANDSHAKE_SUCCEEDED:
                self.connected = True
                self._unanswered = 0        # a new connection: pings sent before may be lost
            elif event == zmq.EVENT_DISCONNECTED and self.connected:
                self.connected = False
                self.down_since = time.monotonic()

    def stop(self) -> None:
        self._stop_event.set()
        try:
            self._wake_w.send(b"\0")
        except OSError:
            pass
        if self.is_alive() and threading.current_thread() is not self:
            self.join(timeout=2.0)

    def run(self) -> None:
        sock = self._context.socket(zmq.DEALER)
        sock.setsockopt(zmq.LINGER, 0)
        sock.setsockopt(zmq.HEARTBEAT_IVL, max(1, int(self.interval * 1000)))
        sock.setsockopt(zmq.HEARTBEAT_TIMEOUT, int(self.zmtp_timeout * 1000))
        # the connection's ups and downs (the unbounded pipe: see Connection.__init__)
        addr = f"inproc://sensorium-heartbeat-{secrets.token_hex(8)}"
        sock.monitor(addr, zmq.EVENT_HANDSHAKE_SUCCEEDED | zmq.EVENT_DISCONNECTED)
        monitor = self._context.socket(zmq.PAIR)
        monitor.setsockopt(zmq.RCVHWM, 0)
        monitor.setsockopt(zmq.LINGER, 0)
        monitor.connect(addr)
        poller = zmq.Poller()
        poller.register(sock, zmq.POLLIN)
        poller.register(monitor, zmq.POLLIN)
        poller.register(self._wake_r.fileno(), zmq.POLLIN)
        try:
            curve_client(sock, self.serverkey)
            sock.connect(self.endpoint)
            ids = itertools.count(1)
            next_ping = time.monotonic()
            last_turn = next_ping
            while not self._stop_event.is_set():
                now = time.monotonic()
                if now - last_turn > max(1.0, 2 * self.interval):
                    # this process did not run (stopped, suspended): the server's silence is ours,
                    # not a sign that it is gone; ask again before judging
                    self.paused_s = max(self.paused_s, now - last_turn)
                    self.last_reply = now
                    self.down_since = max(self.down_since, now)
                    next_ping = now
                last_turn = now
                if now >= next_ping:
                    # a server computing a long step reads none: a few wait for it, not one per beat
                    if self._unanswered < PING_BACKLOG:
                        sock.send(pack({"id": next(ids), "service": "ping", "args": {"session": self.session}}))
                        self.pings += 1
                        self._unanswered += 1
                    next_ping = now + self.interval
                wait_ms = int((next_ping - time.monotonic()) * 1000) + 1
                ready = dict(poller.poll(max(wait_ms, 1)))
                if ready.get(monitor):
                    self._watch(monitor)
                if ready.get(sock):
                    while True:
                        try:
                            reply = unpack(sock.recv_multipart(zmq.NOBLOCK)[-1])
                        except zmq.Again:
                            break
                        except Exception:  # noqa: BLE001 - a garbled pong is no pong
                            continue
                        self.last_reply = time.monotonic()
                        self.replies += 1
                        self._unanswered = 0
                        if isinstance(reply, dict) and reply.get("ok") is False:
                            err = _error_from(reply)
                            why = (f"after this process did not run for {self.paused_s:.1f} s"
                                   if self.paused_s else "after it heard nothing from this controller for "
                                   "3 heartbeats (a network stall?)")
                            self._problem = f"the server released the robot {why} ({err.name})"
        except zmq.ContextTerminated:
            pass
        finally:
            try:
                sock.disable_monitor()
            except zmq.ZMQError:
                pass
            monitor.close(linger=0)
            sock.close(linger=0)
            self._wake_r.close()
            self._wake_w.close()


class SubSocket:
    """A SUB socket on a topic endpoint, for :mod:`sensorium.client.topics` (which stays zmq-free)."""

    def __init__(self, endpoint: str, *, context: zmq.Context | None = None, rcvhwm: int = 1000):
        self.endpoint, serverkey = split_curve(endpoint)
        self._socket = (context or zmq.Context.instance()).socket(zmq.SUB)
        self._socket.setsockopt(zmq.LINGER, 0)
        self._socket.setsockopt(zmq.RCVHWM, rcvhwm)
        curve_client(self._socket, serverkey)
        self._socket.connect(self.endpoint)

    def subscribe(self, prefix: bytes) -> None:
        self._socket.setsockopt(zmq.SUBSCRIBE, prefix)

    def unsubscribe(self, prefix: bytes) -> None:
        self._socket.setsockopt(zmq.UNSUBSCRIBE, prefix)

    def poll(self, timeout_ms: int | None) -> bool:
        """Whether a message is ready within ``timeout_ms`` (``None``: wait for one)."""
        return bool(self._socket.poll(timeout_ms, zmq.POLLIN))

    def recv_frames(self) -> list[bytes]:
        return self._socket.recv_multipart()

    def close(self) -> None:
        self._socket.close(linger=0)
