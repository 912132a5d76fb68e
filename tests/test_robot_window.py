"""Robot windows headless (README "Robot windows"): what a controller sends its window
(``wwi_send``) is published on ``/<robot>/robot_window`` (std_msgs/String) when it arrives, for
subscribers and recordings; what is sent to its window side (``window_send``, ``sensorium window``)
waits in a bounded queue and comes with the controller's next step reply, read one text per
``wwiReceiveText`` call. The core is driven sans-IO here; the processes (serve, CLI, a Python and a
C controller) in the slow tests below and in tests/test_c_client.py."""

from __future__ import annotations

import subprocess
from pathlib import Path
from types import SimpleNamespace

import msgpack
import pytest
from _serve import REPO, Proc, child_env, sensorium, serve, wait_until

from sensorium.schemas import services as S
from sensorium.schemas.wire import ErrorCode, pack
from sensorium.server.daemon.services import Core
from sensorium.server.recording.reader import Recording
from sensorium.server.recording.writer import McapRecorder
from sensorium.server.sim.simulation import Simulation

WORLD = Path(__file__).parent / "worlds" / "server.yaml"
ARENA = REPO / "sensorium" / "worlds" / "arena.yaml"
CTRL = b"controller"
OTHER = b"someone else"


class Client:
    """Requests to a core as one ROUTER peer; replies decoded."""

    def __init__(self, core: Core, peer: bytes):
        self.core, self.peer, self.ids = core, peer, 0

    def send(self, service: str, args: dict | None = None) -> list[dict]:
        self.ids += 1
        body = pack({"id": self.ids, "service": service, "args": args or {}})
        return [msgpack.unpackb(r[-1], raw=False) for r in self.core.handle([self.peer, body], 0.0)]

    def call(self, service: str, args: dict | None = None) -> dict:
        (reply,) = self.send(service, args)
        return reply


def attached_core() -> tuple[Core, Client]:
    core = Core(Simulation.from_file(WORLD, precision="fast"), log=lambda line: None)
    ctl = Client(core, CTRL)
    assert ctl.call("attach", {"robot": "bot"})["ok"]
    return core, ctl


def step(core: Core, ctl: Client, duration: int = 32) -> dict:
    """One step request and the world steps until it is answered: its result."""
    assert ctl.send("/bot/robot/step", {"duration": duration}) == []       # answered later
    while True:
        replies, _ = core.step_once(0.0)
        if replies:
            (reply,) = [msgpack.unpackb(r[-1], raw=False) for r in replies]
            assert reply["ok"], reply
            return reply["result"]


def test_a_controllers_text_is_published_on_its_robot_window_topic_when_it_arrives():
    core, ctl = attached_core()
    core.subscription(b"\x01/bot/robot_window\0")
    assert {"name": "/bot/robot_window", "type": "std_msgs/msg/String"} in ctl.call("get_info")["result"]["topics"]
    got: list[tuple] = []
    core.topics.set_recorder(lambda *m: got.append(m), ["/bot/robot_window"])
    step(core, ctl, 64)                                   # sent at 64 ms: stamped so
    assert ctl.call("/bot/robot/wwi_send", {"text": "time:1.500"})["result"] == {"success": True}
    assert ctl.call("/bot/robot/wwi_send", {"text": "record:0.87\nsecond line"})["ok"]
    frames = core.topics.outbox                          # published between steps: the transport sends these
    assert [f[0] for f in frames] == [b"/bot/robot_window\0"] * 2
    envelopes = [msgpack.unpackb(f[1]) for f in frames]
    assert envelopes == [{"type": "std_msgs/msg/String", "seq": 0, "stamp_ns": 64_000_000},
                         {"type": "std_msgs/msg/String", "seq": 1, "stamp_ns": 64_000_000}]
    assert [msgpack.unpackb(f[2]) for f in frames] == [{"data": "time:1.500"}, {"data": "record:0.87\nsecond line"}]
    # the recorder got the very bytes published
    assert [(g[0], g[1], g[2], g[3], g[4], g[5]) for g in got] == \
        [("/bot/robot_window", "std_msgs/msg/String", f[1], f[2], 64_000_000, k) for k, f in enumerate(frames)]


def test_only_the_attached_controller_sends_its_window_text():
    core, _ = attached_core()
    reply = Client(core, OTHER).call("/bot/robot/wwi_send", {"text": "x"})
    assert not reply["ok"] and reply["error"]["code"] == ErrorCode.NOT_ATTACHED
    assert core.topics.outbox == []


