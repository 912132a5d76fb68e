"""TouchSensor: a bumper from the kinematic contact; force types read Webots' "no value"."""

from __future__ import annotations

import math

import numpy as np

from sensorium.schemas import messages as msgs
from sensorium.schemas import world as wm
from sensorium.server.daemon.services import Core
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import sanitize


def make(kind="bumper"):
    data = {"world_info": {"basic_time_step": 16},
            "solids": [{"name": "wall", "pose": {"translation": [0.3, 0, 0.05]},
                        "geometry": {"type": "box", "size": [0.02, 1.0, 0.1]}}],
            "robots": [{"name": "r", "shapes": [{"pose": {"translation": [0, 0, 0.03]},
                                                  "geometry": {"type": "cylinder", "radius": 0.05, "height": 0.05}}],
                        "differential_drive": {"wheel_radius": 0.02, "axle_length": 0.08, "max_wheel_speed": 100},
                        "devices": [{"device": "TouchSensor", "name": "bumper", "type": kind}]}]}
    sim = Simulation(wm.World.model_validate(data))
    sim.device("r/bumper").enable(16)
    return sim


def drive(sim, w):
    for m in sim.robot("r").motors.values():
        m.set_position(math.inf)
        m.set_velocity(w)


def test_bumper_reads_one_while_pushing_a_wall():
    sim = make()
    b = sim.device("r/bumper")
    assert math.isnan(b.value)
    sim.step()
    assert b.value == 0.0                                  # at rest, nothing touched
    drive(sim, 10.0)                                       # 0.2 m/s towards the wall 0.24 m ahead
    values = []
    for _ in range(100):
        sim.step()
        values.append(b.value)
    first = values.index(1.0)
    # the body (radius 0.05) reaches the wall face (x = 0.29) at x = 0.24: 1.2 s = 75 steps of 16 ms
    assert 73 <= first <= 76 and all(v == 0.0 for v in values[:first]) and all(v == 1.0 for v in values[first:])
    assert sim.robot("r").pose.translation[0] < 0.24 + 1e-9
    drive(sim, -10.0)                                      # backing away: no longer pressing
    sim.step()
    assert b.value == 0.0


def test_force_types_read_no_value_and_are_announced():
    for kind in ("force", "force-3d"):
        sim = make(kind)
        sim.run(2)
        dev = sim.device("r/bumper")
        assert math.isnan(dev.value) and np.isnan(dev.values).all() and dev.measurements == 2
    world = wm.World.model_validate({"robots": [{"name": "r", "devices": [
        {"device": "TouchSensor", "name": "t", "type": "force"}]}]})
    _, warnings = sanitize(world)
    assert any("needs physics" in w and "robots[0].devices[0].type" in w for w in warnings)


def test_services_and_topics():
    core = Core(make())
    assert {"/r/bumper/get_value", "/r/bumper/get_type", "/r/bumper/get_lookup_table"} <= set(core.routes)
    types = {t.name: t.type for t in core.topics.topics}
    assert types["/r/bumper/value"] == msgs.FLOAT64 and "/r/bumper/values" not in types
    core3 = Core(make("force-3d"))
    assert {t.name: t.type for t in core3.topics.topics}["/r/bumper/values"] == msgs.VECTOR3_STAMPED
