"""Lights inside robots and solids as Supervisor nodes (tests/worlds/nested_lights.wbt): found by DEF, by
their parent's ``children`` in file order, by id and by getFromProtoDef; their fields read in their parent's
frame and set with a top-level light's checks; what a set does to light sensors, as the carrying robot or
solid moves; an LED's and a Charger's lights (their writes last until the LED's state changes, the Charger's
next step); exportString, simulationReset and remove(); the C client.

Every reading is a closed form of the LightSensor model (shared spec devices.md §2.2): a sensor looking up
(+z) at p under a point light at q of intensity I, attenuation 0 0 1 and colour C reads
I·max((q − p)_z / d, 0) / d² · (C_r + C_g + C_b) / 3 with d = |q − p|; a spot light adds its factor (1 on
its axis, 0 past its cut-off angle). The lights' world places are worked out by hand in the comments."""

from __future__ import annotations

import math
import sys

import pytest
from test_multiprocess import REPO, run_paused
from test_supervisor import A, Live

from sensorium.schemas.wire import ErrorCode
from sensorium.server.daemon import export
from sensorium.server.daemon import supervisor as sv
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WORLD = REPO / "tests" / "worlds" / "nested_lights.wbt"
LS, LS2 = (0.0, 0.0, 0.0), (10.0, 0.0, 0.0)
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=1:exitcode=86", "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"}


def point(q, intensity: float, p, color=(1.0, 1.0, 1.0), spot: float = 1.0) -> float:
    """A point light's term for an upward-looking sensor at ``p`` (attenuation 0 0 1)."""
    d = [a - b for a, b in zip(q, p)]
    d2 = sum(v * v for v in d)
    return intensity * max(d[2] / math.sqrt(d2), 0.0) / d2 * sum(color) / 3.0 * spot


# the loaded world's terms: HEADLIGHT at (0.5, 0, 1.5) (the Pose turns its location (0, 0, 0.5) onto the
# robot's x), BULB at (10, 0, 1), SPOT at (10, 0, 2) aimed down (ls is 1.37 rad off its axis: past its
# cut-off, 0; ls2 is on it: 1); TAIL and LEDLIGHT off
HEAD = (0.5, 0.0, 1.5)


def bulb(p, q=(10.0, 0.0, 1.0)) -> float:
    return point(q, 3.0, p)


def _live() -> Live:
    lv = Live(Simulation(load_world(WORLD)))
    lv.ok(A, "attach", {"robot": "probe"})
    bot = lv.sim.robot("probe")
    bot.device("ls").enable(8)
    bot.device("ls2").enable(8)
    return lv


def call(lv: Live, item: str, args: dict | None = None):
    return lv.ok(A, f"/probe/robot/{item}", args)


def node(lv: Live, name: str) -> int:
    return call(lv, "get_from_def", {"name": name})["node"]


def get(lv: Live, n: int, field: str):
    return call(lv, "get_field", {"node": n, "field": field})["value"]


def put(lv: Live, n: int, field: str, value) -> None:
    call(lv, "set_field", {"node": n, "field": field, "value": value})


def readings(lv: Live) -> tuple[float, float]:
    lv.step(A, "probe")
    bot = lv.sim.robot("probe")
    return bot.device("ls").value, bot.device("ls2").value


