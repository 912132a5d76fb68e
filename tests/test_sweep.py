"""sensorium.sweep: specs, field paths, one run in closed form, and the same sweep on a local Ray
(2 CPUs) and on the process pool giving identical tables and recordings."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from sensorium.server.recording.reader import Recording
from sensorium.sweep import SpecError, parse_spec, run_sweep
from sensorium.sweep.run import build_world, run_one
from sensorium.sweep.spec import RunSpec, parse_path, set_path
from tests._ray import ray_or_skip

R, VMAX, AXLE = 0.0205, 6.28, 0.052


def room_world(path: Path, noise: float = 0.05) -> Path:
    """A 2 m room, one robot at the origin with a forward distance sensor (noisy table)."""
    data = {
        "world_info": {"basic_time_step": 32, "random_seed": 0},
        "solids": [{"name": n, "pose": {"translation": [x, y, 0.15]}, "geometry": {"type": "box", "size": [sx, sy, 0.3]}}
                   for n, x, y, sx, sy in [("e", 1.05, 0, 0.1, 2.2), ("w", -1.05, 0, 0.1, 2.2),
                                           ("n", 0, 1.05, 2.2, 0.1), ("s", 0, -1.05, 2.2, 0.1)]],
        "robots": [{"name": "bot", "pose": {"translation": [0, 0, 0.05]},
                    "differential_drive": {"wheel_radius": R, "axle_length": AXLE, "max_wheel_speed": VMAX},
                    "devices": [{"device": "DistanceSensor", "name": "front", "type": "laser",
                                 "lookup_table": [[0, 0, noise], [2, 2, noise]]}]}],
    }
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.fixture(scope="module")
def local_ray():
    """One local Ray (2 CPUs, loopback) for the module's Ray tests: starting Ray takes seconds."""
    ray = ray_or_skip()
    from sensorium.sweep.engines import init_ray

    started = not ray.is_initialized()
    r = init_ray(None, workers=2)
    yield r
    if started:
        r.shutdown()


def test_local_ray_runs_on_loopback_only(local_ray):
    nodes = local_ray.nodes()
    assert [n["NodeManagerAddress"] for n in nodes] == ["127.0.0.1"]
    ctx = local_ray.get_runtime_context()
    assert ctx.gcs_address.startswith("127.0.0.1:")


# ------------------------------------------------------------------------------ specs and paths

def test_field_paths_parse_and_set():
    assert parse_path("robots[0].devices[ps0].noise") == ["robots", 0, "devices", ("ps0",), "noise"]
    data = {"robots": [{"name": "a", "devices": [{"name": "ps0"}, {"name": "ps1"}]}]}
    set_path(data, "robots[a].devices[ps1].noise", 0.5)
    set_path(data, "robots[0].devices[-2].aperture", 0.1)
    assert data["robots"][0]["devices"] == [{"name": "ps0", "aperture": 0.1}, {"name": "ps1", "noise": 0.5}]
    for bad, msg in [("robots[3].x", "index 3 outside"), ("robots[b].x", "no item named 'b'"),
                     ("nothing.x", "no 'nothing'"), ("robots.name", "applies to a mapping")]:
        with pytest.raises(SpecError, match=msg):
            set_path(data, bad, 1)
    with pytest.raises(SpecError, match="bad field path"):
        parse_path("robots[0]..x")


def test_a_parameter_changes_only_its_own_field_even_through_yaml_aliases():
    # the arena's ps0..ps7 share one lookup table through a YAML anchor
    loaded, text, _ = build_world("default", 7, (("robots[epuck].devices[ps0].lookup_table[1][2]", 0.25),))
    devs = {d.name: d for d in loaded.world.robots[0].devices}
    assert devs["ps0"].lookup_table[1][2] == 0.25
    assert devs["ps1"].lookup_table[1][2] == 0.0034
    assert loaded.world.world_info.random_seed == 7
    assert yaml.safe_load(text)["robots"][0]["devices"][0]["lookup_table"][1][2] == 0.25


