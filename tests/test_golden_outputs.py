"""Bit-identical outputs across speed work: sensor values captured before an optimisation must come
out again, bit for bit, whenever precision and settings are unchanged.

``tests/data/golden_outputs.npz`` was written by ``_capture()`` below on the code before the
batched distance-sensor and lidar fast paths (``PYTHONPATH=. python tests/test_golden_outputs.py
--write`` rewrites it: do that only for a deliberate change of results, and say so in the commit).
Scenes: the warehouse example (a rotating 16-layer lidar, a planar safety lidar) plus a fixed lidar
with a point cloud; and 24 e-pucks (cylinder bodies, 8 infra-red sensors of 3 rays each, some with
noisy lookup tables) moved between steps in a room with curved obstacles; FAST and EXACT each.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import default_world_path, parse_world

GOLDEN = Path(__file__).parent / "data" / "golden_outputs.npz"

_IR_TABLE = [[0.0, 4095, 0.0], [0.005, 2133.33, 0.0], [0.01, 1465.73, 0.0], [0.015, 601.46, 0.0],
             [0.02, 383.84, 0.0], [0.03, 234.93, 0.0], [0.04, 158.03, 0.0], [0.05, 120.0, 0.0],
             [0.06, 104.09, 0.0], [0.07, 67.19, 0.0]]
_IR_POSES = [((0.0343, -0.0099, 0.01), -0.28), ((0.0252, -0.0252, 0.01), -0.785), ((0.0, -0.0357, 0.01), -1.5708),
             ((-0.0309, -0.0179, 0.01), -2.618), ((-0.0309, 0.0179, 0.01), 2.618), ((0.0, 0.0357, 0.01), 1.5708),
             ((0.0252, 0.0252, 0.01), 0.785), ((0.0343, 0.0099, 0.01), 0.28)]


def _epuck(i: int, x: float, y: float, yaw: float) -> dict:
    table = [[a, b, 0.05 if i % 3 == 0 else 0.0] for a, b, _ in _IR_TABLE]   # every third robot: noisy
    return {"name": f"e{i}", "pose": {"translation": [x, y, 0.025], "rotation": [0, 0, 1, yaw]},
            "body": {"geometry": {"type": "cylinder", "radius": 0.035, "height": 0.05}},
            "devices": [{"device": "DistanceSensor", "name": f"ps{k}", "type": "infra-red",
                         "pose": {"translation": list(p), "rotation": [0, 0, 1, a]}, "lookup_table": table,
                         "number_of_rays": 3, "aperture": 0.2} for k, (p, a) in enumerate(_IR_POSES)]}


def _swarm_world() -> dict:
    solids = [
        {"name": "wall", "pose": {"translation": [0.0, 0.62, 0.05]}, "geometry": {"type": "box", "size": [1.4, 0.04, 0.1]}},
        {"name": "post", "pose": {"translation": [0.2, 0.1, 0.05]}, "geometry": {"type": "cylinder", "radius": 0.03, "height": 0.1}},
        {"name": "ball", "pose": {"translation": [-0.25, -0.2, 0.04]}, "geometry": {"type": "sphere", "radius": 0.04}},
        {"name": "floor", "geometry": {"type": "plane"}},
    ]
    robots = [_epuck(i, -0.5 + 0.2 * (i % 6), -0.45 + 0.22 * (i // 6), 0.37 * i) for i in range(24)]
    return {"world_info": {"basic_time_step": 8, "random_seed": 7}, "solids": solids, "robots": robots}


def _warehouse_world() -> dict:
    world = yaml.safe_load(Path(default_world_path()).with_name("warehouse.yaml").read_text())
    world["robots"][0]["devices"].append({
        "device": "Lidar", "name": "fixed", "pose": {"translation": [0.0, 0.0, 0.9]}, "horizontal_resolution": 256,
        "number_of_layers": 12, "field_of_view": 2 * math.pi, "vertical_field_of_view": 0.6, "near": 0.05,
        "min_range": 0.1, "max_range": 30.0, "type": "fixed"})
    return world


def _capture() -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    base = Path(default_world_path()).parent
    for prec in ("fast", "exact"):
        sim = Simulation(parse_world(_warehouse_world(), base_dir=base), precision=prec)
        lidars = [d for d in sim.all_devices() if d.kind == "Lidar"]
        for d in lidars:
            d.enable(sim.basic_time_step)
        sim.device("forklift/fixed").enable_point_cloud()
        for step in range(3):
            sim.robot("forklift").set_pose([0.4 * step, 0.3 * step, 0.3], [0, 0, 1, 0.2 * step])
            sim.step()
            for d in lidars:
                out[f"{prec}/warehouse/{d.name}/{step}/range"] = d.range_image.copy()
                if d.point_cloud_enabled:
                    pc = d.point_cloud
                    out[f"{prec}/warehouse/{d.name}/{step}/cloud"] = np.stack([pc[k] for k in pc.dtype.names], axis=-1)
        sim = Simulation(parse_world(_swarm_world()), precision=prec)
        devs = list(sim.all_devices())
        for d in devs:
            d.enable(8)
        for step in range(3):
            for i, r in enumerate(sim.robots.values()):
                x, y, _ = r.pose.translation
                r.set_pose([x + 0.013 * math.cos(i + step), y + 0.011 * math.sin(2 * i + step), 0.025],
                           [0, 0, 1, 0.37 * i + 0.3 * step])
            sim.step()
            out[f"{prec}/swarm/{step}"] = np.array([d.value for d in devs])
    return out


@pytest.fixture(scope="module")
def captured() -> dict[str, np.ndarray]:
    return _capture()


@pytest.mark.parametrize("part", ["fast/warehouse", "exact/warehouse", "fast/swarm", "exact/swarm"])
def test_outputs_are_bit_identical_to_the_golden_capture(captured, part):
    gold = np.load(GOLDEN)
    keys = sorted(k for k in gold.files if k.startswith(part + "/"))
    assert keys, f"no golden data for {part}"
    assert sorted(k for k in captured if k.startswith(part + "/")) == keys
    for k in keys:
        a, b = captured[k], gold[k]
        assert a.dtype == b.dtype and a.shape == b.shape, k
        # bit-identical: compare the bytes (NaN == NaN, -0.0 != 0.0)
        same = a.view(np.uint8).reshape(a.shape + (-1,)) == b.view(np.uint8).reshape(b.shape + (-1,))
        assert same.all(), f"{k}: {np.count_nonzero(~same.all(axis=-1))} values differ from the golden capture"


def test_golden_scenes_are_not_trivial(captured):
    """The capture exercises what it claims: hits, misses, noise and distinct values."""
    swarm = np.concatenate([captured[f"fast/swarm/{s}"] for s in range(3)])
    assert len(np.unique(swarm)) > 50                 # real, varied readings (noise on a third)
    assert np.count_nonzero(swarm > 67.19 + 1) > 20    # many sensors see something nearby
    rng = captured["exact/warehouse/fixed/2/range"]
    assert np.isfinite(rng).mean() > 0.5 and np.isinf(rng).any()


if __name__ == "__main__" and "--write" in sys.argv:
    GOLDEN.parent.mkdir(exist_ok=True)
    np.savez_compressed(GOLDEN, **_capture())
    print(f"wrote {GOLDEN}")
