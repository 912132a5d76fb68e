"""The bundled example worlds: ``arena`` (the default), ``warehouse``, ``lighting``.

Every command and :func:`sensorium.server.world.loader.load_world` also take a bundled world's bare
name (``sensorium info warehouse``) when no file of that name exists, so examples work from any
directory; :func:`world_path` gives the file itself.
"""

from __future__ import annotations

from pathlib import Path

HERE = Path(__file__).resolve().parent


def names() -> list[str]:
    """The bundled worlds' names (file names without ``.yaml``)."""
    return sorted(p.stem for p in HERE.glob("*.yaml"))


def world_path(name: str = "arena") -> Path:
    """The file of a bundled world, by name (``"arena"`` or ``"arena.yaml"``)."""
    stem = name[:-5] if name.endswith(".yaml") else name
    path = HERE / f"{stem}.yaml"
    if not path.is_file():
        raise FileNotFoundError(f"no bundled world {name!r} (bundled: {', '.join(names())})")
    return path
