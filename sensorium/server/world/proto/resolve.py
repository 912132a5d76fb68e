"""Resolve: where the file an EXTERNPROTO (or a mesh or texture url) names is on this machine.

Nothing is ever downloaded. A url is looked up, in order:

* relative (``E-puckDistanceSensor.proto``, ``../protos/My.proto``, ``meshes/body.obj``): next to the
  file that names it; a file that came from an assets archive resolves relative urls against the
  url it stands for, as Webots does;
* absolute: as written;
* ``webots://projects/...`` and ``https://raw.githubusercontent.com/cyberbotics/webots/<tag>/projects/...``:
  in the Webots installation (``WEBOTS_HOME`` or an explicit ``webots_home``), then in each
  ``proto_path`` folder, either as a tree (``FOLDER/projects/...``) or as Webots' asset cache layout
  (an unpacked ``assets-<tag>.zip`` or Webots' own cache folder: files named by the SHA-1 of the
  url; ``webots://`` stands for the raw url of the world's version tag);
* any other ``http(s)://`` url: in the ``proto_path`` folders' cache layout;
* and, for a ``.proto`` file still not found, by its file name anywhere under a ``proto_path``
  folder (a project's ``protos/``), as Webots searches a project's protos folder.

A miss raises ``ProtoError`` naming the url, every place tried, the version tag and how to supply
the file (``--webots-home`` / ``WEBOTS_HOME`` / ``--proto-path``).
"""

from __future__ import annotations

import hashlib
import os
import posixpath
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import urljoin

from sensorium.server.world.proto.errors import ProtoError

RAW_PREFIX = "https://raw.githubusercontent.com/cyberbotics/webots/"
_RAW = re.compile(r"^https?://raw\.githubusercontent\.com/cyberbotics/webots/([A-Za-z0-9_\-+.]+)/(.+)$")
PROTO_PATH_ENV = "SENSORIUM_PROTO_PATH"
_INDEX_ENTRIES = 200_000          # files and folders walked when indexing a proto_path folder by PROTO file name

# files found in an asset-cache folder (named by a hash) → the url they stand for, so that relative
# urls inside them resolve against that url (the folder's log.txt says the same when present)
_ORIGINS: dict[str, str] = {}
_LOGS: dict[str, dict[str, str]] = {}
_INDEXES: dict[str, dict[str, Path]] = {}


@dataclass(frozen=True)
class ProtoSearch:
    """Where PROTO files and Webots assets are looked for: the world's folder, a Webots installation
    and extra folders. ``version`` is the Webots version tag ``webots://`` urls refer to (the
    world's header version, e.g. ``R2023b``); :func:`expand` fills it in from the world."""

    world_dir: Path
    webots_home: Path | None = None
    proto_path: tuple[Path, ...] = ()
    version: str | None = field(default=None, compare=False)

    @classmethod
    def create(cls, world_dir: str | Path, webots_home: str | Path | None = None,
               proto_path: tuple[str | Path, ...] | list[str | Path] = (), version: str | None = None) -> ProtoSearch:
        """``webots_home`` defaults to ``$WEBOTS_HOME`` (as Webots reads it); the folders of
        ``$SENSORIUM_PROTO_PATH`` (separated like PATH) follow the given ``proto_path``."""
        home = webots_home if webots_home is not None else (os.environ.get("WEBOTS_HOME") or None)
        extra = [p for p in os.environ.get(PROTO_PATH_ENV, "").split(os.pathsep) if p]
        folders = tuple(dict.fromkeys(Path(p).expanduser() for p in [*proto_path, *extra]))
        return cls(Path(world_dir), Path(home).expanduser() if home is not None else None, folders, version)

    @property
    def home(self) -> Path | None:
        """The installation's root (the ``Contents`` folder of a macOS ``Webots.app``)."""
        if self.webots_home is None:
            return None
        if (self.webots_home / "Contents" / "projects").is_dir():
            return self.webots_home / "Contents"
        return self.webots_home

    def installed_version(self) -> str | None:
        """The installation's version (``resources/version.txt``), when readable."""
        home = self.home
        if home is None:
            return None
        try:
            text = (home / "resources" / "version.txt").read_text(errors="replace")
        except OSError:
            return None
        words = text.split()
        return words[0] if words else None


