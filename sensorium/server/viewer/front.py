"""The viewer's listening socket: a small TCP front before foxglove-sdk's WebSocket server.

Why: foxglove-sdk's server (every release up to 0.30 at least) completes a WebSocket handshake
only when the client offers the subprotocol ``foxglove.sdk.v1``; it answers HTTP 400 to
``foxglove.websocket.v1``, which ``@foxglove/ws-protocol``'s ``FoxgloveClient`` offers by default
(``FoxgloveClient.SUPPORTED_SUBPROTOCOL``), as do older Foxglove apps and Lichtblick before late
2025. The two names carry the same messages (Foxglove's own statement; the SDK's server is the
successor of ws-protocol's), so this front accepts both:

* it reads the client's HTTP upgrade request (at most :data:`MAX_HEADER_BYTES`, within
  :data:`HEADER_TIMEOUT_S`), and when the offered subprotocols include ``foxglove.websocket.v1``
  but not ``foxglove.sdk.v1`` it offers ``foxglove.sdk.v1`` to the SDK instead and names
  ``foxglove.websocket.v1`` in the response (RFC 6455: the server picks one the client offered);
* after the handshake it copies bytes both ways unchanged, with back-pressure (a slow viewer makes
  the SDK's own bounded per-client queue drop its oldest messages, as without the front);
* a viewer that goes away closes its SDK connection at once, so the SDK stops sending to it.

One asyncio loop in one daemon thread serves every connection; the SDK listens on an ephemeral
127.0.0.1 port that only this front connects to. ``on_connect()`` is called (from the front's
thread) after each completed handshake.
"""

from __future__ import annotations

import asyncio
import socket
import threading
from collections.abc import Callable

__all__ = ["SubprotocolFront", "SDK_SUBPROTOCOL", "LEGACY_SUBPROTOCOL", "negotiate", "MAX_CONNECTIONS"]

SDK_SUBPROTOCOL = "foxglove.sdk.v1"
LEGACY_SUBPROTOCOL = "foxglove.websocket.v1"
MAX_HEADER_BYTES = 16 * 1024          # an HTTP upgrade request is a few hundred bytes
HEADER_TIMEOUT_S = 10.0               # a client that sends no complete request in this time is dropped
MAX_CONNECTIONS = 64                  # viewers at once; more are refused (closed) at accept
CHUNK = 64 * 1024


def _header_lines(head: bytes) -> list[bytes]:
    return head.split(b"\r\n")


def offered_subprotocols(head: bytes) -> list[str]:
    """The subprotocols a request head offers (every ``Sec-WebSocket-Protocol`` line, comma lists)."""
    out: list[str] = []
    for line in _header_lines(head)[1:]:
        name, sep, value = line.partition(b":")
        if sep and name.strip().lower() == b"sec-websocket-protocol":
            out.extend(v.strip() for v in value.decode("latin-1").split(",") if v.strip())
    return out


def negotiate(head: bytes) -> tuple[bytes, str | None]:
    """``(request head to send the SDK, subprotocol to name in the response or None)``: the head
    unchanged unless the client offers only the legacy name, which is then replaced."""
    offered = offered_subprotocols(head)
    if SDK_SUBPROTOCOL in offered or LEGACY_SUBPROTOCOL not in offered:
        return head, None
    lines = [line for line in _header_lines(head)
             if line.partition(b":")[0].strip().lower() != b"sec-websocket-protocol"]
    # the request line and headers, then our one protocol line, then the blank line(s) that end the head
    end = len(lines)
    while end > 1 and lines[end - 1] == b"":
        end -= 1
    lines.insert(end, b"Sec-WebSocket-Protocol: " + SDK_SUBPROTOCOL.encode())
    return b"\r\n".join(lines), LEGACY_SUBPROTOCOL


def rename_response_protocol(head: bytes, name: str) -> bytes:
    """The SDK's response head with its ``Sec-WebSocket-Protocol`` value replaced by ``name``."""
    out = []
    for line in _header_lines(head):
        key, sep, _value = line.partition(b":")
        if sep and key.strip().lower() == b"sec-websocket-protocol":
            line = key + b": " + name.encode()
        out.append(line)
    return b"\r\n".join(out)


