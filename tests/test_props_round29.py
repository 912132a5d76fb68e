"""Property tests (Hypothesis, derandomized) of the whole load-and-step path on real-shaped robots: the
sweeps' stand-in worlds (tests/data/sweep*/: Webots samples' robots with their joints, wheels, drives,
lights and devices, our own text) and the test worlds of tests/worlds/ with one to three of their numbers, in the world or in a PROTO it uses,
replaced by a degenerate value (0, −0, ±1, ±1e-6, ±1e-9, ±1e6, the number negated or nudged by 1e-9 of
itself, and the loader's refused 1e-31, 1e12, 1e300 and nan). Each such world loads or is refused with ``WorldError`` lines that each name the file;
once loaded, its Simulation builds, every device enabled and every motor driven, and steps, every robot's
and solid's pose finite. Nothing else may happen: no other exception, no NaN pose.

`sensorium convert`'s YAML of each such world (wbt/emit.py) runs as the world itself: every robot's pose and
every device's value the same bits over the steps.

The batched simulation on the same worlds: two copies, driven as the single simulation is, either refuse the
world in one ``BatchedError`` line or move every robot bit for bit as Simulation does (its C pass and numpy)."""

from __future__ import annotations

import math
import re
import shutil
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pytest
from _fuzz import example_counts
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld, WorldError, load_world

DATA = Path(__file__).parent / "data"
WORLDS = sorted(DATA.glob("sweep*/*.wbt")) + sorted((DATA.parent / "worlds").glob("*.wbt")) + sorted(
    (DATA.parent / "worlds").glob("*/*.wbt"))
# a number token of a world or PROTO file (not inside a word: a DEF name's digits stay)
NUMBER = re.compile(r"(?<![\w.\-+])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.])")
# the refused ones (past the loader's limits) once each, those it takes several times
PICKS = ["0", "-0", "1e-9", "-1e-9", "1e-31", "1e12", "1e300", "nan", "NEG", "NUDGE", "0", "-0", "1e-9", "-1e-9", "1e6",
         "-1e6", "NEG", "NUDGE", "1", "-1", "1e-6", "NUDGE"]
STEPS = 8


def numbers_of(text: str) -> list[re.Match]:
    """The number tokens of a file's text outside comments and strings (a comment or a url keeps its digits)."""
    out, in_string = [], False
    for line_start, line in _lines(text):
        for m in NUMBER.finditer(line):
            before = line[:m.start()]
            if "#" in before or before.count('"') % 2 == 1 or in_string:
                continue
            out.append((line_start + m.start(), line_start + m.end(), m.group()))
    return out


def _lines(text: str):
    at = 0
    for line in text.splitlines(keepends=True):
        yield at, line
        at += len(line)


def replaced(token: str, pick: str) -> str:
    if pick == "NEG":
        return token[1:] if token.startswith("-") else "-" + token.lstrip("+")
    if pick == "NUDGE":
        v = float(token)
        return repr(v * (1.0 + 1e-9) if v != 0.0 else 1e-9)
    return pick


def mutated_copy(world: Path, folder: Path, target: int, cuts: list[tuple[int, int]]) -> tuple[Path, str]:
    """The world's folder copied into ``folder`` (symlinked PROTOs as files), one file of it (the world, or
    one of the PROTOs under the folder by ``target``) with its numbers at the cuts' places replaced; that file's name."""
    shutil.copytree(world.parent, folder, symlinks=False)
    files = [folder / world.name] + sorted(folder.rglob("*.proto"))
    file = files[target % len(files)]
    text = file.read_text()
    spots = numbers_of(text)
    if spots:
        for place, pick in sorted({(p % len(spots), k) for p, k in cuts}, reverse=True):
            start, end, token = spots[place]
            text = text[:start] + replaced(token, PICKS[pick % len(PICKS)]) + text[end:]
    file.write_text(text)
    return folder / world.name, file.name


