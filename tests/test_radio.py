"""Emitter and Receiver (server/sim/radio.py, server/devices/radio.py): Webots' delivery rules and
timing in closed form — channels, media, range at the end-of-step poses, infra-red cones and line of
sight, 1/r² signal strength, the emitter's direction in the receiver frame, noise, bounded queues —
and through the server's step requests and replies."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.schemas.wire import pack, unpack
from sensorium.server.daemon.services import Core
from sensorium.server.devices import radio as rmath
from sensorium.server.sim import radio
from sensorium.server.sim.simulation import Simulation


def world(tx=None, rx=None, a_pose=None, b_pose=None, solids=(), step=16, tx_devices=(), rx_devices=(),
          a_extra=None, b_extra=None):
    a = {"name": "a", "pose": a_pose or {"translation": [0.0, 0.0, 0.1]},
         "devices": [{"device": "Emitter", "name": "tx", **(tx or {})}, *tx_devices], **(a_extra or {})}
    b = {"name": "b", "pose": b_pose or {"translation": [3.0, 4.0, 0.1]},
         "devices": [{"device": "Receiver", "name": "rx", **(rx or {})}, *rx_devices], **(b_extra or {})}
    return Simulation(wm.World.model_validate({"world_info": {"basic_time_step": step, "random_seed": 7},
                                               "solids": list(solids), "robots": [a, b]}))


def delivered(sim, steps=2):
    rx = sim.device("b/rx")
    out = []
    for _ in range(steps):
        sim.step()
        out += rx.take()
    return out


# ---------------------------------------------------------------------- timing

def test_a_packet_is_readable_at_the_receivers_first_due_step_after_it_travelled():
    sim = world()
    tx, rx = sim.device("a/tx"), sim.device("b/rx")
    rx.enable(48)                       # first values at 48 ms (Webots: one period after enable)
    tx.send(b"one")
    times = []
    for _ in range(4):
        sim.step()
        if rx.queue_length:
            times.append(sim.time_ms)
            assert [p.data for p in rx.take()] == [b"one"]
    assert times == [48]
    rx.enable(16)
    tx.send(b"two")
    sim.step()                           # sent before this step, heard at its end (period 16)
    assert [p.data for p in rx.take()] == [b"two"]


def test_only_enabled_receivers_hear_and_a_disabled_one_forgets():
    sim = world()
    tx, rx = sim.device("a/tx"), sim.device("b/rx")
    tx.send(b"lost")                    # the receiver is off when the packet leaves
    sim.step()
    rx.enable(16)
    sim.step()
    assert rx.take() == []
    tx.send(b"kept")
    sim.step()
    tx.send(b"dropped")
    rx.disable()
    sim.step()
    rx.enable(16)
    sim.step()
    assert rx.take() == [] and rx.queue_length == 0


def test_order_is_kept_and_packets_of_several_steps_accumulate():
    sim = world(rx={"channel": 0})
    tx, rx = sim.device("a/tx"), sim.device("b/rx")
    rx.enable(64)
    for k in range(4):
        tx.send(bytes([k]) * (k + 1))
        sim.step()
    assert [p.data for p in rx.take()] == [b"\x00", b"\x01\x01", b"\x02\x02\x02", b"\x03\x03\x03\x03"]


# ---------------------------------------------------------------------- who hears what

@pytest.mark.parametrize("tx_channel,rx_channel,heard", [
    (1, 1, True), (1, 2, False), (-1, 7, True), (7, -1, True), (0, 0, True)])
def test_channels(tx_channel, rx_channel, heard):
    sim = world(tx={"channel": tx_channel}, rx={"channel": rx_channel})
    sim.device("b/rx").enable(16)
    sim.device("a/tx").send(b"x")
    assert bool(delivered(sim, 1)) is heard


@pytest.mark.parametrize("tx_type,rx_type,heard", [
    ("radio", "radio", True), ("serial", "serial", True), ("radio", "serial", False),
    ("serial", "infra-red", False), ("infra-red", "infra-red", True), ("infrared", "infra-red", True)])
def test_media_must_match(tx_type, rx_type, heard):
    sim = world(tx={"type": tx_type}, rx={"type": rx_type})
    sim.device("b/rx").enable(16)
    sim.device("a/tx").send(b"x")
    assert bool(delivered(sim, 1)) is heard


def test_a_robot_never_hears_itself_but_every_other_robot_does():
    sim = world(tx_devices=[{"device": "Receiver", "name": "own"}],
                rx_devices=[{"device": "Receiver", "name": "rx2"}])
    for path in ("a/own", "b/rx", "b/rx2"):
        sim.device(path).enable(16)
    sim.device("a/tx").send(b"x")
    sim.step()
    assert sim.device("a/own").take() == []
    assert len(sim.device("b/rx").take()) == 1 and len(sim.device("b/rx2").take()) == 1


def test_range_is_checked_at_the_end_of_step_poses():
    # the receiver is 5 m away; range 5 hears it (Webots compares r² <= range²), 4.999 does not
    for rng, heard in ((5.0, True), (4.999, False), (-1.0, True)):
        sim = world(tx={"range": rng, "max_range": -1.0})
        sim.device("b/rx").enable(16)
        sim.device("a/tx").send(b"x")
        assert bool(delivered(sim, 1)) is heard, rng
    # a receiver driving into range during the step hears a packet sent before it
    sim = world(tx={"range": 0.5}, b_pose={"translation": [0.52, 0.0, 0.1]},
                b_extra={"differential_drive": {"wheel_radius": 0.1, "axle_length": 0.1, "max_wheel_speed": 100}})
    sim.device("b/rx").enable(16)
    for m in sim.robot("b").motors.values():
        m.set_position(-math.inf)
        m.set_velocity(-25.0)           # backwards at 2.5 m/s: 0.04 m per 16 ms step
    sim.device("a/tx").send(b"x")
    sim.step()
    assert sim.robot("b").pose.translation[0] == pytest.approx(0.48)
    assert [p.data for p in sim.device("b/rx").take()] == [b"x"]


def test_set_range_follows_webots_max_range_rules():
    sim = world(tx={"range": 1.0, "max_range": 2.0})
    tx = sim.device("a/tx")
    tx.set_range(5.0)
    assert tx.range == 2.0                   # capped at maxRange
    tx.set_range(-1.0)
    assert tx.range == 2.0                   # -1 asks for the maximum
    tx.set_range(0.5)
    assert tx.range == 0.5
    with pytest.raises(ValueError):
        tx.set_range(-2.0)
    with pytest.raises(ValueError):
        wm.Emitter(device="Emitter", name="e", range=3.0, max_range=2.0)


# ---------------------------------------------------------------------- what the receiver reads

def test_signal_strength_and_direction_in_closed_form():
    # receiver at (3, 4, 0.1) turned 90° about z: the emitter at the origin is at world direction
    # (-0.6, -0.8, 0), i.e. in the receiver frame (x forward, y left) at (-0.8, 0.6, 0)
    sim = world(b_pose={"translation": [3.0, 4.0, 0.1], "rotation": [0, 0, 1, math.pi / 2]})
    sim.device("b/rx").enable(16)
    sim.device("a/tx").send(b"x")
    [p] = delivered(sim, 1)
    assert p.signal_strength == pytest.approx(1.0 / 25.0, rel=1e-15)
    assert p.direction == pytest.approx((-0.8, 0.6, 0.0), abs=1e-15)
    # device offsets count: the emitter 1 m up its robot, the receiver 1 m ahead of its own
    sim = world(tx={"pose": {"translation": [0.0, 0.0, 1.0]}}, rx={"pose": {"translation": [1.0, 0.0, 0.0]}},
                b_pose={"translation": [1.0, 0.0, 0.1]})
    sim.device("b/rx").enable(16)
    sim.device("a/tx").send(b"x")
    [p] = delivered(sim, 1)
    assert p.signal_strength == pytest.approx(1.0 / 5.0, rel=1e-14)                # r² = 2² + 1²
    assert p.direction == pytest.approx((-2 / math.sqrt(5), 0.0, 1 / math.sqrt(5)), abs=1e-15)


def test_noise_is_webots_per_receiver_stream():
    sim = world(rx={"signal_strength_noise": 0.1, "direction_noise": 0.05})
    rx, tx = sim.device("b/rx"), sim.device("a/tx")
    rx.enable(16)
    got = []
    for _ in range(400):
        tx.send(b"x")
        sim.step()
        got += rx.take()
    s = np.array([p.signal_strength for p in got])
    d = np.array([p.direction for p in got])
    # s = (1/25)(1 + 0.1 N): mean 0.04, σ 0.004 (400 samples: ±4σ/√n on the mean)
    assert abs(s.mean() - 0.04) < 4 * 0.004 / 20 and 0.0032 < s.std() < 0.0048
    assert np.allclose(np.linalg.norm(d, axis=1), 1.0, atol=1e-12)        # renormalised
    assert abs(d[:, 0].mean() + 0.6) < 0.02 and abs(d[:, 1].mean() + 0.8) < 0.02
    # the same world gives the same samples (one stream per receiver from the world seed and its path)
    sim2 = world(rx={"signal_strength_noise": 0.1, "direction_noise": 0.05})
    sim2.device("b/rx").enable(16)
    sim2.device("a/tx").send(b"x")
    [first] = delivered(sim2, 1)
    assert first == got[0]
    # rmath draws the direction's three samples before the strength's
    r = np.random.default_rng(3)
    direction, strength = rmath.reception(np.eye(3), np.zeros(3), np.array([2.0, 0.0, 0.0]), direction_noise=0.1,
                                          signal_strength_noise=0.2, rng=r)
    n = np.random.default_rng(3).standard_normal(4)
    noisy = np.array([2.0, 0.0, 0.0]) + 2.0 * 0.1 * n[:3]
    assert np.allclose(direction, noisy / np.linalg.norm(noisy), rtol=0, atol=1e-15)
    assert strength == pytest.approx(0.25 * (1 + 0.2 * n[3]), rel=1e-15)


# ---------------------------------------------------------------------- infra-red

def ir_world(tx=None, rx=None, solids=(), a_pose=None, b_pose=None):
    body = {"body": {"geometry": {"type": "cylinder", "radius": 0.1, "height": 0.2}}}
    return world(tx={"type": "infra-red", **(tx or {})}, rx={"type": "infra-red", **(rx or {})}, solids=solids,
                 a_pose=a_pose or {"translation": [0.0, 0.0, 0.1]},
                 b_pose=b_pose or {"translation": [2.0, 0.0, 0.1], "rotation": [0, 0, 1, math.pi]},
                 a_extra=body, b_extra=body)


def ir_heard(sim) -> bool:
    sim.device("b/rx").enable(16)
    sim.device("a/tx").send(b"ir")
    return bool(delivered(sim, 1))


def test_infra_red_cones_of_both_devices():
    # emitter faces +x, receiver (turned π) faces -x: face to face
    assert ir_heard(ir_world(tx={"aperture": 0.2}, rx={"aperture": 0.2}))
    # the receiver 0.5 m aside at 2 m: 14.04° off the emitter's axis; half-apertures of 14° / 14.1°
    off = {"translation": [2.0, 0.5, 0.1], "rotation": [0, 0, 1, math.pi]}
    half = math.atan2(0.5, 2.0)
    assert not ir_heard(ir_world(tx={"aperture": 2 * half - 1e-3}, b_pose=off))
    assert ir_heard(ir_world(tx={"aperture": 2 * half + 1e-3}, b_pose=off))
    assert not ir_heard(ir_world(rx={"aperture": 2 * half - 1e-3}, b_pose=off))
    assert ir_heard(ir_world(rx={"aperture": 2 * half + 1e-3}, b_pose=off))
    # behind the emitter: only an omnidirectional one (-1) reaches it
    behind = {"translation": [-2.0, 0.0, 0.1]}
    assert not ir_heard(ir_world(tx={"aperture": 3.0}, b_pose=behind))
    assert ir_heard(ir_world(tx={"aperture": -1.0}, b_pose=behind))
    # radio ignores apertures
    sim = world(tx={"aperture": 0.1}, rx={"aperture": 0.1}, b_pose={"translation": [-2.0, 0.0, 0.1]})
    assert ir_heard(sim)


def test_infra_red_needs_a_clear_line_but_the_two_robots_never_block_it():
    wall = {"name": "wall", "pose": {"translation": [1.0, 0.0, 0.1]}, "geometry": {"type": "box", "size": [0.05, 1, 1]}}
    visual = {**wall, "seen_by": "visual"}
    aside = {**wall, "pose": {"translation": [1.0, 1.0, 0.1]}}
    # both devices sit inside their robots' bodies: those never block
    assert ir_heard(ir_world())
    sim = ir_world(solids=[wall])
    assert not ir_heard(sim)
    assert sim.counters["rays_radio"] >= 1
    assert ir_heard(ir_world(solids=[visual]))        # not a bounding object
    assert ir_heard(ir_world(solids=[aside]))
    # radio passes through walls
    assert ir_heard(world(solids=[wall], b_pose={"translation": [2.0, 0.0, 0.1]}))
    # a third robot's body in between blocks
    sim = ir_world()
    third = wm.World.model_validate({"robots": [{"name": "c", "pose": {"translation": [1.0, 0.0, 0.1]},
                                                 "body": {"geometry": {"type": "box", "size": [0.1, 0.5, 0.5]}}}]})
    w = sim.world.model_copy(update={"robots": [*sim.world.robots, third.robots[0]]})
    sim = Simulation(w)
    assert not ir_heard(sim)


@pytest.mark.parametrize("precision", ["exact", "fast"])
def test_the_receiving_robots_own_shapes_never_block_however_many(precision):
    """Webots: the receiving robot's structure never blocks. A receiver behind 4 of its robot's
    own boxes (8 surfaces on the line) was read as blocked: the line of sight gave up after 8
    re-casts past them. A wall among them (a third party's) still blocks."""
    def sim_of(boxes, solids=()):
        shapes = [{"pose": {"translation": [0.05 + 0.04 * k, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.02, 0.3, 0.1]}}
                  for k in range(boxes)]
        w = world(tx={"type": "infra-red"}, rx={"type": "infra-red", "pose": {"translation": [-0.1, 0.0, 0.0]}},
                  b_pose={"translation": [2.0, 0.0, 0.1], "rotation": [0, 0, 1, math.pi]}, b_extra={"shapes": shapes},
                  solids=solids).world
        return Simulation(w, precision=precision)

    for boxes in (1, 4, 12):
        sim = sim_of(boxes)
        assert ir_heard(sim), boxes
        assert sim.counters["rays_radio"] >= 2 * boxes + 1      # one cast past each surface, one clear
    wall = {"name": "wall", "pose": {"translation": [1.8, 0.0, 0.1]}, "geometry": {"type": "box", "size": [0.01, 1, 1]}}
    assert not ir_heard(sim_of(12, [wall]))                    # (x 1.8: behind 5 of its boxes, seen from a)


# ---------------------------------------------------------------------- bounds and reset

def test_queues_are_bounded_and_drops_counted(monkeypatch):
    monkeypatch.setattr(radio, "MAX_QUEUED_PACKETS", 5)
    sim = world()
    tx, rx = sim.device("a/tx"), sim.device("b/rx")
    rx.enable(64)
    sent = [tx.send(bytes([k])) for k in range(8)]
    assert sent == [True] * 5 + [False] * 3
    sim.step()
    for k in range(3):                          # 5 waiting; 3 more arrive, 0 fit
        tx.send(bytes([10 + k]))
        sim.step()
    got = rx.take()
    assert [p.data[0] for p in got] == [0, 1, 2, 3, 4]
    sim.step()
    assert sim.counters["radio_dropped"] == 3 + 3
    monkeypatch.setattr(radio, "MAX_QUEUED_BYTES", 10)
    tx.send(b"x" * 10)
    assert not tx.send(b"y")


def test_reset_forgets_packets():
    sim = world()
    tx, rx = sim.device("a/tx"), sim.device("b/rx")
    rx.enable(32)
    tx.send(b"x")
    sim.step()
    sim.reset()
    tx.send(b"y")
    sim.run(2)
    assert [p.data for p in rx.take()] == [b"y"]


def test_reset_keeps_the_channels_set_at_run_time():
    """Webots' simulationReset does not restore an Emitter's or Receiver's ``channel`` field set by
    ``setChannel``: WbEmitter::reset / WbReceiver::reset only clear the message queues, and the
    reset matrix of Webots' Supervisor reference resets fields only on a world reload. So after
    ``sim.reset()`` the emitter still sends on channel 4 (the world file says 3) and the receiver
    still listens on 4 (the world file says 3); only the queued packets are gone."""
    sim = world(tx={"channel": 3}, rx={"channel": 3})
    tx, rx = sim.device("a/tx"), sim.device("b/rx")
    rx.enable(16)
    tx.set_channel(4)
    rx.set_channel(4)
    tx.send(b"before")
    sim.reset()
    assert (tx.channel, rx.channel) == (4, 4)
    assert delivered(sim) == []                          # the queued packet is gone
    tx.send(b"after")
    assert [p.data for p in delivered(sim)] == [b"after"]
    rx.set_channel(3)                                    # the world file's channel no longer hears it
    tx.send(b"unheard")
    assert delivered(sim) == []


# ---------------------------------------------------------------------- through the server

_ids = iter(range(1, 1 << 30))


def call(core, peer, service, args=None, now=0.0):
    return [unpack(r[-1]) for r in core.handle([peer, pack({"id": next(_ids), "service": service,
                                                            "args": args or {}})], now)]


def test_packets_travel_with_step_requests_and_replies():
    sim = world(tx={"channel": 3, "allowed_channels": [3, 4]}, rx={"channel": -1})
    core = Core(sim)
    [ra] = call(core, b"A", "attach", {"robot": "a"})
    [rb] = call(core, b"B", "attach", {"robot": "b"})
    devs = {d["name"]: d for d in ra["result"]["devices"] + rb["result"]["devices"]}
    assert devs["tx"]["channel"] == 3 and devs["tx"]["byte_rate"] == -1.0 and devs["tx"]["allowed_channels"] == [3, 4]
    assert devs["rx"]["sampling_period"] == 0 and devs["rx"]["medium"] == "radio"
    assert call(core, b"B", "/b/rx/enable", {"value": 16})[0]["ok"]
    # unknown emitter, a channel not allowed: refused whole
    [bad] = call(core, b"A", "/a/robot/step", {"duration": 16, "emitters": {"nope": []}})
    assert bad["error"]["code"] == 4
    [bad] = call(core, b"A", "/a/robot/step", {"duration": 16, "emitters": {"tx": [
        {"data": b"x", "channel": 5, "range": -1.0}]}})
    assert bad["error"]["code"] == 5 and "allowed" in bad["error"]["message"]
    assert call(core, b"A", "/a/robot/step", {"duration": 16, "emitters": {"tx": [
        {"data": b"hi", "channel": 4, "range": 7.0}, {"data": b"there", "channel": 4, "range": 7.0}]}}) == []
    assert call(core, b"B", "/b/robot/step", {"duration": 16}) == []
    replies, _ = core.step_once(0.0)
    got = {r[0]: unpack(r[-1])["result"] for r in replies}
    assert got[b"A"]["values"] == {}
    packets = got[b"B"]["values"]["rx"]["packets"]
    assert [p["data"] for p in packets] == [b"hi", b"there"]
    assert packets[0]["signal_strength"] == pytest.approx(0.04) and packets[0]["direction"] == pytest.approx([-0.6, -0.8, 0])
    # the emitter took the packets' channel and range, as Webots' node does
    assert call(core, b"X", "/a/tx/get_channel")[0]["result"]["value"] == 4
    assert call(core, b"X", "/a/tx/get_range")[0]["result"]["value"] == 7.0
    assert call(core, b"X", "/b/rx/get_buffer_size")[0]["result"]["value"] == -1
    [bad] = call(core, b"B", "/b/rx/set_channel", {"value": -2})
    assert bad["error"]["code"] == 5
