"""Hypothesis fuzz of CadShape files: mutations of our own COLLADA cube (truncated, random bytes,
huge or negative counts and strides, indices out of range, NaN/inf/overflowing coordinates, units and
matrices, deep nesting, entity tricks, broken references) and of an OBJ file's .mtl materials are
read by ``read_cad``; each is either read, with finite vertices and faces inside its vertex list, or
refused with one line (CadError), with nothing else printed (no numpy warnings) and quickly; through
``sensorium validate`` the same file is one problem line and exit 1, never a traceback."""

from __future__ import annotations

import itertools
import math
import re
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from test_dae import CORNERS, CUBE, cube_dae, dae

from sensorium.cli import main
from sensorium.server.world.cad import CadError, read_cad

FUZZ = settings(max_examples=150, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
GOOD = cube_dae("Y_UP", 0.01)
_names = itertools.count()

SNIPPETS = [' count="99999999999"', ' count="-3"', ' stride="0"', ' offset="7"', "nan ", "inf ", "-inf ", "1e39 ",
            "3.4e38 ", "-0 ", "99999999999999999999 ", "-1 ", "<node>", "</node>", "<p>", "</p>", '<?xml?>', "&amp;",
            "&e;", "&#0;", "&#xD800;", "]]>", "<![CDATA[", '<instance_node url="#n"/>', '<instance_geometry url="#g"/>',
            '<instance_geometry url="#nowhere"/>', '<input semantic="VERTEX" source="#p" offset="0"/>',
            '<unit meter="1e-320"/>', "<up_axis>W_UP</up_axis>", "<matrix>1 0 0 0 0 1 0 0 0 0 1 0</matrix>",
            '<!DOCTYPE COLLADA [<!ENTITY e "x">]>', "\x00", "\ufeff", "\udcff"]
INSIDE = ["<float_array", "<p>", "<triangles", "<accessor", "<node", "<unit", "<asset>", "<instance_geometry",
          "<COLLADA", "</mesh>", "<source", "<vertices"]


@st.composite
def damaged_dae(draw) -> bytes:
    text = GOOD
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(st.integers(0, 5))
        if kind == 0:
            text = text[: draw(st.integers(0, len(text)))]
        elif kind == 1:
            at = draw(st.integers(0, len(text)))
            text = text[:at] + draw(st.sampled_from(SNIPPETS)) + text[at:]
        elif kind == 2:          # a snippet right after a chosen element's name
            tag = draw(st.sampled_from(INSIDE))
            at = text.find(tag)
            if at >= 0:
                at += len(tag) + (0 if tag.endswith(">") else 0)
                text = text[:at] + draw(st.sampled_from(SNIPPETS)) + text[at:]
        elif kind == 3:          # a number replaced
            spans = [m.span() for m in re.finditer(r"-?[0-9][0-9.e+-]*", text)]
            if spans:
                a, b = draw(st.sampled_from(spans))
                text = text[:a] + draw(st.sampled_from(["nan", "inf", "-1", "1e39", "0", "99999999999", "1e-400",
                                                        "0x10", "", "1 2"])) + text[b:]
        elif kind == 4:          # nodes nested deeply
            depth = draw(st.sampled_from([10, 1000, 20000]))
            text = text.replace('<node id="n">', "<node>" * depth + '<node id="n">', 1).replace(
                "</node>", "</node>" * (depth + 1), 1)
        else:
            raw = bytearray(text.encode("utf-8", "surrogatepass"))
            for _ in range(draw(st.integers(1, 8)) if raw else 0):
                raw[draw(st.integers(0, len(raw) - 1))] = draw(st.integers(0, 255))
            return bytes(raw)
    return text.encode("utf-8", "surrogatepass")


def _read_one(path: Path, kind: str, capsys) -> None:
    start = time.monotonic()
    with warnings.catch_warnings():
        warnings.simplefilter("error")            # a warning escaping the reader fails the test
        try:
            got = read_cad(str(path), kind)
        except CadError as exc:
            message = str(exc)
            assert message and "\n" not in message and len(message) < 400, message
        else:
            for part in got.parts:
                assert np.isfinite(part.vertices).all()
                assert part.faces.min() >= 0 and part.faces.max() < len(part.vertices)
                if part.uv is not None:
                    assert part.uv.shape == (*part.faces.shape, 2)
            for m in got.materials:
                assert all(0.0 <= c <= 1.0 for c in m.diffuse) and 0.0 <= m.transparency <= 1.0
    assert time.monotonic() - start < 30
    out = capsys.readouterr()
    assert out.out == "" and out.err == "", out


@FUZZ
@given(data=damaged_dae())
@example(data=dae(CORNERS * math.nan, [("m", CUBE)]).encode())
@example(data=GOOD.replace('count="24">', 'count="24">nan ', 1).replace("nan -", "nan ", 1).encode())
def test_damaged_dae_is_read_or_one_line(tmp_path, capsys, data: bytes) -> None:
    p = tmp_path / f"c{next(_names)}.dae"
    p.write_bytes(data)
    _read_one(p, "dae", capsys)


def test_nan_positions_are_refused_not_read_as_zero(tmp_path) -> None:
    """pycollada reads 'nan' in a float_array as 0: the cube's corners would silently move to the origin."""
    p = tmp_path / "nan.dae"
    p.write_text(dae(np.where(CORNERS == 1, math.nan, CORNERS), [("m", CUBE)]))
    with pytest.raises(CadError, match=r"^geometry 'body': non-finite vertex coordinates$"):
        read_cad(str(p), "dae")


def test_overflowing_dae_coordinates_say_one_line_without_numpy_warnings(tmp_path, capsys) -> None:
    (tmp_path / "big.dae").write_text(dae(CORNERS * 1e300, [("m", CUBE)]))
    (tmp_path / "w.wbt").write_text('#VRML_SIM R2023b utf8\nSolid { children [ CadShape { url [ "big.dae" ] } ] }\n')
    assert main(["validate", str(tmp_path / "w.wbt")]) == 1
    err = capsys.readouterr().err
    assert "Warning" not in err and len(err.splitlines()) == 2, err
    assert "cannot read COLLADA mesh big.dae: geometry 'body': non-finite vertex coordinates" in err


def test_nodes_nested_too_deeply_say_so(tmp_path) -> None:
    p = tmp_path / "deep.dae"
    p.write_text(GOOD.replace('<node id="n">', "<node>" * 100000 + '<node id="n">', 1)
                 .replace("</node>", "</node>" * 100001, 1))
    with pytest.raises(CadError, match=r"^its elements are nested too deeply$"):
        read_cad(str(p), "dae")


@settings(FUZZ, max_examples=10)
@given(data=damaged_dae())
def test_validate_says_one_problem_line_never_a_traceback(tmp_path, capsys, data: bytes) -> None:
    name = f"v{next(_names)}.dae"
    (tmp_path / name).write_bytes(data)
    (tmp_path / "w.wbt").write_text(f'#VRML_SIM R2023b utf8\nSolid {{ children [ CadShape {{ url [ "{name}" ] }} ] }}\n')
    code = main(["validate", str(tmp_path / "w.wbt")])
    err = capsys.readouterr().err
    assert "Traceback" not in err and "Warning" not in err
    assert code in (0, 1) and (code == 0) == (err == ""), err
    if code:
        assert len(err.splitlines()) == 2, err


OBJ = ("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\nf 1/1 2/2 3/3\n"
       "usemtl b\nf 2/2 4/1 3/3\n")
MTL_WORDS = ["newmtl", "Kd", "d", "Tr", "map_Kd", "-s", "a", "b", "nan", "inf", "-inf", "1e400", "-1", "2", "0.5", "x",
             "..", "/etc/passwd", "\\", "\t", "#", "\x00", "\udcff", "newmtl a", "Kd 1 0"]


@FUZZ
@given(mtl=st.lists(st.lists(st.sampled_from(MTL_WORDS), max_size=5).map(" ".join), max_size=12).map("\n".join),
       obj_cut=st.integers(0, len(OBJ)), faces=st.sampled_from(["", "f 1 2 9\n", "f -1 -2 -3\n", "f 0 1 2\n",
                                                              "v nan 0 0\nf 1 2 5\n", "v 1e400 0 0\nf 5 1 2\n",
                                                              "usemtl \nf 1 2 3\n", "mtllib ../m.mtl m.mtl\n"]))
def test_damaged_obj_and_mtl_are_read_or_one_line(tmp_path, capsys, mtl: str, obj_cut: int, faces: str) -> None:
    n = next(_names)
    (tmp_path / "m.mtl").write_bytes(mtl.encode("utf-8", "surrogatepass"))
    p = tmp_path / f"o{n}.obj"
    p.write_text(OBJ[:obj_cut] + "\n" + faces)
    _read_one(p, "obj", capsys)
