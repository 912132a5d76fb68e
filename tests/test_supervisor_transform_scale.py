"""A nested Transform's ``scale`` as a Supervisor reads it (getField) and sets it: inside a robot and inside a
top-level solid it reads what the world file writes (Webots' reset of a zero component to 1 included); a scaled
Transform inside a solid is a node holding its Shapes; exportString and worldSave write the scale. A set inside a
top-level solid builds the solid again exactly as the world file written with that value (a lidar's ranges and a
camera's image bit for bit), node ids kept, simulationReset restoring the loaded value; a set inside a robot, on a
Transform holding more than Shapes, or of a non-finite value is refused in one line, nothing changed, and so is a
Pose imported into a scaled Transform.

Closed form: the lidar's middle beam runs along +x from the origin at z 0 to the box whose face is at
x = 2 - 0.1·sx (BOX at x 2, its Box 0.2 wide under ST's scale x component)."""

from __future__ import annotations

import numpy as np
import pytest
from test_supervisor import A, Live

from sensorium.schemas.wire import ErrorCode
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WBT = """#VRML_SIM R2023b utf8
WorldInfo {{ basicTimeStep 8 }}
DEF PROBE Robot {{
  name "probe" supervisor TRUE controller "<extern>"
  children [
    Lidar {{ name "lidar" horizontalResolution 9 fieldOfView 0.2 numberOfLayers 1 maxRange 10 }}
    Camera {{ translation 0 0 0.05 name "camera" width 16 height 12 }}
    DEF RT Transform {{
      translation 0 0 0.5 scale 1 1 2
      children [ Shape {{ geometry Box {{ size 0.01 0.01 0.01 }} }} ]
    }}
    DEF RH Transform {{ translation -0.2 0 0 scale 0.5 0.5 0.5 children [ Shape {{ geometry Sphere {{ radius 0.01 }} }} ] }}
    DEF RU Transform {{ translation -0.3 0 0 children [ Shape {{ geometry Sphere {{ radius 0.01 }} }} ] }}
  ]
}}
DEF BOX Solid {{
  translation 2 0 0 name "box"
  children [
    DEF ST Transform {{ scale {st} children [ DEF FACE Shape {{ geometry Box {{ size 0.2 0.2 0.2 }} }} ] }}
    DEF SH Transform {{
      translation 0 1 0 scale 0.5 0.5 0.5
      children [ DEF SMALL Shape {{ geometry Box {{ size 0.2 0.2 0.2 }} }} ]
    }}
    DEF SZ Transform {{ translation 0 -1 0 scale 0 1 2 children [ Shape {{ geometry Sphere {{ radius 0.1 }} }} ] }}
    DEF SU Transform {{ translation 0 0 1 children [ DEF HELD Pose {{ children [ Shape {{ geometry Box {{ size 0.1 0.1 0.1 }} }} ] }} ] }}
  ]
}}
"""


def _live(tmp_path, st: str = "1 1 2") -> Live:
    path = tmp_path / f"scaled_{st.replace(' ', '_')}.wbt"
    path.write_text(WBT.format(st=st))
    lv = Live(Simulation(load_world(path)))
    lv.ok(A, "attach", {"robot": "probe"})
    bot = lv.sim.robot("probe")
    bot.device("lidar").enable(8)
    bot.device("camera").enable(8)
    return lv


def call(lv: Live, item: str, args: dict | None = None):
    return lv.ok(A, f"/probe/robot/{item}", args)


def node(lv: Live, name: str) -> int:
    return call(lv, "get_from_def", {"name": name})["node"]


def get(lv: Live, n: int, field: str):
    return call(lv, "get_field", {"node": n, "field": field})["value"]


def seen(lv: Live) -> tuple[bytes, bytes]:
    lv.step(A, "probe")
    bot = lv.sim.robot("probe")
    return (np.asarray(bot.device("lidar").range_image, dtype=np.float32).tobytes(),
            np.asarray(bot.device("camera").image).tobytes())


def middle(ranges: bytes) -> float:
    return float(np.frombuffer(ranges, dtype=np.float32)[4])