def asset_roots(search: ProtoSearch) -> list[Path]:
    """The read-only folders assets may come from besides the world's own folder: the Webots
    installation and the proto_path folders that exist (for mesh confinement)."""
    roots = [p for p in [search.home, *search.proto_path] if p is not None]
    out = []
    for p in roots:
        try:
            if p.is_dir():
                out.append(p.resolve())
        except OSError:
            continue
    return list(dict.fromkeys(out))


def logical_location(path: str | Path) -> str:
    """What a file stands for: the url of a file found in an asset cache, else its path."""
    key = str(path)
    if key in _ORIGINS:
        return _ORIGINS[key]
    p = Path(key)
    if re.fullmatch(r"[0-9a-f]{40}", p.name):
        origin = _archive_log(p.parent).get(p.name)
        if origin:
            _ORIGINS[key] = origin
            return origin
    return key


def url_tag(location: str) -> str | None:
    """The version tag of a raw.githubusercontent.com/cyberbotics/webots url, else None."""
    m = _RAW.match(location)
    return m.group(1) if m else None


def webots_path(url: str, base_file: str | Path, trees: Sequence[Path] = ()) -> str | None:
    """The path inside Webots' own tree (``projects/…``) that ``url`` names: a ``webots://`` or
    raw.githubusercontent.com/cyberbotics/webots url (any tag), or a relative url written in a file
    that stands for one (a file of ``trees``' ``projects/`` stands for its ``webots://`` url: an
    installation, a --proto-path tree); None for any other url (a local file, another site)."""
    u = url.strip().replace("\\", "/")
    if not re.match(r"^[A-Za-z][A-Za-z0-9+.\-]*://", u) and not u.startswith("/"):
        base = logical_location(base_file)
        for root in trees:
            try:
                inside = Path(base).relative_to(root).as_posix()
            except ValueError:
                continue
            if inside.startswith("projects/"):
                base = "webots://" + inside
                break
        if base.startswith("webots://"):
            u = "webots://" + posixpath.join(posixpath.dirname(base[len("webots://"):]), u)
        elif _RAW.match(base):
            u = urljoin(base, u)
        else:
            return None
    if u.startswith("webots://"):
        rel = u[len("webots://"):].lstrip("/")
    elif (m := _RAW.match(u)) is not None:
        rel = m.group(2)
    else:
        return None
    rel = posixpath.normpath(rel)
    return None if rel.startswith("..") else rel


def _archive_log(folder: Path) -> dict[str, str]:
    key = str(folder)
    if key not in _LOGS:
        table: dict[str, str] = {}
        try:
            with open(folder / "log.txt", encoding="utf-8", errors="replace") as f:
                for line in f:
                    parts = line.split(None, 1)
                    if len(parts) == 2 and len(parts[0]) == 40:
                        table[parts[0]] = parts[1].strip()
        except OSError:
            pass
        _LOGS[key] = table
    return _LOGS[key]


def _hashed(url: str) -> str:
    return hashlib.sha1(url.encode("utf-8")).hexdigest()


def _is_file(p: Path) -> bool:
    try:
        return p.is_file()
    except OSError:
        return False


def proto_index(folder: Path) -> dict[str, Path]:
    """PROTO file name → first path under ``folder`` (bounded walk, sorted for a stable answer)."""
    key = str(folder)
    if key not in _INDEXES:
        index: dict[str, Path] = {}
        seen = 0
        for root, dirs, files in os.walk(folder):        # symbolic links to folders are not entered
            dirs.sort()
            seen += 1                                      # a folder counts: a tree of empty folders is bounded too
            for name in sorted(files):
                seen += 1
                if name.lower().endswith(".proto"):
                    index.setdefault(name, Path(root) / name)
            if seen > _INDEX_ENTRIES:
                break
        _INDEXES[key] = index
    return _INDEXES[key]


def resolve_url(url: str, base_file: str | Path, search: ProtoSearch) -> Path:
    """The local file ``url`` names, written in ``base_file`` (a world, a PROTO file, or the url a
    cached file stands for). Raises ``ProtoError`` listing the places tried."""
    tried: list[str] = []
    found, tag = _find(url, base_file, search, tried)
    if found is not None:
        return found
    raise ProtoError(str(base_file), 0, 0, missing_message(url, tried, tag, search))


