"""A fake simulation with the public surface of ``sensorium.server.sim.simulation.Simulation`` that the
server core uses (robots, devices, schedule, readings, counters), with readings that are simple
functions of time, so the sans-IO server tests need no ray engine.

light = 100 + t_s, distance = t_ms / 2 (table output), lidar range[l][c] = t_s + l + c / 100.
"""

from __future__ import annotations

import math
from collections import Counter
from types import SimpleNamespace

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.sim import sensors
from sensorium.server.sim.motion import DifferentialDrive

POINT_DTYPE = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("layer_id", "<i4"), ("time", "<f4")])


class FakeTable:
    def __init__(self, rows):
        self.rows = [tuple(r) for r in rows]
        self.flattened = tuple(v for r in self.rows for v in r)
        ys = [r[1] for r in self.rows]
        self.min_value = min(ys) if ys else 0.0
        self.max_value = max(ys) if ys else 0.0


class FakeDevice:
    def __init__(self, sim, robot, config):
        self.sim = sim
        self.robot_name = robot
        self.config = config
        self.period = 0
        self.last = 0
        self.measurements = 0
        self.measured_at_ms = -1
        self.enable_calls: list[int] = []

    @property
    def name(self):
        return self.config.name

    @property
    def kind(self):
        return self.config.device

    # the real classes' descriptions (they read only the attributes the fakes have too)
    flat_lookup_table = sensors.Device.flat_lookup_table
    describe = sensors.Device.describe
    step_reading = sensors.Device.step_reading

    def enable(self, period):
        if isinstance(period, bool) or not isinstance(period, int) or period < 0:
            raise ValueError(f"bad period {period!r}")
        self.enable_calls.append(period)
        self.period = period
        self.last = self.sim.time_ms

    def disable(self):
        self.enable(0)

    @property
    def sampling_period(self):
        return self.period

    def due(self, now):
        return self.period > 0 and now - self.last >= self.period

    def measure(self, now):
        self.last = now
        self.measurements += 1
        self.measured_at_ms = now
        self.sim.counters[f"rays_{self.tag}"] += self.rays


class FakeLight(FakeDevice):
    tag, rays = "light", 1
    describe = sensors.LightSensor.describe

    def __init__(self, *a):
        super().__init__(*a)
        self.table = FakeTable(self.config.lookup_table)
        self.value = math.nan

    def measure(self, now):
        super().measure(now)
        self.value = 100.0 + now / 1000.0


class FakeDistance(FakeDevice):
    tag, rays = "distance", 1
    TYPES = {"generic": 0, "infra-red": 1, "infrared": 1, "sonar": 2, "laser": 3}
    describe = sensors.DistanceSensor.describe

    def __init__(self, *a):
        super().__init__(*a)
        self.table = FakeTable(self.config.lookup_table)
        self.type_code = self.TYPES[self.config.type]
        self.value = math.nan

    def measure(self, now):
        super().measure(now)
        self.value = now / 2.0


class FakeLidar(FakeDevice):
    tag = "lidar"
    info, frequency_info, describe = sensors.Lidar.info, sensors.Lidar.frequency_info, sensors.Lidar.describe

    def __init__(self, *a):
        super().__init__(*a)
        c = self.config
        self.rays = c.horizontal_resolution * c.number_of_layers
        self.frequency = float(c.default_frequency)
        self.rotating = c.type == "rotating"
        self.point_cloud_enabled = False
        self.range_image = np.zeros((c.number_of_layers, c.horizontal_resolution), dtype=np.float32)
        self.point_cloud = np.zeros(self.rays, dtype=POINT_DTYPE)

    def enable_point_cloud(self):
        self.point_cloud_enabled = True

    def disable_point_cloud(self):
        self.point_cloud_enabled = False

    def set_frequency(self, f):
        c = self.config
        if not (c.min_frequency <= f <= c.max_frequency):
            raise ValueError(f"frequency {f} outside [{c.min_frequency}, {c.max_frequency}]")
        self.frequency = float(f)

    def layer_range_image(self, i):
        return self.range_image[i].copy()

    def layer_point_cloud(self, i):
        w = self.config.horizontal_resolution
        return self.point_cloud[i * w:(i + 1) * w].copy()

    def measure(self, now):
        super().measure(now)
        L, W = self.range_image.shape
        self.range_image = (now / 1000.0 + np.arange(L)[:, None] + np.arange(W)[None, :] / 100.0).astype(np.float32)
        if self.point_cloud_enabled:
            pc = np.zeros(L * W, dtype=POINT_DTYPE)
            pc["x"] = self.range_image.ravel()
            pc["y"] = -self.range_image.ravel()
            pc["z"] = 0.5
            pc["layer_id"] = np.repeat(np.arange(L), W)
            pc["time"] = now / 1000.0
            self.point_cloud = pc
            self.sim.counters["points_built"] += pc.size


