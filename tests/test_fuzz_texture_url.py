"""Hypothesis fuzz of a Supervisor's ImageTexture url changes (sans-IO, the supervisor module as the
core calls it): random sequences of setMFString/insertMFString/removeMF with urls of every kind (in
the folder, in a sub-folder, with '..', absolute, a symlink out of the folder, huge and empty
strings, a file that is no image, a PNG declaring a huge size, a file replaced between its check and
its read), interleaved with Material colour sets and simulationReset, on the world of
test_supervisor_texture.py. After every change the camera and the infra-red sensor read what the
world file written with the current first url (and colour) reads, or, when that url's image is not
read (missing, no image, outside the folder), what the world written without url reads, with one line
(Webots' rule), or the change was refused with one line and nothing changed (an image over the limits,
bad input); a reset brings the world file's image back; the images no shape uses are let go (memory
bounded)."""

from __future__ import annotations

import os
import struct
import zlib
from pathlib import Path

import numpy as np
import pytest
from _fuzz import example_counts
from hypothesis import example, given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS
from test_supervisor_texture import WORLD, _images, _shot, _sim, field

from sensorium.server.daemon import supervisor as sv
from sensorium.server.world import textures
from sensorium.server.world.limits import WorldLimits

LIMITS = WorldLimits(texture_pixels=10_000)
GOOD = ["a.png", "b.png", "c.jpg", "sub/d.png", "sub/../b.png", "./a.png"]
BAD = ["nope.png", "notes.png", "bomb.png", "alpha.png", "../outside.png", "out_link.png", "", " ", "\t",
       "x" * 5000, "y/" * 2000, "é" * 100_000, "é.png", "sub", ".", "..", "https://x/a.png", "webots://a.png", "a.png\0", "big.png", "/etc/passwd"]


def _png_header(width: int, height: int) -> bytes:
    """A PNG that declares ``width`` x ``height`` pixels and holds a few bytes (a decompression bomb
    for a reader that trusts it)."""
    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(b"\0" * 64)) + chunk(b"IEND", b"")


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("texfuzz")
    folder = root / "world"
    folder.mkdir()
    _images(folder)
    (folder / "world.wbt").write_text(WORLD)
    (root / "outside.png").write_bytes((folder / "a.png").read_bytes())
    os.symlink(root / "outside.png", folder / "out_link.png")
    (folder / "bomb.png").write_bytes(_png_header(100_000, 100_000))
    (folder / "é.png").write_bytes((folder / "b.png").read_bytes())
    return folder


class References:
    """What the world file written with a url (and the wall's Material colour) reads, one
    simulation per distinct pair."""

    def __init__(self, folder: Path):
        self.folder, self.seen = folder, {}

    def __call__(self, url: str | None, diffuse: tuple[float, float, float] | None):
        key = (url, diffuse)
        if key not in self.seen:
            text = WORLD.replace('"a.png"', "" if url is None else f'"{url}"')
            if diffuse is not None:
                text = text.replace("diffuseColor 0.2 0.4 0.6", "diffuseColor " + " ".join(map(repr, diffuse)))
            path = self.folder / f"ref{len(self.seen)}.wbt"
            path.write_text(text)
            self.seen[key] = _shot(_sim(path, LIMITS))
        return self.seen[key]


url = st.sampled_from(GOOD) | st.sampled_from(BAD) | st.text(max_size=12)
op = st.one_of(
    st.tuples(st.sampled_from(["set", "insert"]), st.integers(-3, 3), url),
    st.tuples(st.just("remove"), st.integers(-3, 3), st.none()),
    st.tuples(st.just("swap"), st.sampled_from(["a.png", "b.png", "c.jpg"]),
              st.sampled_from(["notes.png", "bomb.png", "alpha.png", "out_link.png", "big.png"])),
    st.tuples(st.just("diffuse"), st.sampled_from([(0.1, 0.9, 0.3), (1.0, 1.0, 1.0), (0.2, 0.4, 0.6)]), st.none()),
    st.tuples(st.just("reset"), st.none(), st.none()))