def test_a_recording_keeps_the_robot_window_texts_with_their_type(tmp_path):
    core, ctl = attached_core()
    path = tmp_path / "window.mcap"
    rec = McapRecorder(path, world_text=WORLD.read_text(), world_name=WORLD.name, background_flush=False)
    core.topics.set_recorder(rec)                        # every topic, as serve --record
    step(core, ctl)
    ctl.call("/bot/robot/wwi_send", {"text": "score: 12"})
    step(core, ctl)
    ctl.call("/bot/robot/wwi_send", {"text": "stop"})
    core.topics.set_recorder(None)
    rec.close()
    with Recording(path) as r:
        info = {t.topic: t for t in r.topics()}
        assert info["/bot/robot_window"].ros_type == "std_msgs/msg/String"
        msgs = list(r.messages(["/bot/robot_window"]))
        assert "foxglove_view_errors" not in r.metadata()      # its CDR view (std_msgs/String) was written too
    assert [(m.seq, m.stamp_ns, m.decode()) for m in msgs] == [(0, 32_000_000, {"data": "score: 12"}),
                                                               (1, 64_000_000, {"data": "stop"})]


def test_texts_sent_to_the_controller_are_published_on_their_own_topic_when_queued():
    """``window_send`` publishes its text on ``/<robot>/robot_window/to_controller`` at once, stamped
    with the simulated time it was queued, interleaved with the controller's own texts in the order
    they came; a text the full queue refuses is not published."""
    core, ctl = attached_core()
    anyone = Client(core, OTHER)
    core.subscription(b"\x01/bot/robot_window")         # a prefix: both directions
    assert {"name": "/bot/robot_window/to_controller", "type": "std_msgs/msg/String"} in \
        ctl.call("get_info")["result"]["topics"]
    step(core, ctl, 96)
    assert anyone.call("/bot/robot/window_send", {"text": "speed:2"})["result"]["queued"] == 1
    assert ctl.call("/bot/robot/wwi_send", {"text": "ack"})["ok"]
    assert anyone.call("/bot/robot/window_send", {"text": "é ✓\nline"})["ok"]
    step(core, ctl, 32)                                    # the controller takes them; time 128 ms
    assert anyone.call("/bot/robot/window_send", {"text": "later"})["ok"]
    frames = core.topics.outbox
    assert [(f[0], msgpack.unpackb(f[1]), f[2]) for f in frames] == [
        (b"/bot/robot_window/to_controller\0", {"type": "std_msgs/msg/String", "seq": 0, "stamp_ns": 96_000_000},
         pack({"data": "speed:2"})),
        (b"/bot/robot_window\0", {"type": "std_msgs/msg/String", "seq": 0, "stamp_ns": 96_000_000}, pack({"data": "ack"})),
        (b"/bot/robot_window/to_controller\0", {"type": "std_msgs/msg/String", "seq": 1, "stamp_ns": 96_000_000},
         pack({"data": "é ✓\nline"})),
        (b"/bot/robot_window/to_controller\0", {"type": "std_msgs/msg/String", "seq": 2, "stamp_ns": 128_000_000},
         pack({"data": "later"})),
    ]
    core.topics.outbox = []
    for k in range(S.MAX_WINDOW_QUEUE - 1):               # "later" waits already: fill the queue
        assert anyone.call("/bot/robot/window_send", {"text": str(k)})["ok"]
    assert len(core.topics.outbox) == S.MAX_WINDOW_QUEUE - 1
    core.topics.outbox = []
    assert anyone.call("/bot/robot/window_send", {"text": "refused"})["error"]["code"] == ErrorCode.WRONG_STATE
    assert core.topics.outbox == []


def window_dialogue(path: Path) -> None:
    """A recording (every topic, as serve --record) of texts both ways over two steps."""
    core, ctl = attached_core()
    anyone = Client(core, OTHER)
    rec = McapRecorder(path, world_text=WORLD.read_text(), world_name=WORLD.name, background_flush=False)
    core.topics.set_recorder(rec)
    step(core, ctl)
    anyone.call("/bot/robot/window_send", {"text": "start"})
    ctl.call("/bot/robot/wwi_send", {"text": "started"})
    step(core, ctl)
    ctl.call("/bot/robot/wwi_send", {"text": "score: 12"})
    anyone.call("/bot/robot/window_send", {"text": "stop"})
    core.topics.set_recorder(None)
    rec.close()


