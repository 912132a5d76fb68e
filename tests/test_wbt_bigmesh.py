"""Big inline meshes (IndexedFaceSets of tens of thousands of numbers, as the PROTOs of TIAGo, UR
arms or humanoids carry): read as runs of numbers in one go, checked per list instead of per number,
with the same values, the same converted world and the same one-line errors (file, line, column,
path) as a number-by-number reading gives."""

from __future__ import annotations

import random
from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.world import limits as lim
from sensorium.server.world.limits import ProtoLimits, WorldLimits
from sensorium.server.world.loader import WorldError, load_world, parse_world
from sensorium.server.world.wbt import parser as wp
from sensorium.server.world.wbt import wbt_convert
from sensorium.server.world.wbt.convert import EAR_CLIP_WORLD, fan_corners, polygon_corners
from sensorium.server.world.wbt.parser import Tokens, WbtSyntaxError, parse_wbt

HEADER = "#VRML_SIM R2023b utf8\n"
PER_LINE = 12


def numbers(n: int, seed: int = 1) -> list[str]:
    rng = random.Random(seed)
    return [f"{rng.uniform(-1, 1):.6f}" for _ in range(n)]


def lines_of(words: list[str], indent: str = "      ") -> str:
    return "\n".join(indent + " ".join(words[i:i + PER_LINE]) for i in range(0, len(words), PER_LINE))


def mesh_world(points: list[str], index: list[str], scale: str = "1 1 1") -> str:
    return (HEADER + 'Robot { name "r" children [ Transform { scale ' + scale + " children [ Shape { geometry "
            "IndexedFaceSet {\n  coord Coordinate { point [\n" + lines_of(points) + "\n  ] }\n  coordIndex [\n"
            + lines_of(index) + "\n  ]\n} } ] } ] }\n")


def position(text: str, marker: str) -> tuple[int, int]:
    """1-based (line, column) of the first ``marker`` in ``text``."""
    at = text.index(marker)
    return text.count("\n", 0, at) + 1, at - (text.rfind("\n", 0, at) + 1) + 1


def syntax_error(text: str) -> WbtSyntaxError:
    with pytest.raises(WbtSyntaxError) as info:
        parse_wbt(text, "w.wbt")
    return info.value