class SubprotocolFront:
    """Listen on ``(host, port)`` (port 0: a free one) and hand each connection to the SDK server
    at ``127.0.0.1:upstream_port`` with the subprotocol negotiated as above."""

    def __init__(self, host: str, port: int, upstream_port: int, *, on_connect: Callable[[], None] | None = None,
                 on_disconnect: Callable[[], None] | None = None, max_connections: int = MAX_CONNECTIONS):
        self.upstream_port = int(upstream_port)
        self.on_connect = on_connect or (lambda: None)
        self.on_disconnect = on_disconnect or (lambda: None)
        self.max_connections = max_connections
        self.connections = 0               # open now
        self.accepted = 0                  # handshakes completed
        self.renamed = 0                   # of which offered only foxglove.websocket.v1
        self.refused = 0                   # dropped: too many, bad or slow request head, SDK unreachable
        family = socket.AF_INET6 if ":" in host else socket.AF_INET
        self._sock = socket.socket(family, socket.SOCK_STREAM)
        self._sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            self._sock.bind((host, port))
        except OSError:
            self._sock.close()
            raise
        self._sock.listen(128)
        self._sock.setblocking(False)
        self.host, self.port = host, int(self._sock.getsockname()[1])
        self._loop = asyncio.new_event_loop()
        self._server: asyncio.base_events.Server | None = None
        self._ready = threading.Event()
        self._thread = threading.Thread(target=self._run, name="foxglove-front", daemon=True)
        self._thread.start()
        self._ready.wait(10.0)

    # ------------------------------------------------------------------ loop thread
    def _run(self) -> None:
        asyncio.set_event_loop(self._loop)

        async def start() -> None:
            self._server = await asyncio.start_server(self._serve, sock=self._sock, limit=CHUNK)
            self._ready.set()

        self._loop.run_until_complete(start())
        try:
            self._loop.run_forever()
        finally:
            self._loop.close()

    async def _serve(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        if self.connections >= self.max_connections:
            self.refused += 1
            writer.close()
            return
        self.connections += 1
        up_writer: asyncio.StreamWriter | None = None
        try:
            try:
                head = await asyncio.wait_for(reader.readuntil(b"\r\n\r\n"), HEADER_TIMEOUT_S)
            except (asyncio.IncompleteReadError, asyncio.LimitOverrunError, asyncio.TimeoutError, ConnectionError):
                self.refused += 1
                return
            if len(head) > MAX_HEADER_BYTES:
                self.refused += 1
                return
            head, rename = negotiate(head)
            try:
                up_reader, up_writer = await asyncio.open_connection("127.0.0.1", self.upstream_port, limit=CHUNK)
            except OSError:
                self.refused += 1
                return
            up_writer.write(head)
            try:
                reply = await asyncio.wait_for(up_reader.readuntil(b"\r\n\r\n"), HEADER_TIMEOUT_S)
            except (asyncio.IncompleteReadError, asyncio.LimitOverrunError, asyncio.TimeoutError, ConnectionError):
                self.refused += 1
                return
            upgraded = reply.startswith(b"HTTP/1.1 101")
            if upgraded and rename:
                reply = rename_response_protocol(reply, rename)
                self.renamed += 1
            writer.write(reply)
            await writer.drain()
            if not upgraded:
                return
            self.accepted += 1
            try:
                self.on_connect()
            except Exception:  # noqa: BLE001 - a callback never breaks a connection
                pass
            try:
                await self._pipe_both(reader, writer, up_reader, up_writer)
            finally:
                try:
                    self.on_disconnect()
                except Exception:  # noqa: BLE001
                    pass
        except (ConnectionError, OSError):
            pass
        except asyncio.CancelledError:     # close() with the viewer connected: ends quietly (no traceback)
            pass
        finally:
            self.connections -= 1
            for w in (writer, up_writer):
                if w is not None:
                    w.close()

    @staticmethod
    async def _pipe_both(a_r: asyncio.StreamReader, a_w: asyncio.StreamWriter, b_r: asyncio.StreamReader,
                         b_w: asyncio.StreamWriter) -> None:
        async def pipe(src: asyncio.StreamReader, dst: asyncio.StreamWriter) -> None:
            try:
                while True:
                    data = await src.read(CHUNK)
                    if not data:
                        break
                    dst.write(data)
                    await dst.drain()             # back-pressure: never buffer more than the socket takes
            except (ConnectionError, OSError):
                pass

        tasks = [asyncio.ensure_future(pipe(a_r, b_w)), asyncio.ensure_future(pipe(b_r, a_w))]
        # either side closing ends the connection: the SDK learns at once that the viewer went away
        _done, pending = await asyncio.wait(tasks, return_when=asyncio.FIRST_COMPLETED)
        for t in pending:
            t.cancel()
        await asyncio.gather(*pending, return_exceptions=True)

    # ------------------------------------------------------------------ any thread
    def close(self) -> None:
        if not self._thread.is_alive():
            return

        async def stop() -> None:
            if self._server is not None:
                self._server.close()
            for task in asyncio.all_tasks():
                if task is not asyncio.current_task():
                    task.cancel()

        try:
            asyncio.run_coroutine_threadsafe(stop(), self._loop).result(5.0)
        except Exception:  # noqa: BLE001 - already stopping
            pass
        self._loop.call_soon_threadsafe(self._loop.stop)
        self._thread.join(5.0)
