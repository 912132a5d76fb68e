"""The JavaScript worker: runs template programs in QuickJS for :mod:`.engine`, one at a time.

Run as a script (``python -I engine_worker.py``), it imports only the standard library and
``quickjs``. Frames on stdin/stdout are a 4-byte big-endian length and UTF-8 JSON. A request is
``{"code", "memory", "seconds", "stack"}``; the reply ``{"ok": true, "out", "messages", "cpu"}`` or
``{"ok": false, "error", "kind", "cpu"}``. A fresh QuickJS context per request: nothing survives
from one template to the next. QuickJS can crash on some out-of-memory paths; in this process a
crash only ends the worker (the parent reports it and starts another).
"""

import json
import struct
import sys
import time


def _read(stream, n):
    data = b""
    while len(data) < n:
        chunk = stream.read(n - len(data))
        if not chunk:
            return None
        data += chunk
    return data


def main():
    import quickjs

    stdin, stdout = sys.stdin.buffer, sys.stdout.buffer
    while True:
        head = _read(stdin, 4)
        if head is None:
            return
        body = _read(stdin, struct.unpack(">I", head)[0])
        if body is None:
            return
        req = json.loads(body)
        t0 = time.process_time()
        ctx = quickjs.Context()
        ctx.set_memory_limit(int(req["memory"]))
        ctx.set_max_stack_size(int(req["stack"]))
        ctx.set_time_limit(float(req["seconds"]))
        try:
            out = ctx.eval(req["code"])
            messages = ctx.eval("JSON.stringify(typeof __messages === 'undefined' ? [] : __messages)")
            reply = {"ok": True, "out": out if isinstance(out, str) else json.dumps(None), "messages": messages}
        except Exception as exc:           # quickjs.JSException, StackOverflow
            reply = {"ok": False, "error": str(exc)[:20000], "kind": type(exc).__name__}
        del ctx
        reply["cpu"] = time.process_time() - t0
        data = json.dumps(reply).encode("utf-8")
        stdout.write(struct.pack(">I", len(data)) + data)
        stdout.flush()


if __name__ == "__main__":
    main()
