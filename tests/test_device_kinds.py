"""The device declaration (schemas/devices.py): every kind is complete, and routing, topics, limits
and the device list follow the registry (a kind registered here gets them without other files)."""

from __future__ import annotations

import itertools
import math
import re
from pathlib import Path

import pytest
from pydantic import TypeAdapter

from sensorium.schemas import devices as D
from sensorium.schemas import messages as msgs
from sensorium.schemas import services as S
from sensorium.schemas import world as wm
from sensorium.schemas.wire import pack, unpack
from sensorium.server.daemon.services import Core
from sensorium.server.daemon.topics import MESSAGE_BUILDERS
from sensorium.server.recording.export import SENSOR_TYPES, typestore_for
from sensorium.server.sim.sensors import Device, device_class
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.limits import WorldLimits, check_work

SIMULATED = [k for k in D.KINDS.values() if k.simulated]


def test_registry_is_the_world_files_device_list():
    assert set(D.KINDS) == set(wm.DEVICE_TYPES)
    for k in D.KINDS.values():
        if k.simulated:
            assert k.model is not None and k.model.model_fields["device"].annotation.__args__ == (k.type,)
        else:
            assert k.type in wm.UNSIMULATED_DEVICE_TYPES and not k.services and not k.topics


@pytest.mark.parametrize("k", SIMULATED, ids=lambda k: k.type)
def test_every_simulated_kind_is_complete(k):
    cls = device_class(k.type)
    assert cls is not None and cls.__name__ == k.implementation.rsplit(":", 1)[1]
    handler_prefix = "_motor_" if k.motor else "_dev_"
    assert k.services, k.type
    for item in k.services:
        spec = S.spec("device", item)                              # args and results declared
        assert k.type in spec.devices
        assert callable(getattr(Core, handler_prefix + item)), f"{k.type}: no handler {handler_prefix}{item}"
    assert isinstance(getattr(S, k.description), type), k.description       # what attach says
    store = typestore_for("jazzy")
    for t in k.topics:
        assert t.message in msgs.MESSAGE_TYPES and t.message in MESSAGE_BUILDERS
        assert t.message in store.fielddefs, f"the ROS 2 export has no type {t.message}"
        assert (t.message in SENSOR_TYPES) == t.sensor_qos
    if not k.motor:
        # communication devices carry packets between controllers (step requests and replies): a
        # packet belongs to the receiving controller, which takes it from the receiver's queue; a
        # Brake has no reading (its joint's type and neighbours are its description)
        assert k.topics or k.type in ("Emitter", "Receiver", "Brake"), f"{k.type} publishes nothing"
        assert issubclass(cls, Device)


def test_webots_node_types():
    # Webots' WbNodeType values (include/controller/c/webots/nodes.h), spot checks at both ends of the devices
    assert D.WEBOTS_NODE_TYPES["WB_NODE_NO_NODE"] == 0
    assert D.KINDS["Accelerometer"].node == D.WEBOTS_NODE_TYPES["WB_NODE_ROBOT"] + 1
    assert D.KINDS["DistanceSensor"].node_name == "WB_NODE_DISTANCE_SENSOR"
    assert D.KINDS["InertialUnit"].node_name == "WB_NODE_INERTIAL_UNIT"
    assert D.KINDS["VacuumGripper"].node - D.KINDS["Accelerometer"].node == 26       # 27 device types
    assert len({k.node for k in D.KINDS.values()}) == len(D.KINDS)
    with pytest.raises(ValueError, match="already registered"):
        D.register(D.DeviceKind("GPS", None))


def test_the_python_clients_node_types_are_the_declarations():
    from sensorium.client import nodes, wb

    assert nodes.WEBOTS_NODE_TYPES == D.WEBOTS_NODE_TYPES
    for k in D.KINDS.values():
        assert nodes.node_type(k.type) == k.node and getattr(wb, k.node_name) == k.node


def test_client_node_types_are_webots_names():
    # every WB_NODE_* the C header names is one of Webots' (no typo); the first kinds are all there
    header = (Path(__file__).parents[1] / "sensorium/client/c/include/webots/nodes.h").read_text()
    names = set(re.findall(r"\b(WB_NODE_[A-Z0-9_]+)\b", header))
    assert names <= set(D.WEBOTS_NODE_TYPES) | {"WB_NODE_KEYBOARD"}, names - set(D.WEBOTS_NODE_TYPES)
    for t in ("LightSensor", "DistanceSensor", "Lidar", "PositionSensor", "LED", "RotationalMotor"):
        assert D.KINDS[t].node_name in names


