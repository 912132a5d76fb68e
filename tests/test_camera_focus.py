"""A Camera's Focus (Webots' Focus node): its focal length and the range ``setFocalDistance`` may take,
read from a .wbt and answered by both clients with Webots' refusal line outside the range; the distance
set is read back (no depth of field is drawn: one load warning). Found by the fourteenth sweep's
``camera_auto_focus``, whose every call was refused as out of [0, 0]."""

from __future__ import annotations

import pytest

from sensorium.schemas import world as wm

FOCUS = {"focal_distance": 0.5, "focal_length": 0.25, "min_focal_distance": 0.1, "max_focal_distance": 1.0}
EXPECTED = ["focus 0.25 0.5 0.1 1", "refused 0.5", "set 0.75", "plain 0 0"]
REFUSALS = ["Error: wb_camera_set_focal_distance() out of focus range [0.100000, 1.000000].",
            "Error: wb_camera_set_focal_distance() out of focus range [0.000000, 0.000000]."]


def world_file(tmp_path) -> str:
    import yaml
    world = wm.World.model_validate({
        "world_info": {"basic_time_step": 16},
        "robots": [{"name": "r", "devices": [
            {"device": "Camera", "name": "cam", "width": 8, "height": 6, "focus": FOCUS},
            {"device": "Camera", "name": "plain", "width": 8, "height": 6}]}]})
    path = tmp_path / "focus.yaml"
    path.write_text(yaml.safe_dump(world.model_dump(mode="json", exclude_defaults=True)))
    return str(path)


def test_a_wbt_cameras_focus_node_is_read(tmp_path):
    from sensorium.server.world.loader import load_world
    path = tmp_path / "focus.wbt"
    path.write_text('#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\nRobot { name "r" children [\n'
                    '  Camera { name "cam" focus Focus { focalDistance 0.5 focalLength 0.25 maxFocalDistance 1'
                    ' minFocalDistance -0.1 } }\n  Camera { name "plain" } ] }\n')
    loaded = load_world(path)
    cam, plain = loaded.world.robots[0].devices
    assert cam.focus == wm.Focus(**{**FOCUS, "min_focal_distance": 0.0})    # a negative one reset to 0
    assert plain.focus is None
    assert any("depth of field" in w for w in loaded.warnings)


def test_the_python_client_reads_and_sets_the_focus(tmp_path, capsys):
    from _inproc import inproc_server

    from sensorium.client import wb
    from sensorium.client.webots.controller import Robot
    with inproc_server(heartbeat_ms=5000, world=world_file(tmp_path)) as (core, transport):
        wb.wb_robot_init(f"{transport.rpc_endpoint}/r")
        try:
            robot = Robot()
            cam, plain = robot.getDevice("cam"), robot.getDevice("plain")
            lines = [f"focus {cam.getFocalLength():g} {cam.getFocalDistance():g} {cam.getMinFocalDistance():g} "
                     f"{cam.getMaxFocalDistance():g}"]
            capsys.readouterr()
            cam.setFocalDistance(1.5)
            lines.append(f"refused {cam.getFocalDistance():g}")
            cam.setFocalDistance(0.75)
            lines.append(f"set {cam.getFocalDistance():g}")
            plain.setFocalDistance(0.3)
            lines.append(f"plain {plain.getFocalLength():g} {plain.getFocalDistance():g}")
            assert capsys.readouterr().err.splitlines() == REFUSALS
            robot.step(16)
            assert lines == EXPECTED
        finally:
            wb.wb_robot_cleanup()
            Robot.created = None


@pytest.mark.slow
def test_the_c_client_reads_and_sets_the_focus_as_the_python_client(tmp_path, tmp_path_factory):
    from test_c_client import REPO, sanitized_run
    code, out, err = sanitized_run(tmp_path_factory, REPO / "tests" / "c" / "focus.c", world_file(tmp_path), "r")
    assert code == 0, err
    assert out == EXPECTED
    assert [x for x in err.splitlines() if x.startswith("Error")] == REFUSALS
