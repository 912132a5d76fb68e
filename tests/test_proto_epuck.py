"""The end-to-end proof: a world whose robot is an e-puck-like PROTO we wrote (tests/protos/minipuck:
eight infra-red sensors each in its own housing, eight light sensors, three ground sensors from a
slot's default PROTO, two wheels with encoders, LEDs, a template loop building the sensors) reads
bit for bit what its twin written in base nodes reads, in process and through the server with a
Webots-style controller run unchanged."""

from __future__ import annotations

import contextlib
import math
import os
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
from _serve import serve

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

ROOT = Path(__file__).resolve().parents[1]
WORLDS = Path(__file__).parent / "worlds" / "proto"
PROTO_WORLD, TWIN = WORLDS / "minipuck.wbt", WORLDS / "minipuck_twin.wbt"


def run(sim: Simulation, steps: int = 50) -> list:
    """Every device enabled, the wheels driving an arc: every reading and the robot's pose, each step."""
    for dev in sim.all_devices():
        dev.enable(sim.basic_time_step)
    robot = sim.robot("epuck")
    for side, speed in (("left", 4.0), ("right", 6.5)):
        motor = robot.motor(f"{side} wheel motor")
        motor.set_position(math.inf)
        motor.set_velocity(speed)
    out = []
    for _ in range(steps):
        sim.step()
        for dev in sim.all_devices():
            for key, value in dev.readings().items():
                out.append((dev.path, key, np.array(value, copy=True)))
        out.append(("pose", "translation", np.array(robot.pose.translation, copy=True)))
        out.append(("pose", "rotation", np.array(robot.pose.rotation, copy=True)))
    return out


def _unplaced(world) -> dict:
    """The world as data without ``written_at`` and ``made_at`` (where its file or a PROTO's body writes each
    node)."""
    def strip(v):
        if isinstance(v, dict):
            return {k: strip(x) for k, x in v.items() if k not in ("written_at", "made_at")}
        return [strip(x) for x in v] if isinstance(v, list) else v
    return strip(world.model_dump())


def test_the_proto_robot_reads_bit_for_bit_like_its_base_node_twin() -> None:
    proto, twin = load_world(PROTO_WORLD), load_world(TWIN)
    # the same world but for the robot's Supervisor type name and interface (its PROTO's; the twin's base type)
    named = [n.model_copy(update={"proto": None, "interface": []}) if n.proto == "MiniPuck" else n
             for n in proto.world.top_nodes]
    assert [n.proto for n in proto.world.top_nodes if n.robots] == ["MiniPuck"]
    # and for the DEF names and PROTOs inside it: the PROTO's DEFs are internal (not found by DEF), the
    # twin's written in the world; its sensors are instances of the PROTO's own PROTOs
    # (inner_defs: the body's DEFs as getFromProtoDef finds them)
    no_defs = dict.fromkeys(("def_name", "appearance_def", "material_def", "texture_def", "geometry_def")) | \
        {"inner_defs": []}

    def undefined(world):
        return [r.model_copy(update={"nodes": [n.model_copy(update={"def_name": None, "proto": None, "interface": [],
                                                                    "inner_defs": []})
                                               for n in r.nodes],
                                     "shapes": [p.model_copy(update={"node": p.node and p.node.model_copy(update=no_defs)})
                                                for p in r.shapes], "inner_defs": []}) for r in world.robots]

    # and where the file writes each node (the twin's world writes what the PROTO's body writes; lines differ)
    assert _unplaced(proto.world.model_copy(update={"top_nodes": named, "robots": undefined(proto.world)})) == \
        _unplaced(twin.world.model_copy(update={"robots": undefined(twin.world)}))
    assert [n.def_name for n in proto.world.robots[0].nodes if n.def_name] == []
    (robot,) = proto.world.robots
    names = [d.name for d in robot.devices]
    assert names[:16] == [f"ps{i}" for i in range(8)] + [f"ls{i}" for i in range(8)]
    assert {f"led{i}" for i in range(8)} | {"gs0", "gs1", "gs2", "top ranger", "left wheel sensor",
                                             "right wheel sensor"} <= set(names)
    assert robot.differential_drive.max_wheel_speed == 7.536           # version "2", chosen by the template
    a, b = run(Simulation(proto)), run(Simulation(twin))
    assert len(a) == len(b)
    for (pa, ka, va), (pb, kb, vb) in zip(a, b):
        assert (pa, ka) == (pb, kb)
        assert va.dtype == vb.dtype and np.array_equal(va, vb, equal_nan=True), (pa, ka)
    # and the readings are real: the wall is seen in front, the lamp lights the eyes, the floor is
    # under the ground sensors, the wheels turn and the robot moves
    last = {p: v for p, k, v in a if k == "value"}
    near = max(float(v) for p, k, v in a if p in ("epuck/ps1", "epuck/ps2") and k == "value")
    assert near > 300 and max(float(last[f"epuck/ls{i}"]) for i in range(8)) > 1000
    assert all(float(last[f"epuck/gs{i}"]) == float(last["epuck/gs0"]) > 300 for i in range(3))
    assert float(last["epuck/left wheel sensor"]) > 0
    poses = [v for p, k, v in a if p == "pose" and k == "translation"]
    assert np.linalg.norm(poses[-1] - poses[0]) > 0.05


def test_where_the_robot_came_from_is_kept() -> None:
    from sensorium.server.world.proto import ProtoSearch, expand
    from sensorium.server.world.wbt.parser import read_wbt

    expansion = expand(read_wbt(PROTO_WORLD), ProtoSearch.create(WORLDS))
    robot = next(n for n in expansion.nodes if n.type == "Robot")
    assert robot.proto == "MiniPuck" and robot.def_name == "EPUCK" and robot.instance_at == (str(PROTO_WORLD), 37, 11)
    # (the url cleaned as Webots cleans it, QDir::cleanPath: no "..")
    assert robot.source == os.path.normpath(WORLDS / "../../protos/minipuck/MiniPuck.proto")
    uses = {u.name: (u.instances, u.license) for u in expansion.protos if not u.builtin}
    assert uses == {"MiniPuck": (1, "Apache License 2.0 (Sensorium's own test PROTO)"),
                    "MiniPuckDistanceSensor": (8, "Apache License 2.0 (Sensorium's own test PROTO)"),
                    "MiniPuckGroundSensors": (1, "Apache License 2.0 (Sensorium's own test PROTO)")}


@contextlib.contextmanager
def serving(world: Path):
    with serve(world, "--precision", "exact", pub="tcp://127.0.0.1:*", stop_signal=signal.SIGTERM) as s:
        yield s.rpc


def controller_output(world: Path, steps: int = 60) -> list[str]:
    script = ROOT / "sensorium" / "client" / "examples" / "braitenberg.py"
    with serving(world) as rpc:
        out = subprocess.run([sys.executable, "-m", "sensorium", "controller", str(script), "--robot", "epuck",
                              "--url", f"{rpc}/epuck", str(steps)], capture_output=True, text=True, timeout=300,
                             env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert out.returncode == 0, out.stderr
    return [x for x in out.stdout.splitlines() if x.startswith("t=")]


def test_a_webots_controller_reads_the_proto_world_like_its_twin() -> None:
    """The example Braitenberg controller (a Webots controller: `from controller import Robot`),
    unchanged, against the PROTO world and its twin through the server: the same lines."""
    proto, twin = controller_output(PROTO_WORLD), controller_output(TWIN)
    assert len(proto) == 60 and proto == twin
    light = [float(x.split("ls0=")[1].split()[0]) for x in proto]
    assert len(set(light)) > 5                          # it moves, and sees the lamp change
