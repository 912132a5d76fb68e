"""docker/: no Docker engine here, so run the compose services' exact commands and environment
variables as plain processes on loopback (hosts and ports rewritten, nothing else)."""

from __future__ import annotations

import re
import signal
import socket
import time
from pathlib import Path

import yaml
from _serve import Proc, Served, sensorium

ROOT = Path(__file__).resolve().parents[1]
COMPOSE = yaml.safe_load((ROOT / "docker" / "compose.yaml").read_text())


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _localise(arg: str, ports: dict[str, int]) -> str:
    for port, local in ports.items():
        arg = arg.replace(f"0.0.0.0:{port}", f"127.0.0.1:{local}").replace(f"server:{port}", f"127.0.0.1:{local}")
    return arg.replace("/app/", f"{ROOT}/")


def _wait_recorded(path: Path, recorder: Proc, within_s: float = 60.0) -> None:
    """Poll until the recorder has flushed a message into ``path`` (it flushes at least once a second)."""
    from sensorium.server.recording.reader import Recording

    deadline = time.monotonic() + within_s
    while recorder.returncode is None and time.monotonic() < deadline:
        try:
            with Recording(path) as rec:
                if next(iter(rec.messages()), None) is not None:
                    return
        except Exception:       # not there yet, or its first chunk half-written
            pass
        time.sleep(0.1)


def test_dockerfile_copies_what_exists() -> None:
    text = (ROOT / "docker" / "Dockerfile").read_text()
    for src in re.findall(r"^COPY (.+) \S+$", text, flags=re.M):
        if src.startswith("--from="):        # from the build stage, not the build context
            continue
        for part in src.split():
            assert (ROOT / part).exists(), part
    assert 'ENTRYPOINT ["sensorium"]' in text


def test_the_image_runs_the_compiled_paths_built_in_its_build_stage() -> None:
    """No Docker engine here: the Dockerfile's stages read as text. The build stage has the compiler,
    installs (setup.py builds the C step path) and compiles packets.c into the cache the image keeps,
    failing unless both paths are active; the image has no compiler and reads that cache."""
    text = (ROOT / "docker" / "Dockerfile").read_text()
    build = text.split("FROM python:3.11-slim AS build", 1)[1].split("\nFROM ", 1)[0]
    image = text.split("FROM python:3.11-slim AS build", 1)[1].split("\nFROM ", 1)[1]
    assert "gcc" in build and "gcc" not in image and "apt-get" not in image
    assert re.search(r"pip install --no-cache-dir \.$", build, flags=re.M)
    cache = re.search(r"^ENV SENSORIUM_CACHE_DIR=(\S+)$", build, flags=re.M).group(1)
    assert "compiled_paths()" in build and "step path: C" in build and "Embree packets" in build
    assert f"COPY --from=build {cache} {cache}" in image and f"SENSORIUM_CACHE_DIR={cache}" in image
    assert "COPY --from=build /opt/sensorium /opt/sensorium" in image and "PATH=/opt/sensorium/bin:$PATH" in image


def test_compose_services_run_as_processes(tmp_path: Path) -> None:
    (tmp_path / "recordings").mkdir()
    services = COMPOSE["services"]
    assert set(services) == {"server", "braitenberg", "wanderer", "recorder"}
    ports = {"5560": _free_port(), "5561": _free_port()}
    server_cmd = [_localise(a, ports) for a in services["server"]["command"]] + ["--until", "1500"]
    procs: list[tuple[str, Proc]] = []
    with Served(sensorium(*server_cmd), "sensorium: serving world").wait_ready() as server:
        try:
            # the recorder first, and only once it records do the controllers start the world's clock:
            # a recorder that joins late (a loaded machine) would find a world that already ran out
            for name in ("recorder", "braitenberg", "wanderer"):
                svc = services[name]
                procs.append((name, Proc(sensorium(*(_localise(a, ports) for a in svc["command"])), cwd=tmp_path,
                                         env={k: _localise(v, ports) for k, v in svc.get("environment", {}).items()})))
                if name == "recorder":
                    procs[-1][1].wait_line("sensorium: recording")
            assert server.wait() == 0, server.stderr()
            for name, p in procs:
                if name == "recorder":
                    _wait_recorded(tmp_path / "recordings" / "run.mcap", p)
                    p.stop(signal.SIGINT)
                assert p.wait() == 0, f"{name}: {p.stdout()}\n{p.stderr()}"
        finally:
            for _, p in procs:
                p.stop()
    from sensorium.server.recording.reader import summarize

    summary = summarize(tmp_path / "recordings" / "run.mcap")
    assert summary["messages"] > 0 and not summary["truncated"]


def test_compose_publishes_ports_on_loopback_only() -> None:
    """The server has no authentication without --curve-keys: compose must not expose it on every
    host interface ("5560:5560" would publish on 0.0.0.0)."""
    ports = COMPOSE["services"]["server"]["ports"]
    assert ports, "the server publishes its ports"
    for spec in ports:
        host_ip = str(spec).split(":")[0]
        assert host_ip == "127.0.0.1", f"port {spec!r} is published beyond loopback"


def test_the_recorders_volume_is_writable_by_the_images_user() -> None:
    """A host folder bind-mounted by docker is created root-owned, and the image runs as the user
    'sensorium': the recorder could not write its file. The recorder now writes to a named volume
    whose mount point the image creates as its own user (a new named volume copies that ownership)."""
    text = (ROOT / "docker" / "Dockerfile").read_text()
    user = re.findall(r"^USER (\S+)$", text, flags=re.M)
    assert user == ["sensorium"]
    recorder = COMPOSE["services"]["recorder"]
    (volume,) = recorder["volumes"]
    source, target = str(volume).split(":")[:2]
    assert not source.startswith((".", "/", "~")), f"{volume}: a host path, created root-owned by docker"
    assert source in (COMPOSE.get("volumes") or {}), f"named volume {source!r} is not declared"
    # the mount point is made after USER sensorium (so owned by it), and the recorder writes inside it
    after_user = text.split("USER sensorium", 1)[1]
    assert re.search(rf"^RUN mkdir -p {re.escape(target)}$", after_user, flags=re.M), target
    out = recorder["command"][1]
    assert ("/home/sensorium/" + out).startswith(target + "/"), (out, target)


def test_the_dockerfile_advice_publishes_on_loopback_or_with_keys() -> None:
    text = (ROOT / "docker" / "Dockerfile").read_text()
    runs = [line for line in text.splitlines() if "docker run" in line]
    assert runs
    for line in runs:
        for spec in re.findall(r"-p (\S+)", line):
            assert spec.startswith("127.0.0.1:"), f"{line.strip()}: publishes {spec} on every interface"
