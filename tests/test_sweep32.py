"""Sweep 32: Webots' ``projects/samples/contests`` ratslife world, not run before (only loaded, in the first
sweep), on a stand-in world of ours (tests/data/sweep32/: the sample's 121 walls, 121 intervals, 4 feeders
and two e-pucks where the world stores them, our own PROTOs, sweep 22's E-puck) driven in process by the calls
its supervisor ``contest_manager`` makes (maze_builder.c, texture_generator.c, round_manager.c) and checked
against closed forms."""

from __future__ import annotations

import math
import random
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from test_supervisor import A, Live

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data"
WORLD = DATA / "sweep32" / "ratslife.wbt"
MANAGER = "contest manager"
RATIO = 0.112                     # parameters.h: a cell is 0.112 m
SIZE = 10                         # the maze is 10 × 10 cells
NORTH, SOUTH, EAST, WEST = "N", "S", "E", "W"
FEEDERS = {(0, 0): SOUTH, (9, 0): EAST, (0, 9): WEST, (9, 9): NORTH}     # our maze's special cells
RATS = {(4, 4): NORTH, (5, 5): SOUTH}


def maze_walls(seed: int = 32) -> list[tuple[tuple[int, int], tuple[int, int]]]:
    """Our own 10 × 10 maze (a random spanning tree of the cells, as the sample's generator makes one):
    the links between neighbouring cells the tree does not use, each a wall: 180 − 99 = 81 of them, so
    that with the 40 outer walls the 121 LegoWalls of the world are all used (MAX_WALLS)."""
    rng = random.Random(seed)
    seen, stack, open_links = {(0, 0)}, [(0, 0)], set()
    while stack:
        x, y = stack[-1]
        ahead = [(x + dx, y + dy) for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1))
                 if 0 <= x + dx < SIZE and 0 <= y + dy < SIZE and (x + dx, y + dy) not in seen]
        if not ahead:
            stack.pop()
            continue
        nxt = rng.choice(ahead)
        open_links.add(frozenset(((x, y), nxt)))
        seen.add(nxt)
        stack.append(nxt)
    links = [((x, y), (x + 1, y)) for x in range(SIZE - 1) for y in range(SIZE)] + \
            [((x, y), (x, y + 1)) for x in range(SIZE) for y in range(SIZE - 1)]
    return [link for link in links if frozenset(link) not in open_links]


def placements() -> list[tuple[str, float, float, float]]:
    """build_maze's placements in its order: (DEF name, x, y, alpha) for the outer walls, the inner walls,
    the intervals between the outer walls, those where inner walls meet, then the feeders and e-pucks."""
    out: list[tuple[str, float, float, float]] = []
    walls = iter(f"W{i:03d}" for i in range(121))
    intervals = iter(f"I{i:03d}" for i in range(121))
    for i in range(SIZE):
        out += [(next(walls), RATIO * i, -RATIO * 0.5, math.pi / 2),
                (next(walls), RATIO * i, RATIO * (-0.5 + SIZE), math.pi / 2)]
    for i in range(SIZE):
        out += [(next(walls), -RATIO * 0.5, RATIO * i, 0.0), (next(walls), RATIO * (-0.5 + SIZE), RATIO * i, 0.0)]
    inner = maze_walls()
    mids = []
    for a, b in inner:
        x, y = 0.5 * (RATIO * a[0] + RATIO * b[0]), 0.5 * (RATIO * a[1] + RATIO * b[1])
        mids.append((x, y))
        out.append((next(walls), x, y, 0.0 if a[0] != b[0] else math.pi / 2))
    for i in range(SIZE + 1):
        out += [(next(intervals), RATIO * (-0.5 + i), -0.5 * RATIO, 0.0),
                (next(intervals), RATIO * (-0.5 + i), RATIO * (-0.5 + SIZE), 0.0)]
    for i in range(1, SIZE):
        out += [(next(intervals), -RATIO * 0.5, RATIO * (-0.5 + i), 0.0),
                (next(intervals), RATIO * (-0.5 + SIZE), RATIO * (-0.5 + i), 0.0)]
    for j in range(SIZE - 1):
        for i in range(SIZE - 1):
            px, py = RATIO * (0.5 + i), RATIO * (0.5 + j)
            if any(math.hypot(px - x, py - y) < 1.1 * RATIO for x, y in mids):
                out.append((next(intervals), px, py, 0.0))
    feeder_angle = {NORTH: math.pi, SOUTH: 0.0, EAST: math.pi / 2, WEST: -math.pi / 2}
    rat_angle = {NORTH: 0.0, SOUTH: math.pi, EAST: -math.pi / 2, WEST: math.pi / 2}
    feeders, rats = iter(range(4)), iter(range(2))
    for j in range(SIZE):                      # maze->cells in the generator's order: row by row
        for i in range(SIZE):
            if (i, j) in FEEDERS:
                out.append((f"F{next(feeders)}", RATIO * i, RATIO * j, feeder_angle[FEEDERS[(i, j)]]))
            elif (i, j) in RATS:
                out.append((f"R{next(rats)}", RATIO * i, RATIO * j, rat_angle[RATS[(i, j)]]))
    return out