def test_nested_lights_are_nodes_found_by_def_children_and_id():
    lv = _live()
    carrier, mount, lamp, arm = (node(lv, n) for n in ("CARRIER", "MOUNT", "LAMP", "ARM"))
    lights = {n: call(lv, "get_from_def", {"name": n}) for n in ("HEADLIGHT", "TAIL", "LEDLIGHT", "BULB", "SPOT")}
    assert {n: (r["type"], r["def_name"], r["proto"]) for n, r in lights.items()} == {
        "HEADLIGHT": ("PointLight", "HEADLIGHT", ""), "TAIL": ("PointLight", "TAIL", ""),
        "LEDLIGHT": ("PointLight", "LEDLIGHT", ""), "BULB": ("PointLight", "BULB", ""),
        "SPOT": ("SpotLight", "SPOT", "")}
    led = lights["LEDLIGHT"]["parent"]            # the LED device's node
    assert lights["HEADLIGHT"]["parent"] == mount and lights["TAIL"]["parent"] == carrier
    assert lights["BULB"]["parent"] == lamp and lights["SPOT"]["parent"] == arm
    # every child counts, in file order: the Pose, the light, the distance sensor, the LED
    kids = get(lv, carrier, "children")
    assert len(kids) == 4 and kids[0] == mount and kids[1] == lights["TAIL"]["node"] and kids[3] == led
    assert call(lv, "get_from_id", {"id": kids[2]})["type"] == "DistanceSensor"
    assert call(lv, "get_from_id", {"id": led})["type"] == "LED"
    assert get(lv, mount, "children") == [lights["HEADLIGHT"]["node"]]
    assert get(lv, led, "children") == [lights["LEDLIGHT"]["node"]]
    assert get(lv, lamp, "children") == [lights["BULB"]["node"], arm]
    assert get(lv, arm, "children") == [lights["SPOT"]["node"]]
    for r in lights.values():
        assert call(lv, "get_from_id", {"id": r["node"]}) == r
    # fields as written, in the parent's frame; no pose (Webots: a light is no Pose, NaN)
    head = lights["HEADLIGHT"]["node"]
    assert get(lv, head, "location") == [0.0, 0.0, 0.5] and get(lv, head, "intensity") == 2.0
    assert get(lv, lights["SPOT"]["node"], "direction") == [0.0, 0.0, 1.0]
    assert get(lv, lights["TAIL"]["node"], "on") is False
    pose = call(lv, "get_node_pose", {"node": head})
    assert all(math.isnan(v) for v in pose["position"])


def test_a_robots_lights_set_change_the_readings_as_it_moves():
    lv = _live()
    head, tail, carrier = node(lv, "HEADLIGHT"), node(lv, "TAIL"), node(lv, "CARRIER")
    spot_ls2 = point((10.0, 0.0, 2.0), 4.0, LS2)
    assert readings(lv) == pytest.approx((point(HEAD, 2.0, LS) + bulb(LS),
                                          point(HEAD, 2.0, LS2) + bulb(LS2) + spot_ls2), rel=1e-12)
    put(lv, head, "on", False)
    assert readings(lv) == pytest.approx((bulb(LS), bulb(LS2) + spot_ls2), rel=1e-12)
    put(lv, head, "on", True)
    put(lv, head, "intensity", 4.0)
    put(lv, head, "color", [1.0, 0.5, 0.0])
    assert readings(lv)[0] == pytest.approx(point(HEAD, 4.0, LS, (1.0, 0.5, 0.0)) + bulb(LS), rel=1e-12)
    # a new location, in MOUNT's frame: (0, 0, 1) there is (1, 0, 0.5) in the robot, (1, 0, 1.5) in the world
    put(lv, head, "location", [0.0, 0.0, 1.0])
    assert get(lv, head, "location") == [0.0, 0.0, 1.0]
    assert readings(lv)[0] == pytest.approx(point((1.0, 0.0, 1.5), 4.0, LS, (1.0, 0.5, 0.0)) + bulb(LS), rel=1e-12)
    # the robot moves 2 m along x: the light with it; TAIL switched on at (0, 0, 3) in the robot
    put(lv, carrier, "translation", [2.0, 0.0, 1.0])
    put(lv, tail, "on", True)
    ls, ls2 = readings(lv)
    assert ls == pytest.approx(point((3.0, 0.0, 1.5), 4.0, LS, (1.0, 0.5, 0.0)) + point((2.0, 0.0, 4.0), 5.0, LS)
                               + bulb(LS), rel=1e-12)
    assert ls2 == pytest.approx(point((3.0, 0.0, 1.5), 4.0, LS2, (1.0, 0.5, 0.0)) + point((2.0, 0.0, 4.0), 5.0, LS2)
                                + bulb(LS2) + spot_ls2, rel=1e-12)


