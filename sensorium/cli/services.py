"""``sensorium services`` and ``sensorium call``: list and call a running server's services from the
shell, like ``ros2 service list -t`` / ``ros2 service call`` (pyzmq + msgpack only; PyYAML, when
installed, lets arguments be written in YAML flow style as well as JSON); ``sensorium window``: one
text to a robot's controller (``window_send``)."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from sensorium.cli.format import dumps, to_yaml
from sensorium.client.connection import DEFAULT_RPC_ENDPOINT, Connection, SensoriumError, parse_controller_url


def _endpoint(url: str | None) -> str:
    return parse_controller_url(url or DEFAULT_RPC_ENDPOINT).endpoint


def services(args: argparse.Namespace) -> int:
    try:
        with Connection(_endpoint(args.url), timeout=args.timeout) as conn:
            try:
                listed = conn.call("get_services")["services"]
            except SensoriumError as exc:
                if exc.name not in ("UNKNOWN_SERVICE", "WRONG_STATE"):
                    raise
                # a replay (sensorium replay) lists its service names in get_info
                listed = [{"name": n, "scope": "server", "robot": None, "device": None, "device_type": None,
                           "attached": False, "args": {}} for n in conn.call("get_info").get("services", [])]
    except SensoriumError as exc:
        print(f"sensorium services: {exc}", file=sys.stderr)
        return 1
    if args.robot:                        # one robot's services, or 'server' for the server's own
        robots = list(dict.fromkeys(str(s["robot"]) for s in listed if s.get("robot") is not None))
        if args.robot != "server" and args.robot not in robots:
            print(f"sensorium services: no robot {args.robot!r} (robots: {', '.join(robots) or 'none'}; "
                  "'server' for the server's own services)", file=sys.stderr)
            return 1
        listed = [s for s in listed if s.get("robot") == (None if args.robot == "server" else args.robot)]
    if args.json:
        print(dumps({"services": listed}))
        return 0
    group = None
    for s in listed:
        here = ("server" if s.get("robot") is None else
                f"{s['robot']}" if s.get("device") is None else f"{s['robot']}/{s['device']} ({s['device_type']})")
        if here != group:
            group = here
            print(f"{here}:")
        arg_text = ", ".join(f"{k}: {v}" for k, v in s.get("args", {}).items())
        mark = ("  [not simulated: its functions answer Webots' no value (NaN, NULL, 0)]" if s.get("simulated") is False else
                "  [supervisor controller only: robot with supervisor: true]" if s.get("supervisor") else
                "  [attached controller only]" if s.get("attached") else "")
        print(f"  {s['name']}  {{{arg_text}}}{mark}")
    return 0


def parse_args_text(text: str | None) -> dict[str, Any]:
    """ARGS of ``sensorium call``: a JSON object, or YAML flow style (``{mode: fast}``) when PyYAML is there."""
    if text is None or not text.strip():
        return {}
    try:
        value = json.loads(text)
    except json.JSONDecodeError as exc:
        try:
            import yaml
        except ImportError:
            raise ValueError(f"ARGS is not JSON: {exc}") from None
        try:
            value = yaml.safe_load(text)
        except yaml.YAMLError as yexc:
            mark = getattr(yexc, "problem_mark", None)
            problem = getattr(yexc, "problem", None) or str(yexc).splitlines()[0]
            where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
            raise ValueError(f"ARGS {text!r} is neither JSON nor YAML{where}: {problem}") from None
    if not isinstance(value, dict):
        raise ValueError(f"ARGS must be a mapping such as '{{\"mode\": \"fast\"}}', got {text!r}")
    problem = _unsendable(value, "")
    if problem:
        raise ValueError(f"ARGS {text!r}: {problem}")
    return value


def _unsendable(value: Any, where: str) -> str | None:
    """What in a parsed ARGS value msgpack cannot carry to the server (a YAML date, a set, an
    integer beyond 64 bits, a key that is not a string), naming where; None when all of it can."""
    at = f" at {where[1:]}" if where else ""
    if isinstance(value, dict):
        for key, item in value.items():
            if not isinstance(key, str):
                return f"key {key!r}{at} is not a string (write it in quotes)"
            problem = _unsendable(item, f"{where}.{key}")
            if problem:
                return problem
        return None
    if isinstance(value, list):
        for k, item in enumerate(value):
            problem = _unsendable(item, f"{where}[{k}]")
            if problem:
                return problem
        return None
    if isinstance(value, bool) or value is None or isinstance(value, (str, float, bytes)):
        return None
    if isinstance(value, int):
        if -(1 << 63) <= value < (1 << 64):
            return None
        return f"the integer{at} does not fit in 64 bits"
    return f"the {type(value).__name__} value {str(value)!r}{at} cannot be sent (write it in quotes for a string)"


def window(args: argparse.Namespace) -> int:
    """``sensorium window ROBOT TEXT``: the service ``/<robot>/robot/window_send``."""
    service = f"/{args.robot}/robot/window_send"
    try:
        with Connection(_endpoint(args.url), timeout=args.timeout) as conn:
            result = conn.call(service, {"text": args.text})
    except SensoriumError as exc:
        print(f"sensorium window: {exc}", file=sys.stderr)
        return 1
    print(f"queued: {result.get('queued')}")
    return 0


def call(args: argparse.Namespace) -> int:
    try:
        request = parse_args_text(args.args)
    except ValueError as exc:
        print(f"sensorium call: {exc}", file=sys.stderr)
        return 2
    try:
        with Connection(_endpoint(args.url), timeout=args.timeout) as conn:
            result = conn.call(args.service, request)
    except SensoriumError as exc:
        hint = ""
        if exc.name == "NOT_ATTACHED":
            hint = " (only the robot's controller may call it: see `sensorium services`)"
        elif exc.name in ("UNKNOWN_SERVICE", "UNKNOWN_ROBOT", "UNKNOWN_DEVICE"):
            hint = " (`sensorium services` lists them)"
        print(f"sensorium call {args.service}: {exc}{hint}", file=sys.stderr)
        return 1
    if args.json:
        print(dumps(result))
    else:
        print("\n".join(to_yaml(result, args.full)) if result else "{}")
    return 0
