"""The Radar (Webots' node) in the simulation, closed form: which solids and robots it detects and
the distance, received power (the radar equation, by hand here), radial speed and azimuth it reads;
its limits (frustum, ranges, detectable signal, radial speeds), occlusion, cell merging, seeded
noise, its .wbt fields, its topic and ROS 2 export, and the batched simulation's refusal."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import messages as msgs
from sensorium.schemas import world as wm
from sensorium.server.daemon.services import Core
from sensorium.server.devices import radar as rmath
from sensorium.server.sim.batched import BatchedError, check_observable
from sensorium.server.sim.radar import geometry_sphere
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

STEP = 16


def world(radar: dict | None = None, solids: list | None = None, robots: list | None = None, seed: int = 0) -> wm.World:
    return wm.World.model_validate({
        "world_info": {"basic_time_step": STEP, "random_seed": seed},
        "robots": [{"name": "car", "devices": [{"device": "Radar", "name": "radar", **(radar or {})}]},
                   *(robots or [])],
        "solids": solids or []})


def target(name: str, x: float, y: float, z: float = 0.0, rcs: float = 5.0, size: float = 0.5) -> dict:
    """A ball of diameter ``size``: wholly in view, its box's centre is its origin (closed forms)."""
    return {"name": name, "pose": {"translation": [x, y, z]}, "radar_cross_section": rcs,
            "geometry": {"type": "sphere", "radius": size / 2.0}}


def by_hand_dbm(distance: float, rcs: float, pt_dbm: float = 20.0, gain_dbi: float = 20.0, f_ghz: float = 24.0) -> float:
    """The radar equation: Pr = Pt G² λ² σ / ((4π)³ r⁴), in dBm."""
    pt = 10.0 ** (pt_dbm / 10.0) / 1000.0                 # W
    g = 10.0 ** (gain_dbi / 10.0)
    lam = 299_792_458.0 / (f_ghz * 1e9)                   # m
    pr = pt * g * g * lam * lam * rcs / ((4.0 * math.pi) ** 3 * distance ** 4)
    return 10.0 * math.log10(pr / 0.001)


def run(sim: Simulation, steps: int = 1, period: int = STEP, name: str = "car/radar"):
    radar = sim.device(name)
    if not radar.enabled:
        radar.enable(period)
    for _ in range(steps):
        sim.step()
    return radar.targets


def test_a_target_ahead_reads_its_distance_power_and_azimuth() -> None:
    # a target 10 m ahead and 2 m to the right (-y): azimuth positive (Webots' sign), atan(2/10)
    sim = Simulation(world(solids=[target("truck", 10.0, -2.0, rcs=5.0)]))
    [t] = run(sim)
    d = math.sqrt(104.0)
    assert t.distance == pytest.approx(d, rel=1e-14)
    assert t.azimuth == pytest.approx(math.atan(0.2), rel=1e-14)
    assert t.received_power == pytest.approx(by_hand_dbm(d, 5.0), abs=1e-12)
    assert math.isnan(t.speed)                          # no previous position at the first value
    [t] = run(sim)
    assert t.speed == 0.0                               # at rest
    # to the left: the azimuth's sign turns; other radar settings enter the equation as written
    sim = Simulation(world({"transmitted_power": 30.0, "antenna_gain": 10.0, "frequency": 77.0},
                           solids=[target("car2", 20.0, 3.0, rcs=2.0)]))
    [t] = run(sim)
    assert t.azimuth == pytest.approx(-math.atan(3.0 / 20.0), rel=1e-14)
    assert t.received_power == pytest.approx(by_hand_dbm(math.hypot(20.0, 3.0), 2.0, 30.0, 10.0, 77.0), abs=1e-12)


def test_the_radar_pose_on_its_robot_and_the_robot_pose_count() -> None:
    # the radar 1 m forward and turned 90° left on a robot at (5, 0) facing +y: the target at (5, 11)
    # is 10 m straight ahead of it
    w = world({"pose": {"translation": [1.0, 0.0, 0.0], "rotation": [0, 0, 1, 0]}},
              solids=[target("ahead", 5.0, 11.0)])
    w = w.model_copy(update={"robots": [w.robots[0].model_copy(update={
        "pose": wm.Pose(translation=(5.0, 0.0, 0.0), rotation=(0.0, 0.0, 1.0, math.pi / 2))})]})
    [t] = run(Simulation(w))
    assert t.distance == pytest.approx(10.0, abs=1e-12) and t.azimuth == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("radar, solid", [
    ({}, target("wide", 10.0, -5.0)),                                   # |y| > x tan(0.39): outside the 0.78 rad cone
    ({}, target("high", 10.0, 0.0, z=1.0)),                             # |z| > x tan(0.05)
    ({}, target("behind", -10.0, 0.0)),
    ({}, target("far", 50.5, 0.0)),                                     # beyond max_range (50 m)
    ({}, target("near", 0.5, 0.0, size=0.2)),                           # nearer than min_range − 0.1 m
    ({}, target("plain", 10.0, 0.0, rcs=0.0)),                          # no cross section: not a target
    ({}, target("faint", 40.0, 0.0, rcs=0.001)),                       # echo weaker than -100 dBm
    ({"min_detectable_signal": -60.0}, target("faint", 10.0, 0.0, rcs=0.01)),
], ids=["azimuth", "elevation", "behind", "max_range", "min_range", "rcs0", "signal", "threshold"])
def test_what_the_radar_does_not_see(radar: dict, solid: dict) -> None:
    sim = Simulation(world(radar, solids=[solid, target("seen", 20.0, 0.0)]))
    run(sim, 2)
    assert [round(t.distance, 9) for t in sim.device("car/radar").targets] == [20.0]
    # the thresholds, by hand: the faint echoes are below them, the seen one (5 m² at 20 m) above
    assert by_hand_dbm(40.0, 0.001) < -100.0 and by_hand_dbm(10.0, 0.01) < -60.0 < by_hand_dbm(20.0, 5.0)