class Manager:
    """The contest manager's Supervisor calls, in process."""

    def __init__(self, sim: Simulation, log: list[str] | None = None) -> None:
        self.lv = Live(sim)
        if log is not None:
            import itertools

            from sensorium.server.daemon.services import Core
            count = itertools.count()
            self.lv.core = Core(sim, new_token=lambda: f"s{next(count)}", log=log.append)
        self.lv.ok(A, "attach", {"robot": MANAGER})

    def node(self, name: str) -> int:
        return self.lv.ok(A, f"/{MANAGER}/robot/get_from_def", {"name": name})["node"]

    def get(self, node: int, field: str) -> list:
        return self.lv.ok(A, f"/{MANAGER}/robot/get_field", {"node": node, "field": field})["value"]

    def set(self, node: int, field: str, value, **item) -> None:
        self.lv.ok(A, f"/{MANAGER}/robot/set_field", {"node": node, "field": field, "value": value, **item})

    def place_object(self, name: str, x: float, y: float, alpha: float) -> None:
        """maze_builder.c's place_object: x and y set, z kept, turned alpha + 1.5708 about z."""
        node = self.node(name)
        t = self.get(node, "translation")
        self.get(node, "rotation")
        self.set(node, "translation", [x, y, t[2]])
        self.set(node, "rotation", [0.0, 0.0, 1.0, alpha + 1.5708])


def test_the_ratslife_world_loads_with_its_walls_feeders_and_rats() -> None:
    """The stand-in loads with one line per rat (their motors' consumption is not simulated: README
    "Battery and Charger"); 121 walls, 121 intervals and 4 feeders, each feeder a Charger of the sample's
    battery; two e-pucks with their battery [200, 100, 1000] and the manager's two displays (64 × 32 and
    21 × 21, the sizes texture_generator.c reads)."""
    w = load_world(WORLD)
    assert len(w.warnings) == 2 and all("energy consumption" in x for x in w.warnings)
    names = [s.name for s in w.world.solids]
    assert sum(n.startswith("LEGO wall") for n in names) == 121
    assert sum(n.startswith("LEGO interval") for n in names) == 121
    assert [(c.battery, c.radius, c.gradual) for c in w.world.chargers] == [([100.0, 100.0, 0.833], 0.064, False)] * 4
    assert [(r.name, r.battery) for r in w.world.robots[:2]] == [("Rat0", [200.0, 100.0, 1000.0]),
                                                                 ("Rat1", [200.0, 100.0, 1000.0])]
    sim = Simulation(w, "exact")
    helper, debug = sim.device(f"{MANAGER}/helper_display"), sim.device(f"{MANAGER}/debug_display")
    assert (helper.width, helper.height, debug.width, debug.height) == (64, 32, 21, 21)


