"""Hypothesis fuzz of a controller's runtime.ini as a careless or hostile project writes it (no
process): any text, any bytes, references to references, huge expansions. The result is always
defined: the values Webots' reader gives, or one line naming the file and the line; never another
exception, a hang or unbounded memory. And whatever the file sets, the controller attaches to the
server and robot `sensorium run` gives it."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from _fuzz import example_counts
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sensorium import runtime_ini
from sensorium.client.connection import controller_url_from_env
from sensorium.launch import ControllerSpec, Launcher
from sensorium.runtime_ini import MAX_SET, RuntimeIni, RuntimeIniError, environment, parse

SETTINGS = settings(max_examples=300, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
SECTIONS = ["environment variables", "Environment Variables with paths", "environment variables for linux",
            "python", "java", "nothing known", ""]
ATTACH = ["SENSORIUM_CONTROLLER_URL", "WEBOTS_CONTROLLER_URL", "WEBOTS_ROBOT_NAME", "SENSORIUM_CURVE_SERVERKEY",
          "PYTHONPATH", "LD_LIBRARY_PATH", "PYTHONUNBUFFERED"]
NAMES = ["A", "B", "C", "PATH", "UNSET", *ATTACH]
# text with every character a file may hold: controls, NUL, quotes, ';', '=', '$(', brackets, non-BMP
ANY_TEXT = st.text(st.characters(codec="utf-8", exclude_categories=["Cs"]), max_size=60) | st.sampled_from(
    ["$(A)", "$(", "$(A", "$()", "=", ";", '"', '"a;b"', '"a', "\0", "\r", "\ufeff", "\x0c", "\u2028", "[", "]"])


def one_line(exc: RuntimeIniError, where: str) -> str:
    text = str(exc)
    assert "\n" not in text and "\r" not in text and text.startswith(f"{where}: "), text
    return text


@pytest.mark.parametrize("examples", example_counts(300))
def test_any_text_parses_to_entries_or_one_line(examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(st.lists(ANY_TEXT, max_size=30), st.sampled_from(["\n", "\r\n", "\r", "\x0b", "\u2028"]), st.booleans())
    def run(pieces: list[str], newline: str, bom: bool) -> None:
        _any_text_parses_to_entries_or_one_line(pieces, newline, bom)

    run()


def _any_text_parses_to_entries_or_one_line(pieces: list[str], newline: str, bom: bool) -> None:
    text = ("\ufeff" if bom else "") + newline.join(pieces)
    try:
        ini = parse(text, "p/runtime.ini")
    except RuntimeIniError as exc:
        assert " line " in one_line(exc, "p/runtime.ini") and "before the '='" in str(exc)
        return
    assert len(ini.lines) == len(ini.entries) and list(ini.lines) == sorted(ini.lines)
    for section, key, value in ini.entries:
        assert "\n" not in key + value + section and "\0" not in key + value + section   # a line ends at \n, text at NUL
        assert ";" not in key and "=" not in key
        assert section == section.lower()
    try:
        env = environment(ini, {"A": "1", "PATH": "/bin"}, "linux")
    except RuntimeIniError as exc:        # nothing here comes near the bound
        pytest.fail(f"unexpected: {exc}")
    assert all("\0" not in k + v for k, v in env.items())


@st.composite
def ini_file(draw: st.DrawFn) -> tuple[str, list[tuple[str, str, str]]]:
    """A runtime.ini built line by line, and the entries Webots' reader makes of it."""
    lines, expected, section = [], [], ""
    for _ in range(draw(st.integers(0, 12))):
        kind = draw(st.sampled_from(["section", "entry", "quoted", "comment", "junk", "blank"]))
        pad = draw(st.sampled_from(["", " ", "\t", "  "]))
        if kind == "section":
            name = draw(st.sampled_from(SECTIONS))
            lines.append(f"{pad}[{name}]{pad}" + draw(st.sampled_from(["", " ; note", ";x=y"])))
            section = name.lower()
        elif kind in ("entry", "quoted"):
            key = draw(st.sampled_from(NAMES))
            plain = draw(st.text(st.sampled_from("ab/:$()=.x é\"-"), max_size=12)).strip()
            if kind == "entry":
                value = plain.split(";")[0].strip()
                if value.startswith('"'):
                    continue
                lines.append(f"{pad}{key}{pad}={pad}{plain}" + draw(st.sampled_from(["", " ; note", ";"])))
            else:
                inner = draw(st.text(st.sampled_from("ab;= $()"), max_size=10)).strip()
                lines.append(f'{key} = "{inner}"' + draw(st.sampled_from(["", " ; note", "  "])))
                value = inner
            expected.append((section, key, value))
        elif kind == "comment":
            lines.append(f"{pad}; {draw(ANY_TEXT).replace(chr(10), ' ')}")
        elif kind == "junk":
            lines.append(draw(st.sampled_from(["not a definition", "   ", "]]", "x", "a ] b"])))
        else:
            lines.append("")
    newline = draw(st.sampled_from(["\n", "\r\n"]))
    return ("\ufeff" if draw(st.booleans()) else "") + newline.join(lines), expected