def test_a_moving_robot_gives_its_radial_speed() -> None:
    # a robot target 10 m ahead moved 0.25 m further each 16 ms step: +15.625 m/s (moving away);
    # then the radar's own robot drives towards it faster: the relative speed turns negative
    other = {"name": "lead", "pose": {"translation": [10.0, 0.0, 0.0]}, "radar_cross_section": 10.0,
             "body": {"geometry": {"type": "sphere", "radius": 0.2}}}
    sim = Simulation(world(robots=[other]))
    run(sim)
    lead, car = sim.robot("lead"), sim.robot("car")
    lead.set_pose([10.25, 0.0, 0.0])
    [t] = run(sim)
    assert t.speed == pytest.approx(0.25 / 0.016, rel=1e-12)
    assert t.received_power == pytest.approx(by_hand_dbm(10.25, 10.0), abs=1e-12)
    lead.set_pose([10.5, 3.0, 0.0])                       # off axis: only the radial part counts
    car.set_pose([1.0, 0.0, 0.0])
    [t] = run(sim)
    direction = np.array([9.5, 3.0, 0.0]) / math.hypot(9.5, 3.0)
    relative = (np.array([0.25, 3.0, 0.0]) - np.array([1.0, 0.0, 0.0])) / 0.016
    assert t.speed == pytest.approx(float(direction @ relative), rel=1e-12)
    assert t.distance == pytest.approx(math.hypot(9.5, 3.0), rel=1e-14)
    # radial speed limits: a window that leaves this speed out drops the target
    sim = Simulation(world({"min_radial_speed": 1.0, "max_radial_speed": 20.0}, robots=[other]))
    run(sim)
    sim.robot("lead").set_pose([10.25, 0.0, 0.0])
    assert len(run(sim)) == 1                            # 15.625 m/s: inside
    sim.robot("lead").set_pose([10.25, 0.0, 0.0])
    assert run(sim) == []                                # 0 m/s: below min_radial_speed
    # and a minimum absolute radial speed above it drops it too
    sim = Simulation(world({"min_absolute_radial_speed": 16.0}, robots=[other]))
    run(sim)
    sim.robot("lead").set_pose([10.25, 0.0, 0.0])
    assert run(sim) == []


def test_occlusion_hides_a_target_behind_a_wall() -> None:
    wall = {"name": "wall", "pose": {"translation": [5.0, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.2, 1.0, 2.0]}}
    solids = [target("hidden", 10.0, 0.0), target("clear", 10.0, -3.0), wall]
    assert sorted(round(t.distance, 6) for t in run(Simulation(world(solids=solids)))) == [
        10.0, round(math.hypot(10.0, 3.0), 6)]
    [t] = run(Simulation(world({"occlusion": True}, solids=solids)))
    assert t.distance == pytest.approx(math.hypot(10.0, 3.0), rel=1e-14)
    # the target's own shape in the way does not hide it (a 2 m box around its origin)
    [t] = run(Simulation(world({"occlusion": True}, solids=[target("big", 10.0, 0.0, size=2.0)])))
    assert t.distance == pytest.approx(10.0, rel=1e-14)


def test_targets_within_a_cell_merge_weighted_by_power() -> None:
    solids = [target("a", 10.0, -1.0, rcs=4.0), target("b", 10.2, 1.0, rcs=1.0), target("c", 30.0, 0.0)]
    sim = Simulation(world({"cell_distance": 0.5}, solids=solids))
    merged, far = run(sim)
    da, db = math.hypot(10.0, 1.0), math.hypot(10.2, 1.0)
    pa, pb = (10.0 ** (by_hand_dbm(d, s) / 10.0) for d, s in ((da, 4.0), (db, 1.0)))    # mW
    assert merged.received_power == pytest.approx(10.0 * math.log10(pa + pb), abs=1e-12)
    assert merged.distance == pytest.approx((da * pa + db * pb) / (pa + pb), rel=1e-13)
    assert merged.azimuth == pytest.approx((math.atan(0.1) * pa - math.atan(1.0 / 10.2) * pb) / (pa + pb), rel=1e-12)
    assert far.distance == pytest.approx(30.0, rel=1e-14)
    # the pure model: cell_speed > 0 keeps targets of different speeds apart
    ts = [rmath.RadarTarget(10.0, 1.0, 0.0, 0.0), rmath.RadarTarget(10.1, 1.0, 5.0, 0.0)]
    assert len(rmath.merge(ts, 0.5, 1.0)) == 2 and len(rmath.merge(ts, 0.5, 0.0)) == 1