def test_bad_specs_are_one_clear_error():
    for data, msg in [({"seeds": []}, "seeds"), ({"duration_ms": 1.5}, "duration_ms"), ({"colour": 1}, "unknown key"),
                      ({"parameters": {"robots[0]..x": [1]}}, "bad field path"), ({"parameters": {"a": 1}}, "non-empty list"),
                      ({"record": "yes"}, "record")]:
        with pytest.raises(SpecError, match=msg):
            parse_spec(data)
    # the work a spec asks for is bounded before anything is listed (a count of 10**9 seeds built a
    # list of 10**9 integers, then as many runs)
    from sensorium.sweep.spec import MAX_RUNS
    with pytest.raises(SpecError, match=rf"^<spec>: seeds.count: at most {MAX_RUNS} runs in a sweep, got 1000000000$"):
        parse_spec({"seeds": {"count": 10**9}})
    with pytest.raises(SpecError, match=rf"^<spec>: 100200 runs \(worlds x parameter values x controllers x seeds\); "
                                        rf"a sweep holds at most {MAX_RUNS}$"):
        parse_spec({"seeds": {"count": 501}, "parameters": {"a.b": [1, 2], "c": list(range(100))}})
    assert len(parse_spec({"seeds": {"count": 500}, "parameters": {"a.b": [1, 2], "c": list(range(100))}}).runs(None)) == MAX_RUNS
    s = parse_spec({"worlds": ["w.yaml"], "seeds": {"start": 5, "count": 3}, "parameters": {"a.b": [1, 2]},
                    "controllers": ["idle", "spin"]}, base_dir=Path("/tmp"))
    runs = s.runs("/out")
    assert len(runs) == 1 * 2 * 2 * 3 and [r.seed for r in runs[:3]] == [5, 6, 7]
    assert runs[0].world == "/tmp/w.yaml" and runs[-1].recording == "/out/runs/0011.mcap"


# ------------------------------------------------------------------------------ one run

def test_circle_run_ends_where_the_arc_says_and_records_every_step(tmp_path):
    world = room_world(tmp_path / "room.yaml")
    row = run_one(RunSpec(0, str(world), 3, (), "circle", 640, str(tmp_path / "r.mcap")))
    assert row["status"] == "ok", row["error"]
    steps = 20
    v = R * (0.5 * VMAX + VMAX) / 2.0          # left wheel at half speed, right at full
    w = R * (VMAX - 0.5 * VMAX) / AXLE
    t = steps * 0.032
    assert row["steps"] == steps and row["sim_time_ms"] == 640
    assert row["bot.x"] == pytest.approx(v / w * math.sin(w * t), abs=1e-12)
    assert row["bot.y"] == pytest.approx(v / w * (1 - math.cos(w * t)), abs=1e-12)
    chord = 2 * (v / w) * math.sin(w * 0.032 / 2)
    assert row["bot.path_m"] == pytest.approx(steps * chord, abs=1e-12)
    assert row["bot/front.n"] == steps                 # the recorder demands the sensor every step
    with Recording(tmp_path / "r.mcap") as rec:
        counts = {t.topic: t.count for t in rec.topics()}
        assert counts["/bot/front/value"] == steps and counts["/clock"] == steps
        assert rec.metadata()["sensorium"]["seed"] == "3"


def test_builtin_controllers_drive_every_wheel_of_a_skid_steer_robot(tmp_path):
    """A skid-steer robot (two wheels per side) runs the circle at the same arc as a two-wheel one:
    the built-in controllers set every wheel of a side (before, the second wheels held still and
    the robot went at half speed)."""
    plain = room_world(tmp_path / "plain.yaml")
    data = yaml.safe_load(plain.read_text())
    data["robots"][0]["differential_drive"].update(
        {"left_motor": "left front", "right_motor": "right front",
         "skid_steer": {"left": ["left back"], "right": ["right back"]}})
    skid = tmp_path / "skid.yaml"
    skid.write_text(yaml.safe_dump(data))
    rows = [run_one(RunSpec(0, str(w), 3, (), "circle", 640, None)) for w in (plain, skid)]
    assert all(r["status"] == "ok" for r in rows), [r["error"] for r in rows]
    assert (rows[1]["bot.x"], rows[1]["bot.y"]) == (rows[0]["bot.x"], rows[0]["bot.y"])
    assert rows[1]["bot.path_m"] == rows[0]["bot.path_m"] > 0


def forward_controller(tmp_path: Path) -> Path:
    """A Python file controller driving every wheel of robot 'bot' at 2 rad/s."""
    ctrl = tmp_path / "fwd.py"
    ctrl.write_text("import math\n"
                    "def make(sim):\n"
                    "    for m in sim.robot('bot').motors.values():\n"
                    "        m.set_position(math.inf); m.set_velocity(2.0)\n")
    return ctrl

