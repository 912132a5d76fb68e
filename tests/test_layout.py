"""The import arrows of ARCHITECTURE.md, checked on the source (every ``import`` statement of every
module, including imports inside functions), so a violation fails here and not in a review.

Areas are ``sensorium.<folder>`` and, under the server, ``server.<stage>``. Each rule lists what an
area may import of sensorium besides itself (the top package ``sensorium`` — ``__version__`` — is
always allowed). Third-party imports with a single owner (zmq, embreex) are checked too.
"""

from __future__ import annotations

import dis
import types
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "sensorium"

IMPORT_NAME = bytes([dis.opmap["IMPORT_NAME"]])

SERVER_STAGES = ("world", "raycast", "devices", "sim", "daemon", "recording", "viewer")

# area -> the other areas it may import (None: no rule beyond "server never imports cli/client")
ALLOWED: dict[str, set[str] | None] = {
    "sensorium.schemas": set(),                                   # the contract stands alone
    "sensorium.client": set(),                                    # pyzmq + msgpack only: never server or schemas
    "server.world": {"sensorium.schemas"},
    "server.raycast": {"server.world"},
    "server.devices": set(),                                      # pure models: numpy and themselves
    "server.sim": {"sensorium.schemas", "server.world", "server.raycast", "server.devices"},
    "server.daemon": {"sensorium.schemas", "server.world", "server.raycast", "server.devices", "server.sim"},
    # recording and viewer both turn the daemon's topics into files/streams; they share Foxglove helpers
    "server.recording": {"sensorium.schemas", "server.world", "server.sim", "server.daemon", "server.viewer"},
    "server.viewer": {"sensorium.schemas", "server.world", "server.raycast", "server.devices", "server.sim",
                      "server.daemon", "server.recording"},
}
SERVER_NEVER = {"sensorium.cli", "sensorium.client", "sensorium.benchmarks", "sensorium.demo", "sensorium.gym",
                "sensorium.sweep"}

# third-party modules that only these files may import (relative to sensorium/)
OWNED = {
    "embreex": {"server/raycast/", "benchmarks/"},
    "zmq": {"client/connection.py", "server/daemon/transport.py", "server/daemon/steppath.py", "server/recording/live.py",
            "server/recording/replay.py", "cli/", "benchmarks/", "gym/", "sweep/", "demo/"},
}


def area(module: str) -> str:
    parts = module.split(".")
    if len(parts) >= 3 and parts[1] == "server":
        return "server." + parts[2]
    return ".".join(parts[:2])


def module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def code_objects(code: types.CodeType) -> Iterator[types.CodeType]:
    yield code
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            yield from code_objects(const)


def instruction_lines(code: types.CodeType) -> Iterator[tuple[int, dis.Instruction]]:
    line = code.co_firstlineno
    for ins in dis.get_instructions(code):
        positions = getattr(ins, "positions", None)                 # Python 3.11+
        if positions is not None and positions.lineno is not None:
            line = positions.lineno
        elif isinstance(ins.starts_line, int) and not isinstance(ins.starts_line, bool):
            line = ins.starts_line
        yield line, ins


def imports(path: Path, source: str | None = None) -> list[tuple[int, str]]:
    """(line, absolute module name) of every import statement in a module.

    Read from the compiled code, not an ``ast`` walk: every import statement, at any depth, compiles
    to an ``IMPORT_NAME`` preceded by its level and names, and compiling builds no Python tree
    (``ast.parse`` of the whole package was most of this file's time). A ``finally`` body is compiled
    twice, so a repeated (line, module) is kept once."""
    module = module_name(path)
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    code = compile(source if source is not None else path.read_text(), str(path), "exec", dont_inherit=True)
    out: dict[tuple[int, str], None] = {}
    for each in code_objects(code):
        if IMPORT_NAME not in each.co_code[::2]:                     # opcodes sit at even offsets
            continue
        listed = list(instruction_lines(each))
        for i, (line, ins) in enumerate(listed):
            if ins.opname != "IMPORT_NAME":
                continue
            level, names = listed[i - 2][1].argval, listed[i - 1][1].argval
            if level:
                base = package.split(".")[:len(package.split(".")) - (level - 1)]
                name = ".".join(base + ([ins.argval] if ins.argval else []))
                # "from . import x" imports submodules: check each as its own module
                if not ins.argval:
                    out.update(((line, f"{name}.{a}"), None) for a in names)
                    continue
                out[(line, name)] = None
            else:
                out[(line, ins.argval)] = None
    return list(out)