def test_a_solids_lights_set_change_the_readings_as_it_moves():
    lv = _live()
    bulb_node, spot, lamp = node(lv, "BULB"), node(lv, "SPOT"), node(lv, "LAMP")
    head_ls2 = point(HEAD, 2.0, LS2)
    put(lv, spot, "intensity", 8.0)
    put(lv, bulb_node, "location", [0.0, 0.0, 2.0])          # (10, 0, 2) in the world
    assert readings(lv)[1] == pytest.approx(head_ls2 + point((10.0, 0.0, 2.0), 3.0, LS2) + 2.0, rel=1e-12)
    # the spot aimed along the arm's x (the world's -x: the arm is turned half a turn about y): ls2 is
    # 90 degrees off its axis, past the cut-off
    put(lv, spot, "direction", [1.0, 0.0, 0.0])
    assert readings(lv)[1] == pytest.approx(head_ls2 + point((10.0, 0.0, 2.0), 3.0, LS2), rel=1e-12)
    put(lv, spot, "direction", [0.0, 0.0, 1.0])
    put(lv, spot, "cutOffAngle", 0.25)
    assert get(lv, spot, "cutOffAngle") == 0.25 and get(lv, spot, "beamWidth") == 0.2
    # the lamp moves to (0, 0, -1): the bulb and the spot 1 m above ls, its axis through it
    put(lv, lamp, "translation", [0.0, 0.0, -1.0])
    assert readings(lv)[0] == pytest.approx(point(HEAD, 2.0, LS) + 3.0 + 8.0, rel=1e-12)


def test_an_leds_light_follows_its_led_until_a_write_and_the_leds_next_change():
    lv = _live()
    light = node(lv, "LEDLIGHT")
    led = lv.sim.robot("carrier").device("led")
    base = point(HEAD, 2.0, LS) + bulb(LS)
    assert (get(lv, light, "on"), get(lv, light, "color")) == (False, [0.0, 0.0, 0.0])   # off until set (WbLed)
    led.set(1, lv.sim.time_ms)          # its light at (0, 0, 0.5) in red: 1 / 0.25 · 1/3
    assert (get(lv, light, "on"), get(lv, light, "color")) == (True, [1.0, 0.0, 0.0])
    assert readings(lv)[0] == pytest.approx(base + 4.0 / 3.0, rel=1e-12)
    put(lv, light, "color", [0.0, 0.5, 0.0])
    put(lv, light, "intensity", 3.0)
    assert readings(lv)[0] == pytest.approx(base + 3.0 * 4.0 * 0.5 / 3.0, rel=1e-12)
    led.set(1, lv.sim.time_ms)          # the same value: nothing changes (WbLed::setValue)
    assert get(lv, light, "color") == [0.0, 0.5, 0.0]
    led.set(0, lv.sim.time_ms)
    led.set(1, lv.sim.time_ms)          # a change: the LED's colour again, the intensity written stays
    assert (get(lv, light, "color"), get(lv, light, "intensity")) == ([1.0, 0.0, 0.0], 3.0)
    assert readings(lv)[0] == pytest.approx(base + 3.0 * 4.0 / 3.0, rel=1e-12)