def test_noise_is_seeded_and_reproducible() -> None:
    noisy = {"range_noise": 0.1, "speed_noise": 0.2, "angular_noise": 0.01}

    def readings(seed: int) -> list:
        sim = Simulation(world(noisy, solids=[target("a", 10.0, 0.0), target("b", 20.0, -2.0)], seed=seed))
        return [[t.as_list() for t in run(sim)] for _ in range(4)]

    a, b, c = (np.array(readings(seed)) for seed in (7, 7, 8))      # (steps, targets, 4)
    assert np.array_equal(a, b, equal_nan=True) and not np.array_equal(a, c, equal_nan=True)
    flat = a[1:].reshape(-1, 4)
    assert np.all(flat[:, 0] != np.round(flat[:, 0])) and np.all(flat[:, 2] != 0.0)   # noise was drawn
    assert np.all(np.abs(flat[:, 0] - np.tile([10.0, math.hypot(20.0, 2.0)], 3)) < 1.0)


def test_wbt_fields_and_cross_sections_are_read(tmp_path: Path) -> None:
    p = tmp_path / "w.wbt"
    p.write_text("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n"
                 'Robot { name "car" radarCrossSection 2.5 children [\n'
                 '  Radar { name "front radar" translation 0.5 0 0.2 minRange 0.5 maxRange 80 horizontalFieldOfView 0.5\n'
                 '          verticalFieldOfView 0.2 occlusion TRUE speedNoise 0.1 cellDistance 1 transmittedPower 30\n'
                 '          minRadialSpeed -5 maxRadialSpeed 40 minDetectableSignal -90 }\n] }\n'
                 'Solid { translation 20 0 0.2 name "truck" radarCrossSection 10\n'
                 '  children [ Solid { name "inner" radarCrossSection 3 } ] }\n'
                 'Solid { translation 30 0 0 name "plain" }\n')
    loaded = load_world(p)
    w = loaded.world
    r = w.robots[0].devices[0]
    assert isinstance(r, wm.Radar) and r.name == "front radar"
    assert (r.min_range, r.max_range, r.horizontal_field_of_view, r.vertical_field_of_view) == (0.5, 80.0, 0.5, 0.2)
    assert (r.occlusion, r.speed_noise, r.cell_distance, r.transmitted_power) == (True, 0.1, 1.0, 30.0)
    assert (r.min_radial_speed, r.max_radial_speed, r.min_detectable_signal) == (-5.0, 40.0, -90.0)
    assert r.antenna_gain == 20.0 and r.frequency == 24.0          # Webots' defaults
    assert w.robots[0].radar_cross_section == 2.5
    assert [(s.name, s.radar_cross_section) for s in w.solids] == [("truck", 10.0), ("plain", 0.0)]
    assert w.solids[0].children[0].radar_cross_section == 3.0        # a nested solid is a target too (Webots)
    assert not any("radarCrossSection" in line for line in loaded.warnings)
    assert not any("Radar" in line and "not simulated" in line for line in loaded.warnings)
    # the truck and its inner solid, both shape-less points 19.5 m ahead, merge in one 1 m cell
    [t] = run(Simulation(loaded), name="car/front radar")
    assert t.distance == pytest.approx(19.5, rel=1e-14)
    assert t.received_power == pytest.approx(by_hand_dbm(19.5, 13.0, pt_dbm=30.0), abs=1e-12)


def test_bad_radar_fields_are_reset_as_webots_does(tmp_path: Path) -> None:
    # WbRadar's update functions at load: each value reset with one warning naming the field
    p = tmp_path / "w.yaml"
    p.write_text("robots:\n  - name: car\n    devices:\n"
                 "      - {device: Radar, name: a, min_range: 5, max_range: 2, horizontal_field_of_view: 4,\n"
                 "         vertical_field_of_view: 2, min_radial_speed: 3, max_radial_speed: 1, range_noise: -1,\n"
                 "         frequency: -3}\n"
                 "      - {device: Radar, name: b, min_range: -1, max_range: 0}\n")
    loaded = load_world(p)
    a, b = loaded.world.robots[0].devices
    assert (a.min_range, a.max_range) == (1.0, 2.0)              # max - 1 (updateMinRange)
    assert (a.horizontal_field_of_view, a.vertical_field_of_view) == (0.78, 0.1)
    assert (a.min_radial_speed, a.max_radial_speed, a.range_noise, a.frequency) == (3.0, 4.0, 0.0, 24.0)
    assert (b.min_range, b.max_range) == (0.0, 1.0)
    assert "robots[0].devices[0].min_range: not less than max_range, reset to 1" in loaded.warnings
    assert "robots[0].devices[0].horizontal_field_of_view: outside (0, pi), reset to 0.78" in loaded.warnings
    assert "robots[0].devices[1].max_range: not greater than min_range, reset to 1" in loaded.warnings
    assert len([w for w in loaded.warnings if "devices[0]" in w]) == 6
    # a .wbt radar too, at its line
    q = tmp_path / "w.wbt"
    q.write_text("#VRML_SIM R2023b utf8\nRobot { name \"car\" children [ Radar { horizontalFieldOfView 3.5 } ] }\n")
    loaded = load_world(q)
    assert loaded.world.robots[0].devices[0].horizontal_field_of_view == 0.78
    assert any(w.endswith(":2:31: Radar (robots[0].devices[0].horizontal_field_of_view): outside (0, pi), reset to 0.78")
               for w in loaded.warnings)