def one_at_a_time(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every number its own token (the reading before runs): what a run must match."""
    monkeypatch.setattr(wp, "RUN_MIN", 10 ** 12)


# ------------------------------------------------------------------ the tokenizer


def test_a_big_run_of_numbers_is_one_token_with_the_same_values() -> None:
    words = numbers(50_000)
    text = HEADER + "Coordinate { point [ " + lines_of(words) + " ] }\n"
    toks = Tokens(text, "w.wbt")
    toks.get(10 ** 9)
    assert len(toks.items) < 20                     # not a token per number
    wbt = parse_wbt(text, "w.wbt")
    assert wbt.nodes[0].fields["point"] == [float(w) for w in words]


@pytest.mark.parametrize("bad, message", [
    ("nan", "number 'nan' is not finite (a world's numbers must be finite)"),
    ("-Infinity", "number '-Infinity' is not finite (a world's numbers must be finite)"),
    ("1e999", "number '1e999' is out of range (beyond ±1.8e308)"),
    ("abc", "expected '{' after node type abc, found "),
])
def test_a_bad_number_deep_in_a_50k_list_is_named_at_its_line_and_column(bad: str, message: str) -> None:
    words = numbers(50_000)
    words[37_123] = bad
    text = HEADER + "Coordinate { point [\n" + lines_of(words) + "\n] }\n"
    exc = syntax_error(text)
    line, col = position(text, " " + bad + " ")
    if bad == "abc":                                   # a node type: the error is at the number after it
        col += len(bad) + 1
    assert (exc.line, exc.col) == (line, col + 1)
    assert exc.line == 3 + 37_123 // PER_LINE            # header, "Coordinate {", then 12 a line
    assert exc.message.startswith(message)
    assert "\n" not in str(exc) and len(str(exc)) < 200


def test_runs_read_exactly_as_one_number_at_a_time(monkeypatch: pytest.MonkeyPatch) -> None:
    """Random texts of numbers with the odd ones in (hex, signs, exponents, commas, comments, words
    glued to numbers, non-finite spellings): the same tree or the same error either way."""
    rng = random.Random(7)
    odd = ["0x1F", "-0X0a", "+.5", "5.", "-3e-2", "1E+3", ",", ",,", "# note 1 2\n", "1.5.3", "7-8", "3e", "1e999",
           "nan", "-inf", "Inf", "abc", "TRUE", "]", "[", "1_0", "'", "2\t", "\n", "\u0663", "1\u0663", "\u00a0",
           "5\u00e9", "e5", ".e1", "1e", "+", ".", "1.2e+"]

    def read(text: str) -> object:
        try:
            wbt = parse_wbt(text, "w.wbt")
        except WbtSyntaxError as exc:
            return str(exc)
        return [(n.type, n.fields) for n in wbt.nodes]

    for trial in range(300):
        words = numbers(rng.randrange(10, 200), seed=trial)
        for _ in range(rng.randrange(0, 4)):
            words.insert(rng.randrange(len(words) + 1), rng.choice(odd))
        sep = rng.choice([" ", ", ", "\n", " ,\t"])
        body = sep.join(words)
        text = HEADER + rng.choice([f"Shape {{ a [ {body} ] }}\n", f"Shape {{ a {body} }}\n",
                                    f"Shape {{ a [ {body} ] b [ 1 2 ] }}\n"])
        fast = read(text)
        with monkeypatch.context() as m:
            one_at_a_time(m)
            slow = read(text)
        assert fast == slow, text[:300]


def test_hex_numbers_in_a_long_run_keep_their_values() -> None:
    words = numbers(40)
    words[20] = "0x10"
    wbt = parse_wbt(HEADER + "Coordinate { point [ " + " ".join(words) + " ] }\n", "w.wbt")
    assert wbt.nodes[0].fields["point"][20] == 16.0
    assert len(wbt.nodes[0].fields["point"]) == 40


def test_the_value_bound_names_the_number_that_passes_it(monkeypatch: pytest.MonkeyPatch) -> None:
    words = numbers(50_000)
    text = HEADER + "Coordinate { point [\n" + lines_of(words) + "\n] }\n"
    limits = ProtoLimits(values=40_000)

    def refused() -> WbtSyntaxError:
        with pytest.raises(WbtSyntaxError) as info:
            parse_wbt(text, "w.wbt", limits)
        return info.value

    exc = refused()
    assert exc.message == "more than 40,000 values once DEF/USE copies are counted (raise the limits with --allow-large)"
    assert exc.line == 3 + 40_000 // PER_LINE          # the 40,001st number
    assert exc.col == 1 + len("      ") + sum(len(w) + 1 for w in words[40_000 - 40_000 % PER_LINE:40_000])
    with monkeypatch.context() as m:
        one_at_a_time(m)
        assert str(refused()) == str(exc)


# ------------------------------------------------------------------ conversion


def fan(index: list[int]) -> list[list[int]]:
    """Fan triangulation written out (first, k, k + 1 of each polygon between -1s)."""
    out, poly = [], []
    for i in [*index, -1]:
        if i >= 0:
            poly.append(i)
            continue
        out += [[poly[0], poly[k], poly[k + 1]] for k in range(1, len(poly) - 1)]
        poly = []
    return out


def test_fan_corners_match_the_fan_triangulation() -> None:
    rng = random.Random(3)
    for _ in range(200):
        index: list[int] = []
        for _ in range(rng.randrange(0, 30)):
            index += [rng.randrange(1000) for _ in range(rng.randrange(0, 7))] + [-1] * rng.randrange(1, 3)
        if rng.random() < 0.5 and index:
            index.pop()                                   # no -1 after the last polygon
        corners = fan_corners(index).tolist()
        assert [[index[c] for c in tri] for tri in corners] == fan(index)


def test_a_big_mesh_converts_to_its_points_and_triangles(tmp_path: Path) -> None:
    """Quads, pentagons and triangles, under a uniform scale of 2: each vertex exactly twice its
    point, each face its triangulation (the fan, concave polygons cut along their diagonals:
    test_wbt_polygons.py)."""
    rng = random.Random(5)
    n = 20_000
    pts = numbers(3 * n)
    index: list[int] = []
    while len(index) < 60_000:
        index += [rng.randrange(n) for _ in range(rng.choice([3, 4, 5]))] + [-1]
    p = tmp_path / "w.wbt"
    p.write_text(mesh_world(pts, [str(i) for i in index], scale="2 2 2"))
    conv = wbt_convert(p)
    geom = conv.data["robots"][0]["shapes"][0]["geometry"]
    assert geom["type"] == "triangles"
    assert isinstance(geom["vertices"], np.ndarray) and isinstance(geom["faces"], np.ndarray)    # compact, as converted
    geom = {**geom, "vertices": geom["vertices"].tolist(), "faces": geom["faces"].tolist()}
    assert geom["vertices"] == [[float(pts[i]) * 2.0, float(pts[i + 1]) * 2.0, float(pts[i + 2]) * 2.0]
                                for i in range(0, 3 * n, 3)]
    corners, _ = polygon_corners(index, [float(x) for x in pts], [EAR_CLIP_WORLD])
    assert geom["faces"] == [[index[c] for c in tri] for tri in corners.tolist()]
    assert len(geom["faces"]) == len(fan(index)) and geom["faces"] != fan(index)   # random polygons: some concave
    assert all(type(x) is int for f in geom["faces"][:100] for x in f)
    loaded = load_world(p)
    tri = loaded.world.robots[0].shapes[0].geometry
    assert isinstance(tri, wm.Triangles) and len(tri.vertices) == n and len(tri.faces) == len(fan(index))


# ------------------------------------------------------------------ the world's limits


def big_triangles(n: int = 20_000) -> dict:
    pts = [float(x) for x in numbers(3 * n)]
    return {"type": "triangles", "vertices": [pts[i:i + 3] for i in range(0, 3 * n, 3)],
            "faces": [[i, (i + 1) % n, (i + 2) % n] for i in range(n)]}


def world_with(geometry: dict) -> dict:
    return {"robots": [{"name": "r", "shapes": [{"geometry": geometry}]}]}


@pytest.mark.parametrize("bad, message", [
    (1e12, "the magnitude of 1e+12 exceeds the limit of 1e+09 (raise the limits with --allow-large)"),
    (1e-40, "1e-40 is too close to 0 (use 0, or a magnitude of at least 1e-30)"),
    (float("nan"), "expected a finite number, got nan"),
    (True, "expected a number, got True"),
])
def test_a_bad_vertex_deep_in_a_big_mesh_is_refused_at_its_path(bad: object, message: str) -> None:
    geom = big_triangles()
    geom["vertices"][13_333][1] = bad
    with pytest.raises(WorldError) as info:
        parse_world(world_with(geom))
    problems = [(p.path, p.message) for p in info.value.problems]
    path = "robots[0].shapes[0].geometry.vertices" + ("" if bad is True else "[13333][1]")
    assert [(pp, m) for pp, m in problems if m == message] and all(pp.startswith(path) for pp, _ in problems)


def test_every_bad_vertex_is_listed_in_file_order() -> None:
    geom = big_triangles()
    for i in (19_000, 7, 12_345):
        geom["vertices"][i][2] = 5e9
    with pytest.raises(WorldError) as info:
        parse_world(world_with(geom))
    assert [p.path for p in info.value.problems] == [f"robots[0].shapes[0].geometry.vertices[{i}][2]"
                                                    for i in (7, 12_345, 19_000)]


def test_the_world_value_bound_counts_every_number_of_a_big_mesh(monkeypatch: pytest.MonkeyPatch) -> None:
    data = world_with(big_triangles())
    mesh = 2 * (1 + 20_000 + 60_000)    # each list, its rows and their numbers

    def bound() -> int:
        """The least value bound the world passes."""
        for extra in range(40):
            try:
                lim.check_data(data, WorldLimits(values=mesh + extra))
            except lim.LimitError as exc:
                assert exc.message == f"more than {mesh + extra} values (raise the limits with --allow-large)"
                continue
            return mesh + extra
        raise AssertionError("no bound passes")

    fast = bound()
    monkeypatch.setattr(lim, "BLOCK_MIN", 10 ** 12)       # every value walked one at a time
    assert bound() == fast
    with pytest.raises(WorldError, match=f"more than {fast - 1} values"):
        parse_world(data, limits=WorldLimits(values=fast - 1))


def test_the_work_checks_skip_a_meshs_numbers_without_walking_them() -> None:
    world = parse_world(world_with(big_triangles())).world
    assert sum(1 for _ in lim._walk(world)) < 100
    assert sum(1 for _ in lim._walk(world, numbers=True)) > 160_000


def test_an_inline_mesh_is_held_as_arrays_in_the_model(tmp_path: Path) -> None:
    """A .wbt IndexedFaceSet's points and faces, and a JSON world's inline triangles, are held by the
    validated model as one read-only float64 / int64 array each (``wm.Rows``), not lists of Python
    numbers; the scene's mesh takes those arrays without a copy; the model still reads as the lists
    of tuples it stands for and writes numbers."""
    pts = numbers(3 * 40, seed=11)
    index = [str(i) for k in range(38) for i in (0, k + 1, k + 2, -1)]
    p = tmp_path / "w.wbt"
    p.write_text(mesh_world(pts, index))
    g = load_world(p).world.robots[0].shapes[0].geometry
    assert isinstance(g, wm.Triangles) and isinstance(g.vertices, wm.Rows) and isinstance(g.faces, wm.Rows)
    v, f = g.vertices.array, g.faces.array
    assert (v.dtype, v.shape, f.dtype, f.shape) == (np.float64, (40, 3), np.int64, (38, 3))
    assert not v.flags.writeable and not f.flags.writeable
    assert v.tolist() == [[float(x) for x in pts[i:i + 3]] for i in range(0, len(pts), 3)]
    assert f.tolist() == [[0, k + 1, k + 2] for k in range(38)]
    assert np.asarray(g.vertices) is v and np.asarray(g.faces, dtype=np.int64) is f     # no copy
    assert g.vertices[1] == tuple(float(x) for x in pts[3:6]) and list(g.faces)[0] == (0, 1, 2)
    assert g.model_dump(mode="json")["faces"][:2] == [[0, 1, 2], [0, 2, 3]]
    from sensorium.server.world.geometry import Mesh

    mesh = Mesh(vertices=g.vertices, faces=g.faces, closed=False)
    assert np.shares_memory(mesh.vertices, v) and np.shares_memory(mesh.faces, f)
    data = {"robots": [{"name": "r", "shapes": [{"geometry": {"type": "triangles", "vertices": v.tolist(),
                                                              "faces": f.tolist()}}]}]}
    h = parse_world(data).world.robots[0].shapes[0].geometry
    assert isinstance(h.vertices, wm.Rows) and h.vertices == g.vertices and h.faces == g.faces
    assert h == g and hash(h) == hash(g)
    uv = [[k / 40, 1 - k / 40] for k in range(40)]
    data["robots"][0]["shapes"][0]["geometry"].update(tex_coords=uv, tex_coord_faces=f.tolist())
    t = parse_world(data).world.robots[0].shapes[0].geometry
    assert isinstance(t.tex_coords, wm.Rows) and isinstance(t.tex_coord_faces, wm.Rows)
    assert t.tex_coords.array.dtype == np.float64 and t.tex_coords.tolist() == uv and t.tex_coord_faces == t.faces
