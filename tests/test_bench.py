"""Smoke test of ``sensorium bench``: a quick run of one cheap section writes a sane report.
Timings are never asserted (this machine is shared); only that the numbers exist and that the
accuracy results say what the engine guarantees (EXACT is exact, FAST sees the tessellation)."""

from __future__ import annotations

import json
import math

import pytest

from sensorium.cli import main


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench")
    assert main(["bench", "--quick", "--only", "accuracy", "--out", str(out)]) == 0
    return out, json.loads((out / "benchmarks.json").read_text())


def test_json_and_markdown_are_written(report) -> None:
    out, doc = report
    assert doc["schema"] == 1 and doc["quick"] is True
    sec = doc["sections"]["accuracy"]
    ids = {t["id"] for t in sec["tables"]}
    assert {"precision", "distance_rays", "lidar_resolution", "tessellation", "occlusion", "noise", "point_cloud"} <= ids
    for t in sec["tables"]:
        assert t["rows"] and all(len(r) == len(t["columns"]) for r in t["rows"])
    md = (out / "benchmarks.md").read_text()
    assert md.startswith("# Sensorium benchmarks")
    assert "sensorium bench" in md and "## Accuracy vs time" in md
    assert "_fresh" not in (out / "benchmarks.json").read_text()


def test_numbers_are_sane(report) -> None:
    _, doc = report
    data = doc["sections"]["accuracy"]["data"]
    for d in data["precision"]:
        assert d["time_s"] > 0
        if d["mode"] == "exact" and d["offset_m"] <= 1e4:
            assert d["err_max_m"] < 1e-9
    for d in data["tessellation"]:
        if d["mode"] == "exact":
            assert d["err_max_m"] < 1e-9 and d["hit_miss_disagree"] == 0
    coarse = [d for d in data["tessellation"] if d["mode"] == "fast" and d["shape"].startswith("sphere")]
    assert coarse[0]["err_max_m"] > coarse[-1]["err_max_m"] > 0          # finer shells are closer
    rays = data["distance_rays"]
    assert all(math.isfinite(d["abs_err_m"]) and d["step_s"] > 0 for d in rays)
    occl = {d["occlusion"]: d for d in data["occlusion"]}
    assert occl[True]["wrong"] == 0 and occl[False]["wrong"] > 0
    lid = [d for d in data["noise"] if d["device"] == "lidar"]
    for d in lid:                                                          # RMS error follows sigma
        assert d["rmse_m"] < 1e-6 if d["sigma_m"] == 0 else 0.7 < d["rmse_m"] / d["sigma_m"] < 1.3
    pc = {d["point_cloud"]: d for d in data["point_cloud"]}
    assert pc[True]["err_max_m"] < 1e-5 and pc[True]["message_bytes"] > pc[False]["message_bytes"]


def test_plots_when_matplotlib_is_installed(report) -> None:
    pytest.importorskip("matplotlib")
    out, doc = report
    pngs = [out / p for p in doc["plots"].values()]
    assert pngs and all(p.is_file() and p.read_bytes()[:4] == b"\x89PNG" for p in pngs)


def test_a_section_measured_again_keeps_the_headers_run_and_names_its_machine(report, tmp_path) -> None:
    """``--only`` on another machine (or day): the header still says when and where the full run was,
    the section says its own, and a line says the sections' machines differ."""
    out, doc = report
    doc = json.loads(json.dumps(doc))
    doc["generated"], doc["machine"]["cpu"] = "2000-01-01 00:00 UTC", "Elsewhere CPU"
    (tmp_path / "benchmarks.json").write_text(json.dumps(doc))
    assert main(["bench", "--quick", "--only", "accuracy", "--out", str(tmp_path)]) == 0
    again = json.loads((tmp_path / "benchmarks.json").read_text())
    assert (again["generated"], again["machine"]["cpu"]) == ("2000-01-01 00:00 UTC", "Elsewhere CPU")
    cpu = again["sections"]["accuracy"]["machine"]["cpu"]
    assert cpu != "Elsewhere CPU"
    md = (tmp_path / "benchmarks.md").read_text()
    assert "Measured 2000-01-01 00:00 UTC on Elsewhere CPU" in md
    assert "Sections measured again since on another machine: `accuracy` (" in md and f" on {cpu})" in md