DIALOGUE = [("/bot/robot_window/to_controller", 32_000_000, "start"), ("/bot/robot_window", 32_000_000, "started"),
            ("/bot/robot_window", 64_000_000, "score: 12"), ("/bot/robot_window/to_controller", 64_000_000, "stop")]


def test_a_recording_holds_both_directions_in_order(tmp_path):
    path = tmp_path / "dialogue.mcap"
    window_dialogue(path)
    with Recording(path) as r:
        info = {t.topic: t for t in r.topics()}
        assert info["/bot/robot_window/to_controller"].ros_type == "std_msgs/msg/String"
        assert "foxglove_view_errors" not in r.metadata()
        msgs = list(r.messages(["/bot/robot_window"]))   # a prefix: both directions, in publication order
    assert [(m.topic, m.stamp_ns, m.decode()["data"]) for m in msgs] == DIALOGUE
    assert [m.seq for m in msgs] == [0, 0, 1, 1]


@pytest.mark.slow
def test_a_replay_publishes_both_directions_in_order(tmp_path):
    """`sensorium replay --topics /bot/robot_window` (a pattern taking both topics) and `sensorium echo`:
    the dialogue as it was published, with its stamps."""
    import json

    from _serve import Served

    path = tmp_path / "dialogue.mcap"
    window_dialogue(path)
    any_port = "tcp://127.0.0.1:*"
    with Served(sensorium("replay", str(path), "--pub", any_port, "--rpc", any_port, "--rate", "0", "--wait",
                          "--topics", "/bot/robot_window"), "sensorium: replaying").wait_ready() as replay:
        with Proc(sensorium("echo", "/bot/", "--json", "--count", "4", "--url", replay.rpc)) as printer:
            assert printer.wait(60) == 0, printer.stderr()
        assert replay.wait(60) == 0, replay.stderr()
    printed = [json.loads(line) for line in printer.stdout().splitlines()]
    assert [(m["topic"], m["stamp_ns"], m["body"]["data"]) for m in printed] == DIALOGUE


def test_foxglove_readers_decode_both_directions_in_order(tmp_path):
    """Foxglove's TypeScript MCAP reader (@mcap/core) and ROS 2 CDR decoder read the Foxglove-ready
    view of both topics, in the order they were published."""
    from _node import require_node, run_script

    require_node()
    path = tmp_path / "dialogue.mcap"
    window_dialogue(path)
    got = run_script("read_mcap.js", str(path), "/bot/robot_window", "/bot/robot_window/to_controller")[0]
    assert got["errors"] == []
    channels = {c["topic"]: c for c in got["channels"]}
    assert channels["/bot/robot_window/to_controller"]["schemaName"] == "std_msgs/msg/String"
    assert [(m["topic"], m["log_time"], m["msg"]) for m in got["every"]] == \
        [(topic, ns, {"data": text}) for topic, ns, text in DIALOGUE]


def test_texts_sent_to_the_window_side_come_with_the_next_step_reply_in_order():
    core, ctl = attached_core()
    anyone = Client(core, OTHER)                         # any caller (open controls): the CLI's way
    assert [anyone.call("/bot/robot/window_send", {"text": t})["result"]["queued"] for t in ("go", "left", "é ✓")] \
        == [1, 2, 3]
    first = step(core, ctl)
    assert first["robot_window"] == ["go", "left", "é ✓"]
    assert "robot_window" not in step(core, ctl)          # delivered once
    anyone.call("/bot/robot/window_send", {"text": "now"})
    now = ctl.call("/bot/robot/step", {"duration": 0})["result"]     # step(0) delivers them too
    assert now["robot_window"] == ["now"] and now["time_ms"] == 64


