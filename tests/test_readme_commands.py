"""What the docs name exists, so a reader who copies it is not stopped by a rename or a move.

Every ``sensorium CMD ...`` that README.md, ARCHITECTURE.md or PROTOCOL.md shows (in a ``sh`` block
or an inline code span) names a subcommand and only options that subcommand has, with values its
choices allow, and parses when it has no placeholders; every ``python -m sensorium.MODULE --flag``
names a module that exists and an option it defines; every lone ```--flag``` span is an option of
some sensorium command or module (or of the external tool the text names); every relative link
points at a file that exists, and at a heading there when it has an anchor; every repository path
the README names, and every file ARCHITECTURE.md and PROTOCOL.md name, exists; every README Python
snippet compiles. Nothing is run: tests/test_readme.py runs the snippets and the offline commands."""

from __future__ import annotations

import argparse
import re
import shlex
from pathlib import Path
from typing import NoReturn
from unittest import mock

import pytest

from sensorium.cli import build_parser
from sensorium.worlds import names as bundled_worlds

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "sensorium" / "client" / "examples"
README = ROOT / "README.md"
DOCS = ("README.md", "ARCHITECTURE.md", "PROTOCOL.md", "docs/webots-samples.md")
FLAG = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]*")
# options of other programs the README names in passing: Webots' command line (`webots --batch
# --stdout`, a controller's `--stdout`/`--stderr` console filters), `docker run --rm`, `ray start`
EXTERNAL_FLAGS = {"--batch", "--stdout", "--stderr", "--rm", "--head", "--node-ip-address", "--port",
                  "--address", "--node-manager-port", "--object-manager-port", "--min-worker-port",
                  "--max-worker-port"}
EXTERNAL_PROGRAMS = ("webots", "docker", "ray ", "pip", "python3 -m pip", "python3 -m pytest", "make", "cc ")
# paths the README shows as examples of a reader's own files, not files of this repository
EXAMPLE_PATHS = {"tests/test_x.py"}


