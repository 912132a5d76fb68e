"""Hypothesis fuzz of the sans-IO core (issue 16): random ROUTER messages — frames, bodies, service
names, argument maps — into :meth:`Core.handle`, and random XPUB events into
:meth:`Core.subscription`, on real simulations of two test worlds.

Every reply must be a well-formed msgpack reply (``id``, ``ok``, ``result`` or ``error`` with a
protocol code) to the envelope it came from; no request may end in ``INTERNAL`` or a logged
internal error; publications carry only demanded topics. Bounded: a few hundred examples per test
(a few seconds each), no deadline (a busy CI machine)."""

from __future__ import annotations

import copy
import functools
import itertools
from collections import Counter
from pathlib import Path

import msgpack
import pytest
from _fuzz import example_counts
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sensorium.schemas import services as S
from sensorium.schemas.wire import ErrorCode
from sensorium.server.daemon.services import Core
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld, load_world

WORLDS = Path(__file__).resolve().parent / "worlds"
PEERS = [b"A", b"B", b"C"]
CODES = {int(c) for c in ErrorCode}
TOKENS = [f"s{i}" for i in range(6)]          # the cores below hand out these session tokens
SETTINGS = settings(max_examples=400, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])


@functools.cache
def _loaded_once(world: str) -> LoadedWorld:
    return load_world(WORLDS / world)


class Fuzzed:
    """One core, kept across examples (state accumulates: attached robots, pending steps, modes).
    ``copied``: its world a deep copy of the file loaded once, for a fuzz that builds a core per
    example (the copy is a fraction of a millisecond, the load tens)."""

    def __init__(self, world: str, copied: bool = False):
        self.sim = Simulation(copy.deepcopy(_loaded_once(world)) if copied else load_world(WORLDS / world))
        n = itertools.count()
        self.logs: list[str] = []
        self.core = Core(self.sim, new_token=lambda: f"s{next(n) % len(TOKENS)}", log=self.logs.append)
        self.now = 0.0

    def check_reply(self, frames: list[bytes], envelope: list[bytes] | None, rid: object) -> None:
        assert all(isinstance(f, bytes) for f in frames), frames
        if envelope is not None:
            assert frames[:-1] == envelope
        reply = msgpack.unpackb(frames[-1], raw=False, strict_map_key=False)
        assert isinstance(reply, dict) and set(reply) >= {"id", "ok"}, reply
        if isinstance(rid, int) and 0 <= rid < 1 << 64 and envelope is not None:
            assert reply["id"] == rid, (reply, rid)
        if reply["ok"] is True:
            assert isinstance(reply["result"], dict), reply
        else:
            assert reply["ok"] is False, reply
            err = reply["error"]
            assert isinstance(err["message"], str) and err["message"], reply
            assert err["code"] in CODES and err["code"] != ErrorCode.INTERNAL, reply

    def steps(self) -> None:
        """Advance while the lockstep allows (pending steps get answered)."""
        self.now += 0.05
        for _ in range(5):
            t = self.core.next_advance(self.now)
            if t is None or t > self.now:
                break
            replies, pubs = self.core.step_once(self.now)
            for frames in replies:
                self.check_reply(frames, None, None)
            demanded = {t.encode() for t in self.core.topics.demanded}
            for p in pubs:
                assert p[0].rstrip(b"\0") in demanded, p[0]

    def assert_healthy(self) -> None:
        assert self.core.errors == 0 and not [line for line in self.logs if "internal error" in line], self.logs


_CORES: dict[str, Fuzzed] = {}


def fuzzed(world: str) -> Fuzzed:
    if world not in _CORES:
        _CORES[world] = Fuzzed(world)
    return _CORES[world]


ARG_NAMES = sorted({name for spec in S.SERVICES for name in spec.args.model_fields})
scalars = (st.none() | st.booleans() | st.integers(-(1 << 63), (1 << 64) - 1)
           | st.sampled_from([0, 1, 2, 3, 8, 16, 32, 64, -1, 10_000, 1 << 31])
           | st.floats(allow_nan=True, allow_infinity=True) | st.floats(-10, 10)
           | st.text(max_size=12) | st.binary(max_size=12)
           | st.sampled_from(TOKENS + ["pause", "fast", "realtime", "translation", "rotation", "bot", "pioneer",
                                       "rover", "ls", "lidar", "left wheel motor"]))
