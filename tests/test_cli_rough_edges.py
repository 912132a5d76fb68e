"""First-hour rough edges of the command line (issue 26): each one clear line or fixed."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def run(*args: str, cwd: Path | None = None, timeout: float = 120) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, "-m", "sensorium", *args], capture_output=True, text=True, env=env,
                          cwd=cwd, timeout=timeout)


def test_convert_takes_a_bundled_world_name(tmp_path):
    out = tmp_path / "out.yaml"
    r = run("convert", "epuck.wbt", str(out), cwd=tmp_path)               # no epuck.wbt here: the bundled one
    assert r.returncode == 0, r.stderr
    assert "Traceback" not in r.stderr and "robots:" in out.read_text()
    missing = run("convert", "nope.wbt", str(tmp_path / "x.yaml"), cwd=tmp_path)
    assert missing.returncode == 1 and "Traceback" not in missing.stderr
    assert missing.stderr.strip().splitlines() == [
        f"nope.wbt: no such file (nor a bundled world: {missing.stderr.split('bundled world: ')[1].strip()}"]
    assert "epuck.wbt" in missing.stderr


def test_pytest_says_at_the_end_which_node_tests_it_skipped_and_how_to_run_them(tmp_path):
    env = dict(os.environ, PYTHONPATH=str(ROOT), PATH=str(Path(sys.executable).parent))   # no node on PATH
    env.pop("SENSORIUM_REQUIRE_NODE", None)
    r = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-W", "ignore",
                        str(ROOT / "tests" / "test_foxglove_live.py"), "-k", "replay_serves", "-m", "slow or not slow"],
                       capture_output=True, text=True, env=env, cwd=ROOT, timeout=300)
    lines = [line for line in r.stdout.splitlines() if line.startswith("sensorium: ")]
    assert len(lines) == 1, r.stdout[-3000:]
    assert "1 Foxglove/Node test(s) skipped (node is not installed)" in lines[0] and "npm ci" in lines[0]


def test_a_bad_yaml_argument_to_call_names_its_position():
    import pytest

    from sensorium.cli.services import parse_args_text

    with pytest.raises(ValueError) as exc:
        parse_args_text("{mode: [fast}")
    assert str(exc.value) == ("ARGS '{mode: [fast}' is neither JSON nor YAML at line 1, column 13: "
                              "expected ',' or ']', but got '}'")
    r = run("call", "set_mode", "{mode: fast", "--url", "tcp://127.0.0.1:1")
    assert r.returncode == 2 and r.stderr.strip().splitlines() == [
        "sensorium call: ARGS '{mode: fast' is neither JSON nor YAML at line 1, column 12: "
        "expected ',' or '}', but got '<stream end>'"]


def test_call_args_msgpack_cannot_carry_are_one_line_naming_the_value():
    """A YAML date, a set or an integer beyond 64 bits in ARGS ended `sensorium call` in a msgpack
    traceback; a non-string key got the server's misleading 'not a msgpack document'."""
    import pytest

    from sensorium.cli.services import parse_args_text

    for text, said in (("{a: 2020-01-01}", "the date value '2020-01-01' at a cannot be sent"),
                       ("{a: [1, {b: 99999999999999999999999}]}", "the integer at a[1].b does not fit in 64 bits"),
                       ("{translation: [1, 2, !!set {x}]}", "the set value \"{'x'}\" at translation[2] cannot be sent"),
                       ("{1: fast}", "key 1 is not a string")):
        with pytest.raises(ValueError) as exc:
            parse_args_text(text)
        assert str(exc.value).startswith(f"ARGS {text!r}: {said}"), str(exc.value)
    assert parse_args_text('{a: "2020-01-01", b: -9223372036854775808, c: 18446744073709551615, d: [.inf, null]}') == {
        "a": "2020-01-01", "b": -(1 << 63), "c": (1 << 64) - 1, "d": [float("inf"), None]}
    r = run("call", "get_info", "{when: 2020-01-01}", "--url", "tcp://127.0.0.1:1")
    assert r.returncode == 2 and r.stderr.strip().splitlines() == [
        "sensorium call: ARGS '{when: 2020-01-01}': the date value '2020-01-01' at when cannot be sent (write it in "
        "quotes for a string)"]


