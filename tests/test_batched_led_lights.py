"""An LED's lights in the batched simulation (``BatchedSimulation.set_led``; batched_lights.py): each
copy lit by the lights of its own LEDs exactly while they are on there, in their colour, bit for bit
the single Simulation with that copy's seed and the same ``LED.set`` calls; reset copies' LEDs off."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_batched_robot_lights import PERIODS, SENSORS, _world

from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld
from tests._copies import copies_and_singles, reseed_copy, steer_randomly

LEDS = [
    {"device": "LED", "name": "lamp", "pose": {"translation": [0.02, 0.0, 0.12], "rotation": [0, 0, 1, 0.7]},
     "color": [[1.0, 0.9, 0.3], [0.2, 0.6, 1.0]],
     "lights": [{"type": "PointLight", "intensity": 1.2, "attenuation": [0.2, 0.3, 1.0], "cast_shadows": True,
                 "ambient_intensity": 0.03},
                {"type": "SpotLight", "location": [0.08, 0, 0], "direction": [1, 0.2, -0.3], "intensity": 2.0,
                 "attenuation": [1, 0.5, 0.8], "beam_width": 0.4, "cut_off_angle": 0.8}]},
    {"device": "LED", "name": "rgb", "gradual": True, "color": [], "pose": {"translation": [-0.05, 0.03, 0.1]},
     "lights": [{"type": "PointLight", "intensity": 0.9, "attenuation": [0.5, 0.0, 1.0]}]},
    {"device": "LED", "name": "plain"},
]


def _led_world(seed: int) -> LoadedWorld:
    lw = _world(seed)
    robots = list(lw.world.robots)
    leader = robots[0]
    robots[0] = leader.model_validate({**leader.model_dump(mode="json", exclude_defaults=True), "devices": LEDS})
    return LoadedWorld(world=lw.world.model_copy(update={"robots": robots}), source=lw.source, base_dir=lw.base_dir)


def _assert_same(bs: BatchedSimulation, sims: list[Simulation], step: int) -> None:
    for c, s in enumerate(sims):
        seeker = s.robot("seeker")
        for n in SENSORS:
            want, got = seeker.device(n).value, float(bs.value(bs.device("seeker", n))[c])
            assert want == got or (math.isnan(want) and math.isnan(got)), (step, c, n, want, got)
        assert seeker.device("eye").image.tobytes() == bs.image(bs.device("seeker", "eye"))[c].tobytes(), (step, c)


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_every_copy_is_lit_by_its_own_leds_as_the_single_simulation(precision: str):
    seeds = [5, 6, 7]
    bs, sims = copies_and_singles(_led_world, seeds, precision, PERIODS)
    assert bs.carried is not None and bs.carried.switched
    leader = bs.slot("leader")
    rng = np.random.default_rng(3)
    front = bs.device("seeker", "front")
    seen = []
    plan = {0: ("lamp", 1, [0]), 4: ("rgb", 0x40A0FF, [1, 2]), 9: ("lamp", 2, [1]), 15: ("lamp", 0, [0, 1]),
            20: ("rgb", 0xFF2000, [0]), 26: ("plain", 1, [2])}
    for step in range(34):
        if step % 10 == 0:
            steer_randomly(bs, sims, rng, ("leader", "seeker"), 0.4)
        if step in plan:
            name, value, copies = plan[step]
            bs.set_led(leader, name, value, copies)
            for c in copies:
                sims[c].device(f"leader/{name}").set(value, sims[c].time_ms)
        if step == 30:                          # copy 2 as a new world: its LEDs off again
            reseed_copy(bs, sims, _led_world, 2, 42, precision, PERIODS)
        bs.step()
        for s in sims:
            s.step()
        _assert_same(bs, sims, step)
        seen.append(bs.value(front).copy())
    assert bs.led_value_of(leader, "rgb").tolist() == [0xFF2000, 0x40A0FF, 0]
    values = np.array(seen)
    assert len({v.tobytes() for v in values.T}) == len(seeds)


def test_set_led_checks_as_the_single_led():
    bs = BatchedSimulation(_led_world(0), 2)
    with pytest.raises(ValueError, match="colour index"):
        bs.set_led(bs.slot("leader"), "lamp", 3)
    with pytest.raises(KeyError, match="no LED"):
        bs.set_led(bs.slot("seeker"), "lamp", 1)
