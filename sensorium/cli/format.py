"""Printing decoded messages and replies for people (YAML-like) and programs (JSON).

Client side: only the standard library (arrays may be numpy arrays or ``array.array``; neither is
imported here). Arrays are summarised as ``<float32[360] 0.21..5.9 (12 inf)>`` unless ``full``.
"""

from __future__ import annotations

import base64
import json
import math
from typing import Any

FLOW_MAX_ITEMS = 8          # lists of scalars up to this long print in full even when summarising


def _is_array(value: Any) -> bool:
    return (getattr(value, "shape", None) is not None and hasattr(value, "dtype")) or hasattr(value, "typecode")


def _array_values(value: Any) -> list[float]:
    if hasattr(value, "reshape"):
        return [float(v) for v in value.reshape(-1)]
    return [float(v) for v in value]


def _array_head(value: Any) -> str:
    shape = getattr(value, "shape", None)
    if shape is not None and hasattr(value, "dtype"):
        return f"{value.dtype}[{'x'.join(str(d) for d in shape)}]"
    code = getattr(value, "typecode", "?")
    return f"{'float32' if code == 'f' else 'float64' if code == 'd' else code}[{len(value)}]"


def array_summary(value: Any) -> str:
    values = _array_values(value) if len(value) <= 2_000_000 else []
    return _stats(_array_head(value), values)


def _stats(head: str, values: list[float]) -> str:
    if not values:
        return f"<{head}>"
    finite = [v for v in values if math.isfinite(v)]
    n_inf = sum(1 for v in values if math.isinf(v))
    n_nan = len(values) - len(finite) - n_inf
    extras = [f"{n} {what}" for n, what in ((n_inf, "inf"), (n_nan, "nan")) if n]
    rng = f" {min(finite):.4g}..{max(finite):.4g}" if finite else ""
    return f"<{head}{rng}{' (' + ', '.join(extras) + ')' if extras else ''}>"


def scalar(value: Any) -> str:
    """One YAML scalar: floats in shortest form (.inf/.nan as YAML writes them), strings quoted when needed."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if math.isnan(value):
            return ".nan"
        if math.isinf(value):
            return ".inf" if value > 0 else "-.inf"
        return repr(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, (bytes, bytearray, memoryview)):
        return f"<bytes[{len(value)}]>"
    text = str(value)
    plain = text and text.strip() == text and not any(c in text for c in ":#{}[],&*!|>'\"%@`\n") \
        and text.lower() not in ("null", "true", "false", "yes", "no", "~")
    return text if plain else json.dumps(text)


def _is_scalar(value: Any) -> bool:
    return value is None or isinstance(value, (bool, int, float, str, bytes, bytearray, memoryview))


def _flow(value: Any, full: bool) -> str | None:
    """A one-line form when the value is small enough, else None."""
    if _is_scalar(value):
        return scalar(value)
    if _is_array(value):
        if full or len(value) <= FLOW_MAX_ITEMS:
            return "[" + ", ".join(scalar(v) for v in _array_values(value)) + "]"
        return array_summary(value)
    if isinstance(value, list):
        if not value:
            return "[]"
        if all(_is_scalar(v) for v in value):
            if full or len(value) <= FLOW_MAX_ITEMS:
                return "[" + ", ".join(scalar(v) for v in value) + "]"
            if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
                return _stats(f"list[{len(value)}]", [float(v) for v in value])
            return f"<list[{len(value)}]>"
        return None
    if isinstance(value, dict):
        if not value:
            return "{}"
        if len(value) <= 4 and all(_is_scalar(v) for v in value.values()):
            return "{" + ", ".join(f"{k}: {scalar(v)}" for k, v in value.items()) + "}"
    return None


def to_yaml(value: Any, full: bool = False, indent: int = 0) -> list[str]:
    """YAML-like lines of a decoded message body or reply."""
    pad = " " * indent
    if isinstance(value, dict):
        lines = []
        for k, v in value.items():
            flow = _flow(v, full)
            if flow is not None:
                lines.append(f"{pad}{k}: {flow}")
            else:
                lines.append(f"{pad}{k}:")
                lines += to_yaml(v, full, indent + 2)
        return lines
    if isinstance(value, list):
        if not full and len(value) > 3 * FLOW_MAX_ITEMS:
            return [f"{pad}<list of {len(value)} items; --full shows them>"]
        lines = []
        for item in value:
            sub = to_yaml(item, full, indent + 2)
            if sub and isinstance(item, (dict, list)):
                lines.append(f"{pad}- {sub[0].lstrip()}")
                lines += sub[1:]
            else:
                lines.append(f"{pad}- {_flow(item, full)}")
        return lines
    return [pad + (_flow(value, full) or str(value))]


def jsonable(value: Any) -> Any:
    """JSON-ready: arrays → lists, bytes → base64 text, non-finite floats → "inf"/"-inf"/"nan"."""
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if _is_array(value):
        return [jsonable(v) for v in _array_values(value)]
    if isinstance(value, (bytes, bytearray, memoryview)):
        return base64.b64encode(bytes(value)).decode("ascii")
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if hasattr(value, "item"):                       # numpy scalar
        return jsonable(value.item())
    return value


def dumps(value: Any) -> str:
    return json.dumps(jsonable(value), separators=(",", ":"), allow_nan=False)