def test_topic_get_targets_step_reading_and_ros2_export() -> None:
    from sensorium.server.recording.export import to_ros, to_rosbags, typestore_for
    sim = Simulation(world(solids=[target("truck", 10.0, -2.0)]))
    core = Core(sim)
    assert {"/car/radar/enable", "/car/radar/get_sampling_period", "/car/radar/get_targets"} <= set(core.routes)
    assert {t.name: t.type for t in core.topics.topics}["/car/radar/targets"] == msgs.RADAR_SCAN
    [t] = run(sim)
    ctl = core.topics.controls["car/radar"]
    scan = msgs.validate(msgs.RADAR_SCAN, core.topics.build(ctl, "targets", sim.time_ms))
    [ret] = scan.returns
    assert (ret.range, ret.azimuth, ret.amplitude) == (t.distance, -t.azimuth, t.received_power)   # REP 103: left +
    assert core.topics.reading(ctl) == {"targets": t.as_list()}
    store = typestore_for("jazzy")
    body = core.topics.build(ctl, "targets", sim.time_ms)
    ros = to_rosbags(store, msgs.RADAR_SCAN, to_ros(store, msgs.RADAR_SCAN, body))
    raw = store.serialize_cdr(ros, msgs.RADAR_SCAN)
    back = store.deserialize_cdr(raw, msgs.RADAR_SCAN)
    assert back.returns[0].range == pytest.approx(t.distance, rel=1e-6)
    assert back.header.frame_id == body["header"]["frame_id"]
    # the encoder of bag exports, Foxglove-ready recordings and the live viewer gives the same bytes
    import msgpack

    from sensorium.server.recording.export import CdrEncoder
    for distro in ("humble", "jazzy"):
        assert CdrEncoder(distro).encode(msgs.RADAR_SCAN, msgpack.packb(body)) == (msgs.RADAR_SCAN, bytes(raw))


def test_the_batched_simulation_refuses_a_radar_in_one_line() -> None:
    w = world(solids=[target("truck", 10.0, 0.0)])
    with pytest.raises(BatchedError, match=r"device 'radar' is a Radar; the batched simulation measures"):
        check_observable(w, "car", ["radar"])


def test_a_driven_robot_ahead_reads_its_wheel_speed() -> None:
    # a two-wheel robot 10 m ahead driving away at ω r = 5 rad/s × 0.1 m = 0.5 m/s
    lead = {"name": "lead", "pose": {"translation": [10.0, 0.0, 0.0]}, "radar_cross_section": 1.0,
            "body": {"geometry": {"type": "box", "size": [0.4, 0.3, 0.2]}},
            "differential_drive": {"wheel_radius": 0.1, "axle_length": 0.3, "max_wheel_speed": 10.0}}
    sim = Simulation(world(robots=[lead]))
    for motor in ("left wheel motor", "right wheel motor"):
        sim.robot("lead").motor(motor).set_position(math.inf)
        sim.robot("lead").motor(motor).set_velocity(5.0)
    run(sim)
    for k in range(2, 5):
        [t] = run(sim)
        assert t.speed == pytest.approx(0.5, rel=1e-9)
        assert t.distance == pytest.approx(10.0 + 0.5 * k * STEP / 1000.0, rel=1e-12)


def test_a_supervisor_reads_and_sets_radar_cross_sections() -> None:
    from sensorium.server.daemon.supervisor import find_node, get_field, set_field
    sim = Simulation(world(solids=[target("truck", 10.0, 0.0, rcs=5.0), target("plain", 20.0, 0.0, rcs=0.0)]))
    truck, plain, car = find_node(sim, "truck"), find_node(sim, "plain"), find_node(sim, "car")
    assert truck is not None and plain is not None and car is not None
    assert get_field(sim, truck, "radarCrossSection") == {"type": "SFFloat", "value": 5.0}
    assert get_field(sim, car, "radarCrossSection")["value"] == 0.0
    [t] = run(sim)
    set_field(sim, plain, "radarCrossSection", 2.0)            # a new target, after the others
    set_field(sim, truck, "radarCrossSection", 0.0)            # no longer one
    [t] = run(sim)
    assert t.distance == pytest.approx(20.0) and t.received_power == pytest.approx(by_hand_dbm(20.0, 2.0), abs=1e-12)
    with pytest.raises(ValueError, match="must be >= 0"):
        set_field(sim, plain, "radarCrossSection", -1.0)
    sim.reset()                                                 # back to the world file's
    assert [round(t.distance, 9) for t in run(sim)] == [10.0]


def test_probe_prints_a_radar_s_targets(capsys) -> None:
    from sensorium.cli import main
    world_file = Path(__file__).parent / "worlds" / "radar.yaml"
    assert main(["probe", str(world_file), "--enable", "bot/radar:16", "--steps", "1", "--json"]) == 0
    import json
    row = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert row["device"] == "radar" and row["targets"]["shape"] == [2, 4]
    assert row["targets"]["max"] == pytest.approx(math.sqrt(404.0), rel=1e-14)     # the truck's distance