def _parser() -> tuple[argparse.ArgumentParser, dict[str, argparse.ArgumentParser]]:
    parser = build_parser()
    (sub,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return parser, dict(sub.choices)


PARSER, SUBCOMMANDS = _parser()


def _options(parser: argparse.ArgumentParser) -> dict[str, argparse.Action]:
    return {s: a for a in parser._actions for s in a.option_strings}


def _fenced(text: str) -> list[tuple[str, int, str]]:
    """(language, first line number, body) of each fenced block."""
    return [(m.group(1), text.count("\n", 0, m.start()) + 2, m.group(2))
            for m in re.finditer(r"^```(\w*)\n(.*?)^```", text, flags=re.S | re.M)]


def _prose(text: str) -> str:
    """The text with fenced blocks blanked (their lines kept, so line numbers still hold)."""
    return re.sub(r"^```.*?^```", lambda m: "\n" * m.group(0).count("\n"), text, flags=re.S | re.M)


def code_snippets(text: str) -> list[tuple[int, str]]:
    """(line, snippet): each command of a sh block (comments and a trailing & dropped, split at &&)
    and each inline code span of the prose."""
    out: list[tuple[int, str]] = []
    for lang, first, body in _fenced(text):
        if lang != "sh":
            continue
        for i, line in enumerate(body.splitlines()):
            line = re.sub(r"(^|\s+)#\s.*$", "", line).strip().removesuffix("&").strip()
            out += [(first + i, part.strip()) for part in line.split("&&") if part.strip()]
    for i, line in enumerate(_prose(text).splitlines(), 1):
        out += [(i, m.group(1)) for m in re.finditer(r"`([^`\n]+)`", line)]
    return out


def sensorium_commands(text: str) -> list[tuple[int, str, str]]:
    """(line, subcommand, the rest) of every snippet that is a `sensorium` command line."""
    out = []
    for line, snippet in code_snippets(text):
        m = re.match(r"(?:python3? -m )?sensorium ([a-z][a-z0-9-]*)(.*)$", snippet)
        if m:
            out.append((line, m.group(1), m.group(2)))
    return out


def module_commands(text: str) -> list[tuple[int, str, str]]:
    """(line, module, the rest) of every `python -m sensorium.MODULE ...` the README shows."""
    return [(line, m.group(1), m.group(2)) for line, snippet in code_snippets(text)
            for m in [re.match(r"python3? -m (sensorium(?:\.\w+)+)(.*)$", snippet)] if m]


def _placeholder(token: str) -> bool:
    return (any(c in token for c in "[]<>…") or "..." in token or token == "|"
            or (token.isupper() and token.isalpha()) or bool(re.fullmatch(r"[A-Z][A-Z_0-9.:]*", token)))


class _Refused(Exception):
    pass


def _parse_error(argv: list[str]) -> str | None:
    """What argparse would print before exiting on argv, or None when it parses."""
    def refuse(self: argparse.ArgumentParser, message: str) -> NoReturn:
        raise _Refused(message)

    with mock.patch.object(argparse.ArgumentParser, "error", refuse):
        try:
            PARSER.parse_args(argv)
        except _Refused as exc:
            return str(exc)
    return None


def _passed_on(parser: argparse.ArgumentParser, before: list[str]) -> bool:
    """Whether an option after these tokens belongs to a program the command starts: `sensorium
    controller SCRIPT ARGS...` hands what follows SCRIPT to the script (`example:wanderer -v`)."""
    takes_the_rest = any(a.nargs == argparse.REMAINDER for a in parser._actions)
    return takes_the_rest and any(not t.startswith("-") for t in before)


def command_problems(text: str, doc: str = "README.md") -> list[str]:
    problems: list[str] = []
    for line, name, rest in sensorium_commands(text):
        found = len(problems)
        if name not in SUBCOMMANDS:
            problems.append(f"{doc}:{line}: `sensorium {name}`: no such command")
            continue
        options = _options(SUBCOMMANDS[name]) | _options(PARSER)
        rest = rest.split(":")[0] if rest.startswith(":") else rest      # `sensorium run: ...` is its log line
        try:
            tokens = shlex.split(rest)
        except ValueError:
            tokens = rest.split()
        for k, token in enumerate(tokens):
            flag = token.strip("[]").split("=")[0]
            if not (FLAG.fullmatch(flag) or re.fullmatch(r"-[a-zA-Z]", flag)):
                continue
            if flag not in options and not _passed_on(SUBCOMMANDS[name], tokens[:k]):
                problems.append(f"{doc}:{line}: `sensorium {name}` has no option {flag}")
                continue
            choices = options[flag].choices if flag in options else None
            value = tokens[k + 1].strip("[]") if k + 1 < len(tokens) else ""
            if choices and value and not value.startswith("-") and not _placeholder(value):
                bad = [v for v in value.split("|") if v not in choices]
                if bad:
                    problems.append(f"{doc}:{line}: `sensorium {name} {flag}` takes one of "
                                    f"{', '.join(map(str, choices))}, not {bad[0]}")
        if tokens and len(problems) == found and not any(_placeholder(t) for t in tokens) and "|" not in rest:
            refused = _parse_error([name, *tokens])
            # a span that names a command with an option (`sensorium run --robot-window-log`) leaves
            # out its positional arguments; anything else argparse refuses is a wrong line
            if refused and not refused.startswith("the following arguments are required"):
                problems.append(f"{doc}:{line}: `sensorium {name}{rest}` does not parse: {refused}")
    return problems


def named_things_problems(text: str, doc: str = "README.md") -> list[str]:
    """A bundled example controller (`example:NAME`) or bundled world (`sensorium serve NAME`, a bare
    name where a command takes a world) the text names is bundled."""
    problems = [f"{doc}:{text.count(chr(10), 0, m.start()) + 1}: example:{m.group(1)}: no such bundled controller"
                for m in re.finditer(r"\bexample:([a-z_]+)", text)
                if not (EXAMPLES / f"{m.group(1)}.py").exists()]
    for line, name, rest in sensorium_commands(text):
        parser = SUBCOMMANDS.get(name)
        world = [a for a in parser._actions if a.dest in ("world", "path", "source") and not a.option_strings] if parser else []
        tokens = [t for t in rest.split() if not t.startswith("-")]
        if world and tokens and re.fullmatch(r"[a-z][a-z0-9_]*", tokens[0]) and tokens[0] not in bundled_worlds():
            problems.append(f"{doc}:{line}: `sensorium {name} {tokens[0]}`: no bundled world {tokens[0]!r}")
    return problems


def _module_file(module: str) -> Path | None:
    path = ROOT.joinpath(*module.split("."))
    for candidate in (path.with_suffix(".py"), path / "__main__.py"):
        if candidate.exists():
            return candidate
    return None


def _defined_flags(source: str) -> set[str]:
    return set(re.findall(r"""["'](--[a-z][a-z0-9-]*)["']""", source))


def module_problems(text: str, doc: str = "README.md") -> list[str]:
    problems = []
    for line, module, rest in module_commands(text):
        path = _module_file(module)
        if path is None:
            problems.append(f"{doc}:{line}: `python -m {module}`: no such module")
            continue
        defined = _defined_flags(path.read_text())
        problems += [f"{doc}:{line}: `python -m {module}` has no option {flag}"
                     for flag in FLAG.findall(rest) if flag not in defined]
    return problems


def known_flags() -> set[str]:
    flags = set(_options(PARSER)).union(*(_options(p) for p in SUBCOMMANDS.values()))
    for path in (ROOT / "sensorium").rglob("*.py"):
        flags |= _defined_flags(path.read_text())
    return flags | EXTERNAL_FLAGS


def lone_flag_problems(text: str, doc: str = "README.md") -> list[str]:
    """A span that is only options (```--compare```, ```--body box```) names an option that exists."""
    known = known_flags()
    return [f"{doc}:{line}: {flag} is no option of any sensorium command or module"
            for line, snippet in code_snippets(text) if snippet.startswith("--")
            for flag in FLAG.findall(snippet) if flag not in known]


def _slug(heading: str) -> str:
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces to hyphens."""
    heading = re.sub(r"[`*_]|\[([^]]*)\]\([^)]*\)", lambda m: m.group(1) or "", heading.strip().lower())
    return re.sub(r"[^\w\- ]", "", heading).replace(" ", "-")


def _anchors(text: str) -> set[str]:
    """A heading's slug, or an HTML anchor the text sets (`<a id="joints"></a>**Joints.**`)."""
    prose = _prose(text)
    return ({_slug(m.group(1)) for m in re.finditer(r"^#{1,6} (.+)$", prose, flags=re.M)}
            | set(re.findall(r"""<a (?:id|name)="([^"]+)">""", prose)))


def link_problems(name: str, text: str) -> list[str]:
    problems = []
    prose = _prose(text)
    for m in re.finditer(r"\]\(([^)\s]+)\)", prose):
        target = m.group(1)
        if re.match(r"[a-z][a-z0-9+.-]*:", target):                   # http:, https:, mailto:
            continue
        path, _, anchor = target.partition("#")
        line = prose.count("\n", 0, m.start()) + 1
        file = (ROOT / name).parent / path if path else ROOT / name
        if not file.exists():
            problems.append(f"{name}:{line}: link to {path}: no such file")
        elif anchor and file.suffix == ".md" and anchor not in _anchors(file.read_text()):
            problems.append(f"{name}:{line}: link to {target}: no such heading in {file.name}")
    return problems


def path_problems(text: str) -> list[str]:
    """Repository paths (sensorium/..., tests/..., docs/..., docker/..., .ci/...) the text names exist;
    gym ids (sensorium/ReachLight-v0) and build outputs are not files of the repository."""
    problems = []
    for i, line in enumerate(text.splitlines(), 1):
        for m in re.finditer(r"(?<![\w./~$-])((?:sensorium|tests|docs|docker|\.ci)/[\w./-]*[\w/])", line):
            path = m.group(1)
            if (re.search(r"-v\d+$", path) or "/build" in path or path in EXAMPLE_PATHS
                    or (ROOT / path).exists()):
                continue
            problems.append(f"line {i}: {path}: no such file or folder")
    return problems


def module_path_problems(text: str) -> list[str]:
    """ARCHITECTURE.md and PROTOCOL.md name files by their path under the package or one of its
    folders (`server/sim/scene.py`, `sim/motion.py`, `client/c/src/robot.c`): each is a file here."""
    bases = [ROOT, ROOT / "sensorium", ROOT / "sensorium" / "server", ROOT / "sensorium" / "client"]
    problems = []
    for i, line in enumerate(text.splitlines(), 1):
        for m in re.finditer(r"(?<![\w./~<$-])([\w-]+(?:/[\w.-]+)+\.(?:py|pyi|yaml|json|c|h|hpp|cpp|wbt|md|toml|js))\b",
                             line):
            if not any((base / m.group(1)).exists() for base in bases):
                problems.append(f"line {i}: {m.group(1)}: no such file")
    return problems


def python_snippets(text: str) -> list[tuple[int, str]]:
    """Each ```python block, and the code of each `python -c "..."` in a sh block."""
    out = [(first, body) for lang, first, body in _fenced(text) if lang == "python"]
    for line, snippet in code_snippets(text):
        m = re.match(r"""python3? -c (["'])(.*)\1$""", snippet)
        if m:
            out.append((line, m.group(2)))
    return out


def test_the_readme_shows_commands_of_each_kind():
    text = README.read_text()
    assert len(sensorium_commands(text)) > 100 and len(module_commands(text)) > 10
    assert len(python_snippets(text)) >= 6


@pytest.mark.parametrize("name", DOCS)
def test_every_sensorium_command_shown_has_its_options(name):
    assert command_problems((ROOT / name).read_text(), name) == []


@pytest.mark.parametrize("name", DOCS)
def test_every_bundled_controller_and_world_named_is_bundled(name):
    assert named_things_problems((ROOT / name).read_text(), name) == []


@pytest.mark.parametrize("name", DOCS)
def test_every_python_module_shown_exists_with_its_options(name):
    assert module_problems((ROOT / name).read_text(), name) == []


@pytest.mark.parametrize("name", DOCS)
def test_every_option_named_alone_exists(name):
    assert lone_flag_problems((ROOT / name).read_text(), name) == []


@pytest.mark.parametrize("name", DOCS)
def test_relative_links_point_at_files_and_headings_that_exist(name):
    assert link_problems(name, (ROOT / name).read_text()) == []


@pytest.mark.parametrize("name", ["README.md", "docs/webots-samples.md"])
def test_every_repository_path_the_readme_names_exists(name):
    assert path_problems((ROOT / name).read_text()) == []


@pytest.mark.parametrize("name", ["ARCHITECTURE.md", "PROTOCOL.md"])
def test_every_file_architecture_and_protocol_name_exists(name):
    assert module_path_problems((ROOT / name).read_text()) == []


def test_python_snippets_compile():
    for line, code in python_snippets(README.read_text()):
        compile(code, f"README.md:{line}", "exec")


# the checks themselves: a README line with each kind of mistake is caught

def test_a_renamed_option_an_unknown_command_and_a_bad_choice_are_caught():
    text = ("```sh\nsensorium serve arena --no-contacts   # a typo\nsensorium serv arena\n```\n"
            "and `sensorium bench --only image` and `sensorium serve --mode fast|slow`\n")
    problems = command_problems(text)
    assert any("has no option --no-contacts" in p for p in problems)
    assert any("`sensorium serv`: no such command" in p for p in problems)
    assert any("takes one of" in p and "not image" in p for p in problems)
    assert any("not slow" in p for p in problems)
    assert command_problems("`sensorium controller -q example:wanderer --robot scout -v`") == [
        "README.md:1: `sensorium controller` has no option -q"]
    assert command_problems("`sensorium probe arena --steps five`") == [
        "README.md:1: `sensorium probe arena --steps five` does not parse: "
        "argument --steps: invalid int value: 'five'"]


def test_a_missing_module_option_a_lone_option_a_link_and_a_path_are_caught():
    assert module_problems("`python -m sensorium.benchmarks.moves --solid 10`") == [
        "README.md:1: `python -m sensorium.benchmarks.moves` has no option --solid"]
    assert module_problems("`python -m sensorium.benchmarks.nothing`") == [
        "README.md:1: `python -m sensorium.benchmarks.nothing`: no such module"]
    assert lone_flag_problems("with `--no-such-flag`") == [
        "README.md:1: --no-such-flag is no option of any sensorium command or module"]
    assert link_problems("README.md", "see [x](PROTOCOL.md#no-such-section) and [y](NOPE.md)") == [
        "README.md:1: link to PROTOCOL.md#no-such-section: no such heading in PROTOCOL.md",
        "README.md:1: link to NOPE.md: no such file"]
    assert named_things_problems("`sensorium serve arena_2` and `sensorium controller example:follower`") == [
        "README.md:1: example:follower: no such bundled controller",
        "README.md:1: `sensorium serve arena_2`: no bundled world 'arena_2'"]
    assert module_path_problems("2. `server/devices/compass.py`: the pure model") == [
        "line 1: server/devices/compass.py: no such file"]
    assert path_problems("in `sensorium/worlds/no_such_world.yaml`") == [
        "line 1: sensorium/worlds/no_such_world.yaml: no such file or folder"]
    with pytest.raises(SyntaxError):
        for line, code in python_snippets("```python\nprint(1\n```\n"):
            compile(code, f"README.md:{line}", "exec")


def test_every_gymnasium_id_the_readme_names_is_registered():
    gym = pytest.importorskip("gymnasium")
    import sensorium.gym  # noqa: F401  (registers the ids)

    named = set(re.findall(r"\bsensorium/[A-Za-z]+-v\d+\b", README.read_text()))
    assert named and sorted(named - set(gym.registry)) == []
