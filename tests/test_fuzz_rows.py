"""Hypothesis fuzz of inline meshes held as arrays (``schemas.world.Rows``): random JSON and Python
triangles (wrong shapes, bools, strings, NaN, huge ints, empty, nested) validate into a ``Triangles``
exactly as the plain list types did (the same values, or the same errors: path, words, kind), and a
.wbt IndexedFaceSet's runs of odd tokens (1e400, -0, hex, commas, missing -1s) give the same world or
the same one-line error as reading the numbers one at a time."""

from __future__ import annotations

import json
import math
import tempfile
from pathlib import Path
from typing import Annotated, Any, Literal

import pytest
from _fuzz import example_counts
from hypothesis import given, settings
from hypothesis import strategies as st
from pydantic import Field, ValidationError
from test_fuzz_core import SETTINGS

from sensorium.schemas import world as wm
from sensorium.server.world.loader import WorldError, load_world
from sensorium.server.world.wbt import parser as wp


class PlainTriangles(wm.Strict):
    """Triangles as they were before Rows: the same list types and bounds, no arrays."""

    type: Literal["triangles"]
    vertices: Annotated[list[wm.Vec3], Field(max_length=1_000_000)]
    faces: Annotated[list[tuple[int, int, int]], Field(min_length=1, max_length=2_000_000)]
    tex_coords: Annotated[list[tuple[float, float]], Field(max_length=1_000_000)] | None = None
    tex_coord_faces: Annotated[list[tuple[int, int, int]], Field(max_length=2_000_000)] | None = None


ODD = [True, False, None, "1", "1.5", "x", "", "nan", "inf", "-0", math.nan, math.inf, -math.inf, -0.0, 0, -1,
       2 ** 31, 2 ** 63 - 1, 2 ** 63, -(2 ** 63) - 1, 2 ** 64, 10 ** 30, 10 ** 400, 1e308, 5e-324, 0.5, 1.0, 3.0,
       [], [1], {}, {"a": 1}]
scalar = st.sampled_from(ODD) | st.integers(-5, 5) | st.floats(-1e3, 1e3, allow_nan=False)
row = st.lists(scalar, min_size=0, max_size=4) | st.tuples(scalar, scalar, scalar) | st.lists(st.integers(0, 3),
                                                                                               min_size=3, max_size=3)
rows = st.lists(row, max_size=5) | st.sampled_from([[], None, "abc", 3, {}, [[[0, 1, 2]]], [[0, 1, 2], 7]]) | row


def _outcome(model: type, data: Any, as_json: bool) -> tuple[str, Any]:
    try:
        if as_json:
            got = model.model_validate_json(json.dumps(data, allow_nan=True))
        else:
            got = model.model_validate(data)
    except ValidationError as exc:
        return "error", [(e["loc"], e["msg"], e["type"]) for e in exc.errors()]
    except ValueError as exc:      # (json.dumps of a number JSON cannot hold)
        return "unwritable", str(exc)
    out = {}
    for name in ("vertices", "faces", "tex_coords", "tex_coord_faces"):
        v = getattr(got, name)
        out[name] = None if v is None else [tuple(r) for r in v]
    return "ok", out


@pytest.mark.parametrize("examples", example_counts(400))
def test_rows_validate_as_the_plain_lists_did(examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(st.fixed_dictionaries({"type": st.just("triangles"), "vertices": rows, "faces": rows},
                                 optional={"tex_coords": rows, "tex_coord_faces": rows}),
           st.booleans())
    def run(data, as_json) -> None:
        _rows_validate_as_the_plain_lists_did(data, as_json)

    run()


def _rows_validate_as_the_plain_lists_did(data, as_json) -> None:
    want = _outcome(PlainTriangles, data, as_json)
    got = _outcome(wm.Triangles, data, as_json)
    assert got == want, (data, as_json)


def test_rows_keep_values_bit_for_bit() -> None:
    data = {"type": "triangles", "vertices": [[-0.0, 5e-324, 1e308], [1, 2 ** 62 + 1, 3]], "faces": [[0, 1, 1]]}
    t = wm.Triangles.model_validate(data)
    assert math.copysign(1.0, t.vertices[0][0]) == -1.0
    assert t.vertices == [(-0.0, 5e-324, 1e308), (1.0, float(2 ** 62 + 1), 3.0)]


# ---------------------------------------------------------------- .wbt runs of odd tokens

TOKENS = ["0", "1", "2", "-1", "-0", "1e400", "-1e400", "0x10", "1,", ",", "1.5", "+2", ".5", "5.", "1e-400",
          "3", "nan", "inf", "1e", "--1", "0.0", "2e0", "07"]


def _world(points: list[str], index: list[str], tex: list[str] | None = None) -> str:
    uv = "" if tex is None else ("  texCoord TextureCoordinate { point [ " + " ".join(tex[: len(tex) // 2 * 2])
                                 + " ] }\n  texCoordIndex [ " + " ".join(index) + " ]\n")
    return ('#VRML_SIM R2023b utf8\nRobot { name "r" children [ Shape { geometry IndexedFaceSet {\n'
            "  coord Coordinate { point [ " + " ".join(points) + " ] }\n  coordIndex [ " + " ".join(index)
            + " ]\n" + uv + "} } ] }\n")


def _read(text: str, folder: Path) -> tuple[str, Any]:
    """The world's mesh, loaded whole (parsed, converted, validated), or its one-line error."""
    path = folder / "w.wbt"
    path.write_text(text)
    try:
        world = load_world(path).world
    except WorldError as exc:
        assert "Traceback" not in str(exc)
        return "error", str(exc)
    g = world.robots[0].shapes[0].geometry if world.robots[0].shapes else None
    if g is None:
        return "ok", None
    return "ok", tuple(None if v is None else [tuple(r) for r in v]
                       for v in (g.vertices, g.faces, g.tex_coords, g.tex_coord_faces))


@pytest.mark.parametrize("examples", example_counts(400))
def test_wbt_runs_read_as_one_number_at_a_time(examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(st.lists(st.sampled_from(TOKENS), min_size=0, max_size=40), st.lists(st.sampled_from(TOKENS), max_size=40),
           st.integers(1, 3), st.none() | st.lists(st.sampled_from(TOKENS), max_size=30))
    def run(points, index, run_min, tex) -> None:
        _wbt_runs_read_as_one_number_at_a_time(points, index, run_min, tex)

    run()


def _wbt_runs_read_as_one_number_at_a_time(points, index, run_min, tex) -> None:
    text = _world(points * 3, index * 2, None if tex is None else tex * 2)
    with tempfile.TemporaryDirectory() as tmp, pytest.MonkeyPatch.context() as mp:
        mp.setattr(wp, "RUN_MIN", run_min)
        runs = _read(text, Path(tmp))
        mp.setattr(wp, "RUN_MIN", 10 ** 12)
        single = _read(text, Path(tmp))
    assert runs == single, text
