"""The bundled example worlds: ``arena`` (the default), ``warehouse``, ``lighting``,
``line_following`` (YAML; its floor texture in ``textures/``, made by :mod:`.line_loop`),
``blob_chase`` (a camera and a red ball, for ``example:blob_follower``), ``car_park`` (a car-like
robot and a lamp, for ``sensorium/CarReachLight-v0``) and
``epuck.wbt`` (a Webots world).

Every command and :func:`sensorium.server.world.loader.load_world` also take a bundled world's bare
name (``sensorium info warehouse``) when no file of that name exists, so examples work from any
directory; :func:`world_path` gives the file itself.
"""

from __future__ import annotations

from pathlib import Path

HERE = Path(__file__).resolve().parent


SUFFIXES = (".yaml", ".wbt")


def names() -> list[str]:
    """The bundled worlds' names: YAML worlds without their suffix, Webots worlds with it."""
    return sorted([p.stem for p in HERE.glob("*.yaml")] + [p.name for p in HERE.glob("*.wbt")])


def world_path(name: str = "arena") -> Path:
    """The file of a bundled world, by name (``"arena"``, ``"arena.yaml"``, ``"epuck.wbt"``)."""
    candidates = [HERE / name] if name.endswith(SUFFIXES) else [HERE / f"{name}{s}" for s in SUFFIXES]
    for path in candidates:
        if path.is_file() and path.parent == HERE:
            return path
    raise FileNotFoundError(f"no bundled world {name!r} (bundled: {', '.join(names())})")