def test_the_contest_manager_builds_the_maze_where_build_maze_places_each_piece() -> None:
    """build_maze's 248 placements (121 walls, 121 intervals with ours, 4 feeders, 2 e-pucks), each read
    then set through the piece's PROTO fields (place_object): every piece stands at (x, y) with its z kept,
    turned alpha + 1.5708 about z (1e-12); a turn past π (alpha = π/2: 3.1415963) reads back as the same
    turn about −z (3.1415890, Webots' angle in [0, π]); each feeder's Charger now takes the robot that
    comes within 0.064 m of its new place."""
    sim = Simulation(load_world(WORLD), "exact")
    m = Manager(sim)
    todo = placements()
    assert len(todo) == 248 and sum(n.startswith("W") for n, *_ in todo) == 121
    assert sum(n.startswith("I") for n, *_ in todo) == 121
    for name, x, y, alpha in todo:
        m.place_object(name, x, y, alpha)
    sim.step()
    poses = {**sim.scene.solid_poses, **{r: sim.robot(r).pose for r in ("Rat0", "Rat1")}}
    for name, x, y, alpha in todo:
        node = m.node(name)
        t = np.array(m.get(node, "translation"))
        z = 0.025 if name[0] in "WI" else (0.0 if name[0] == "F" else -0.0001)
        assert t == pytest.approx([x, y, z], abs=1e-12), name
        angle = alpha + 1.5708
        r = m.get(node, "rotation")
        want = [0, 0, 1, angle] if angle <= math.pi else [0, 0, -1, 2 * math.pi - angle]
        assert r == pytest.approx(want, abs=1e-12), name
    assert m.get(m.node("W000"), "rotation") == pytest.approx([0, 0, -1, 2 * math.pi - (math.pi / 2 + 1.5708)], abs=1e-15)
    c, s = math.cos(0.0 + 1.5708), math.sin(0.0 + 1.5708)
    wall = todo[20][0]                                              # an outer side wall, alpha 0
    assert todo[20][3] == 0.0
    assert np.asarray(poses[f"LEGO wall({int(wall[1:]) + 1})"].rotation)[:2, :2] == pytest.approx(np.array([[c, -s], [s, c]]), abs=1e-15)
    # the feeders' Chargers at their new places: F0 (cell 0, 0) gives energy to a robot put there
    rat = m.node("R0")
    m.set(rat, "battery", 50.0, index=0)
    m.set(rat, "translation", [0.03, 0.0, -0.0001])
    before = m.get(rat, "battery")[0]
    sim.step()
    assert m.get(rat, "battery")[0] == pytest.approx(before + 1000 * 0.016 - 10 * 0.016, abs=1e-9)