CLASSES = {"LightSensor": FakeLight, "DistanceSensor": FakeDistance, "Lidar": FakeLidar}


class FakeRobot:
    def __init__(self, sim, model: wm.Robot):
        self.name = model.name
        self.synchronization = model.synchronization
        self.controller = model.controller
        self.devices = {d.name: CLASSES[d.device](sim, model.name, d) for d in model.devices}
        self.pose = SimpleNamespace(translation=(0.0, 0.0, 0.0), rotation=np.eye(3))
        # the real kinematic drive (motors and pose integration are cheap and exact)
        self.drive = DifferentialDrive(model.differential_drive, self.pose) if model.differential_drive else None
        self.motors = self.drive.motors if self.drive else {}

    def set_pose(self, translation, rotation=None, quaternion=None):
        if rotation is not None and math.hypot(*rotation[:3]) == 0:
            raise ValueError("rotation axis must not be zero")
        self.pose = SimpleNamespace(translation=tuple(translation), rotation=np.eye(3))
        if self.drive is not None:
            self.drive.reset(self.pose)


class FakeSim:
    def __init__(self, world: wm.World):
        self.world = world
        self.basic_time_step = world.world_info.basic_time_step
        self.time_ms = 0
        self.counters: Counter[str] = Counter()
        self.robots = {r.name: FakeRobot(self, r) for r in world.robots}
        self.fail = False

    def enable_battery_sensor(self, robot, period_ms):       # what Core calls when a controller leaves
        robot.battery_period = period_ms

    def step(self):
        if self.fail:
            raise RuntimeError("boom")
        self.time_ms += self.basic_time_step
        for r in self.robots.values():
            if r.drive is not None and (pose := r.drive.step(self.basic_time_step)) is not None:
                r.pose = pose
            for d in r.devices.values():
                if d.due(self.time_ms):
                    d.measure(self.time_ms)


def small_world(**robot_kw) -> wm.World:
    """One synchronous robot ``bot`` (light ``ls``, distance ``ds`` sonar, 1-layer lidar ``lidar``
    4 columns, 2-layer lidar ``lidar2``) and one asynchronous robot ``free`` (one light ``ls``)."""
    return wm.World.model_validate({
        "world_info": {"name": "small", "basic_time_step": 32},
        "robots": [
            {"name": "bot", "devices": [
                {"device": "LightSensor", "name": "ls"},
                {"device": "DistanceSensor", "name": "ds", "type": "sonar", "aperture": 0.3,
                 "lookup_table": [[0.0, 0.0, 0.0], [2.0, 2000.0, 0.0]]},
                {"device": "Lidar", "name": "lidar", "horizontal_resolution": 4, "number_of_layers": 1,
                 "field_of_view": 1.0, "max_range": 5.0},
                {"device": "Lidar", "name": "lidar2", "horizontal_resolution": 3, "number_of_layers": 2},
            ], **robot_kw},
            {"name": "free", "synchronization": False, "devices": [{"device": "LightSensor", "name": "ls"}]},
        ],
    })