def missing_message(url: str, tried: list[str], tag: str | None, search: ProtoSearch) -> str:
    shown = tried[:8] + ([f"… ({len(tried) - 8} more)"] if len(tried) > 8 else [])
    where = ", ".join(shown) if shown else "nothing (no Webots installation, no --proto-path folder)"
    version = f"Webots {tag}" if tag else "Webots"
    how = (f"give --webots-home DIR (or set WEBOTS_HOME) for a {version} installation, or --proto-path DIR "
           f"for a folder holding it (a project's protos/, an unpacked assets-{tag or 'RELEASE'}.zip)")
    if search.webots_home is None:
        how += "; WEBOTS_HOME is not set"
    else:       # a mistyped --webots-home: say so, not only "give --webots-home", which the user did
        problem = installation_problem(search.webots_home)
        if problem:
            how = f"the Webots installation given (--webots-home or WEBOTS_HOME) {problem}; " + how
    return f'"{_short(url)}" not found ({version}); looked in: {where}; nothing is downloaded: {how}'


def installation_problem(home: Path) -> str | None:
    """What makes ``home`` no Webots installation (a folder with ``projects/``, or a macOS
    ``Webots.app``), said after its name; None when it looks like one."""
    try:
        if not home.is_dir():
            return f"{_short(str(home))} is not a folder"
        if (home / "projects").is_dir() or (home / "Contents" / "projects").is_dir():
            return None
    except OSError as exc:
        return f"{_short(str(home))} cannot be read ({exc.strerror or exc})"
    return f"{_short(str(home))} has no projects/ folder, so it is no Webots installation"


def _short(text: str, limit: int = 200) -> str:
    return text if len(text) <= limit else text[:limit] + f"… ({len(text)} characters)"


def _find(url: str, base_file: str | Path, search: ProtoSearch, tried: list[str]) -> tuple[Path | None, str | None]:
    u = url.strip().replace("\\", "/")
    if not u:
        return None, search.version
    base = logical_location(base_file)
    tag = url_tag(base) or search.version
    if not re.match(r"^[A-Za-z][A-Za-z0-9+.\-]*://", u) and not u.startswith("/") and not re.match(r"^[A-Za-z]:/", u):
        # relative: against what the naming file stands for
        if re.match(r"^https?://", base):
            u = urljoin(base, u)
        elif base.startswith("webots://"):
            u = "webots://" + posixpath.normpath(posixpath.join(posixpath.dirname(base[len("webots://"):]), u))
        else:
            # the path cleaned before it is looked up, as Webots' QDir::cleanPath: "tex/../a.png" names
            # the a.png beside the naming file whether or not a folder tex is there
            p = Path(os.path.normpath(Path(base).parent / u))
            tried.append(str(p))
            if _is_file(p):
                return p, tag
            return _by_name(u, search, tried), tag
    home = search.home
    rel: str | None = None
    remote: str | None = None
    if u.startswith("webots://"):
        rel = posixpath.normpath(u[len("webots://"):].lstrip("/"))
        remote = RAW_PREFIX + f"{tag}/{rel}" if tag else None
    elif (m := _RAW.match(u)) is not None:
        tag, rel = m.group(1), posixpath.normpath(m.group(2))
        remote = u
    elif re.match(r"^https?://", u):
        remote = u
    else:                                   # absolute path
        p = Path(u)
        tried.append(str(p))
        if _is_file(p):
            return p, tag
        return _by_name(u, search, tried), tag
    if rel is not None and not rel.startswith(".."):
        for root in ([home] if home is not None else []) + list(search.proto_path):
            p = root / rel
            tried.append(str(p))
            if _is_file(p):
                return p, tag
    if remote is not None:
        for root in search.proto_path:
            p = root / _hashed(remote)
            tried.append(f"{root}/<sha1 of {_short(remote, 120)}>")
            if _is_file(p):
                _ORIGINS[str(p)] = remote
                return p, tag
    return _by_name(u, search, tried), tag


def _by_name(u: str, search: ProtoSearch, tried: list[str]) -> Path | None:
    name = u.rsplit("/", 1)[-1]
    if not name.lower().endswith(".proto") or not search.proto_path:
        return None
    for root in search.proto_path:
        tried.append(f"{root}/**/{name}")
        hit = proto_index(root).get(name)
        if hit is not None and _is_file(hit):
            return hit
    return None
