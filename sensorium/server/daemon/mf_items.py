"""Webots' index rules for an MF field's items (``setMF*``, ``insertMF*``, ``removeMF``), in one place
for every field a Supervisor changes item by item (an imported line set's lists, an ImageTexture's
``url``, a PROTO field of a rebuilt solid)."""

from __future__ import annotations

from typing import Any

__all__ = ["item_position"]


def item_position(where: str, op: str, index: Any, count: int) -> int:
    """The list position of item ``index`` of a field holding ``count`` items for ``op`` (``set``,
    ``insert``, ``remove``): negative from the end, as Webots (an insert at -1 goes after the last
    item). ValueError, one line starting with ``where`` and ending "nothing changed", for an index
    that is no whole number, out of bounds, or an unknown ``op``."""
    if isinstance(index, bool) or not isinstance(index, int):
        raise ValueError(f"{where}: the index must be a whole number, got {index!r}; nothing changed")
    if op == "insert":
        at = index + count + 1 if index < 0 else index
        if not 0 <= at <= count:
            raise ValueError(f"{where}: out-of-bound index {index} (should be between {-count - 1} and {count}); "
                             "nothing changed")
        return at
    if op not in ("set", "remove"):
        raise ValueError(f"{where}: unknown change {op!r}; nothing changed")
    if not -count <= index < count:
        raise ValueError(f"{where}: out-of-bound index {index} (should be between {-count} and {count - 1}); "
                         "nothing changed" if count else f"{where}: the list is empty; nothing changed")
    return index + count if index < 0 else index