@pytest.mark.parametrize("distro", ["humble", "jazzy"])
def test_a_recorded_radar_scan_exports_to_a_ros2_bag(tmp_path: Path, distro: str) -> None:
    """The radar's topic in a recording becomes radar_msgs/msg/RadarScan in a rosbag2 directory,
    with its message definition, read back by mcap_ros2's decoder."""
    from _recdata import make_recording
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    from sensorium.server.recording.export import export_ros2
    sim = Simulation(world(solids=[target("truck", 10.0, -2.0), target("sign", 20.0, 3.0, rcs=1.0)]))
    core = Core(sim)
    run(sim)
    ctl = core.topics.controls["car/radar"]
    body = core.topics.build(ctl, "targets", sim.time_ms)
    src = tmp_path / "rec.mcap"
    make_recording(src, steps=3, topics={"/car/radar/targets": (msgs.RADAR_SCAN, lambda t_ns, i: body, 1)})
    out = tmp_path / "bag"
    report = export_ros2(src, out, distro=distro)
    assert report.messages == 3 and not report.skipped
    [bag] = out.glob("*.mcap")
    with open(bag, "rb") as f:
        decoded = [(schema.name, obj) for schema, _, _, obj in
                   make_reader(f, decoder_factories=[DecoderFactory()]).iter_decoded_messages()]
    assert len(decoded) == 3 and all(name == msgs.RADAR_SCAN for name, _ in decoded)
    returns = decoded[0][1].returns
    assert [r.range for r in returns] == pytest.approx([math.sqrt(104.0), math.sqrt(409.0)], rel=1e-6)
    assert returns[0].azimuth == pytest.approx(-math.atan(0.2), rel=1e-6)      # REP 103: right is negative
    assert returns[1].amplitude == pytest.approx(by_hand_dbm(math.sqrt(409.0), 1.0), rel=1e-6)


def test_a_target_is_its_box_in_view_as_webots_places_it() -> None:
    # Webots' WbObjectDetection: the distance is that of the centre of the target's box in view, the
    # azimuth and speed those of its origin. A car whose shape sits 2 m ahead of its origin reads 12 m.
    car = {"name": "car2", "pose": {"translation": [10.0, 0.0, 0.0]}, "radar_cross_section": 5.0,
           "shapes": [{"pose": {"translation": [2.0, 0.0, 0.0]}, "geometry": {"type": "sphere", "radius": 0.5}}]}
    [t] = run(Simulation(world(solids=[car])))
    assert t.distance == pytest.approx(12.0, rel=1e-14) and t.azimuth == 0.0
    assert t.received_power == pytest.approx(by_hand_dbm(12.0, 5.0), abs=1e-12)
    # a ball of radius 3 whose origin is outside the frustum (atan(6/10) > 0.39) but part of it in
    # view: its box is cut at the right plane, and the azimuth is clamped to h/2
    th = math.tan(float(np.float32(0.39)))
    n = math.hypot(th, 1.0)
    d_right = (th * 10.0 - 6.0) / n                       # signed distance of the centre to the right plane
    assert -3.0 < d_right < 0.0
    centre_y = -6.0 + 0.5 * (3.0 - d_right)
    [t] = run(Simulation(world(solids=[target("wall", 10.0, -6.0, size=6.0)])))
    assert t.distance == pytest.approx(math.hypot(10.0, centre_y), rel=1e-14)
    assert t.azimuth == pytest.approx(0.39, rel=1e-15)
    # a box wholly in view: its centre (its origin here) whatever its size; and the near half of a
    # box counts for min_range: a 1 m ball 1.4 m ahead is seen at min_range 1.8 (1.4 >= 1.8 − 0.5), clamped
    [t] = run(Simulation(world({"min_range": 1.8}, solids=[target("ball", 1.4, 0.0, size=1.0)])))
    assert t.distance == 1.8


def test_occlusion_spares_a_wall_within_half_the_target_s_box() -> None:
    # Webots' hasCollided: the ray to the origin must meet something more than half the target's box
    # (along x) before the origin. The target: two balls beside its origin spanning x 8.8..11.2 (2.4 m).
    pair = {"name": "pair", "pose": {"translation": [10.0, 0.0, 0.0]}, "radar_cross_section": 5.0,
            "shapes": [{"pose": {"translation": [dx, 0.8, 0.0]}, "geometry": {"type": "sphere", "radius": 0.2}}
                       for dx in (-1.0, 1.0)]}

    def wall(x: float) -> dict:
        return {"name": "wall", "pose": {"translation": [x, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.1, 0.5, 0.5]}}

    [t] = run(Simulation(world({"occlusion": True}, solids=[pair, wall(9.2)])))    # hit at 9.15: 0.85 <= 1.2
    assert t.distance == pytest.approx(math.hypot(10.0, 0.8), rel=1e-14)
    assert run(Simulation(world({"occlusion": True}, solids=[pair, wall(7.0)]))) == []   # 3.05 > 1.2: hidden


def test_occlusion_looks_past_the_target_s_own_first_surface() -> None:
    # Webots' ONE_RAY occlusion counts every contact of the ray but the target's own: a target whose
    # only shape is a thin plate 5 m before its origin (wholly in view: its box 0.02 m along x, centre 5 m away) is
    # hidden by a wall between the plate and its origin (met at 7.45: 2.55 m > 0.01 m before the origin)
    plate = {"name": "plate", "pose": {"translation": [10.0, 0.0, 0.0]}, "radar_cross_section": 5.0,
             "shapes": [{"pose": {"translation": [-5.0, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.02, 0.4, 0.4]}}]}
    wall = {"name": "wall", "pose": {"translation": [7.5, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.1, 0.5, 0.5]}}
    [t] = run(Simulation(world({"occlusion": True}, solids=[plate])))
    assert t.distance == pytest.approx(5.0, rel=1e-14) and t.azimuth == 0.0
    [t] = run(Simulation(world(solids=[plate, wall])))
    assert t.distance == pytest.approx(5.0, rel=1e-14)
    assert run(Simulation(world({"occlusion": True}, solids=[plate, wall]))) == []