def loaded_or_refused(path: Path) -> LoadedWorld | None:
    """The world loaded, or None when it is refused in WorldError lines that each name the file."""
    try:
        return load_world(path)
    except WorldError as exc:
        lines = str(exc).split("\n")
        assert lines and all(line.startswith(str(path)) for line in lines), str(exc)[:2000]
        assert len(lines) <= 100 and max(len(line) for line in lines) < 2600
        return None


def drive(sim) -> None:
    """Every motor of every robot in velocity control: a two-wheel or skid-steer drive's sides at 1 and 3 rad/s
    (the batched simulation keeps one state per side: README "Wheels"), every other motor ±2 rad/s (or m/s) by
    its name's place in sorted order."""
    for name in sorted(sim.robots):
        robot = sim.robot(name)
        sides = getattr(robot.drive, "lefts", None), getattr(robot.drive, "rights", None)
        on_sides = set()
        if sides[0] is not None and sides[1] is not None:
            for side, speed in zip(sides, (1.0, 3.0), strict=True):
                for motor in side:
                    motor.set_position(math.inf)
                    motor.set_velocity(speed)
                    on_sides.add(motor.name)
        motors = robot.motors
        for k, m in enumerate(sorted(set(motors) - on_sides)):
            motors[m].set_position(math.inf)
            motors[m].set_velocity((-1.0) ** k * 2.0)


def run_world(path: Path) -> None:
    """Load, build, enable every device, drive every motor and step: only WorldError may stop it."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        loaded = loaded_or_refused(path)
        if loaded is None:
            return
        sim = Simulation(loaded, "exact")
        step = sim.basic_time_step
        for device in sim.all_devices():
            if hasattr(device, "enable"):
                device.enable(step)
        drive(sim)
        for _ in range(STEPS):
            sim.step()
        for name, robot in sim.robots.items():
            pose = robot.pose
            assert np.isfinite(pose.translation).all() and np.isfinite(pose.rotation).all(), (name, pose)


def test_every_world_loads_and_steps_unmutated() -> None:
    """The baseline: each stand-in world as committed loads and steps under this test's driving (so a mutation's
    failure is the mutation's)."""
    assert len(WORLDS) >= 60
    for world in WORLDS:
        run_world(world)


@pytest.mark.parametrize("examples", example_counts(600, share=6))
def test_worlds_with_degenerate_numbers_load_or_fail_in_lines_and_step_finite(examples: int) -> None:
    @settings(max_examples=examples, deadline=None, derandomize=True,
              suppress_health_check=[HealthCheck.too_slow])
    @given(which=st.integers(0, len(WORLDS) - 1), target=st.integers(0, 40),
           cuts=st.lists(st.tuples(st.integers(0, 10_000), st.integers(0, len(PICKS) - 1)), min_size=1, max_size=3))
    def run(which: int, target: int, cuts: list[tuple[int, int]]) -> None:
        with tempfile.TemporaryDirectory() as tmp:
            path, _file = mutated_copy(WORLDS[which], Path(tmp) / "w", target, cuts)
            run_world(path)

    run()


def run_batched(path: Path, c_pass: bool) -> None:
    """Two batched copies against the single simulation, the same motors driven: refused in one line, or
    every robot's pose bit for bit at every step."""
    from sensorium.gym.views import CopySim
    from sensorium.server.sim.batched import BatchedError, BatchedSimulation

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        loaded = loaded_or_refused(path)
        if loaded is None or not loaded.world.robots:
            return
        try:
            batched = BatchedSimulation(loaded, 2)
        except BatchedError as exc:
            assert "\n" not in str(exc) and str(exc).startswith(str(path)), str(exc)[:2000]
            return
        if not c_pass:
            batched._drive_step = None
        single = Simulation(loaded, "exact")
        drive(single)
        for c in range(2):
            drive(CopySim(batched, c))
        slots = {name: batched.slot(name) for name in single.robots}
        for t in range(STEPS):
            batched.step()
            single.step()
            for name, slot in slots.items():
                pose = single.robot(name).pose
                for c in range(2):
                    assert batched.pos[c, slot].tobytes() == pose.translation.tobytes(), (t, c, name)
                    assert batched.rot[c, slot].tobytes() == pose.rotation.tobytes(), (t, c, name)