def test_the_window_queue_is_bounded_and_overflow_is_one_clear_error():
    core, ctl = attached_core()
    anyone = Client(core, OTHER)
    for k in range(S.MAX_WINDOW_QUEUE):
        assert anyone.call("/bot/robot/window_send", {"text": str(k)})["ok"]
    full = anyone.call("/bot/robot/window_send", {"text": "one more"})
    assert not full["ok"] and full["error"]["code"] == ErrorCode.WRONG_STATE
    assert full["error"]["message"] == ("window_send: robot 'bot''s window queue is full (256 texts, 658 characters "
                                        "waiting; at most 256 texts and 1,048,576 characters): its controller takes "
                                        "them with its steps")
    assert step(core, ctl)["robot_window"] == [str(k) for k in range(S.MAX_WINDOW_QUEUE)]   # none lost, in order
    assert anyone.call("/bot/robot/window_send", {"text": "one more"})["result"]["queued"] == 1
    # characters: four texts of the longest size fill the queue's 2^20 characters exactly
    step(core, ctl)
    big = "w" * S.MAX_WINDOW_TEXT
    assert [anyone.call("/bot/robot/window_send", {"text": big})["ok"] for _ in range(4)] == [True] * 4
    over = anyone.call("/bot/robot/window_send", {"text": "x"})
    assert over["error"]["code"] == ErrorCode.WRONG_STATE and "1,048,576 characters waiting" in over["error"]["message"]
    # one text longer than the bound: refused, naming the argument
    for service in ("/bot/robot/window_send", "/bot/robot/wwi_send"):
        long = (anyone if "window" in service else ctl).call(service, {"text": "y" * (S.MAX_WINDOW_TEXT + 1)})
        assert long["error"]["code"] == ErrorCode.INVALID_ARGUMENT and "'text'" in long["error"]["message"], long


def test_wwi_receive_text_reads_a_steps_texts_one_per_call_and_the_next_step_drops_the_rest(monkeypatch):
    """libController's rule in the Python client: the first read after a step takes every text that
    came, one per call, then None; what is left of that batch when a step begins is gone, while texts
    that came meanwhile wait for the next read."""
    from sensorium.client import wb_input, wb_robot

    r = SimpleNamespace(window_inbox=[], window_batch=[], window_fresh=True)
    monkeypatch.setattr(wb_robot, "_robot", r)
    assert wb_input.wb_robot_wwi_receive_text() is None
    r.window_inbox += ["a", "b", "c"]                    # a step reply's texts
    r.window_fresh = True                                # ... after a step began
    assert [wb_input.wb_robot_wwi_receive_text() for _ in range(2)] == ["a", "b"]
    r.window_inbox += ["d"]                              # came with a step(0) reply: not this batch's
    assert [wb_input.wb_robot_wwi_receive_text() for _ in range(2)] == ["c", None]
    r.window_inbox += ["e"]
    r.window_fresh = True
    assert wb_input.wb_robot_wwi_receive_text() == "d"
    r.window_fresh = True                                # the next step began: "e" dropped
    assert wb_input.wb_robot_wwi_receive_text() is None


@pytest.mark.slow
def test_a_python_controller_talks_with_the_cli_through_its_robot_window(tmp_path):
    """`sensorium window ROBOT TEXT` reaches a Python controller's wwiReceiveText in order; its
    wwiSendText answers are on /epuck/robot_window for a subscriber and in serve's recording, the
    texts sent to it on /epuck/robot_window/to_controller; `sensorium echo` of both topics prints the
    dialogue in order."""
    import json

    from sensorium.client.topics import Subscriber

    record = tmp_path / "window.mcap"
    both = ["/epuck/robot_window", "/epuck/robot_window/to_controller"]
    with serve(ARENA, "--mode", "fast", "--record", str(record)) as server:
        printer = Proc(sensorium("echo", *both, "--json", "--count", "7", "--url", server.rpc))
        with printer, Subscriber(server.pub, "/epuck/robot_window") as sub:
            wait_until(lambda: {b"/epuck/robot_window\0", b"/epuck/robot_window/to_controller\0"}
                       <= set(server.conn.call("get_counters")["subscriptions"]), what="the subscriptions")
            ctl = Proc(sensorium("controller", str(REPO / "tests" / "controllers" / "window_echo.py"),
                                 "--url", server.url("epuck")))
            try:
                first = sub.recv(timeout=60)
                assert first is not None and first.body == {"data": "ready"}, ctl.stderr()
                assert first.type == "std_msgs/msg/String" and first.seq == 0
                for k, text in enumerate(["go", "turn left", "stop"], start=1):
                    done = subprocess.run(sensorium("window", "epuck", text, "--url", server.rpc),
                                          capture_output=True, text=True, timeout=60, env=child_env())
                    assert done.returncode == 0 and done.stdout == "queued: 1\n", done.stderr
                    echo = sub.recv(timeout=60)                 # answered before the next text is sent
                    assert echo is not None and (echo.body, echo.seq) == ({"data": f"echo:{text}"}, k)
                assert ctl.wait(60) == 0, ctl.stderr()
            finally:
                ctl.stop()
            assert ctl.stdout().splitlines() == ["received go|turn left|stop"]
            assert printer.wait(60) == 0, printer.stderr()
        dialogue = [("/epuck/robot_window", "ready")]
        for text in ["go", "turn left", "stop"]:
            dialogue += [("/epuck/robot_window/to_controller", text), ("/epuck/robot_window", f"echo:{text}")]
        printed = [json.loads(line) for line in printer.stdout().splitlines()]
        assert [(m["topic"], m["body"]["data"]) for m in printed] == dialogue
        assert [m["seq"] for m in printed] == [0, 0, 1, 1, 2, 2, 3]
        # bad input: one line, exit 1
        done = subprocess.run(sensorium("window", "nobody", "hi", "--url", server.rpc), capture_output=True,
                              text=True, timeout=60, env=child_env())
        assert done.returncode == 1 and done.stdout == "", done
        assert done.stderr.startswith("sensorium window: ") and "no robot 'nobody'" in done.stderr
        assert len(done.stderr.splitlines()) == 1, done.stderr
    with Recording(record) as r:
        said = [m.decode()["data"] for m in r.messages(lambda topic: topic == "/epuck/robot_window")]
        recorded = [(m.topic, m.decode()["data"]) for m in r.messages(both)]
    assert said == ["ready", "echo:go", "echo:turn left", "echo:stop"]
    assert recorded == dialogue