def test_bad_values_get_one_line_and_change_nothing():
    lv = _live()
    head, spot = node(lv, "HEADLIGHT"), node(lv, "SPOT")
    before = readings(lv)
    for n, field, value, words in ((head, "intensity", -1.0, "must be >= 0"),
                                   (head, "attenuation", [0.0, 0.0, 0.0], "attenuation"),
                                   (head, "color", [2.0, 0.0, 0.0], "color"),
                                   (spot, "cutOffAngle", 2.0, "cut_off_angle"),
                                   (head, "location", [1e9, 0.0, 0.0], "world bounds"),
                                   # (found: a value a world file may not hold was taken, and its export refused)
                                   (head, "intensity", 1e-40, "too close to 0"),
                                   (head, "location", [0.0, 1e-310, 0.5], "too close to 0"),
                                   (head, "on", 1.5, "on")):
        r = lv.call(A, "/probe/robot/set_field", {"node": head if n == head else spot, "field": field, "value": value})
        assert r["ok"] is False and r["error"]["code"] == ErrorCode.INVALID_ARGUMENT, r
        message = r["error"]["message"]
        assert "\n" not in message and words in message, message
    assert get(lv, head, "intensity") == 2.0 and get(lv, head, "location") == [0.0, 0.0, 0.5]
    assert readings(lv) == before


def test_export_reset_and_remove():
    lv = _live()
    head, carrier, mount, bulb_node = node(lv, "HEADLIGHT"), node(lv, "CARRIER"), node(lv, "MOUNT"), node(lv, "BULB")
    before = readings(lv)
    put(lv, head, "location", [0.0, 0.0, 1.0])
    put(lv, bulb_node, "color", [0.0, 1.0, 0.0])
    text = call(lv, "node_export_string", {"node": head})["value"]
    assert text.splitlines() == ["DEF HEADLIGHT PointLight {", "  location 0 0 1", "  intensity 2",
                                 "  attenuation 0 0 1", "}"]
    assert "      color 0 1 0\n" in call(lv, "node_export_string", {"node": node(lv, "LAMP")})["value"]
    assert "        location 0 0 1\n" in call(lv, "world_save")["value"]
    call(lv, "simulation_reset")
    assert readings(lv) == pytest.approx(before, rel=1e-12)     # the fields as loaded
    assert get(lv, head, "location") == [0.0, 0.0, 0.5] and get(lv, bulb_node, "color") == [1.0, 1.0, 1.0]
    call(lv, "remove_node", {"node": head})                    # unlit from the next measurement
    assert readings(lv)[0] == pytest.approx(bulb(LS), rel=1e-12)
    assert node(lv, "HEADLIGHT") == 0 and get(lv, mount, "children") == []
    assert len(get(lv, carrier, "children")) == 4              # (the Pose holding it stays)
    assert "HEADLIGHT" not in call(lv, "node_export_string", {"node": carrier})["value"]
    call(lv, "simulation_reset")                               # removed nodes stay removed (Webots)
    assert readings(lv)[0] == pytest.approx(bulb(LS), rel=1e-12)


CHARGER_WBT = """#VRML_SIM R2023b utf8
WorldInfo { basicTimeStep 16 }
Charger {
  children [
    DEF GLOW PointLight { color 0 0 1 location 0 0 1 attenuation 0 0 1 }
  ]
  name "dock"
  battery [ 0, 1, 10 ]
  emissiveColor 1 0.5 0
}
Robot { controller "<none>" supervisor TRUE }
"""