@pytest.mark.parametrize("examples", example_counts(400))
def test_random_url_changes_read_as_the_world_file_with_that_url(folder: Path, monkeypatch, examples: int) -> None:
    refs = References(folder)
    sim = _sim(folder / "world.wbt", LIMITS)
    tex = sv.find_node(sim, "TEX")
    material = sv.node_by_id(sim, field(sim, sv.node_by_id(sim, field(sim, sv.node_by_id(
        sim, field(sim, sv.find_node(sim, "WALL"), "children")[0]), "appearance")), "material"))
    header = textures.image_header
    swap: list[tuple[str, object]] = []

    def header_then_swap(path, display):
        """The header is read from the file as it is; then the file is replaced by another."""
        out = header(path, display)
        for good, bad in list(swap):
            if good != display:
                continue
            target = folder / good
            saved = target.read_bytes()
            target.unlink()
            if bad == "out_link.png":
                os.symlink(os.readlink(folder / "out_link.png"), target)
            else:
                target.write_bytes((folder / str(bad)).read_bytes())
            swap[:] = [("restore", (good, saved))]
        return out

    monkeypatch.setattr(textures, "image_header", header_then_swap)

    @settings(SETTINGS, max_examples=examples)
    @given(st.lists(op, min_size=1, max_size=6))
    @example([("swap", "b.png", "out_link.png")])       # found: the file read after its check, outside the folder
    @example([("swap", "c.jpg", "alpha.png")])
    @example([("set", 0, "x" * 5000)])                    # found: the whole url quoted in the refusal line
    @example([("set", 0, "y/" * 2000)])
    def run(ops):
        sim.reset()
        urls, diffuse = ["a.png"], None
        unread = False                  # the first url's image was not read: the shapes untextured
        for kind, a, b in ops:
            before = (field(sim, tex, "url"), _shot(sim))
            lines: list[str] = []
            try:
                if kind == "reset":
                    sim.reset()
                    urls, diffuse, unread = ["a.png"], None, False
                elif kind == "diffuse":
                    sv.set_field(sim, material, "diffuseColor", list(a))
                    diffuse = a
                elif kind == "swap":
                    if urls[:1] == [a]:
                        continue
                    swap[:] = [(a, b)]
                    try:
                        lines = sv.change_item(sim, tex, "url", "set", 0, a)
                    finally:
                        for kind_, done in swap:
                            if kind_ == "restore":
                                good, saved = done
                                (folder / good).unlink()
                                (folder / good).write_bytes(saved)
                        swap.clear()
                else:
                    lines = sv.change_item(sim, tex, "url", kind, a, b)
                now = field(sim, tex, "url")
                assert len(lines) <= 1 and all("\n" not in x and len(x) < 600 for x in lines), lines
                if lines:
                    assert "drawn without its texture" in lines[0] and now != urls, (lines, now, urls)
                    unread = True
                elif now != urls:      # the list changed and its first url's image (or none) was read
                    unread = False
                urls = now
            except ValueError as exc:
                line = str(exc)
                assert "\n" not in line and len(line) < 600 and "nothing changed" in line, line
                assert field(sim, tex, "url") == before[0]
                got = _shot(sim)
                assert np.array_equal(got[0], before[1][0]) and got[1] == before[1][1], (kind, a, b)
                continue
            first = urls[0] if urls and urls[0].strip() and not unread else None
            want = refs(first, diffuse)
            got = _shot(sim)
            assert np.array_equal(got[0], want[0]) and got[1] == want[1], (kind, a, b, urls, diffuse)
            sampler = sim.scene.textures
            assert len(sampler._images) <= 2, sampler._images.keys()     # the world's a.png and the one shown

    run()
    sim.reset()
    assert field(sim, tex, "url") == ["a.png"]
    assert np.array_equal(_shot(sim)[0], refs("a.png", None)[0])