def test_a_python_file_controller_and_parameters(tmp_path):
    world = room_world(tmp_path / "room.yaml")
    ctrl = forward_controller(tmp_path)
    res = run_sweep({"worlds": [str(world)], "seeds": [0], "duration_ms": 320, "controllers": [f"{ctrl}:make"],
                     "parameters": {"robots[bot].differential_drive.wheel_radius": [0.01, 0.02]}, "record": False},
                    None, engine="local", workers=1, progress=False)
    assert [r["status"] for r in res.rows] == ["ok", "ok"]
    assert [r["bot.x"] for r in res.rows] == pytest.approx([2.0 * 0.01 * 0.32, 2.0 * 0.02 * 0.32], abs=1e-12)
    assert res.rows[0]["param:robots[bot].differential_drive.wheel_radius"] == 0.01


def test_a_nue_world_row_is_east_north_and_the_heading_of_the_drive(tmp_path):
    """In a NUE world (x north, y up, z east) a row's x, y are the robot's east and north and its yaw
    the heading of its drive's forward about up from east (sim/frames.py, as the gym's info["pose"]).
    The robot is built y-up, its forward its own -z, turned 0.7 about up: driven straight it goes
    d = r * w * t along (-cos 0.7, -sin 0.7) (east, north) and heads at 0.7 - pi. Before, the row read
    the world's x and y (north and up) and the own x's angle about the world's z."""
    turn, d = 0.7, 0.02 * 2.0 * 0.32
    c, s = math.cos(turn), math.sin(turn)
    data = {"world_info": {"coordinate_system": "NUE", "basic_time_step": 32},
            "robots": [{"name": "bot", "pose": {"translation": [0.4, 0.0, -0.3],
                                                "quaternion": [0.0, math.sin(turn / 2), 0.0, math.cos(turn / 2)]},
                        "differential_drive": {"wheel_radius": 0.02, "axle_length": 0.1, "max_wheel_speed": 10.0,
                                               "forward": [0.0, 0.0, -1.0]}}]}
    world = tmp_path / "nue.yaml"
    world.write_text(yaml.safe_dump(data))
    ctrl = forward_controller(tmp_path)
    res = run_sweep({"worlds": [str(world)], "seeds": [0], "duration_ms": 320, "controllers": [f"{ctrl}:make"],
                     "record": False}, None, engine="local", workers=1, progress=False)
    row = res.rows[0]
    assert row["status"] == "ok", row["error"]
    assert row["bot.x"] == pytest.approx(-0.3 - d * c, abs=1e-12)          # east: the world's z
    assert row["bot.y"] == pytest.approx(0.4 - d * s, abs=1e-12)           # north: the world's x
    assert row["bot.yaw"] == pytest.approx(turn - math.pi, abs=1e-12)
    assert row["bot.path_m"] == pytest.approx(d, abs=1e-12)


# ------------------------------------------------------------------------------ engines

def _messages(path: Path) -> list[tuple]:
    with Recording(path) as rec:
        return [(m.topic, m.ros_type, m.seq, m.stamp_ns, bytes(m.data)) for m in rec.messages()]


def test_same_sweep_on_ray_and_on_the_process_pool_gives_identical_results(tmp_path, local_ray):
    worlds = [room_world(tmp_path / "room.yaml"), "default", room_world(tmp_path / "quiet.yaml", noise=0.0)]
    bad = tmp_path / "bad.yaml"
    bad.write_text("robots:\n  - name: x\n    devices:\n      - {device: Lidar, name: l, horizontal_resolution: 0}\n")
    spec = {"worlds": [str(w) for w in worlds] + [str(bad)], "seeds": [0, 1, 2, 3], "duration_ms": 160,
            "controllers": ["circle"]}
    on_ray = run_sweep(spec, tmp_path / "ray", engine="ray", progress=False)
    on_pool = run_sweep(spec, tmp_path / "pool", engine="local", workers=2, progress=False)
    assert on_ray.engine == "ray" and on_pool.engine == "local"
    assert len(on_ray.rows) == 16
    # the bad world: 4 error rows naming the file and the field; the sweep went on
    errors = [r for r in on_ray.rows if r["status"] != "ok"]
    assert [r["run"] for r in errors] == [12, 13, 14, 15]
    assert all(str(bad) in r["error"] and "horizontal_resolution" in r["error"] for r in errors)
    strip = lambda rows: [{k: v for k, v in r.items() if k != "wall_s"} for r in rows]
    assert strip(on_ray.rows) == strip(on_pool.rows)
    assert on_ray.columns == on_pool.columns
    ok = [r for r in on_ray.rows if r["status"] == "ok"]
    # noise makes seeds differ; the noiseless room's recordings differ only in the seed metadata
    assert len({r["digest"] for r in ok[:4]}) == 4
    assert len({r["digest"] for r in ok[8:12]}) == 1
    for r in ok:
        a, b = tmp_path / "ray" / r["recording"], tmp_path / "pool" / r["recording"]
        assert _messages(a) == _messages(b) and len(_messages(a)) == r["messages"] > 0
    # the tables on disk
    import pyarrow.parquet as pq

    for out in ("ray", "pool"):
        table = pq.read_table(tmp_path / out / "summary.parquet").to_pylist()
        assert [t["digest"] for t in table] == [r["digest"] for r in on_ray.rows]
        csv_lines = (tmp_path / out / "summary.csv").read_text().splitlines()
        assert len(csv_lines) == 17 and csv_lines[0].startswith("run,world,seed,controller,status")