def source_files() -> list[Path]:
    return sorted(p for p in PKG.rglob("*.py") if not p.relative_to(PKG).as_posix().startswith("client/c/"))


def violations(path: Path, source: str | None = None) -> list[str]:
    """Every broken arrow of one module, as ``file:line: what``."""
    rel = path.relative_to(PKG).as_posix()
    mine = area(module_name(path))
    out = []
    for line, target in imports(path, source):
        where = f"sensorium/{rel}:{line}"
        top = target.split(".")[0]
        owners = OWNED.get(top)
        if owners is not None and not any(rel == o or (o.endswith("/") and rel.startswith(o)) for o in owners):
            out.append(f"{where}: imports {top}, which only {', '.join(sorted(owners))} may import")
        if top != "sensorium" or target == "sensorium":
            continue
        theirs = area(target)
        if theirs == mine:
            continue
        if mine.startswith("server.") and theirs in SERVER_NEVER:
            out.append(f"{where}: the server imports {target} (server never imports {theirs})")
            continue
        allowed = ALLOWED.get(mine)
        stage_folder = rel.startswith("server/") and rel.count("/") >= 2      # server/<stage>/...: a stage
        if mine.startswith("server.") and mine not in ALLOWED and stage_folder:
            out.append(f"{where}: new server stage {mine}: add its rule to tests/test_layout.py and ARCHITECTURE.md")
        elif allowed is not None and theirs not in allowed:
            out.append(f"{where}: {mine} imports {target} ({mine} may import only "
                       f"{', '.join(sorted(allowed)) or 'itself'})")
    return out


def test_every_module_keeps_the_arrows() -> None:
    found = [v for path in source_files() for v in violations(path)]
    assert not found, "import arrows broken (see ARCHITECTURE.md):\n" + "\n".join(found)


def test_the_scan_sees_every_package() -> None:
    # a walk that silently found nothing would pass the test above
    areas = {area(module_name(p)) for p in source_files()}
    assert {"sensorium.schemas", "sensorium.client", "sensorium.cli", "server.world", "server.raycast",
            "server.devices", "server.sim", "server.daemon", "server.recording"} <= areas
    assert "sensorium.schemas" in {m for _, m in imports(PKG / "server" / "world" / "loader.py")}


@pytest.mark.parametrize(("file", "line", "expected"), [
    ("client/wb.py", "from sensorium.schemas.wire import ErrorCode", "sensorium.client may import only itself"),
    ("client/topics.py", "import sensorium.server.daemon.topics", "sensorium.client may import only itself"),
    ("client/wb.py", "import zmq", "imports zmq"),
    ("server/world/loader.py", "from sensorium.server.sim.simulation import Simulation",
     "server.world may import only sensorium.schemas"),
    ("server/world/meshes.py", "from sensorium.server.raycast import engine", "server.world may import only"),
    ("server/devices/light.py", "from sensorium.server.world.geometry import Pose", "server.devices may import only itself"),
    ("server/daemon/services.py", "from sensorium.server.recording.writer import McapRecorder",
     "server.daemon may import only"),
    ("server/recording/reader.py", "    from sensorium.cli.recording import print_info", "server never imports sensorium.cli"),
    ("server/sim/batches.py", "from ..daemon import topics", "server.sim may import only"),
    ("server/sim/motion.py", "import embreex", "imports embreex"),
    ("schemas/world.py", "from sensorium.server.world.loader import WorldError", "sensorium.schemas may import only itself"),
    ("server/newstage/x.py", "from sensorium.server.sim import simulation", "new server stage server.newstage"),
    ("server/glue.py", "from sensorium.cli import main", "server never imports sensorium.cli"),
])
def test_a_violation_is_reported(file: str, line: str, expected: str) -> None:
    path = PKG / file
    body = f"def f():\n{line}\n" if line.startswith(" ") else line + "\n"
    found = violations(path, body)
    assert any(expected in v for v in found), found
    assert all(v.startswith(f"sensorium/{file}:") for v in found)