def test_the_decoded_images_a_supervisor_let_go_are_not_kept(folder: Path) -> None:
    """Cycling through many images keeps no more decoded than the shapes show."""
    from PIL import Image

    rng = np.random.default_rng(3)
    for i in range(40):
        Image.fromarray(rng.integers(0, 256, (50, 50, 3), dtype=np.uint8)).save(folder / f"many{i}.png")
    sim = _sim(folder / "world.wbt", LIMITS)
    tex = sv.find_node(sim, "TEX")
    textures._decode.cache_clear()
    for i in range(40):
        sv.change_item(sim, tex, "url", "set", 0, f"many{i}.png")
        _shot(sim)
    assert textures._decode.cache_info().currsize <= 4


def test_a_world_image_deleted_after_load_still_comes_back_on_reset(tmp_path: Path) -> None:
    """Found: the world's own image was looked for on disk again when a reset brought it back (a
    TextureFileError, no reset); it is held from the load."""
    _images(tmp_path)
    (tmp_path / "world.wbt").write_text(WORLD)
    sim = _sim(tmp_path / "world.wbt", LIMITS)
    first = _shot(sim)
    tex = sv.find_node(sim, "TEX")
    sv.change_item(sim, tex, "url", "set", 0, "b.png")
    (tmp_path / "a.png").unlink()
    sim.reset()
    again = _shot(sim)
    assert np.array_equal(again[0], first[0]) and again[1] == first[1]
    sv.change_item(sim, tex, "url", "set", 0, "c.jpg")      # and a shape holding it is checked without reading it
    (line,) = sv.change_item(sim, tex, "url", "set", 0, "a.png")     # a url set is read now: gone, untextured
    assert "texture file 'a.png' not found" in line and sim.scene.shape_model(0).appearance.texture is None


@pytest.mark.parametrize("examples", example_counts(400))
def test_url_changes_through_the_core_answer_or_refuse_in_one_line(folder: Path, examples: int) -> None:
    """The same changes as a controller sends them (set_field with an index and an op), random
    arguments included: one reply each, a refusal one line and never INTERNAL, the core healthy."""
    from test_fuzz_core import Fuzzed
    from test_fuzz_new_devices import send, values

    f = Fuzzed(str(folder / "world.wbt"))
    [reply] = send(f, "attach", {"robot": "looker"})
    assert reply["ok"], reply
    [reply] = send(f, "/looker/robot/get_from_def", {"name": "TEX"})
    tex = reply["result"]["node"]
    well_formed = st.fixed_dictionaries({"node": st.just(tex), "field": st.just("url"), "value": url,
                                         "index": st.integers(-2, 1), "op": st.sampled_from(["set", "insert"])})
    broken = st.fixed_dictionaries(
        {"node": st.just(tex), "field": st.sampled_from(["url", "repeatS", "filtering"]),
         "value": url | values, "index": st.integers(-3, 3) | values,
         "op": st.sampled_from(["set", "insert", "remove"]) | values},
        optional={"level": st.integers(-2, 2)})
    request = well_formed | well_formed | broken

    done = {True: 0, False: 0}

    @settings(SETTINGS, max_examples=examples)
    @given(st.lists(request | st.just("reset"), min_size=1, max_size=5))
    def run(batch):
        for args in batch:
            if args == "reset":
                [reply] = send(f, "/looker/robot/simulation_reset", {})
                assert reply["ok"], reply
                continue
            [reply] = send(f, "/looker/robot/set_field", args)
            done[reply["ok"]] += 1
            if not reply["ok"]:
                message = reply["error"]["message"]
                assert "\n" not in message and len(message) < 1000, reply
            f.assert_healthy()
        f.steps()
        f.assert_healthy()

    run()
    assert done[True] > 20, done         # (the changes that apply were exercised too)