def test_a_target_without_bounding_shapes_is_its_bounding_sphere() -> None:
    """Webots' WbObjectDetection bounds a target without bounding objects by its bounding sphere
    (WbBoundingSphere: its shapes' spheres enclosed one after the other). Three visual balls of
    radius 1 at (0, 0), (4, 0) and (0, 4) in the frame of a target 10 m ahead: the first two give the
    sphere centred (2, 0) of radius 3; the third grows it to radius 2 + √5, its centre moved
    √5 − 1 towards (0, 4), along (-1, 2)/√5. Wide fields of view keep that sphere wholly in view."""
    balls = {"name": "balls", "pose": {"translation": [10.0, 0.0, 0.0]}, "radar_cross_section": 5.0,
             "shapes": [{"pose": {"translation": [x, y, 0.0]}, "geometry": {"type": "sphere", "radius": 1.0},
                         "seen_by": "visual"} for x, y in ((0, 0), (4, 0), (0, 4))]}
    wide = {"horizontal_field_of_view": 1.5, "vertical_field_of_view": 1.5}
    [t] = run(Simulation(world(wide, solids=[balls])))
    k = (math.sqrt(5.0) - 1.0) / math.sqrt(5.0)
    assert t.distance == pytest.approx(math.hypot(12.0 - k, 2.0 * k), rel=1e-13)      # not the boxes' (12, 2)
    assert t.azimuth == 0.0                                                          # its origin's
    # its x extent is the sphere's diameter: a visual 2 m cube 11.5 m ahead is within max_range 10 plus
    # half its sphere's diameter (√3), read at max_range
    cube = {"name": "cube", "pose": {"translation": [11.5, 0.0, 0.0]}, "radar_cross_section": 5.0,
            "shapes": [{"geometry": {"type": "box", "size": [2, 2, 2]}, "seen_by": "visual"}]}
    [t] = run(Simulation(world({"max_range": 10.0, "vertical_field_of_view": 0.5}, solids=[cube])))
    assert t.distance == 10.0 and t.received_power == pytest.approx(by_hand_dbm(10.0, 5.0), abs=1e-12)
    # Webots' sphere of each geometry, in its frame: a cone taller than wide, through apex and rim
    centre, r = geometry_sphere(wm.Cone(type="cone", bottom_radius=1.0, height=4.0), Path("."))
    assert r == pytest.approx(2.0 + 1.0 / 8.0) and centre == pytest.approx([0.0, 0.0, 2.0 - r])
    assert geometry_sphere(wm.Cylinder(type="cylinder", radius=3.0, height=8.0), Path("."))[1] == 5.0
    assert geometry_sphere(wm.Capsule(type="capsule", radius=1.0, height=2.0), Path("."))[1] == 2.0
    # Ritter's sphere of a mesh's points: the two farthest from the first's farthest, then each enclosed
    centre, r = rmath.ritter_sphere(np.array([[0.0, 0, 0], [2, 0, 0], [1, 1.5, 0]]))
    assert r == pytest.approx((1.5 + 1.0) / 2.0) and centre == pytest.approx([1.0, 1.5 - r, 0.0])