def window_panels(layout: str) -> list[tuple[str, str]]:
    """The robot-window panels of a layout (the side column's last item): (tab or panel title, topic)."""
    import json

    last = json.loads(layout)["content"]["items"][1]["content"]["items"][-1]["content"]
    if last.get("type") == "tabs":
        return [(t["title"], t["content"]["config"]["topicPath"]) for t in last["tabs"]
                if t["content"]["panelType"] == "RawMessages"]
    if last.get("panelType") == "RawMessages" and last["config"]["topicPath"] != "/clock":
        return [(last["title"], last["config"]["topicPath"])]
    return []


def test_the_layout_shows_the_robot_window_of_each_robot_with_a_controller_in_tabs(tmp_path):
    """One panel whatever the number of robots: a tab per robot with a controller (``<none>`` has
    none), at most MAX_WINDOW_TABS, the first by name; one robot: the panel itself."""
    import json

    pytest.importorskip("foxglove.layouts")
    from sensorium.server.viewer.layout import MAX_WINDOW_TABS, layout_for

    names = [f"r{k:02d}" for k in range(11)]
    robots = [{"name": n, "controller": "<none>" if n == "r01" else "<extern>", "devices": []} for n in reversed(names)]
    world = tmp_path / "many.json"
    world.write_text(json.dumps({"world_info": {"basic_time_step": 16}, "robots": robots}))
    shown = [n for n in names if n != "r01"][:MAX_WINDOW_TABS]
    assert MAX_WINDOW_TABS == 8 and window_panels(layout_for(world)) == [(n, f"/{n}/robot_window") for n in shown]
    world.write_text(json.dumps({"world_info": {"basic_time_step": 16}, "robots": robots[-2:]}))   # r01, r00
    assert window_panels(layout_for(world)) == [("r00 robot window", "/r00/robot_window")]
    world.write_text(json.dumps({"world_info": {"basic_time_step": 16}, "robots": robots[-2:-1]}))  # r01 alone
    assert window_panels(layout_for(world)) == []


def test_the_layout_of_a_recording_shows_the_windows_it_has_texts_of(tmp_path):
    pytest.importorskip("foxglove.layouts")
    from sensorium.server.viewer.layout import layout_for

    path = tmp_path / "dialogue.mcap"
    window_dialogue(path)                                # bot's texts both ways; bot2, free, rover said nothing
    assert window_panels(layout_for(path)) == [("bot robot window", "/bot/robot_window")]
    core, _ = attached_core()                            # a text only to a controller counts too
    rec = McapRecorder(tmp_path / "to.mcap", world_text=WORLD.read_text(), world_name=WORLD.name,
                       background_flush=False)
    core.topics.set_recorder(rec)
    Client(core, OTHER).call("/bot2/robot/window_send", {"text": "to bot2 only"})
    core.topics.set_recorder(None)
    rec.close()
    assert window_panels(layout_for(tmp_path / "to.mcap")) == [("bot2 robot window", "/bot2/robot_window")]