def generate_texture(display, rng: random.Random) -> np.ndarray:
    """texture_generator.c's generate_texture on the 64 × 32 display: white, the lower right quarter's
    bottom black, two groups of 4 × 3 tiles of 8 px in one of four colours, each tile drawn or not; the
    image it copies (0xAARRGGBB)."""
    w, h = display.width, display.height
    cmds = [["color", 0xFFFFFF], ["rectangle", 0, 0, w, h, True], ["color", 0x000000],
            ["rectangle", w // 2, 3 * h // 4, w // 2, h // 4, True]]
    offset = 0
    for _ in range(2):
        cmds.append(["color", (0xFF0000, 0x00FF00, 0x0000FF, 0xFFFF00)[rng.randrange(4)]])
        for i in range(offset, offset + 4):
            for j in range(3):
                if rng.randrange(2):
                    cmds.append(["rectangle", 8 * i, 8 * j, 8, 8, True])
        offset += 4
    display.apply(display.check(cmds), 0)
    return np.array(display.pixels)


def save_jpeg(pixels: np.ndarray, path: Path) -> None:
    """wb_display_image_save's JPEG (libController's: quality 100, 4:4:4), as the client writes it."""
    rgb = np.stack([(pixels >> 16) & 255, (pixels >> 8) & 255, pixels & 255], axis=-1).astype(np.uint8)
    Image.fromarray(rgb, "RGB").save(path, format="JPEG", quality=100, subsampling=0)


def test_the_wall_textures_the_manager_saves_are_shown_on_the_walls(tmp_path: Path) -> None:
    """update_wall_textures for the first walls: the helper display draws a random texture, saves it as
    JPEG in $TMP and the manager sets the wall's ``textureUrl`` to that file, which builds the wall again
    (a PROTO field: Webots regenerates the node) where the maze put it (1e-12). With $TMP in the world's
    folder each wall shows its image (the file as Pillow decodes it); the same file named relative to the
    world (a url the PROTO does not hold, which Webots looks up in the project's protos/ and the world's
    folder) too, where it was looked for beside the PROTO only and the wall drawn untextured without a
    word; a file outside the world's folder (the sample's /tmp) is not read here: the wall is drawn
    untextured and the server's log says so in one line (README: a departure), as for a file in neither
    place (the line naming both)."""
    for folder in ("sweep32", "sweep22"):
        shutil.copytree(DATA / folder, tmp_path / folder)
    world = tmp_path / "sweep32" / "ratslife.wbt"
    sim = Simulation(load_world(world), "exact")
    log: list[str] = []
    m = Manager(sim, log)
    for name, x, y, alpha in placements()[:4]:
        m.place_object(name, x, y, alpha)
    helper = sim.device(f"{MANAGER}/helper_display")
    rng = random.Random(7)
    outside = Path("/tmp") / f"sensorium_sweep32_{id(sim)}.jpg"
    try:
        for k, url in enumerate([str(tmp_path / "sweep32" / "ratslife_0.jpg"), "ratslife_1.jpg", str(outside),
                                 str(tmp_path / "sweep32" / "ratslife_3.jpg")]):
            pixels = generate_texture(helper, rng)
            save_jpeg(pixels, Path(url) if Path(url).is_absolute() else tmp_path / "sweep32" / url)
            m.set(m.node(f"W{k:03d}"), "textureUrl", url, index=0)
        sim.step()
    finally:
        outside.unlink(missing_ok=True)
    for k, (_name, x, y, _alpha) in enumerate(placements()[:4]):
        key = f"LEGO wall({k + 1})"
        assert np.asarray(sim.scene.solid_poses[key].translation) == pytest.approx([x, y, 0.025], abs=1e-12)
        (shape,) = sim.scene.solid_shapes(key)
        texture = sim.scene.shape_model(shape).appearance.texture
        if k == 2:
            assert texture is None
            continue
        assert texture is not None and Path(texture.url).name == f"ratslife_{k}.jpg"
    assert len(log) == 1 and "1 texture not loaded" in log[0] and outside.name in log[0] and "outside" in log[0]
    # a file in neither place: its line names both (a fresh log: the server says a line's first 200
    # characters once, and these lines start alike)
    sim = Simulation(load_world(world), "exact")
    log = []
    m = Manager(sim, log)
    m.set(m.node("W004"), "textureUrl", "missing.jpg", index=0)
    (line,) = log
    assert f"looked in: {tmp_path / 'sweep32' / 'protos' / 'missing.jpg'}, {tmp_path / 'sweep32' / 'missing.jpg'};" \
        in line
    assert sim.scene.shape_model(sim.scene.solid_shapes("LEGO wall(5)")[0]).appearance.texture is None


def test_the_round_reads_the_rats_batteries_until_one_is_empty() -> None:
    """run_round each 64 ms: both batteries read through the robots' ``battery`` field (item 0, the energy
    now) drain by the e-puck's 10 W from 200 J (200 − 10·t, 1e-9), nothing charging them (the rats' own
    controllers are not run); both are empty at 20.0 s and the first read at or below 0 (20.032 s: the
    manager's step boundary) is rat 0's, so the manager declares "Rat1 wins", as round_manager.c's first
    branch does when both are empty."""
    sim = Simulation(load_world(WORLD), "exact")
    m = Manager(sim)
    rats = [m.node("R0"), m.node("R1")]
    winner, counter = None, 0
    while winner is None:
        for _ in range(4):
            sim.step()
        t = sim.time_ms / 1000.0
        battery = [m.get(r, "battery")[0] for r in rats]
        assert battery == pytest.approx([max(200.0 - 10.0 * t, 0.0)] * 2, abs=1e-9), t
        if battery[0] <= 0.0:
            winner = "Rat1"
            text = f"{winner} wins"
        elif counter > 100:
            text = f"Rat0: {battery[0]:3.2f}"
        else:
            text = "Rat0 vs Rat1"
        m.lv.ok(A, f"/{MANAGER}/robot/set_label", {"id": 0, "text": text, "x": 0.0, "y": 0.0, "size": 0.1,
                                                    "transparency": 0.0, "color": 0xFFFFFF, "font": "Arial"})
        counter += 1
    assert (winner, sim.time_ms, counter) == ("Rat1", 20032, 313)


MANAGER_CONTROLLER = '''
import os
import random
import sys
from controller import Supervisor

sys.path.insert(0, os.environ["SWEEP32_TESTS"])
from test_sweep32 import placements  # noqa: E402  (the maze's placements, build_maze's order)

sup = Supervisor()
for name, x, y, alpha in placements():                 # maze_builder.c's place_object
    node = sup.getFromDef(name)
    t = node.getField("translation").getSFVec3f()
    node.getField("rotation").getSFRotation()
    node.getField("translation").setSFVec3f([x, y, t[2]])
    node.getField("rotation").setSFRotation([0.0, 0.0, 1.0, alpha + 1.5708])
display = sup.getDevice("helper_display")
rng = random.Random(7)
w, h = display.getWidth(), display.getHeight()
for k in range(121):                                   # texture_generator.c's update_wall_textures
    display.setColor(0xFFFFFF)
    display.fillRectangle(0, 0, w, h)
    display.setColor(0x000000)
    display.fillRectangle(w // 2, 3 * h // 4, w // 2, h // 4)
    offset = 0
    for _ in range(2):
        display.setColor((0xFF0000, 0x00FF00, 0x0000FF, 0xFFFF00)[rng.randrange(4)])
        for i in range(offset, offset + 4):
            for j in range(3):
                if rng.randrange(2):
                    display.fillRectangle(8 * i, 8 * j, 8, 8)
        offset += 4
    image = display.imageCopy(0, 0, w, h)
    path = os.path.join(os.environ["TMP"], f"ratslife_{k}.jpg")
    display.imageSave(image, path)
    display.imageDelete(image)
    sup.getFromDef(f"W{k:03d}").getField("textureUrl").setMFString(0, path)
sup.step(0)
print("built", sup.getFromDef("W000").getField("translation").getSFVec3f(),
      sup.getFromDef("W000").getField("rotation").getSFRotation(), flush=True)
rats = [sup.getFromDef("R0").getField("battery"), sup.getFromDef("R1").getField("battery")]
counter = 0
while sup.step(64) != -1:                              # round_manager.c's run_round
    battery = [f.getMFFloat(0) for f in rats]
    if battery[0] <= 0.0:
        sup.setLabel(0, "Rat1 wins", 0.0, 0.0, 0.1, 0xFFFFFF, 0.0, "Arial")
        print("Rat1 wins", round(sup.getTime() * 1000), counter, flush=True)
        break
    if counter > 100:
        sup.setLabel(0, f"Rat0: {battery[0]:3.2f}", 0.0, 0.0, 0.1, 0xFF0000, 0.0, "Arial")
    else:
        sup.setLabel(0, "Rat0 vs Rat1", 0.0, 0.0, 0.1, 0xFFFFFF, 0.0, "Arial")
    if counter % 50 == 0:
        print("battery", round(sup.getTime() * 1000), *battery, flush=True)
    counter += 1
'''


@pytest.mark.slow
def test_our_contest_manager_runs_the_round_under_sensorium_run(tmp_path: Path) -> None:
    """Our Python controller making contest_manager.c's calls under ``sensorium run``, ``TMP`` in the world's
    folder: the 248 placements, 121 textures saved as JPEG by ``imageSave`` and set on the walls without a
    line, the first wall where the maze puts it (1e-12), the batteries 200 − 10·t at each 3.2 s, and the
    round won by Rat1 at 20.032 s, the manager's 313th read."""
    from _serve import child_env, sensorium

    for folder in ("sweep32", "sweep22"):
        shutil.copytree(DATA / folder, tmp_path / folder)
    world = tmp_path / "sweep32" / "ratslife.wbt"
    text = world.read_text()
    head, manager = text.rsplit('controller "<extern>"', 1)
    world.write_text(head.replace('controller "<extern>"', 'controller "<none>"') + 'controller "contest_manager"'
                     + manager)
    (tmp_path / "controllers" / "contest_manager").mkdir(parents=True)
    (tmp_path / "controllers" / "contest_manager" / "contest_manager.py").write_text(MANAGER_CONTROLLER)
    (tmp_path / "sweep32" / "tmp").mkdir()
    env = {**child_env(), "TMP": str(tmp_path / "sweep32" / "tmp"), "SWEEP32_TESTS": str(Path(__file__).parent)}
    done = subprocess.run(sensorium("run", str(world), "--until", "20200", "--rpc", "tcp://127.0.0.1:0",
                                    "--pub", "tcp://127.0.0.1:0"),
                          env=env, cwd=tmp_path, capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "not loaded" not in done.stdout + done.stderr
    assert len(list((tmp_path / "sweep32" / "tmp").glob("ratslife_*.jpg"))) == 121
    lines = [line.split("] ", 1)[1] for line in done.stdout.splitlines() if line.startswith("[contest manager] ")]
    assert lines, done.stdout[-2000:] + done.stderr[-2000:]
    built = next(line for line in lines if line.startswith("built"))
    _, x, y, alpha = placements()[0]
    numbers = [float(v) for v in built.replace("[", " ").replace("]", " ").replace(",", " ").split()[1:]]
    assert numbers == pytest.approx([x, y, 0.025, 0, 0, -1, 2 * math.pi - (alpha + 1.5708)], abs=1e-12)
    for line in (line for line in lines if line.startswith("battery")):
        t, b0, b1 = (float(v) for v in line.split()[1:])
        assert [b0, b1] == pytest.approx([200.0 - 10.0 * t / 1000.0] * 2, abs=1e-9), line
    assert "Rat1 wins 20032 312" in lines             # counter counts the reads before this one, lines[-5:]


# ------------------------------------------------------------------------------------------------ battery
# battery (projects/samples/devices, R2023a, not run by the earlier sweeps: Batteries were not simulated when
# the nineteenth ran): MyBot (wheels of radius 0.025 m, 0.09 m apart) at (0, −0.15) heading 1 rad, its battery
# [50 J, 100 J, 30 W], cpuConsumption 0.5 W; four Chargers at the arena's corners, radius 0.1, [100, 100, s]
# with s = 3, 4, 2, 5 W. battery.c: 64 ms steps, the battery sensor enabled, both wheels at 6 rad/s unless a
# distance sensor reads over 500, then turning away in proportion to the readings.
CHARGERS = [((0.43, 0.43), 3.0), ((-0.43, 0.43), 4.0), ((-0.43, -0.43), 2.0), ((0.43, -0.43), 5.0)]


def battery_speeds(v0: float, v1: float) -> tuple[float, float]:
    """battery.c's wheel speeds for the readings ``v0`` (ds0) and ``v1`` (ds1)."""
    if v1 > 500:
        return (-6.0, -3.0) if v0 > 200 else (-v1 / 100, v0 / 100 + 0.5)
    if v0 > 500:
        return v1 / 100 + 0.5, -v0 / 100
    return 6.0, 6.0


def test_the_battery_sample_drains_recharges_and_drives_by_the_closed_forms() -> None:
    """battery.c's calls in process for 20 s. The robot drives the differential drive's arcs of the speeds it
    sets (1e-12 every step: nothing stops it), turning away from the green box from 1.216 s (ds1 557) and
    along the arena's walls; its battery sensor reads the energy each 64 ms (NaN before the first sample) by
    WbCharger's rule: 50 − 0.5·t until, at 6.72 s, it comes within 0.1 m of charger 0 (full), which then
    gives 30 W (the robot's speed) each basic step while it stays within 0.11 m, until the robot holds its
    100 J (the rest wasted: it then drains from 100), and is emptied when it leaves (then gathers its 3 W);
    charger 3 takes it at 13.216 s (the basic step from there: it samples every 32 ms). The
    motors' consumption (consumptionFactor 70 × torque: physics) is not simulated: one load line."""
    w = load_world(DATA / "sweep32" / "battery.wbt")
    assert sum("energy consumption" in x for x in w.warnings) == 1
    sim = Simulation(w, "exact")
    bot = sim.robot("MyBot")
    ds = [sim.device("MyBot/ds0"), sim.device("MyBot/ds1")]
    for d in ds:
        d.enable(64)
    left, right = bot.motor("left wheel motor"), bot.motor("right wheel motor")
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(0.0)
    sim.enable_battery_sensor(bot, 64)
    assert math.isnan(bot.battery_value)
    x, y, th, speeds = 0.0, -0.15, 1.0, (0.0, 0.0)
    energy = 50.0
    chargers = [{"n": n, "at": at, "e": 100.0, "s": s, "held": False, "done": True}
                for n, (at, s) in enumerate(CHARGERS)]
    taken, first_turn = [], None
    for k in range(1, 313):
        for _ in range(2):                               # two basic steps of 32 ms
            for c in chargers:                           # WbCharger, at the step's starting position
                d = math.hypot(x - c["at"][0], y - c["at"][1])
                if c["held"] and d > 0.11:
                    c["held"], c["e"] = False, 0.0       # the robot leaving empties it
                elif not c["held"] and d <= 0.1 and c["e"] == 100.0:
                    c["held"], c["done"] = True, False
                    taken.append((c["n"], sim.time_ms))
                if c["held"]:                            # it gives the robot's 30 W; once the robot is
                    given = min(30.0 * 0.032, c["e"])    # full ("done") that energy is wasted
                    c["e"] -= given
                    if not c["done"]:
                        energy += given
                        if energy > 100.0:
                            energy, c["done"] = 100.0, True
                else:
                    c["e"] = min(c["e"] + c["s"] * 0.032, 100.0)
            sim.step()
            v, om = 0.025 * sum(speeds) / 2, 0.025 * (speeds[1] - speeds[0]) / 0.09
            if om == 0.0:
                x, y = x + v * 0.032 * math.cos(th), y + v * 0.032 * math.sin(th)
            else:
                x += v / om * (math.sin(th + om * 0.032) - math.sin(th))
                y -= v / om * (math.cos(th + om * 0.032) - math.cos(th))
                th += om * 0.032
            energy = max(energy - 0.5 * 0.032, 0.0)
        assert list(bot.pose.translation[:2]) == pytest.approx([x, y], abs=1e-12), k
        assert bot.battery_value == pytest.approx(energy, abs=1e-9), k
        if k * 64 < 6720:
            assert energy == pytest.approx(50.0 - 0.5 * k * 0.064, abs=1e-9)
        speeds = battery_speeds(ds[0].value, ds[1].value)
        if first_turn is None and speeds != (6.0, 6.0):
            first_turn = (sim.time_ms, round(ds[1].value, 2))
        left.set_velocity(speeds[0])
        right.set_velocity(speeds[1])
    assert first_turn == (1216, 557.18)
    assert taken == [(0, 6720), (3, 13216)]