# ---------------------------------------------------------------------- a kind registered here

class ToyAltimeter(Device):
    """A toy kind on a listed-only node type: reads the robot's height (z), no rays."""

    kinematic = True

    def __post_init__(self) -> None:
        super().__post_init__()
        self.value = math.nan
        self.robot = None

    def bind(self, robot) -> None:
        self.robot = robot

    def measure(self, now_ms: int) -> None:
        self.value = float(self.robot.pose.translation[2])
        self._mark(now_ms)


TOY = D.DeviceKind("Speaker", wm.UnsimulatedDevice, f"{__name__}:ToyAltimeter",
                   services=("enable", "get_sampling_period", "get_value"),
                   topics=(D.TopicDecl("value", msgs.ILLUMINANCE),))

WORLD = {
    "world_info": {"basic_time_step": 16},
    "robots": [{"name": "bot", "pose": {"translation": [0.0, 0.0, 0.25]},
                "devices": [{"device": "Skin", "name": "skin", "model": "u-blox"},
                            {"device": "Speaker", "name": "alt", "model": "toy 1"},
                            {"device": "LightSensor", "name": "ls"}]}],
}


_ids = itertools.count(1)


def call(core, service, args=None):
    [reply] = core.handle([b"peer", pack({"id": next(_ids), "service": service, "args": args or {}})], 0.0)
    return unpack(reply[-1])


def test_a_registered_kind_gets_routing_topics_and_its_place(monkeypatch):
    monkeypatch.setitem(D.KINDS, "Speaker", TOY)
    sim = Simulation(wm.World.model_validate(WORLD))
    core = Core(sim)
    assert {"/bot/alt/enable", "/bot/alt/get_sampling_period", "/bot/alt/get_value"} <= set(core.routes)
    assert "/bot/alt/value" in core.topics.by_name
    assert not any(r.startswith("/bot/skin/") for r in core.routes)        # listed, not simulated
    info = call(core, "get_info")["result"]
    assert info["robots"][0]["devices"] == [
        {"name": "skin", "type": "Skin", "model": "u-blox", "index": 0, "simulated": False},
        {"name": "alt", "type": "Speaker", "model": "toy 1", "index": 1, "simulated": True},
        {"name": "ls", "type": "LightSensor", "model": "", "index": 2, "simulated": True}]
    attached = call(core, "attach", {"robot": "bot"})["result"]
    assert [(d["name"], d["index"], d["simulated"]) for d in attached["devices"]] == [
        ("skin", 0, False), ("alt", 1, True), ("ls", 2, True)]
    # (the toy has no description model: a real kind adds one)
    described = TypeAdapter(S.DeviceDescription)
    assert isinstance(described.validate_python(attached["devices"][0]), S.UnsimulatedDescription)
    assert isinstance(described.validate_python(attached["devices"][2]), S.LightSensorDescription)
    assert call(core, "/bot/alt/enable", {"value": 32})["ok"]
    assert math.isnan(call(core, "/bot/alt/get_value")["result"]["value"])    # NaN before the first value
    for _ in range(2):
        sim.step()
    assert call(core, "/bot/alt/get_value")["result"]["value"] == 0.25
    listed = {s["name"]: s for s in call(core, "get_services")["result"]["services"]}
    assert listed["/bot/skin/*"]["simulated"] is False and listed["/bot/alt/get_value"]["simulated"] is True


def test_limits_follow_the_declared_rays():
    world = wm.World.model_validate({"robots": [{"name": "r", "devices": [
        {"device": "DistanceSensor", "name": "d", "number_of_rays": 40},
        {"device": "Lidar", "name": "l", "horizontal_resolution": 100, "number_of_layers": 2}]}]})
    problems = check_work(world, WorldLimits(rays_per_sensor=30, beams_per_lidar=150, rays_per_step=200),
                          lambda geom: 0)
    text = "\n".join(f"{p[0]}: {p[1]}" for p in problems)
    assert "robots[0].devices[0].number_of_rays" in text and "40" in text
    assert "robots[0].devices[1]" in text and "200" in text
    assert "240" in text                         # rays in one step: 40 + 200