def test_numbers_out_of_range_are_refused_by_the_parser(capsys):
    """--start nan / --end inf ended replay and export in a traceback; --duration -1 recorded
    nothing and --max-messages 0 one message; hz --window -5 was an IndexError, --window 0 printed
    nothing; negative timeouts and rates of /clock were taken as given."""
    import pytest

    from sensorium.cli import build_parser

    parser = build_parser()
    for argv, said in ((["replay", "r.mcap", "--start", "nan"], "argument --start: must be a finite number >= 0, got 'nan'"),
                       (["replay", "r.mcap", "--end", "inf"], "argument --end: must be a finite number >= 0, got 'inf'"),
                       (["replay", "r.mcap", "--clock", "-5"], "argument --clock: must be a finite number > 0, got '-5'"),
                       (["replay", "r.mcap", "--sndhwm", "-1"], "argument --sndhwm: must be an integer >= 0, got '-1'"),
                       (["export", "r.mcap", "out", "--ros2", "--start", "nan"], "argument --start: must be a finite"),
                       (["record", "r.mcap", "--duration", "-1"], "argument --duration: must be a finite number > 0"),
                       (["record", "r.mcap", "--max-messages", "0"], "argument --max-messages: must be an integer >= 1"),
                       (["record", "r.mcap", "--chunk-size", "-1"], "argument --chunk-size: must be an integer >= 1"),
                       (["hz", "/clock", "--window", "-5"], "argument --window: must be an integer >= 1, got '-5'"),
                       (["hz", "/clock", "--every", "0"], "argument --every: must be a finite number > 0, got '0'"),
                       (["hz", "/clock", "--duration", "-1"], "argument --duration: must be a finite number > 0"),
                       (["echo", "/clock", "--count", "0"], "argument --count: must be an integer >= 1, got '0'"),
                       (["echo", "/clock", "--timeout", "-1"], "argument --timeout: must be a finite number > 0"),
                       (["call", "get_info", "--timeout", "nan"], "argument --timeout: must be a finite number > 0"),
                       (["topics", "--timeout", "0"], "argument --timeout: must be a finite number > 0, got '0'"),
                       (["echo", "/clock", "--count", "x"], "argument --count: invalid integer value: 'x'")):
        with pytest.raises(SystemExit) as exc:
            parser.parse_args(argv)
        err = capsys.readouterr().err
        assert exc.value.code == 2 and said in err.strip().splitlines()[-1], (argv, err)
    args = parser.parse_args(["replay", "r.mcap", "--rate", "0", "--start", "1.5", "--clock", "--sndhwm", "0"])
    assert (args.rate, args.start, args.clock, args.sndhwm) == (0.0, 1.5, 40.0, 0)


def test_services_marks_supervisor_only_services_and_replay_shows_arguments(tmp_path):
    import signal

    from _recdata import make_recording
    from _serve import Served, sensorium, serve

    with serve(ROOT / "tests" / "worlds" / "webots_api.yaml", stop_signal=signal.SIGTERM) as s:
        r = run("services", "--url", s.rpc)
        assert r.returncode == 0, r.stderr
        lines = r.stdout.splitlines()
        set_field = [line for line in lines if "/robot/set_field " in line]
        assert set_field and all("[supervisor controller only" in line for line in set_field), set_field
        step = [line for line in lines if "/robot/step " in line]
        assert step and all(line.endswith("[attached controller only]") for line in step), step
    rec = tmp_path / "rec.mcap"
    make_recording(rec, steps=5)
    replay = Served(sensorium("replay", str(rec), "--loop", "--pub", "tcp://127.0.0.1:0", "--rpc", "tcp://127.0.0.1:0",
                              "--no-progress"), "sensorium: replaying")
    with replay.wait_ready() as rp:
        rpc = rp.fields.get("rpc")
        r = run("services", "--url", rpc)
    assert r.returncode == 0, r.stderr
    assert "  /replay/set_rate  {value: float}" in r.stdout.splitlines(), r.stdout


