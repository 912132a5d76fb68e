"""The ``slow`` marker: multi-process and subprocess-heavy tests. A plain ``pytest`` runs the rest (the
fast suite, a few minutes on 2 cores) and says how many slow tests it left out; ``pytest -m slow``
runs those, ``pytest -m "slow or not slow"`` (or ``SENSORIUM_SLOW=1``) everything. CI runs both.

A test is slow when its module runs servers and controllers as processes (``SLOW_MODULES``), when
it starts a subprocess itself or through a helper or fixture of its module (found in the module's
source: a function or class that mentions ``subprocess``/``Popen`` or starts one with tests/_serve.py
— ``Proc(``, ``Served(``, ``serve(``, ``run_example(`` — or test_multiprocess's ``start_server(``/``run_paused(``,
or starts a local Ray cluster (``init_ray(``), or calls one that does), or when it is listed in
``SLOW_TESTS`` (long single-process runs, worker pools). The long randomized tests (Hypothesis, seeded
loops) draw a share of their cases in the fast suite and all of them as slow cases (tests/_fuzz.py).
"""

from __future__ import annotations

import ast
import os
import re
from functools import cache
from pathlib import Path

import pytest

SLOW_MODULES = {"test_multiprocess", "test_server", "test_record_live", "test_demo", "test_docker", "test_bench"}
SLOW_TESTS = {
    "test_simulation.py::test_million_steps_no_clock_drift",
    "test_simulation.py::test_circle_stays_on_circle_for_a_million_steps",
    "test_sweep.py::test_same_sweep_on_ray_and_on_the_process_pool_gives_identical_results",   # a Ray cluster
    "test_train.py::test_ppo_on_the_batched_env_reaches_the_lamp",                             # ~1.5 min of PPO
    "test_train.py::test_evolution_strategy_on_ray_actors_equals_the_same_workers_in_process",  # a Ray cluster
    # mesh worker processes: a file read until the worker's memory limit stops it (~20 s), and five
    # workers started one per file; test_mesh_worker's other tests keep a worker reading in the fast suite
    "test_mesh_worker.py::test_a_file_over_the_memory_limit_is_one_line_and_the_next_file_loads",
    "test_mesh_worker.py::test_the_files_of_a_world_are_read_by_one_worker_with_the_triangles_of_a_worker_per_file",
}


# tests/_serve.py's helpers and test_multiprocess's (imported by other modules) start processes; so
# does sensorium.sweep's init_ray (Ray's GCS, raylet and workers)
SPAWNS = re.compile(r"subprocess|Popen|\b(?:Proc|Served|serve|start_server|run_paused|run_controller|run_example"
                    r"|sanitized_controller|init_ray)\(")


@cache
def _spawning_functions(path: Path) -> frozenset[str]:
    """Names of the module's functions (and classes) that start a process, directly or through another of them."""
    source = path.read_text()
    funcs = {node.name: ast.get_source_segment(source, node) or ""
             for node in ast.walk(ast.parse(source)) if isinstance(node, (ast.FunctionDef, ast.ClassDef))}
    spawning = {name for name, text in funcs.items() if SPAWNS.search(text)}
    grown = True
    while grown:
        grown = False
        for name, text in funcs.items():
            if name not in spawning and any(f"{other}(" in text for other in spawning):
                spawning.add(name)
                grown = True
    return frozenset(spawning)


def is_slow(item: pytest.Item) -> bool:
    path = Path(str(item.path))
    name = getattr(item, "originalname", None) or item.name
    spawning = _spawning_functions(path)
    return (path.stem in SLOW_MODULES or f"{path.name}::{name}" in SLOW_TESTS
            or name in spawning or any(f in spawning for f in getattr(item, "fixturenames", ())))


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        if is_slow(item):
            item.add_marker(pytest.mark.slow)
    # without a marker expression (and unless SENSORIUM_SLOW=1) the slow tests are left out; a test
    # named on the command line (file::name) always runs
    named = any("::" in arg for arg in config.args)
    if config.getoption("markexpr") or os.environ.get("SENSORIUM_SLOW") == "1" or named:
        return
    slow = [item for item in items if item.get_closest_marker("slow")]
    if slow:
        config.hook.pytest_deselected(items=slow)
        items[:] = [item for item in items if not item.get_closest_marker("slow")]
        config.stash[_SLOW_LEFT_OUT] = len(slow)


_SLOW_LEFT_OUT = pytest.StashKey[int]()


NODE_SKIP_MARKERS = ("npm ci", "node is not installed")


def pytest_terminal_summary(terminalreporter, exitstatus, config) -> None:  # noqa: ARG001
    """One line at the end when slow tests were left out, and one when the Foxglove/Node tests
    (tests/js) were skipped, each saying how to run them."""
    left_out = config.stash.get(_SLOW_LEFT_OUT, 0)
    if left_out:
        terminalreporter.write_line(
            f"sensorium: {left_out} slow test(s) (servers, controllers and tools as processes, full fuzz runs) left out: "
            "run `pytest -m slow` for them, or SENSORIUM_SLOW=1 pytest for everything (CI runs both)", yellow=True)
    skipped = terminalreporter.stats.get("skipped", [])
    node = [r for r in skipped if any(m in str(getattr(r, "longrepr", "")) for m in NODE_SKIP_MARKERS)]
    if node:
        why = "node is not installed" if any("node is not installed" in str(r.longrepr) for r in node) \
            else "the npm packages are not installed"
        terminalreporter.write_line(
            f"sensorium: {len(node)} Foxglove/Node test(s) skipped ({why}): install Node.js, run `npm ci` in "
            f"{Path(__file__).parent / 'js'}, then run pytest again (CI sets SENSORIUM_REQUIRE_NODE=1 to fail instead)",
            yellow=True)


@pytest.fixture(scope="module")
def texture_dir(tmp_path_factory) -> Path:
    """tests/worlds/camera.yaml's folder with its floor's texture: 8 x 8 texels of seeded random colours
    (written here, not committed; tests/test_batched_camera.py and test_camera_light_radius.py)."""
    import numpy as np
    from PIL import Image

    world = Path(__file__).parent / "worlds" / "camera.yaml"
    d = tmp_path_factory.mktemp("camera_world")
    texels = np.random.default_rng(7).integers(0, 256, (8, 8, 3), dtype=np.uint8)
    Image.fromarray(texels, "RGB").save(d / "checker.png")
    (d / world.name).write_text(world.read_text())
    return d
