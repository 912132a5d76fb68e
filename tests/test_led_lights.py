"""An LED's lights (Webots' PointLight/SpotLight children of an LED, WbLed): on exactly while the LED
is (value != 0), in its colour (single precision, as WbLed computes it), off and black before the
first ``set`` and after a reset; light sensors and cameras see them then. Closed forms: a LightSensor
facing the LED's point light at distance d reads I/d² · (F·C)/3 through its table (devices.md §2);
a camera's wall pixels are the flat-wall closed form of test_camera.py with the LED's colour."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_camera import ALBEDO, WALL, expected_bytes, rays, rgb
from test_supervisor import Live

from sensorium.schemas import world as wm
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, parse_world

D = 2.0              # the LED's distance from the sensor (m)
I = 0.5              # its light's intensity
FILTER = (0.5, 1.0, 0.25)
COLORS = [(1.0, 0.0, 0.0), (0.0, 0.5, 1.0), (0.9, 0.3, 0.7)]


def sensor_world(led: dict | None = None, robot_lights=(), supervisor=False) -> wm.World:
    """A LightSensor at the robot's origin facing +x, an LED D m ahead holding a point light."""
    led = led if led is not None else {"color": [list(c) for c in COLORS],
                                       "lights": [{"type": "PointLight", "intensity": I, "attenuation": [0, 0, 1],
                                                   "color": [0.2, 0.2, 0.2]}]}
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 16},
        "robots": [{"name": "bot", "supervisor": supervisor, "lights": list(robot_lights), "devices": [
            {"device": "LightSensor", "name": "ls", "color_filter": list(FILTER)},
            {"device": "LED", "name": "led", "pose": {"translation": [D, 0, 0]}, **led}]}]})


def read(sim: Simulation) -> float:
    sim.run(1)
    return sim.device("bot/ls").value


def closed_form(color) -> float:
    """1000 · E with E = I/d² · (F·C)/3 (the default table [0 0 0, 1 1000 0], E < 1 here)."""
    c = [float(np.float32(x)) for x in color]        # WbLed's float r, g, b
    return 1000.0 * (I / D**2 * (FILTER[0] * c[0] + FILTER[1] * c[1] + FILTER[2] * c[2]) / 3.0)


def test_a_light_sensor_reads_the_leds_light_exactly_while_it_is_on_in_its_colour():
    sim = Simulation(sensor_world())
    sim.device("bot/ls").enable(16)
    led = sim.device("bot/led")
    assert read(sim) == 0.0                          # off before the first set: the light's own on is overridden
    for value in (1, 2, 3, 0, 2):
        led.set(value, sim.time_ms)
        want = 0.0 if value == 0 else closed_form(COLORS[value - 1])
        assert read(sim) == pytest.approx(want, rel=1e-12, abs=0.0), value
    assert closed_form(COLORS[1]) == pytest.approx(1000 * 0.5 / 4 * (0.5 + 0.25) / 3)


def test_on_is_the_same_as_a_robot_light_of_the_leds_colour_bit_for_bit():
    # an LED on in colour k lights exactly as a light carried at its place in that colour
    for k, color in enumerate(COLORS, start=1):
        sim = Simulation(sensor_world())
        sim.device("bot/ls").enable(16)
        sim.device("bot/led").set(k, 0)
        c32 = [float(np.float32(x)) for x in color]
        plain = Simulation(sensor_world({"color": [[1, 0, 0]]}, [{"type": "PointLight", "intensity": I, "location": [D, 0, 0],
                                                                  "attenuation": [0, 0, 1], "color": c32}]))
        plain.device("bot/ls").enable(16)
        assert read(sim) == read(plain)


def test_a_gradual_led_gives_its_lights_its_0xRRGGBB_colour():
    sim = Simulation(sensor_world({"gradual": True, "color": [], "lights": [{"type": "PointLight", "intensity": I,
                                                                             "attenuation": [0, 0, 1]}]}))
    sim.device("bot/ls").enable(16)
    sim.device("bot/led").set(0x336699, 0)
    rgb8 = [np.float32(b) / np.float32(255.0) for b in (0x33, 0x66, 0x99)]
    assert read(sim) == pytest.approx(closed_form(rgb8), rel=1e-12)
    assert sim.scene.world_lights()[0].color == tuple(float(v) for v in rgb8)