def test_a_solid_a_robot_carries_is_a_target_of_its_own(tmp_path: Path) -> None:
    """Webots: every Solid with radarCrossSection > 0 is a radar target, one a robot carries too: at
    its own origin, its own shapes being its box, whatever its robot's cross section. A robot at
    (5, 0) turned 90° about z carries a tag at (1, 2, 0.1) in its frame: (3, 1, 0.1) in the world."""
    tag_wbt = ('Robot {{ translation 5 0 0 rotation 0 0 1 1.5707963267948966 name "other" {own}children [\n'
               '  Solid {{ translation 1 2 0.1 name "tag" radarCrossSection 1.5\n'
               '          boundingObject Box {{ size 0.2 0.2 0.2 }} }}\n'
               '] boundingObject Box {{ size 1 1 1 }} }}\n')
    head = ("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n"
            'Robot { name "car" children [ Radar { translation 0 0 0.1 maxRange 20 verticalFieldOfView 0.5 } ] }\n')
    p = tmp_path / "w.wbt"
    p.write_text(head + tag_wbt.format(own=""))
    loaded = load_world(p)
    other = loaded.world.robots[1]
    assert other.radar_cross_section == 0.0 and [(t.name, t.radar_cross_section) for t in other.radar_targets] == [
        ("tag", 1.5)]
    assert not any("radarCrossSection" in line for line in loaded.warnings)
    yaml_robot = {"name": "other", "pose": {"translation": [5, 0, 0], "rotation": [0, 0, 1, math.pi / 2]},
                  "shapes": [{"geometry": {"type": "box", "size": [1, 1, 1]}, "seen_by": "bounding"},
                             {"pose": {"translation": [1, 2, 0.1]}, "geometry": {"type": "box", "size": [0.2, 0.2, 0.2]},
                              "seen_by": "bounding"}],
                  "radar_targets": [{"name": "tag", "pose": {"translation": [1, 2, 0.1]}, "radar_cross_section": 1.5,
                                     "shapes": [1]}]}
    yaml_world = world({"max_range": 20, "vertical_field_of_view": 0.5, "pose": {"translation": [0, 0, 0.1]}},
                       robots=[yaml_robot])
    for w in (loaded, yaml_world):
        [t] = run(Simulation(w), name="car/radar")
        assert t.distance == pytest.approx(math.sqrt(10.0), rel=1e-12)
        assert t.azimuth == pytest.approx(-math.atan2(1.0, 3.0), rel=1e-12)       # to the left: negative
        assert t.received_power == pytest.approx(by_hand_dbm(math.sqrt(10.0), 1.5), abs=1e-9)
    # with a cross section of its own the robot is a second target, its box that of its solids' bounding
    # objects, the tag's included (Webots' recursivelyCheckIfWithinBounds): in the radar frame x 2.9..5.5,
    # y -0.5..1.1, z -0.6..0.4, centre (4.2, 0.3, -0.1); its azimuth that of its origin, straight ahead
    p.write_text(head + tag_wbt.format(own="radarCrossSection 4 "))
    robot, tag = run(Simulation(load_world(p)), name="car/radar")
    assert robot.distance == pytest.approx(math.sqrt(4.2 ** 2 + 0.3 ** 2 + 0.1 ** 2), rel=1e-12) and robot.azimuth == 0.0
    assert robot.received_power == pytest.approx(by_hand_dbm(robot.distance, 4.0), abs=1e-9)
    assert tag.distance == pytest.approx(math.sqrt(10.0), rel=1e-12)


def test_the_carrying_robot_hides_its_target_from_an_occlusion_ray() -> None:
    # a tag 2 m behind its robot's 1 m cube, seen from the radar through that cube: the cube is not the
    # tag's (Webots spares the target and its solid children only), 2.5 m before its origin: hidden
    robot = {"name": "other", "pose": {"translation": [5, 0, 0]},
             "shapes": [{"geometry": {"type": "box", "size": [1, 1, 1]}},
                        {"pose": {"translation": [2, 0, 0]}, "geometry": {"type": "sphere", "radius": 0.1}}],
             "radar_targets": [{"name": "tag", "pose": {"translation": [2, 0, 0]}, "radar_cross_section": 1.0,
                                "shapes": [1]}]}
    [t] = run(Simulation(world(robots=[robot])))
    assert t.distance == pytest.approx(7.0, rel=1e-14)
    assert run(Simulation(world({"occlusion": True}, robots=[robot]))) == []


def test_a_carried_target_is_refused_in_one_line_when_its_shape_is_not_there() -> None:
    with pytest.raises(ValueError, match=r"radar_targets\[0\] \(tag\): shape index 3"):
        world(robots=[{"name": "other", "radar_targets": [{"name": "tag", "radar_cross_section": 1.0, "shapes": [3]}]}])


def test_a_solid_inside_a_top_level_solid_is_a_target_of_its_own() -> None:
    """Webots: a nested Solid with a cross section is a target at its own origin, its box its own
    bounding shapes and those of the solids inside it. A shelf at (10, 0) turned 90° about z holds a
    box at (2, 0) in its frame, (10, 2) in the world, holding in turn a ball 1 m further along its x
    (the shelf's y), its own child: the box's target spans both, x 9.75..10.25 and y 1.8..3.25: centre
    (10, 2.525); its azimuth that of its own origin, atan(2/10) to the left. A Supervisor removing
    the shelf removes its nested target too; one importing it adds it."""
    shelf = {"name": "shelf", "pose": {"translation": [10, 0, 0], "rotation": [0, 0, 1, math.pi / 2]},
             "geometry": {"type": "box", "size": [1, 1, 1]},
             "children": [{"name": "box", "pose": {"translation": [2, 0, 0]}, "radar_cross_section": 2.0,
                           "geometry": {"type": "box", "size": [0.4, 0.4, 0.04]},
                           "children": [{"name": "ball", "pose": {"translation": [1, 0, 0]},
                                         "geometry": {"type": "sphere", "radius": 0.25}}]}]}
    sim = Simulation(world({"max_range": 20, "horizontal_field_of_view": 1.0}, solids=[shelf]))
    [t] = run(sim)
    assert t.distance == pytest.approx(math.hypot(10.0, 2.525), rel=1e-12)
    assert t.azimuth == pytest.approx(-math.atan2(2.0, 10.0), rel=1e-12)
    assert t.received_power == pytest.approx(by_hand_dbm(t.distance, 2.0), abs=1e-9)
    sim.scene.remove_solid("shelf")
    assert run(sim) == []
    # one a Supervisor imports brings its nested target along
    sim.scene.add_solid(wm.Solid.model_validate({**shelf, "name": "shelf2"}), node_id=99)
    [t] = run(sim)
    assert t.distance == pytest.approx(math.hypot(10.0, 2.525), rel=1e-12)