def test_a_chargers_light_reads_its_glow_and_a_write_lasts_until_its_next_step(tmp_path):
    """WbCharger sets its first child's lights' colour at each step: c0 + (emissiveColor − c0)·E/Emax
    (10 W, 16 ms: E = 0.16 J a step), c0 the light's own colour; a Supervisor's write reads back until then."""
    path = tmp_path / "dock.wbt"
    path.write_text(CHARGER_WBT)
    sim = Simulation(load_world(path))
    glow = sv.find_node(sim, "GLOW")
    c0, full = [0.0, 0.0, 1.0], [1.0, 0.5, 0.0]

    def colour(energy: float) -> list[float]:
        return [a + (b - a) * energy for a, b in zip(c0, full)]

    assert (glow.type, sv.node_ref(sim, glow)["parent"]) == ("PointLight", sv.find_node(sim, "dock").id)
    sim.run(1)
    assert sv.get_field(sim, glow, "color")["value"] == pytest.approx(colour(0.16), abs=1e-15)
    sv.set_field(sim, glow, "color", [0.0, 1.0, 0.0])
    assert sv.get_field(sim, glow, "color")["value"] == [0.0, 1.0, 0.0]
    assert "color 0 1 0" in export.node_string(sim, glow)
    sim.run(1)
    assert sv.get_field(sim, glow, "color")["value"] == pytest.approx(colour(0.32), abs=1e-15)


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_c_supervisor_finds_reads_and_sets_them(tmp_path, tmp_path_factory):
    from test_c_client import sanitized_controller

    exe = sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "supervisor_nested_lights.c")
    ctl = run_paused(WORLD, tmp_path, exe, "probe", env=SAN_ENV)
    err = ctl.stderr()
    assert "Sanitizer" not in err and "runtime error" not in err, err
    out = dict(line.split(" ", 1) for line in ctl.out)
    assert out["head"] == "PointLight PointLight HEADLIGHT MOUNT 0 0 0.5 1"
    assert out["count"] == "4 1"
    ls = [float(v) for v in out["ls"].split()]
    assert ls == pytest.approx([point(HEAD, 2.0, LS) + bulb(LS), bulb(LS),
                                point((1.0, 0.0, 1.5), 2.0, LS) + bulb(LS)], rel=1e-12)
    assert out["bad"] == "2"            # the negative intensity refused: the field keeps its value
    assert "intensity: must be >= 0" in err


CAMERA_WBT = """#VRML_SIM R2023b utf8
WorldInfo { basicTimeStep 16 }
Robot {
  translation 0 0 1
  name "cam"
  supervisor TRUE
  controller "<extern>"
  children [ Camera { rotation 0 1 0 1.5707963267948966 width 24 height 16 } ]
}
Solid { translation 0 0 -0.05 children [ Shape { geometry Box { size 4 4 0.1 } } ] name "floor" }
%s
"""
CARRIED = """Robot {
  translation 0 0 1.5
  name "carrier"
  controller "<extern>"
  children [ Pose { translation 0 0 0.5 children [ DEF HL PointLight { location 0 0 0 } ] } ]
}"""


def test_cameras_see_a_nested_lights_set_as_a_world_file_writing_it_there(tmp_path):
    """A camera looking down at a floor lit by a light a robot carries: after the light is switched off its
    image is black (no other light, a black sky); after its intensity, colour and location are set, the image
    is byte for byte that of the world file writing a top-level light with those fields at its place now
    ((0.3, 0, 2): the robot's 1.5 m, the Pose's 0.5 m and the new location's 0.3 m along x)."""
    def image(body: str, change=None):
        path = tmp_path / f"w{len(list(tmp_path.iterdir()))}.wbt"
        path.write_text(CAMERA_WBT % body)
        sim = Simulation(load_world(path))
        if change is not None:
            change(sim)
        cam = sim.robot("cam").device("camera")
        cam.enable(16)
        sim.step()
        return cam.image.copy()

    def off(sim):
        sv.set_field(sim, sv.find_node(sim, "HL"), "on", False)

    def changed(sim):
        hl = sv.find_node(sim, "HL")
        sv.set_field(sim, hl, "intensity", 2.0)
        sv.set_field(sim, hl, "color", [1.0, 0.5, 0.25])
        sv.set_field(sim, hl, "location", [0.3, 0.0, 0.0])

    lit = image(CARRIED)
    assert lit[:, :, :3].any() and not image(CARRIED, off)[:, :, :3].any()
    want = image("PointLight { location 0.3 0 2 intensity 2 color 1 0.5 0.25 }")
    got = image(CARRIED, changed)
    assert got.tobytes() == want.tobytes() and got.tobytes() != lit.tobytes()


