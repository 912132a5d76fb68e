"""Build the transport benchmark's C processes (``sensorium/benchmarks/c``): a controller on the
C client library (``sensorium/client/c``, built with its Makefile, -O2, no sanitizers), and a raw
libzmq REQ client and REP echo server compiled the same way (the C floor). Skipped, with the
reason, when there is no C compiler, ``make``, libzmq or msgpack-c."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

HERE = Path(__file__).resolve().parent / "c"
CLIB = Path(__file__).resolve().parents[1] / "client" / "c"


def _run(cmd: list[str]) -> str:
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    if done.returncode != 0:
        lines = (done.stderr or done.stdout).strip().splitlines()
        raise RuntimeError(f"{' '.join(cmd[:3])} …: {lines[-1] if lines else f'exit {done.returncode}'}")
    return done.stdout


def build(tmp: Path) -> tuple[dict[str, str] | None, str]:
    """``({"controller", "raw_req", "rep_echo"} → executable path, "")``, or ``(None, why not)``."""
    cc = shutil.which("cc")
    if cc is None or shutil.which("make") is None:
        return None, "no C compiler or make on PATH"
    out = tmp / "cbuild"
    try:
        _run(["make", "-s", "-C", str(CLIB), f"BUILD={out}", f"{out}/libController.a"])
        libs = _run(["make", "-s", "-C", str(CLIB), "libs"]).split()
        flags = [cc, "-std=c11", "-O2", "-Wall", "-Wextra", "-Werror", f"-I{CLIB / 'include'}", f"-I{HERE}"]
        exes = {}
        for name in ("controller", "raw_req", "rep_echo"):
            exe = out / name
            extra = [str(out / "libController.a")] if name == "controller" else []
            _run([*flags, str(HERE / f"{name}.c"), "-o", str(exe), *extra, *libs])
            exes[name] = str(exe)
    except (RuntimeError, OSError, subprocess.TimeoutExpired) as exc:
        return None, f"C build failed: {exc}"
    return exes, ""