values = st.recursive(scalars, lambda c: st.lists(c, max_size=5) | st.dictionaries(st.text(max_size=6), c, max_size=3),
                      max_leaves=16)
arg_maps = st.dictionaries(st.sampled_from(ARG_NAMES) | st.text(max_size=8), values, max_size=4)


@st.composite
def services_of(draw, core: Core) -> str:
    """Mostly real service names; sometimes near misses and noise."""
    names = sorted(core.routes)
    pick = draw(st.sampled_from(range(10)))
    if pick < 7:
        return draw(st.sampled_from(names))
    if pick == 7:
        return draw(st.sampled_from(names))[:-1]
    if pick == 8:
        return draw(st.sampled_from(["/", "//", "/bot/", "/bot/robot/", "/pioneer/robot/x", "/nobody/ls/get_value"]))
    return draw(st.text(max_size=24))


@st.composite
def messages(draw, core: Core):
    """Mostly well-shaped requests to real services with their own argument names (so handlers run),
    some with foreign or missing arguments, some malformed envelopes and bodies."""
    peer = draw(st.sampled_from(PEERS))
    envelope = [peer] + (draw(st.lists(st.binary(max_size=8), max_size=2)) if draw(st.sampled_from(range(5))) == 0 else [])
    kind = draw(st.sampled_from(range(20)))
    rid: object = draw(st.integers(0, 1 << 20)) if kind > 2 else draw(
        st.integers(0, (1 << 64) - 1) | st.integers(-5, -1) | st.none() | st.text(max_size=3))
    if kind == 0:
        return envelope, draw(st.binary(max_size=64)), None           # not msgpack, or the wrong shape
    if kind == 1:
        return envelope, msgpack.packb(draw(values)), None
    service = draw(services_of(core))
    route = core.routes.get(service)
    if route is not None and kind > 4:                                 # the service's own arguments
        fields = sorted(route.spec.args.model_fields)
        args: object = draw(st.dictionaries(st.sampled_from(fields), values, max_size=len(fields))) if fields else {}
    else:
        args = draw(arg_maps | values)
    req = {"id": rid, "service": service, "args": args}
    if kind == 2:
        del req[draw(st.sampled_from(["id", "service", "args"]))]     # a missing key
        if "id" not in req:
            rid = None
    return envelope, msgpack.packb(req), rid


@pytest.mark.parametrize("examples", example_counts(400))
@pytest.mark.parametrize("world", ["server.yaml", "webots_api.yaml"])
def test_every_request_gets_one_well_formed_reply(world, examples):
    f = fuzzed(world)

    @settings(SETTINGS, max_examples=examples)
    @given(st.lists(messages(f.core), min_size=1, max_size=8))
    def run(batch):
        for envelope, body, rid in batch:
            for frames in f.core.handle(envelope + [body], f.now):
                f.check_reply(frames, envelope if frames[:len(envelope)] == envelope else None, rid)
            f.assert_healthy()
        f.steps()
        f.assert_healthy()

    run()


@pytest.mark.parametrize("examples", example_counts(400))
@pytest.mark.parametrize("world", ["server.yaml", "webots_api.yaml"])
def test_subscription_events_keep_the_demand_consistent(world, examples):
    f = fuzzed(world)
    frames = [t.frame for t in f.core.topics.topics]
    prefixes = st.sampled_from(frames) | st.sampled_from(frames).map(lambda b: b[: max(0, len(b) // 2)]) \
        | st.binary(max_size=16) | st.just(b"")
    events = st.tuples(st.sampled_from([0, 1]), prefixes).map(lambda e: bytes([e[0]]) + e[1]) | st.binary(max_size=8)

    @settings(SETTINGS, max_examples=examples)
    @given(st.lists(events, max_size=20))
    def run(evs):
        model: Counter[bytes] = Counter()        # subscriptions per prefix (several subscribers may share one)
        for ev in evs:
            f.core.subscription(ev)
            if ev and ev[0] == 1:
                model[ev[1:]] += 1
            elif ev and ev[0] == 0 and model[ev[1:]] > 0:
                model[ev[1:]] -= 1
            live = [p for p, n in model.items() if n > 0]
            want = {t.name for t in f.core.topics.topics if any(t.frame.startswith(p) for p in live)}
            assert f.core.topics.subscribed == want
        f.steps()
        for p, n in model.items():                                # the subscribers go away
            for _ in range(n):
                f.core.subscription(b"\0" + p)
        assert f.core.topics.subscribed == set()
        f.assert_healthy()

    run()
