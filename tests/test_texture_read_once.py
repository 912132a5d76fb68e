"""A world's texture files are read once, when the world is checked, and the images that check read
are the ones sensors see: a file replaced between the check and the scene (its colours, its alpha)
cannot slip through unchecked (world/textures.py ``check_textures`` → ``LoadedWorld.textures`` →
the scene's sampler)."""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import numpy as np

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world import textures
from sensorium.server.world.loader import load_world

WORLD = {
    "world_info": {"basic_time_step": 16},
    "lights": [{"type": "PointLight", "location": [0.3, 0.0, 0.05], "intensity": 1.0, "ambient_intensity": 0.3,
                "cast_shadows": True}],
    "solids": [
        {"name": "wall", "pose": {"translation": [2.0, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.1, 20, 20]},
         "appearance": {"texture": {"url": "wall.png"}}},
        # the same file under another url, and an image whose pixel format has alpha (no shadow from it)
        {"name": "post", "pose": {"translation": [1.5, 0.6, 0.0]}, "geometry": {"type": "box", "size": [0.1, 0.2, 0.2]},
         "appearance": {"texture": {"url": "./wall.png"}}},
        {"name": "block", "pose": {"translation": [1.0, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.1, 0.4, 0.4]},
         "appearance": {"texture": {"url": "leaf.png"}}}],
    "robots": [{"name": "r", "devices": [
        {"device": "Camera", "name": "cam", "width": 24, "height": 18, "field_of_view": 1.2},
        {"device": "DistanceSensor", "name": "ir", "type": "infra-red", "pose": {"rotation": [0, 0, 1, 0.3]},
         "lookup_table": [[0, 0, 0], [10, 1000, 0]]}]}]}


def _images(folder: Path, replaced: bool) -> None:
    from PIL import Image

    if not replaced:
        Image.fromarray(np.arange(48, dtype=np.uint8).reshape(4, 4, 3) * 5).save(folder / "wall.png")
        Image.new("RGBA", (2, 2), (200, 40, 40, 255)).save(folder / "leaf.png")
    else:       # other colours and another size; the leaf without alpha (it would cast a shadow)
        Image.new("RGB", (8, 8), (10, 250, 10)).save(folder / "wall.png")
        Image.new("RGB", (2, 2), (40, 40, 200)).save(folder / "leaf.png")


def _folder(tmp_path: Path, name: str, replaced: bool) -> Path:
    folder = tmp_path / name
    folder.mkdir()
    (folder / "world.yaml").write_text(json.dumps(WORLD))
    _images(folder, replaced)
    return folder


def _readings(loaded) -> tuple[np.ndarray, float]:
    sim = Simulation(loaded)
    sim.device("r/cam").enable(16)
    sim.device("r/ir").enable(16)
    sim.run(1)
    return sim.device("r/cam").image.copy(), float(sim.device("r/ir").value)


def test_each_texture_file_is_read_once_and_the_checked_image_is_the_one_seen(tmp_path, monkeypatch):
    folder = _folder(tmp_path, "world", replaced=False)
    original = _readings(load_world(_folder(tmp_path, "original", replaced=False) / "world.yaml"))
    other = _readings(load_world(_folder(tmp_path, "other", replaced=True) / "world.yaml"))
    assert not np.array_equal(original[0], other[0]) and original[1] != other[1]     # the images tell apart

    reads: Counter[str] = Counter()
    read = textures.read_texture_file

    def counted(file, url, max_bytes):
        reads[Path(file).name] += 1
        return read(file, url, max_bytes)

    def by_path(*args, **kwargs):
        raise AssertionError(f"a texture file read again by its path: {args}")

    check = textures.check_textures

    def check_then_replace(*args, **kwargs):
        problems = check(*args, **kwargs)
        _images(folder, replaced=True)          # the files change between the check and the scene
        return problems

    monkeypatch.setattr(textures, "read_texture_file", counted)
    monkeypatch.setattr(textures, "_decoded", by_path)
    monkeypatch.setattr(textures, "check_textures", check_then_replace)
    loaded = load_world(folder / "world.yaml")
    got = _readings(loaded)
    assert dict(reads) == {"wall.png": 1, "leaf.png": 1}
    assert np.array_equal(got[0], original[0]) and got[1] == original[1]
    assert set(loaded.textures) == {"wall.png", "./wall.png", "leaf.png"}
    assert loaded.textures["wall.png"][1] is loaded.textures["./wall.png"][1]          # one image per file



def _batched_readings(loaded) -> tuple[np.ndarray, np.ndarray]:
    from sensorium.server.sim.batched import BatchedSimulation

    b = BatchedSimulation(loaded, 2)
    cam, ir = b.device("r", "cam"), b.device("r", "ir")
    b.enable(cam, 16)
    b.enable(ir, 16)
    b.step()
    return b.image(cam).copy(), b.value(ir).copy()


def test_the_batched_simulation_shows_the_checked_images_too(tmp_path, monkeypatch):
    """Training's batched copies (and the gym's worker processes, which get the loaded world) take the
    images the check read, as the single simulation does: no file is read again by its path."""
    folder = _folder(tmp_path, "world", replaced=False)
    single = _readings(load_world(_folder(tmp_path, "original", replaced=False) / "world.yaml"))
    loaded = load_world(folder / "world.yaml")
    _images(folder, replaced=True)                 # the files change after the world loaded

    def by_path(*args, **kwargs):
        raise AssertionError(f"a texture file read again by its path: {args}")

    monkeypatch.setattr(textures, "_decoded", by_path)
    image, ir = _batched_readings(loaded)
    assert all(np.array_equal(image[c], single[0]) for c in range(2))
    assert ir.tolist() == [single[1]] * 2



WBT = """#VRML_SIM R2023b utf8
WorldInfo {
  basicTimeStep 16
}
DirectionalLight {
  direction 1 0 0
  intensity 0
  ambientIntensity 0.5
}
Solid {
  translation 1 0 0
  name "wall"
  children [
    Shape {
      appearance Appearance {
        texture ImageTexture {
          url [
            "wall.png"
          ]
        }
      }
      geometry Box {
        size 0.1 1 1
      }
    }
  ]
}
Robot {
  name "r"
  controller "<extern>"
  children [
    Camera {
      name "cam"
      width 8
      height 8
      fieldOfView 0.6
    }
    DistanceSensor {
      name "ir"
      type "infra-red"
      lookupTable [ 0 0 0, 10 1000 0 ]
    }
  ]
}
"""


def test_a_wbt_worlds_textures_too(tmp_path, monkeypatch):
    folders = {name: tmp_path / name for name in ("original", "world")}
    for folder in folders.values():
        folder.mkdir()
        (folder / "world.wbt").write_text(WBT)
        _images(folder, replaced=False)
    original = _readings(load_world(folders["original"] / "world.wbt"))
    reads: Counter[str] = Counter()
    read, check = textures.read_texture_file, textures.check_textures

    def counted(file, url, max_bytes):
        reads[Path(file).name] += 1
        return read(file, url, max_bytes)

    def check_then_replace(*args, **kwargs):
        problems = check(*args, **kwargs)
        _images(folders["world"], replaced=True)
        return problems

    monkeypatch.setattr(textures, "read_texture_file", counted)
    monkeypatch.setattr(textures, "check_textures", check_then_replace)
    got = _readings(load_world(folders["world"] / "world.wbt"))
    assert dict(reads) == {"wall.png": 1}
    assert np.array_equal(got[0], original[0]) and got[1] == original[1]
    assert not np.array_equal(got[0], _readings(load_world(folders["world"] / "world.wbt"))[0])   # now replaced