def test_info_names_a_bad_file_once_and_claims_only_the_views_a_recording_has(tmp_path):
    from _recdata import make_recording

    bad = tmp_path / "cut5.mcap"
    bad.write_bytes(b"hello")
    r = run("info", str(bad))
    assert r.returncode == 1 and r.stderr == f"sensorium info: {bad}: not an MCAP file\n"
    missing = run("info", str(tmp_path / "none.mcap"))
    assert missing.returncode == 1 and missing.stderr.count("none.mcap") == 1, missing.stderr
    rec = tmp_path / "rec.mcap"                          # Foxglove-ready (format 2), recorded without a world
    make_recording(rec, steps=5)
    r = run("info", str(rec))
    line = next(line for line in r.stdout.splitlines() if line.startswith("Foxglove:"))
    assert line.split(None, 1)[1] == "ready (ROS 2 CDR views; bodies kept byte for byte)"     # no /tf, no /scene


def test_replay_says_interrupted_after_ctrl_c_not_finished(tmp_path):
    import signal

    from _recdata import make_recording
    from _serve import Served, sensorium

    rec = tmp_path / "rec.mcap"
    make_recording(rec, steps=5)
    replay = Served(sensorium("replay", str(rec), "--loop", "--pub", "tcp://127.0.0.1:0", "--rpc", "tcp://127.0.0.1:0",
                              "--no-progress"), "sensorium: replaying")
    with replay.wait_ready() as rp:
        assert rp.stop(signal.SIGINT) == 0
    lines = rp.stderr().splitlines()
    assert any(line.startswith("sensorium: replay interrupted after ") for line in lines), lines
    assert not any("replay finished" in line for line in lines), lines


def test_step_path_variable_shows_in_version_and_a_bad_one_stops_serve_in_one_line(monkeypatch, capsys):
    """SENSORIUM_STEP_PATH=python: --version said 'C' while the server ran Python; a bad value made
    serve end in a traceback."""
    import pytest

    from sensorium.cli import main

    monkeypatch.setenv("SENSORIUM_STEP_PATH", "python")
    with pytest.raises(SystemExit):
        main(["--version"])
    assert capsys.readouterr().out.splitlines()[1] == "step path: Python (SENSORIUM_STEP_PATH=python)"
    monkeypatch.setenv("SENSORIUM_STEP_PATH", "bogus")
    assert main(["serve", "--rpc", "tcp://127.0.0.1:0", "--pub", "tcp://127.0.0.1:0"]) == 2
    err = capsys.readouterr().err
    assert err == "sensorium serve: SENSORIUM_STEP_PATH / step_path must be one of auto, c, python, got 'bogus'\n"
    from sensorium.server.daemon import steppath

    monkeypatch.setattr(steppath, "_native", (None, "the C step path is not built (no module)"))
    monkeypatch.setenv("SENSORIUM_STEP_PATH", "c")
    assert main(["serve", "--rpc", "tcp://127.0.0.1:0", "--pub", "tcp://127.0.0.1:0"]) == 2
    assert capsys.readouterr().err == "sensorium serve: SENSORIUM_STEP_PATH=c: the C step path is not built (no module)\n"