def test_webots_radar_sample_s_target_boxes_are_targets_of_their_own(tmp_path: Path) -> None:
    """Webots' radar sample puts a small Solid with radarCrossSection 1 on each robot (and its Radar,
    a Solid too, has one): each is a target at its own place, the robots themselves none."""
    p = tmp_path / "w.wbt"
    carrier = ('Robot {{ translation {x} {y} 0 name "{name}" children [\n'
               '  Solid {{ translation 0 0 0.1 name "tag" radarCrossSection 1 children [ Shape {{ geometry Box {{ size 0.04 0.04 0.04 }} }} ] }}\n'
               '  {more}] boundingObject Pose {{ translation 0 0 0.1 children [ Box {{ size 0.2 0.2 0.2 }} ] }} }}\n')
    p.write_text("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n"
                 'Robot { name "car" children [ Radar { translation 0 0 0.1 minRange 0.01 maxRange 10 verticalFieldOfView 0.5\n'
                 '                                     radarCrossSection 2 } ] }\n'
                 + carrier.format(x=2, y=0, name="one", more="")
                 + carrier.format(x=4, y=0.5, name="two", more='Solid { name "tag2" translation 0 0 0.1 radarCrossSection 0.5 }\n'))
    loaded = load_world(p)
    assert [r.radar_cross_section for r in loaded.world.robots] == [0.0, 0.0, 0.0]
    assert [[(t.name, t.radar_cross_section) for t in r.radar_targets] for r in loaded.world.robots] == [
        [("radar", 2.0)], [("tag", 1.0)], [("tag", 1.0), ("tag2", 0.5)]]
    targets = run(Simulation(loaded), name="car/radar")       # its own Radar, at its own place, is not one
    assert len(targets) == 3
    for t, (x, y, rcs) in zip(targets, ((2.0, 0.0, 1.0), (4.0, 0.5, 1.0), (4.0, 0.5, 0.5))):
        r = math.hypot(x, y)            # each tag's box (a point for the shape-less tag2) at the radar's height
        assert t.distance == pytest.approx(r, rel=1e-12)
        assert t.received_power == pytest.approx(by_hand_dbm(r, rcs), abs=1e-9)
        assert t.azimuth == pytest.approx(-math.atan2(y, x), abs=1e-12)     # Webots: positive to the right


def test_a_wbt_target_solid_past_a_hinge_rides_on_its_joint(tmp_path: Path) -> None:
    # the .wbt import gives a carried target found in a joint's end point that joint's motor: turned
    # by -pi/2 about z, the tag 3 m to the robot's left comes to 3 m ahead of it (13 m from the radar)
    p = tmp_path / "w.wbt"
    p.write_text("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n"
                 'Robot { name "car" children [ Radar { } ] }\n'
                 'Robot { translation 10 0 0 name "arm" children [\n'
                 '  HingeJoint { jointParameters HingeJointParameters { axis 0 0 1 }\n'
                 '    device [ RotationalMotor { name "pan" maxVelocity 100 maxTorque 100000 } ]\n'
                 '    endPoint Solid { translation 0 3 0 name "tag" radarCrossSection 1\n'
                 '                     boundingObject Box { size 0.2 0.2 0.2 } } }\n'
                 '] controller "<extern>" }\n')
    loaded = load_world(p)
    [tag] = loaded.world.robots[1].radar_targets
    assert (tag.name, tag.on_joint, tag.radar_cross_section, tag.shapes) == ("tag", "pan", 1.0, [0])
    sim = Simulation(loaded)
    [t] = run(sim)
    assert t.distance == pytest.approx(math.hypot(10.0, 3.0), abs=1e-12)
    sim.robot("arm").motor("pan").set_position(-math.pi / 2)
    [t] = run(sim)
    assert t.distance == pytest.approx(13.0, abs=1e-12) and t.azimuth == pytest.approx(0.0, abs=1e-12)


def test_target_boxes_named_empty_as_in_webots_radar_sample_load(tmp_path: Path) -> None:
    """Webots' radar.wbt names its target boxes ``name ""``; the import refused the world ("robots[1].
    radar_targets[0].name: String should have at least 1 character"), and a top-level or nested Solid
    named "" the same. An empty Solid name is the default one ("solid"), as when none is given; the
    boxes are targets at their places."""
    p = tmp_path / "w.wbt"
    p.write_text("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n"
                 'Robot { name "car" children [ Radar { translation 0 0 0.1 minRange 0.01 maxRange 10 '
                 'verticalFieldOfView 0.5 } ] }\n'
                 'Robot { translation 2 0 0 name "one" children [\n'
                 '  Solid { translation 0 0 0.1 name "" radarCrossSection 1 children [ Shape { geometry Box { '
                 'size 0.04 0.04 0.04 } } ] } ] }\n'
                 'Solid { translation 4 1 0.1 name "" children [ Solid { name "" radarCrossSection 0.5 } ] }\n')
    loaded = load_world(p)
    assert [(t.name, t.radar_cross_section) for t in loaded.world.robots[1].radar_targets] == [("solid", 1.0)]
    (top,) = loaded.world.solids
    assert top.name == "solid" and [c.name for c in top.children] == ["solid"]
    targets = run(Simulation(loaded), name="car/radar")
    # each at its box's centre (a point for the shape-less nested one), at the radar's height
    assert [t.distance for t in targets] == [pytest.approx(2.0, rel=1e-12), pytest.approx(math.hypot(4, 1), rel=1e-12)]
