"""A Display's size from a C controller (the C library built with AddressSanitizer and UBSan) and
from a Webots Python controller against ``sensorium serve``, for the same robot written as YAML
(tests/worlds/display.yaml) and as .wbt (tests/worlds/display.wbt): wb_display_get_width/height
answer the world's size (Webots' 64 x 64 by default), so the drawing loops of Webots' samples run;
the drawing calls answer like any unsimulated device's (one warning line per Display), image
references are usable, and image_save says once that it writes no file."""

from __future__ import annotations

from pathlib import Path

import pytest
from _serve import run_controller, sensorium
from test_c_client import sanitized_controller

from sensorium.schemas import world as wm
from sensorium.server.world.loader import load_world

REPO = Path(__file__).resolve().parents[1]
CLIB = REPO / "sensorium" / "client" / "c"
WORLDS = [REPO / "tests" / "worlds" / "display.yaml", REPO / "tests" / "worlds" / "display.wbt"]
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=1:exitcode=86", "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"}
EXPECTED = ["screen 320 240", "small 64 64", "properties 320 240", "pixels 1920", "refs 1 1 1", "done"]


@pytest.fixture(scope="module")
def c_controller(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "display_size.c")


def test_both_world_formats_keep_the_display_size() -> None:
    for world in WORLDS:
        devices = load_world(world).world.robots[0].devices
        assert [(type(d), d.name, d.width, d.height) for d in devices] == [
            (wm.Display, "screen", 320, 240), (wm.Display, "small", 64, 64)], world


def test_a_display_size_below_one_is_one_as_in_webots(tmp_path: Path) -> None:
    p = tmp_path / "w.wbt"
    p.write_text('#VRML_SIM R2023b utf8\nRobot { name "r" children [ Display { width 0 height -3 } ] }\n')
    w = load_world(p)
    d = w.world.robots[0].devices[0]
    assert (d.width, d.height) == (1, 1)
    assert any("width" in line for line in w.warnings) and any("height" in line for line in w.warnings)


def _check(lines: list[str], err: str) -> None:
    assert lines == EXPECTED, lines
    warned = [line for line in err.splitlines() if "Sensorium does not simulate Display" in line]
    assert len(warned) == 1 and "'screen'" in warned[0], err       # getWidth/getHeight say nothing
    saved = [line for line in err.splitlines() if "wb_display_image_save()" in line and "not written" in line]
    assert saved == ["Warning: wb_display_image_save(): Display 'screen' draws no image here: 'screen.png' is not "
                     "written."], err


@pytest.mark.parametrize("world", WORLDS, ids=lambda p: p.suffix[1:])
def test_a_python_controller_reads_the_display_size(world: Path) -> None:
    lines, err = run_controller(world, lambda url: sensorium(
        "controller", "--url", url, str(REPO / "tests" / "controllers" / "display_size.py")))
    _check(lines, err)


@pytest.mark.parametrize("world", WORLDS, ids=lambda p: p.suffix[1:])
def test_a_c_controller_reads_the_display_size(world: Path, c_controller: str) -> None:
    lines, err = run_controller(world, lambda url: [c_controller], env=SAN_ENV)
    assert "Sanitizer" not in err and "runtime error" not in err, err
    _check(lines, err)
