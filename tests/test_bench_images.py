"""Smoke test of ``sensorium bench --only images`` (issue 23): its tables are written, every device's
image is timed beside raw embreex on the same rays, and the counters show that only the enabled
device casts (timings are never asserted: this machine is shared)."""

from __future__ import annotations

import json

import pytest

from sensorium.cli import main

pytestmark = pytest.mark.slow


def test_images_section(tmp_path):
    pytest.importorskip("embreex")
    assert main(["bench", "--quick", "--only", "images", "--out", str(tmp_path)]) == 0
    sec = json.loads((tmp_path / "benchmarks.json").read_text())["sections"]["images"]
    tables = {t["id"]: t for t in sec["tables"]}
    assert set(tables) == {"images_time", "images_split", "images_counters", "images_fog"}
    assert [r[0] for r in tables["images_fog"]["rows"]] == ["no fog", "LINEAR", "EXPONENTIAL", "EXPONENTIAL2"]
    assert all(v > 0 for v in sec["data"]["fog"].values())
    for prec in ("fast", "exact"):
        for label, pixels in (("e-puck camera 52×39", 2028), ("camera 640×480", 307200), ("range finder 320×240", 76800)):
            d = sec["data"][prec][label]
            assert d["pixels"] == pixels and d["step_s"] > 0 and d["raw_embreex_s"] > 0
    counters = {(r[0], r[1]): r[2:] for r in tables["images_counters"]["rows"]}
    assert counters[("exact", "none enabled (2 steps)")] == ["0", "0", "0"]
    assert counters[("exact", "camera 640×480 enabled (1 step)")] == ["307200", "0", "307200"]
    assert counters[("fast", "range finder 320×240 enabled (1 step)")] == ["0", "76800", "76800"]
    assert "## Images: cameras and range finders" in (tmp_path / "benchmarks.md").read_text()