SCALED_WBT = """#VRML_SIM R2023b utf8
WorldInfo { basicTimeStep 8 }
DEF PROBE Robot {
  name "probe" supervisor TRUE controller "<extern>"
  children [
    LightSensor { rotation 0 1 0 -1.5707963267948966 name "ls" lookupTable [ 0 0 0, 100 100 0 ] }
    LightSensor { translation 10 0 0 rotation 0 1 0 -1.5707963267948966 name "ls2" lookupTable [ 0 0 0, 100 100 0 ] }
  ]
}
DEF CARRIER Robot {
  translation 0 0 1 name "carrier" controller "<extern>"
  children [
    DEF GROW Transform {
      translation 0 0 0.5 rotation 0 1 0 1.5707963267948966 scale 1 1 2
      children [ DEF HEADLIGHT PointLight { location 0 0 0.25 intensity 2 attenuation 0 0 1 } ]
    }
  ]
}
DEF LAMP Solid {
  translation 10 0 0 name "lamp"
  children [
    DEF BIG Transform { scale 2 2 2 children [ DEF BULB PointLight { location 0 0 0.5 intensity 3 attenuation 0 0 1 } ] }
  ]
}
"""


def test_lights_under_scaled_transforms_are_nodes_whose_location_is_set_through_the_scale(tmp_path):
    """HEADLIGHT at (0, 0, 0.25) under GROW (scale 1 1 2, turned +90 degrees about y, 0.5 m up the robot at
    z 1): (0, 0, 0.5) scaled, (0.5, 0, 0) turned, HEAD in the world; BULB at (0, 0, 0.5) under BIG (scale 2)
    in the lamp at (10, 0, 0): (10, 0, 1). A location set is scaled the same way: HEADLIGHT's (0, 0, 0.5)
    is (1, 0, 1.5), BULB's (0, 0, 1) is (10, 0, 2). Both Transforms are nodes holding their lights, their
    scale read as written."""
    path = tmp_path / "scaled_lights.wbt"
    path.write_text(SCALED_WBT)
    lv = Live(Simulation(load_world(path)))
    lv.ok(A, "attach", {"robot": "probe"})
    bot = lv.sim.robot("probe")
    bot.device("ls").enable(8)
    bot.device("ls2").enable(8)
    head, bulb_node, grow, big, lamp = (node(lv, n) for n in ("HEADLIGHT", "BULB", "GROW", "BIG", "LAMP"))
    assert head and bulb_node
    assert call(lv, "get_from_id", {"id": head})["parent"] == grow and get(lv, grow, "children") == [head]
    assert call(lv, "get_from_id", {"id": bulb_node})["parent"] == big and get(lv, big, "children") == [bulb_node]
    assert get(lv, lamp, "children") == [big]
    assert get(lv, grow, "scale") == [1.0, 1.0, 2.0] and get(lv, big, "scale") == [2.0, 2.0, 2.0]
    assert get(lv, head, "location") == [0.0, 0.0, 0.25] and get(lv, bulb_node, "location") == [0.0, 0.0, 0.5]
    assert readings(lv) == pytest.approx((point(HEAD, 2.0, LS) + bulb(LS), point(HEAD, 2.0, LS2) + bulb(LS2)),
                                         rel=1e-12)
    put(lv, head, "location", [0.0, 0.0, 0.5])
    put(lv, bulb_node, "location", [0.0, 0.0, 1.0])
    assert get(lv, head, "location") == [0.0, 0.0, 0.5] and get(lv, bulb_node, "location") == [0.0, 0.0, 1.0]
    far = (10.0, 0.0, 2.0)
    assert readings(lv) == pytest.approx((point((1.0, 0.0, 1.5), 2.0, LS) + point(far, 3.0, LS),
                                          point((1.0, 0.0, 1.5), 2.0, LS2) + point(far, 3.0, LS2)), rel=1e-12)