def test_cli_sweep_exit_codes_and_no_silent_overwrite(tmp_path):
    world = room_world(tmp_path / "room.yaml")
    spec = tmp_path / "spec.yaml"
    spec.write_text(yaml.safe_dump({"worlds": ["room.yaml", "missing.yaml"], "seeds": [1], "duration_ms": 64}))
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(Path(__file__).resolve().parents[1]),
                                                        os.environ.get("PYTHONPATH", "")])}
    cmd = [sys.executable, "-m", "sensorium", "sweep", str(spec), "--out", str(tmp_path / "out"), "--engine", "local",
           "--workers", "1", "--format", "csv", "--json"]
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=300)
    assert p.returncode == 1, p.stderr                      # one run failed: missing world
    summary = json.loads(p.stdout)
    assert summary["runs"] == 2 and summary["failed"] == 1 and summary["simulated_s"] == 0.064
    assert world.exists() and (tmp_path / "out" / "runs" / "0000.mcap").exists()
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=300)
    assert p.returncode == 2 and "already exists" in p.stderr and "Traceback" not in p.stderr
    spec.write_text("seeds: [-1]\n")
    p = subprocess.run(cmd + ["--overwrite"], capture_output=True, text=True, env=env, timeout=300)
    assert p.returncode == 2 and p.stderr.count("\n") == 1 and "seeds" in p.stderr


def test_cli_unreachable_ray_cluster_is_one_line_not_a_hang(tmp_path):
    pytest.importorskip("ray")
    spec = tmp_path / "spec.yaml"
    spec.write_text("seeds: [0]\nduration_ms: 32\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(Path(__file__).resolve().parents[1]),
                                                        os.environ.get("PYTHONPATH", "")])}
    p = subprocess.run([sys.executable, "-m", "sensorium", "sweep", str(spec), "--out", str(tmp_path / "o"),
                        "--engine", "ray", "--address", "127.0.0.1:1"], capture_output=True, text=True, env=env,
                       timeout=120)
    assert p.returncode == 2
    assert p.stderr.strip().count("\n") == 0 and "cannot join the Ray cluster at '127.0.0.1:1'" in p.stderr


# the Ray case starts a local Ray cluster (processes): slow, as the module's other Ray tests (conftest)
@pytest.mark.parametrize("engine", ["local", pytest.param("ray", marks=pytest.mark.slow)])
def test_a_run_that_kills_its_worker_is_an_error_row_and_the_others_complete(tmp_path, engine, request):
    if engine == "ray":
        request.getfixturevalue("local_ray")
    world = room_world(tmp_path / "room.yaml")
    ctrl = tmp_path / "killer.py"
    ctrl.write_text("import os\n"
                    "def make(sim):\n"
                    "    if sim.seed == 2:\n"
                    "        os._exit(3)\n")
    res = run_sweep({"worlds": [str(world)], "seeds": [0, 1, 2, 3], "duration_ms": 64, "controllers": [f"{ctrl}:make"],
                     "record": False}, None, engine=engine, workers=2, progress=False)
    assert [r["status"] for r in res.rows] == ["ok", "ok", "error", "ok"]
    assert "died" in res.rows[2]["error"] or "Crashed" in res.rows[2]["error"] or "exit" in res.rows[2]["error"]


def test_without_ray_auto_uses_the_process_pool_and_ray_is_a_clear_error(tmp_path, monkeypatch):
    import sensorium.sweep as sweep

    monkeypatch.setattr(sweep, "available", lambda engine: engine != "ray")
    spec = {"worlds": [str(room_world(tmp_path / "room.yaml"))], "seeds": [0], "duration_ms": 32, "record": False}
    assert run_sweep(spec, None, engine="auto", workers=1, progress=False).engine == "local"
    with pytest.raises(SpecError, match=r"needs Ray: pip install 'sensorium\[ray\]'"):
        run_sweep(spec, None, engine="ray", progress=False)