@pytest.mark.parametrize("c_pass", [True, pytest.param(False, marks=pytest.mark.slow)], ids=["c", "numpy"])
def test_every_world_steps_batched_as_single_or_is_refused_in_a_line(c_pass: bool) -> None:
    for world in WORLDS:
        run_batched(world, c_pass)


@pytest.mark.parametrize("examples", example_counts(300, share=10))
def test_worlds_with_degenerate_numbers_step_batched_as_single(examples: int) -> None:
    @settings(max_examples=examples, deadline=None, derandomize=True,
              suppress_health_check=[HealthCheck.too_slow])
    @given(which=st.integers(0, len(WORLDS) - 1), target=st.integers(0, 40), c_pass=st.booleans(),
           cuts=st.lists(st.tuples(st.integers(0, 10_000), st.integers(0, len(PICKS) - 1)), min_size=1, max_size=3))
    def run(which: int, target: int, c_pass: bool, cuts: list[tuple[int, int]]) -> None:
        with tempfile.TemporaryDirectory() as tmp:
            path, _file = mutated_copy(WORLDS[which], Path(tmp) / "w", target, cuts)
            run_batched(path, c_pass)

    run()


def trace(loaded: LoadedWorld) -> list:
    """Every robot's pose and every device's value, as bytes, over STEPS steps with every device enabled and
    every motor driven."""
    sim = Simulation(loaded, "exact")
    for device in sim.all_devices():
        if hasattr(device, "enable"):
            device.enable(sim.basic_time_step)
    drive(sim)
    out: list = []
    for k in range(STEPS):
        sim.step()
        for name in sorted(sim.robots):
            pose = sim.robot(name).pose
            out.append((k, name, pose.translation.tobytes(), pose.rotation.tobytes()))
        for device in sim.all_devices():
            value = getattr(device, "value", None)
            if value is not None:
                out.append((k, device.config.name, np.asarray(value, dtype=np.float64).tobytes()))
    return out


def run_converted(path: Path) -> None:
    """The world's converted YAML, written beside it, loads and runs as the world does, bit for bit."""
    from sensorium.server.world.wbt.emit import converted_world, dump_yaml

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        loaded = loaded_or_refused(path)
        if loaded is None:
            return
        out = path.parent / "converted.yaml"
        out.write_text(dump_yaml(converted_world(path, path.parent)))
        assert trace(load_world(out, allow_outside_meshes=True)) == trace(loaded)


@pytest.mark.parametrize("examples", example_counts(200, share=20))
def test_converted_worlds_with_degenerate_numbers_run_as_the_worlds(examples: int) -> None:
    @settings(max_examples=examples, deadline=None, derandomize=True,
              suppress_health_check=[HealthCheck.too_slow])
    @given(which=st.integers(0, len(WORLDS) - 1), target=st.integers(0, 40),
           cuts=st.lists(st.tuples(st.integers(0, 10_000), st.integers(0, len(PICKS) - 1)), min_size=0, max_size=3))
    def run(which: int, target: int, cuts: list[tuple[int, int]]) -> None:
        with tempfile.TemporaryDirectory() as tmp:
            path, _file = mutated_copy(WORLDS[which], Path(tmp) / "w", target, cuts)
            run_converted(path)

    run()


def test_the_number_finder_skips_comments_strings_and_names() -> None:
    text = 'DEF WHEEL2 Solid { translation 1 -2.5 3e-2 # 7 8\n name "robot 9" size .5 }\n'
    assert [t for _, _, t in numbers_of(text)] == ["1", "-2.5", "3e-2", ".5"]
    assert math.isinf(float(replaced("1", "inf"))) and replaced("-2.5", "NEG") == "2.5"
