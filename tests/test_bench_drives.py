"""The drives benchmark (sensorium/benchmarks/drives.py) runs every kind and says what it measured; its
figures are the README's. No timing is asserted here."""

from __future__ import annotations

import pytest

from sensorium.benchmarks import drives


def test_every_kind_steps_and_is_reported(capsys: pytest.CaptureFixture[str]) -> None:
    assert drives.main(["--copies", "2", "--steps", "8", "--rounds", "1"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("2 copies, 8 basic steps a round")
    assert [line[:22].strip() for line in lines[1:]] == list(drives.KINDS)
    assert all("copy-steps/CPU s" in line and " drive " in line for line in lines[1:])


def test_a_kind_that_does_not_exist_is_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        drives.main(["--only", "hovercraft"])
    assert exc.value.code == 2
    assert "unknown kind 'hovercraft'" in capsys.readouterr().err.splitlines()[-1]