def test_a_gradual_led_with_one_colour_is_a_dimmer_of_it():
    """WbLed's monochrome LED: gradual with one colour (Webots' default list is red) takes an
    intensity 0..255: its lights get value/255.0f times that colour, in single precision."""
    light = [{"type": "PointLight", "intensity": I, "attenuation": [0, 0, 1]}]
    for listed in ({}, {"color": [[0.2, 0.6, 1.0]]}):
        sim = Simulation(sensor_world({"gradual": True, **listed, "lights": light}))
        colour = listed.get("color", [[1.0, 0.0, 0.0]])[0]
        sim.device("bot/ls").enable(16)
        led = sim.device("bot/led")
        led.set(128, 0)
        i = np.float32(128) / np.float32(255.0)
        want = [np.float32(float(i) * c) for c in colour]
        assert read(sim) == pytest.approx(closed_form(want), rel=1e-12)
        assert led.rgb() == pytest.approx([128 / 255.0 * c for c in colour], abs=1e-15)
        with pytest.raises(ValueError, match="an intensity 0..255"):
            led.set(256, 0)


def test_an_led_spot_light_points_from_the_leds_frame():
    # a spot light in an LED turned to face -x: it lights the sensor behind it; turned away, it does not
    turned = {"translation": [D, 0, 0], "rotation": [0, 0, 1, math.pi]}
    spot = {"type": "SpotLight", "intensity": I, "attenuation": [0, 0, 1], "direction": [1, 0, 0],
            "cut_off_angle": 0.3, "beam_width": 0.2}
    for pose, lit in ((turned, True), ({"translation": [D, 0, 0]}, False)):
        sim = Simulation(sensor_world({"pose": pose, "color": [[1, 1, 1]], "lights": [spot]}))
        sim.device("bot/ls").enable(16)
        sim.device("bot/led").set(1, 0)
        got = read(sim)
        assert got == (pytest.approx(closed_form((1, 1, 1)), rel=1e-9) if lit else 0.0)


def test_a_camera_sees_the_wall_lit_by_the_led_only_while_it_is_on():
    # the flat wall of test_camera.py, lit by the LED's point light 1 m ahead (attenuation 1/d²)
    cam = {"width": 9, "height": 7, "field_of_view": 1.0}
    where = [1.0, 0.3, -0.2]
    color = (1.0, 0.9, 0.8)
    w = wm.World.model_validate({
        "world_info": {"basic_time_step": 16, "random_seed": 5}, "solids": [WALL],
        "robots": [{"name": "r", "devices": [
            {"device": "Camera", "name": "cam", **cam},
            {"device": "LED", "name": "led", "pose": {"translation": where}, "color": [list(color)],
             "lights": [{"type": "PointLight", "intensity": 1.5, "attenuation": [0, 0, 1]}]}]}]})
    sim = Simulation(w)
    camera, led = sim.device("r/cam"), sim.device("r/led")
    camera.enable(16)
    sim.run(1)
    dark = rgb(camera.image)
    assert not dark.any()                              # no light: black
    led.set(1, sim.time_ms)
    sim.run(1)
    d = rays(cam)[0]
    P = d * (1.95 / d[..., :1])
    v = np.array(where) - P
    dist = np.linalg.norm(v, axis=-1)
    c32 = np.array([np.float32(x) for x in color], dtype=np.float64)
    want = expected_bytes(ALBEDO * (1.5 * (-v[..., 0] / dist) / dist**2)[..., None] * c32)
    np.testing.assert_array_equal(rgb(camera.image), want)
    led.set(0, sim.time_ms)
    sim.run(1)
    np.testing.assert_array_equal(rgb(camera.image), dark)


def test_set_through_the_services_and_simulation_reset_switch_the_lights():
    live = Live(Simulation(sensor_world(supervisor=True)))
    live.ok(b"A", "attach", {"robot": "bot"})
    live.ok(b"A", "/bot/ls/enable", {"value": 16})
    live.step(b"A", "bot")
    assert live.sim.device("bot/ls").value == 0.0
    live.ok(b"A", "/bot/led/set", {"value": 2})
    live.step(b"A", "bot")
    assert live.sim.device("bot/ls").value == pytest.approx(closed_form(COLORS[1]), rel=1e-12)
    live.ok(b"A", "/bot/robot/simulation_reset")       # WbLed::reset: value 0, its lights off
    assert live.ok(b"A", "/bot/led/get") == {"value": 0}
    live.step(b"A", "bot")
    assert live.sim.device("bot/ls").value == 0.0


