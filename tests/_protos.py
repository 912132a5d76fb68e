"""Helpers for the PROTO tests: write a world and its PROTO files (our own) into a folder, load it."""

from __future__ import annotations

from pathlib import Path

from sensorium.server.world.loader import load_world
from sensorium.server.world.proto import ProtoSearch, expand
from sensorium.server.world.wbt.parser import Node, read_wbt

HEADER = "#VRML_SIM R2023b utf8\n"


def proto_file(folder: Path, name: str, body: str, header: str = "") -> Path:
    """``folder/name.proto`` holding ``PROTO name`` (``body`` starts at the interface's '[')."""
    folder.mkdir(parents=True, exist_ok=True)
    p = folder / f"{name}.proto"
    p.write_text(HEADER + header + f"PROTO {name} {body}\n")
    return p


def webots_home(root: Path, monkeypatch=None, version: str = "R2023b") -> Path:
    """``root`` made a Webots installation (its ``resources/version.txt``) and, with ``monkeypatch``,
    the test's ``WEBOTS_HOME``."""
    (root / "resources").mkdir(parents=True, exist_ok=True)
    (root / "resources" / "version.txt").write_text(version + "\n")
    if monkeypatch is not None:
        monkeypatch.setenv("WEBOTS_HOME", str(root))
    return root


def world_file(folder: Path, body: str, protos: list[str] = (), name: str = "w.wbt") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    p = folder / name
    decl = "".join(f'EXTERNPROTO "{u}"\n' for u in protos)
    p.write_text(HEADER + decl + body)
    return p


def expanded(world: Path, **search):
    """The expansion of a world file (search: webots_home, proto_path)."""
    wbt = read_wbt(world)
    return expand(wbt, ProtoSearch.create(world.parent, **search))


def nodes_of(node: Node, kind: str) -> list[Node]:
    """Every node of type ``kind`` under ``node`` (depth first, in file order)."""
    out = []
    todo = [node]
    while todo:
        n = todo.pop()
        if n.type == kind:
            out.append(n)
        kids = []
        for v in n.fields.values():
            for x in v if isinstance(v, list) else [v]:
                if isinstance(x, Node):
                    kids.append(x)
        todo.extend(reversed(kids))
    return out


def robots(world: Path, **kw):
    return load_world(world, **kw).world.robots