def test_allowed_imports_are_not_reported() -> None:
    assert violations(PKG / "server" / "sim" / "simulation.py",
                      "from sensorium.server.raycast.engine import Precision\nfrom sensorium import __version__\n") == []
    assert violations(PKG / "server" / "raycast" / "engine.py", "from . import engine\nimport numpy\n") == []
    assert violations(PKG / "client" / "connection.py", "import zmq\nfrom sensorium.client import arrays\n") == []
    # a module directly in server/ (glue such as conformance vectors) may use any stage, never cli/client
    assert violations(PKG / "server" / "glue.py", "from sensorium.server.sim.simulation import Simulation\n") == []


def test_error_code_tables_agree() -> None:
    """The client keeps its own copy of the error codes (it never imports schemas): every server code
    is in the client's table with the same value, the client's own codes start at 1000, and
    PROTOCOL.md's table lists each server code."""
    import re

    from sensorium.client.connection import ErrorCode as ClientCode
    from sensorium.schemas.wire import ErrorCode as ServerCode

    server = {c.name: int(c) for c in ServerCode}
    client = {c.name: int(c) for c in ClientCode}
    assert {k: client.get(k) for k in server} == server
    assert all(v >= 1000 for k, v in client.items() if k not in server)
    assert all(v < 1000 for v in server.values())
    table = dict(re.findall(r"^\| (\d+) \| `([A-Z_]+)` \|", (ROOT / "PROTOCOL.md").read_text(), re.M))
    assert {name: int(num) for num, name in table.items()} == server


def test_slow_marker_finds_tests_that_start_processes(request: pytest.FixtureRequest) -> None:
    from conftest import _spawning_functions

    found = _spawning_functions(ROOT / "tests" / "test_world.py")
    assert {"_cli", "test_cli_validate_ok_and_failure", "test_cli_info_default_world"} <= found  # via the helper
    assert "test_infrared_spelling_normalised" not in found
    assert request.node.get_closest_marker("slow") is None           # this test is not


def test_the_compiled_reading_finds_every_form_of_import() -> None:
    # every form once, at every depth; the ``finally`` body (compiled twice) gives one line
    source = ("from __future__ import annotations\nimport zmq, sensorium.server.sim.simulation as s\n"
              "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from sensorium.client import wb\n"
              "from .. import raycast, devices\nfrom .geometry import (\n    Pose,\n    Frame,\n)\n"
              "class A:\n    import embreex\n    def f(self):\n        try:\n            pass\n"
              "        finally:\n            from ...cli import main\n"
              "g = lambda: __import__('os')\nh = [__import__ for _ in ()]\n"
              "def k():\n    def inner():\n        from sensorium.server.daemon import topics\n")
    assert imports(PKG / "server" / "world" / "loader.py", source) == [
        (1, "__future__"), (2, "zmq"), (2, "sensorium.server.sim.simulation"), (3, "typing"),
        (5, "sensorium.client"), (6, "sensorium.server.raycast"), (6, "sensorium.server.devices"),
        (7, "sensorium.server.world.geometry"), (12, "embreex"), (17, "sensorium.cli"),
        (22, "sensorium.server.daemon")]