def test_a_world_without_led_lights_never_recomputes_its_lights_for_a_set():
    sim = Simulation(sensor_world({"color": [[1, 0, 0]]}, [{"type": "PointLight", "location": [D, 0, 0]}]))
    version = sim.scene.lights_version
    sim.device("bot/led").set(1, 0)
    assert sim.scene.lights_version == version
    sim2 = Simulation(sensor_world())
    sim2.device("bot/led").set(1, 0)
    v = sim2.scene.lights_version
    sim2.device("bot/led").set(1, 0)                   # the same value: nothing changes (WbLed::setValue)
    assert sim2.scene.lights_version == v


def test_led_lights_schema_and_sanitising():
    with pytest.raises(WorldError, match="DirectionalLight|type"):
        parse_world({"robots": [{"name": "b", "devices": [
            {"device": "LED", "name": "led", "lights": [{"type": "DirectionalLight"}]}]}]})
    loaded = parse_world({"robots": [{"name": "b", "devices": [
        {"device": "LED", "name": "led", "lights": [{"type": "PointLight", "intensity": -1}]}]}]})
    assert loaded.world.robots[0].devices[0].lights[0].intensity == 1.0     # WbLight: < 0 reset to 1
    assert any("devices[0].lights[0].intensity" in w for w in loaded.warnings)


WBT = """#VRML_SIM R2023b utf8
WorldInfo { basicTimeStep 16 }
Robot {
  name "bot"
  children [
    LightSensor { name "ls" colorFilter 0.5 1 0.25 }
    LED {
      translation %s 0 0
      name "led"
      color [ 1 0 0, 0 0.5 1, 0.9 0.3 0.7 ]
      children [
        %s
        PointLight { location -10 0 0 intensity 0.25 }
      ]
    }
  ]
  controller "<extern>"
}
"""


@pytest.mark.parametrize("first", [
    "PointLight { intensity 0.5 attenuation 0 0 1 color 0.2 0.2 0.2 }",
    "Pose { children [ Group { children [ PointLight { intensity 0.5 attenuation 0 0 1 } ] } ] }",
])
def test_a_wbt_led_holding_a_point_light(tmp_path, first):
    path = tmp_path / "led.wbt"
    path.write_text(WBT % (D, first))
    sim = Simulation.from_file(path)
    robot = sim.world.robots[0]
    led = robot.devices[1]
    assert [lt.type for lt in led.lights] == ["PointLight"] and led.lights[0].location == (0.0, 0.0, 0.0)
    # only the first child counts (WbLed::findMaterialsAndLights): the second light is the robot's, always on
    assert [lt.location for lt in robot.lights] == [(D - 10.0, 0.0, 0.0)]
    sim.device("bot/ls").enable(16)
    base = read(sim)                                  # the robot's own light, behind the sensor: N·L < 0, ambient 0
    assert base == 0.0
    sim.device("bot/led").set(3, sim.time_ms)
    assert read(sim) == pytest.approx(closed_form(COLORS[2]), rel=1e-12)
    sim.device("bot/led").set(0, sim.time_ms)
    assert read(sim) == 0.0


def test_a_python_controllers_led_set_lights_the_sensor(tmp_path):
    import yaml
    from _inproc import inproc_server

    from sensorium.client import wb
    w = sensor_world()
    w = w.model_copy(update={"robots": [w.robots[0].model_copy(update={"synchronization": True})]})
    path = tmp_path / "led.yaml"
    path.write_text(yaml.safe_dump(w.model_dump(mode="json", exclude_defaults=True)))
    with inproc_server(heartbeat_ms=5000, world=path) as (_core, transport):
        wb.wb_robot_init(f"{transport.rpc_endpoint}/bot")
        try:
            from controller import Robot
        except ImportError:
            from sensorium.client.webots.controller import Robot
        try:
            robot = Robot()
            ls, led = robot.getDevice("ls"), robot.getDevice("led")
            ls.enable(16)
            robot.step(16)
            assert ls.getValue() == 0.0
            led.set(2)
            robot.step(16)
            assert led.get() == 2 and ls.getValue() == pytest.approx(closed_form(COLORS[1]), rel=1e-12)
            led.set(0)
            robot.step(16)
            assert ls.getValue() == 0.0
            # Webots' ctypes takes a bool as the C int 0 or 1 (its scara sample blinks its LED with
            # set(True) / set(False)); refused before ('value must be an integer, got True')
            led.set(True)
            robot.step(16)
            assert led.get() == 1 and ls.getValue() == pytest.approx(closed_form(COLORS[0]), rel=1e-12)
            led.set(False)
            robot.step(16)
            assert led.get() == 0 and ls.getValue() == 0.0
        finally:
            wb.wb_robot_cleanup()
            from sensorium.client.webots.controller.robot import Robot as _R
            _R.created = None