@pytest.mark.parametrize("examples", example_counts(300))
def test_a_well_formed_file_gives_webots_entries(examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(ini_file())
    def run(made: tuple[str, list[tuple[str, str, str]]]) -> None:
        _a_well_formed_file_gives_webots_entries(made)

    run()


def _a_well_formed_file_gives_webots_entries(made: tuple[str, list[tuple[str, str, str]]]) -> None:
    text, expected = made
    assert list(parse(text).entries) == expected


def test_the_reader_ends_lines_and_text_as_webots_qt_reader_does() -> None:
    """A byte-order mark is skipped (the section it starts is read), a line's text ends at a NUL
    byte, only '\\n' ends a line (a form feed or U+2028 is inside it), '\\r\\n' is one end."""
    text = "\ufeff[environment variables]\r\nA = 1\0; B = 2\r\nC = x\x0cD = y\nE = p\u2028q\n"
    assert parse(text).entries == (("environment variables", "A", "1"), ("environment variables", "C", "x\x0cD = y"),
                                   ("environment variables", "E", "p\u2028q"))
    # Webots' quote rule: a ';' after the closing quote is a comment, before it part of the value
    quoted = parse('[python]\nCOMMAND = "/opt/my python/bin/python3" ; with a space\nOPTIONS = "-X  utf8;"\n'
                   'X = "never closed; here\nY = "a" b ; c\n')
    assert quoted.entries[:2] == (("python", "COMMAND", "/opt/my python/bin/python3"), ("python", "OPTIONS", "-X  utf8;"))
    assert quoted.entries[2:] == (("python", "X", '"never closed; here'), ("python", "Y", 'a"'))


def test_bytes_that_are_not_utf8_and_nul_bytes_are_read_as_webots_reads_them(tmp_path: Path) -> None:
    (tmp_path / "runtime.ini").write_bytes(b"\xef\xbb\xbf[environment variables]\nA = \xff\xfeok\nB = cut\x00here\n")
    ini = runtime_ini.read(tmp_path)
    assert ini is not None and ini.entries == (("environment variables", "A", "\ufffd\ufffdok"),
                                               ("environment variables", "B", "cut"))
    assert ini.where == str(tmp_path / "runtime.ini") and ini.lines == (2, 3)


def test_references_to_references_are_replaced_once_in_file_order() -> None:
    ini = parse("[environment variables]\nA = $(B)\nB = $(A)\nC = $(UNSET)x$(\nD = $(A)$(\nE = $()\n")
    env = environment(ini, {}, "linux")
    # A takes B's value then (unset: empty); B takes A's; nothing loops; an unclosed $( is text
    assert {k: env[k] for k in "ABCDE"} == {"A": "", "B": "", "C": "x$(", "D": "$(", "E": ""}
    env = environment(parse("[environment variables]\nA = $(B)\nB = $(A)!\n"), {"B": "$(A)"}, "linux")
    assert (env["A"], env["B"]) == ("$(A)", "$(A)!")       # text a variable brings in is not replaced again


def test_an_expansion_past_the_bound_is_one_line_naming_file_and_line() -> None:
    """A = $(A)$(A) on 40 lines would be 2^40 characters: the bound stops it at once."""
    doubling = "[environment variables]\nA = x\n" + "A = $(A)$(A)\n" * 40
    with pytest.raises(RuntimeIniError) as info:
        environment(parse(doubling, "c/runtime.ini"), {}, "linux")
    assert one_line(info.value, "c/runtime.ini") == (
        f"c/runtime.ini: line 25: A's value with its $(...) references replaced makes the file's values longer "
        f"than the {MAX_SET} characters set at most")
    # many variables each taking a large one: the values together are bounded too
    big = {"BIG": "y" * 100_000}
    many = "[environment variables]\n" + "".join(f"V{i} = $(BIG)\n" for i in range(50))
    with pytest.raises(RuntimeIniError, match=r"^x: line 43: V41's value"):
        environment(parse(many, "x"), big, "linux")
    assert len(environment(parse(many.replace("V4", "W")), {"BIG": "y" * 10}, "linux")) == 51


@pytest.mark.parametrize("examples", example_counts(300))
def test_a_runtime_ini_cannot_change_where_the_controller_attaches(examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(st.lists(st.tuples(st.sampled_from(SECTIONS[:3]), st.sampled_from(ATTACH + ["A", "SENSORIUM_CONTROLLER_TIMEOUT"]),
                              st.sampled_from(["", "tcp://127.0.0.1:9/evil", "other", "$(A)", "/x:$(PYTHONPATH)",
                                               "tcp://10.0.0.1:1", "0" * 40, "$(WEBOTS_ROBOT_NAME)x"])), max_size=12),
           st.sampled_from(["alpha", "beta %41", "é/ü"]), st.booleans())
    def run(entries: list[tuple[str, str, str]], robot: str, python: bool) -> None:
        _a_runtime_ini_cannot_change_where_the_controller_attaches(entries, robot, python)

    run()


def _a_runtime_ini_cannot_change_where_the_controller_attaches(entries: list[tuple[str, str, str]], robot: str,
                                                                   python: bool) -> None:
    text = "".join(f"[{section}]\n{key} = {value}\n" for section, key, value in entries)
    folder = Path("/nowhere/controllers/c")
    spec = ControllerSpec(robot, "c", folder, folder / ("c.py" if python else "c"), python, runtime=parse(text))
    launcher = Launcher([spec], "tcp://127.0.0.1:48701")
    try:
        base = {"PYTHONPATH": "/mine", "SENSORIUM_CURVE_SERVERKEY": "0" * 40, "WEBOTS_CONTROLLER_URL": "ipc://x"}
        env = launcher.environment(spec, base)
    finally:
        launcher.close()
    url = controller_url_from_env(env)
    assert (url.endpoint, url.robot) == ("tcp://127.0.0.1:48701", robot)
    assert env["WEBOTS_ROBOT_NAME"] == robot and "WEBOTS_CONTROLLER_URL" not in env
    assert "SENSORIUM_CURVE_SERVERKEY" not in env            # the server is plain: no key from the shell or the file
    assert env["PYTHONPATH"].split(os.pathsep)[0] == str(Path(runtime_ini.__file__).resolve().parent.parent)
    assert env["PYTHONUNBUFFERED"] == "1"


def test_a_curve_server_key_is_the_servers_own() -> None:
    folder = Path("/nowhere/controllers/c")
    spec = ControllerSpec("r", "c", folder, folder / "c.py", True,
                          runtime=parse("[environment variables]\nSENSORIUM_CURVE_SERVERKEY = wrong\n"))
    launcher = Launcher([spec], "tcp://127.0.0.1:48701", serverkey="k" * 40)
    try:
        assert launcher.environment(spec, {})["SENSORIUM_CURVE_SERVERKEY"] == "k" * 40
    finally:
        launcher.close()


def test_an_empty_ini_changes_nothing() -> None:
    assert environment(RuntimeIni(), {"A": "1"}, "linux") == {"A": "1"}


def test_a_megabyte_of_entries_is_read_and_said_in_bounded_lines(tmp_path: Path) -> None:
    """The largest file read: 55,000 distinct variables (the bound's running total, not a sum per
    entry: that was quadratic) and 55,000 unknown [python] keys (8 named, one line for the others)."""
    text = "[environment variables]\n" + "".join(f"V{i}=1\n" for i in range(55_000)) + "[python]\n" + "".join(
        f"K{i}=1\n" for i in range(55_000)) + "K\x1b[2J=1\n"
    assert len(text.encode()) <= runtime_ini.MAX_BYTES
    (tmp_path / "runtime.ini").write_text(text)
    ini = runtime_ini.read(tmp_path)
    assert ini is not None and len(environment(ini, {}, "linux")) == 55_000
    notes = ini.notes()
    assert notes[:2] == ["unknown key K0 in its [python] section (COMMAND and OPTIONS are read)",
                         "unknown key K1 in its [python] section (COMMAND and OPTIONS are read)"]
    assert notes[8:] == ["54993 more unknown keys in its [python] section"]
    assert parse("[python]\nK\x1b[2J = 1\n").notes() == [
        "unknown key 'K\\x1b[2J' in its [python] section (COMMAND and OPTIONS are read)"]


def test_long_lines_and_duplicates_are_read_in_order_and_said_short() -> None:
    ini = parse("[environment variables]\nA = 1\n[python]\nCOMMAND = a\n[environment variables]\nA = $(A)2\n"
                "[python]\nCOMMAND = b\nB = " + "v" * 1_000_000 + "\n")
    assert environment(ini, {}, "linux")["A"] == "12" and ini.python("COMMAND") == "b"
    assert ini.entries[-1] == ("python", "B", "v" * 1_000_000)
    with pytest.raises(RuntimeIniError) as info:
        parse("[environment variables]\n" + "k;" * 500_000 + "= 1\n", "f")
    assert len(one_line(info.value, "f")) < 200
