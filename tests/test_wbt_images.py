"""Webots worlds with image devices (issue 23): Camera (with its Recognition), RangeFinder (and its
deprecated ``spherical``), Background ``skyColor``, Solid/Robot ``recognitionColors`` and ``model``
are read from a .wbt file with Webots' defaults."""

from __future__ import annotations

from pathlib import Path

from sensorium.schemas import world as wm
from sensorium.server.world.loader import load_world

WBT = """#VRML_SIM R2023b utf8
WorldInfo { basicTimeStep 16 }
Background { skyColor [ 0.4 0.7 1 ] }
Robot {
  name "bot"
  recognitionColors [ 0 1 0 ]
  children [
    Camera { translation 0.1 0 0.2 name "cam" width 32 height 24 antiAliasing TRUE exposure 2
             recognition Recognition { segmentation TRUE maxObjects 3 occlusion 2 } }
    RangeFinder { translation 0.1 0 0.25 width 16 height 8 maxRange 4 spherical TRUE }
    Camera { name "plain" }
  ]
}
Solid { translation 2 0 0 name "box" model "crate" recognitionColors [ 1 0 0, 0 0 1 ]
        children [ Shape { geometry Box { size 0.3 0.3 0.3 } }
                   Solid { name "lid" recognitionColors [ 1 1 1 ] } ] }
"""


def test_image_devices_recognition_and_background(tmp_path: Path) -> None:
    p = tmp_path / "w.wbt"
    p.write_text(WBT)
    w = load_world(p)
    cam, rf, plain = w.world.robots[0].devices
    assert isinstance(cam, wm.Camera) and (cam.width, cam.height, cam.anti_aliasing, cam.exposure) == (32, 24, True, 2.0)
    assert cam.recognition == wm.Recognition(segmentation=True, max_objects=3, occlusion=2)
    assert cam.pose.translation == (0.1, 0.0, 0.2)
    assert isinstance(rf, wm.RangeFinder) and rf.name == "range-finder" and rf.projection == "cylindrical"
    assert (rf.width, rf.height, rf.max_range) == (16, 8, 4.0)
    assert isinstance(plain, wm.Camera) and (plain.width, plain.field_of_view, plain.recognition) == (64, 0.785398, None)
    assert w.world.background.sky_color == (0.4, 0.7, 1.0)
    assert w.world.robots[0].recognition_colors == [(0.0, 1.0, 0.0)]
    box = w.world.solids[0]
    assert box.model == "crate" and box.recognition_colors == [(1.0, 0.0, 0.0), (0.0, 0.0, 1.0)]
    assert any("recognitionColors of a nested solid" in m for m in w.warnings)