def test_version_says_which_compiled_paths_are_active(monkeypatch, capsys):
    import pytest

    from sensorium import __version__
    from sensorium.cli import main
    from sensorium.server.daemon import steppath
    from sensorium.server.raycast import packets

    monkeypatch.setattr(packets, "_state", {})
    monkeypatch.setenv("SENSORIUM_PACKETS", "0")
    monkeypatch.setattr(steppath, "_native", (None, "the C step path is not built (no module)"))
    with pytest.raises(SystemExit) as done:
        main(["--version"])
    assert done.value.code == 0
    assert capsys.readouterr().out.splitlines() == [
        f"sensorium {__version__}", "step path: Python (the C step path is not built (no module))",
        "ray traversal: embreex, one ray per call (off (SENSORIUM_PACKETS=0))"]
    # and what this installation has (the C step path: setup.py build_ext; packets.c: a compiler)
    monkeypatch.setattr(packets, "_state", {})
    monkeypatch.delenv("SENSORIUM_PACKETS")
    monkeypatch.setattr(steppath, "_native", None)
    gate, why = steppath.native_gate_class()
    with pytest.raises(SystemExit):
        main(["--version"])
    lines = capsys.readouterr().out.splitlines()
    assert lines[1] == ("step path: C (sensorium.server.daemon._steppath)" if gate is not None else f"step path: Python ({why})")
    assert lines[2] == f"ray traversal: {packets.status()}"


def test_serve_refuses_recording_options_without_a_recording(capsys):
    """--topics, --force and --record-format without --record did nothing, without a word."""
    from sensorium.cli import build_parser
    from sensorium.cli.serve import main

    parser = build_parser()
    for extra, said in ((["--topics", "/clock"], "--topics is for --record FILE, which is not given"),
                        (["--force"], "--force is for --record FILE, which is not given"),
                        (["--record-format", "msgpack", "--topics", "/x"],
                         "--topics and --record-format are for --record FILE, which is not given")):
        args = parser.parse_args(["serve", "arena", "--rpc", "tcp://127.0.0.1:0", "--pub", "tcp://127.0.0.1:0", *extra])
        assert main(args) == 2
        assert capsys.readouterr().err.strip().splitlines() == [f"sensorium serve: {said}"]


def test_a_warning_about_the_users_world_is_one_line(tmp_path):
    """A GroundWarning (a robot over no ground in a world with a terrain) printed by a command is one
    line, ``sensorium: warning: ...``, not Python's form with our source file and code line."""
    import yaml

    ramp = {"name": "ramp", "pose": {"translation": [40.0, 40.0, 0.0]},
            "geometry": {"type": "elevation_grid", "x_dimension": 2, "y_dimension": 2, "x_spacing": 1.0,
                         "y_spacing": 1.0, "height": [0.0, 0.1, 0.0, 0.1]}}
    robot = {"name": "r", "pose": {"translation": [0.0, 0.0, 0.05]},
             "differential_drive": {"wheel_radius": 0.02, "axle_length": 0.05}}
    world = tmp_path / "w.yaml"
    world.write_text(yaml.safe_dump({"solids": [ramp], "robots": [robot]}))
    r = run("probe", str(world))
    lines = r.stderr.splitlines()
    assert lines[0].startswith(f"sensorium: warning: {world}: robot 'r' starts over no ground ("), r.stderr
    assert lines[0].endswith("): it keeps its height, terrains do not lift it"), r.stderr
    assert "GroundWarning" not in r.stderr and ".py:" not in r.stderr


def test_other_libraries_warnings_keep_pythons_form(monkeypatch, capsys):
    import warnings

    from sensorium.cli import one_line_warnings
    from sensorium.server.sim.ground import GroundWarning

    python_form: list[tuple] = []
    monkeypatch.setattr(warnings, "showwarning", lambda *a, **k: python_form.append(a))
    one_line_warnings()
    warnings.showwarning(GroundWarning("over no ground"), GroundWarning, "ground.py", 1)
    warnings.showwarning(DeprecationWarning("a library's own"), DeprecationWarning, "lib.py", 7)
    assert capsys.readouterr().err == "sensorium: warning: over no ground\n"
    assert [(str(m), c, f, n) for m, c, f, n, *_ in python_form] == [("a library's own", DeprecationWarning, "lib.py", 7)]
