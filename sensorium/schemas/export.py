"""JSON Schema export of the contract: world files, topic messages, service requests and replies.

    export_all("schemas/json")        # writes world/messages/services.schema.json
    sensorium schemas [--out DIR] [--check]

The committed files in ``schemas/json/`` are checked against the models by
``tests/test_schemas_export.py``: change a model, run ``sensorium schemas``, commit both.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from pydantic.json_schema import models_json_schema

from sensorium.schemas import messages, services, world

__all__ = ["DEFAULT_DIR", "schemas", "export_all", "render", "main"]

DEFAULT_DIR = Path(__file__).resolve().parent / "json"
DRAFT = "https://json-schema.org/draft/2020-12/schema"


def _bundle(models: list[Any], title: str, description: str) -> dict:
    refs, defs = models_json_schema([(m, "validation") for m in models], ref_template="#/$defs/{model}")
    return {"$schema": DRAFT, "title": title, "description": description,
            "oneOf": [refs[(m, "validation")] for m in models], **defs}


def messages_schema() -> dict:
    models: list[type] = [messages.Envelope, *messages.MESSAGE_TYPES.values()]
    out = _bundle(models, "Sensorium topic messages",
                  "Topic frames are [topic + NUL, envelope, body] (PROTOCOL.md §4); bodies are msgpack maps "
                  "with ROS 2 field names in ROS order, arrays as little-endian bin.")
    out["x-ros-types"] = {name: f"#/$defs/{m.__name__}" for name, m in messages.MESSAGE_TYPES.items()}
    return out


def services_schema() -> dict:
    specs = services.SERVICES
    models: list[type] = [services.Request, services.OkReply, services.ErrorReply]
    for s in specs:
        for m in (s.args, s.result):
            if m not in models:
                models.append(m)
    out = _bundle(models, "Sensorium services",
                  "Requests and replies on the ROUTER socket (PROTOCOL.md §3); one msgpack map per frame.")
    out["oneOf"] = out["oneOf"][:3]        # a frame is a request or a reply; the rest are $defs
    out["x-error-codes"] = {c.name: int(c) for c in services.ErrorCode}
    out["x-services"] = [
        {"name": s.item if s.scope == "server" else (f"/<robot>/robot/{s.item}" if s.scope == "robot"
                                                     else f"/<robot>/<device>/{s.item}"),
         "args": f"#/$defs/{s.args.__name__}", "result": f"#/$defs/{s.result.__name__}",
         "attached": s.attached, "supervisor": s.supervisor, "devices": sorted(s.devices)}
        for s in specs
    ]
    return out


def schemas() -> dict[str, dict]:
    """File name → JSON Schema document."""
    return {
        "world.schema.json": world.json_schema(),
        "messages.schema.json": messages_schema(),
        "services.schema.json": services_schema(),
    }


def render(doc: dict) -> str:
    return json.dumps(doc, indent=2, ensure_ascii=False) + "\n"


def export_all(directory: str | Path = DEFAULT_DIR) -> list[Path]:
    """Write every schema into ``directory`` (created if needed); returns the paths written."""
    d = Path(directory)
    d.mkdir(parents=True, exist_ok=True)
    out = []
    for name, doc in schemas().items():
        p = d / name
        p.write_text(render(doc), encoding="utf-8")
        out.append(p)
    return out


def stale(directory: str | Path = DEFAULT_DIR) -> list[str]:
    """Names of the schema files in ``directory`` that are missing or differ from the models."""
    d = Path(directory)
    bad = []
    for name, doc in schemas().items():
        p = d / name
        if not p.exists() or p.read_text(encoding="utf-8") != render(doc):
            bad.append(name)
    return bad


def main(args: argparse.Namespace) -> int:
    out = Path(args.out) if getattr(args, "out", None) else DEFAULT_DIR
    if getattr(args, "check", False):
        bad = stale(out)
        for name in bad:
            print(f"{out / name}: out of date (run `sensorium schemas --out {out}`)", file=sys.stderr)
        return 1 if bad else 0
    for p in export_all(out):
        print(p)
    return 0