def test_nested_transforms_read_the_scale_their_world_file_writes(tmp_path):
    lv = _live(tmp_path)
    rt, rh, ru, st, sh, sz, su = (node(lv, n) for n in ("RT", "RH", "RU", "ST", "SH", "SZ", "SU"))
    assert all((rt, rh, ru, st, sh, sz, su))
    assert {n: call(lv, "get_field", {"node": n, "field": "scale"}) for n in (rt, rh, ru, st, sh, sz, su)} == {
        rt: {"type": "SFVec3f", "value": [1.0, 1.0, 2.0]}, rh: {"type": "SFVec3f", "value": [0.5, 0.5, 0.5]},
        ru: {"type": "SFVec3f", "value": [1.0, 1.0, 1.0]}, st: {"type": "SFVec3f", "value": [1.0, 1.0, 2.0]},
        sh: {"type": "SFVec3f", "value": [0.5, 0.5, 0.5]},
        sz: {"type": "SFVec3f", "value": [1.0, 1.0, 2.0]},          # x 0 reset to 1, as Webots (its warning)
        su: {"type": "SFVec3f", "value": [1.0, 1.0, 1.0]}}
    assert get(lv, sh, "translation") == [0.0, 1.0, 0.0] and get(lv, rt, "translation") == [0.0, 0.0, 0.5]
    # a scaled Transform inside a solid is a node holding its Shapes, in file order among the solid's children
    box = node(lv, "BOX")
    assert get(lv, box, "children") == [st, sh, sz, su]
    assert get(lv, st, "children") == [node(lv, "FACE")] and get(lv, sh, "children") == [node(lv, "SMALL")]
    assert call(lv, "get_from_id", {"id": node(lv, "SMALL")})["parent"] == sh
    assert get(lv, su, "children") == [node(lv, "HELD")]
    # exportString and worldSave write the scale where the file does
    assert call(lv, "node_export_string", {"node": sh})["value"].splitlines()[:3] == [
        "DEF SH Transform {", "  translation 0 1 0", "  scale 0.5 0.5 0.5"]
    assert "    scale 1 1 2\n" in call(lv, "node_export_string", {"node": node(lv, "PROBE")})["value"]
    saved = call(lv, "world_save")["value"]
    assert "DEF ST Transform {\n      scale 1 1 2\n" in saved and "      scale 0.5 0.5 0.5\n" in saved
    assert "DEF RH Transform {\n      translation -0.2 0 0\n      scale 0.5 0.5 0.5\n" in saved


@pytest.mark.parametrize("value", [[0.5, 0.5, 0.5], [3.0, 1.0, 2.0]])
def test_a_solid_s_transform_scale_set_reads_as_the_world_file_written_with_it(tmp_path, value):
    lv = _live(tmp_path)
    st, face, box = node(lv, "ST"), node(lv, "FACE"), node(lv, "BOX")
    loaded = seen(lv)
    assert middle(loaded[0]) == pytest.approx(1.9, abs=1e-6)
    call(lv, "set_field", {"node": st, "field": "scale", "value": value})
    written = " ".join(f"{v:g}" for v in value)
    twin = _live(tmp_path, written)
    expected = seen(twin)
    assert seen(lv) == expected and expected != loaded               # bit for bit
    assert middle(expected[0]) == pytest.approx(2.0 - 0.1 * value[0], abs=1e-6)
    assert get(lv, st, "scale") == value
    assert node(lv, "ST") == st and node(lv, "FACE") == face and get(lv, st, "children") == [face]
    assert get(lv, box, "children") == get(twin, node(twin, "BOX"), "children")
    assert f"DEF ST Transform {{\n  scale {written}\n" in call(lv, "node_export_string", {"node": st})["value"]
    call(lv, "simulation_reset")                                      # the loaded value back
    assert get(lv, st, "scale") == [1.0, 1.0, 2.0] and seen(lv) == loaded


def test_refused_in_one_line_and_nothing_changes(tmp_path):
    lv = _live(tmp_path)
    before = seen(lv)
    rt, st, su = node(lv, "RT"), node(lv, "ST"), node(lv, "SU")
    for n, value, words in ((rt, [2.0, 2.0, 2.0], "read-only here"),            # inside a robot
                            (su, [2.0, 2.0, 2.0], "it holds a Pose"),           # a Pose under it would be no node
                            (st, [1e300, 1.0, 1.0], "exceeds the limit"),
                            (st, [float("inf"), 1.0, 1.0], "finite")):
        message = lv.err(A, "/probe/robot/set_field", {"node": n, "field": "scale", "value": value},
                         ErrorCode.INVALID_ARGUMENT)
        assert words in message and "\n" not in message, message
    # a Pose imported into a scaled Transform would be no node: one line, the solid as it was
    message = lv.err(A, "/probe/robot/import_node_from_string",
                     {"node": st, "field": "children", "position": -1, "node_string": "Pose { }"},
                     ErrorCode.INVALID_ARGUMENT)
    assert "Pose is no node under a scaled Transform" in message and "\n" not in message, message
    assert get(lv, st, "children") == [node(lv, "FACE")]
    assert get(lv, rt, "scale") == [1.0, 1.0, 2.0] and get(lv, st, "scale") == [1.0, 1.0, 2.0]
    assert get(lv, su, "scale") == [1.0, 1.0, 1.0] and node(lv, "HELD") != 0
    assert seen(lv) == before
