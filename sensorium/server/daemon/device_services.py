"""The device and motor services of the core (``/<robot>/<device>/<item>``), as a mixin of
:class:`sensorium.server.daemon.services.Core`: describing devices for ``attach``/``get_info``,
enabling, reading and configuring them. Sans-IO like the core: a :class:`Call` in, a result map out.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from sensorium.schemas.devices import KINDS
from sensorium.schemas.wire import ErrorCode
from sensorium.server.daemon.topics import Control, header, image_msg, point_cloud_msg
from sensorium.server.sim.joints import JointMotor

if TYPE_CHECKING:
    from sensorium.server.daemon.services import Call

MOTOR = "RotationalMotor"
MOTORS = (MOTOR, "LinearMotor")


class ServiceError(Exception):
    """Raised by a handler: answered with ``code`` and ``message``."""

    def __init__(self, code: ErrorCode, message: str):
        super().__init__(f"{code.name}: {message}")
        self.code = code
        self.message = message


def _configured(c: Call, item: str, *args: Any, code: ErrorCode = ErrorCode.INVALID_ARGUMENT) -> dict:
    """The device service ``item``: the device's method of that name called with ``args``; a
    ValueError it raises (a value the device refuses, or a state it cannot take it in) answers the
    request with ``code``."""
    try:
        getattr(c.ctl.device, item)(*args)
    except ValueError as exc:
        raise ServiceError(code, f"{item}: {exc}") from None
    return {"success": True}


class DeviceServices:
    """Handlers ``_dev_*`` and ``_motor_*``; needs ``self.sim`` and ``self.topics`` (the core's)."""

    sim: Any
    topics: Any

    # ------------------------------------------------------------------ device services
    def _describe_robot(self, robot: str) -> list[dict]:
        """``attach``'s device list: every device in Webots' tree order, each described by its kind
        (an unsimulated one by its identity)."""
        r = self.sim.robots[robot]
        out = []
        for e in self._device_entries(robot):            # type: ignore[attr-defined]
            if not e.simulated:
                d: dict[str, Any] = {"name": e.name, "type": e.type, "simulated": False}
            elif e.type in MOTORS:
                d = self._describe_motor(r.motors[e.name], e.type)
            else:
                d = self._describe(self.topics.controls[f"{robot}/{e.name}"])
            d.update(model=e.model, index=e.index, simulated=e.simulated)
            out.append(d)
        return out

    def _describe(self, ctl: Control) -> dict:
        dev = ctl.device
        out: dict[str, Any] = {"name": dev.name, "type": ctl.kind, "sampling_period": ctl.controller_period}
        if "enable" not in KINDS[ctl.kind].services:          # nothing to enable (an LED)
            del out["sampling_period"]
        out.update(dev.describe())                               # the kind's own fields
        if "point_cloud_enabled" in out:                         # what this controller asked for
            out["point_cloud_enabled"] = ctl.controller_point_cloud
        return out

    @staticmethod
    def _describe_motor(m: Any, kind: str = MOTOR) -> dict:
        """A motor's description; ``kind`` is its entry's type, which a drive's wheel keeps (a tracked
        robot's LinearMotor: m and m/s, its belt a wheel of radius 1)."""
        if isinstance(m, JointMotor):                          # a joint moved kinematically
            return {"name": m.name, "type": m.kind, "maxVelocity": float(m.max_velocity),
                    "minPosition": float(m.min_position), "maxPosition": float(m.max_position),
                    "targetPosition": float(m.target_position), "velocity": float(m.velocity),
                    "acceleration": float(m.acceleration), "maxForce": float(m.max_force),
                    "initialPosition": float(m.initial_position), "multiplier": float(m.multiplier),
                    "coupled": [c.name for c in m.coupled]}
        limit = float(getattr(m, "max_position", math.inf))      # a car's steering motor has limits
        limit = 0.0 if math.isinf(limit) else limit              # Webots: 0 and 0 mean none (a wheel)
        return {"name": m.name, "type": kind, "maxVelocity": float(m.max_velocity), "minPosition": -limit if limit else 0.0,
                "maxPosition": limit, "targetPosition": float(m.target_position), "velocity": float(m.velocity)}

    @staticmethod
    def _lookup_table(dev: Any) -> list[float]:
        return dev.flat_lookup_table()

    @staticmethod
    def _lidar_info(dev: Any) -> dict:
        return dev.info()

    @staticmethod
    def _frequency_info(dev: Any) -> dict:
        return dev.frequency_info()

    def _dev_get_value(self, c: Call) -> dict:
        return {"value": float(c.ctl.device.value)}

    def _dev_get_values(self, c: Call) -> dict:
        return {"value": [float(v) for v in c.ctl.device.values]}

    def _dev_get_speed(self, c: Call) -> dict:
        return {"value": float(c.ctl.device.speed)}

    def _dev_get_speed_vector(self, c: Call) -> dict:
        return {"value": [float(v) for v in c.ctl.device.speed_vector]}

    def _dev_get_coordinate_system(self, c: Call) -> dict:
        return {"value": int(c.ctl.device.coordinate_system)}

    def _dev_get_roll_pitch_yaw(self, c: Call) -> dict:
        return {"value": [float(v) for v in c.ctl.device.roll_pitch_yaw]}

    def _dev_get_quaternion(self, c: Call) -> dict:
        return {"value": [float(v) for v in c.ctl.device.quaternion]}

    def _dev_get_noise(self, c: Call) -> dict:
        return {"value": float(c.ctl.device.config.noise)}

    def _dev_draw(self, c: Call) -> dict:
        """A Display's commands at once, and the image ``save`` asks for (``wb_display_image_save``)."""
        dev = c.ctl.device
        try:
            commands = dev.check(c.args.commands)
        except ValueError as exc:
            raise ServiceError(ErrorCode.INVALID_ARGUMENT, f"draw: {c.robot}/{dev.name}: {exc}") from None
        dev.apply(commands, self.sim.time_ms)
        if c.args.save is None:
            return {}
        img = dev.save_image(c.args.save)
        if img is None:
            return {"width": 0, "height": 0, "data": None}
        return {"width": int(img.shape[1]), "height": int(img.shape[0]), "data": img.astype("<u4").tobytes()}

    def _dev_set_exposure(self, c: Call) -> dict:
        return _configured(c, "set_exposure", c.args.value)

    def _dev_set_fov(self, c: Call) -> dict:
        return _configured(c, "set_fov", c.args.value)

    def _dev_recognition_enable(self, c: Call) -> dict:
        return _configured(c, "recognition_enable", c.args.value, code=ErrorCode.WRONG_STATE)

    def _dev_get_recognition_sampling_period(self, c: Call) -> dict:
        return {"value": int(c.ctl.device.recognition_schedule.period_ms)}

    def _dev_enable_segmentation(self, c: Call) -> dict:
        return _configured(c, "enable_segmentation", c.args.value, code=ErrorCode.WRONG_STATE)

    def _dev_is_segmentation_enabled(self, c: Call) -> dict:
        return {"status": int(c.ctl.device.segmentation_enabled)}

    def _dev_get_recognition_objects(self, c: Call) -> dict:
        return {"value": [o.as_dict() for o in c.ctl.device.objects]}

    def _dev_get_targets(self, c: Call) -> dict:
        """A Radar's targets, flat: distance, received power, speed, azimuth of each in turn."""
        return {"value": [v for t in c.ctl.device.targets for v in t.as_list()]}

    def _dev_set_on(self, c: Call) -> dict:         # a VacuumGripper's pump: on (true) or off
        c.ctl.device.set_on(c.args.value)
        return {"success": True}

    def _dev_play_sound(self, c: Call) -> dict:     # a Speaker: the sound plays from now, in simulated time
        a = c.args
        return _configured(c, "play_sound", a.sound, a.frames, a.rate, a.pitch, a.loop, a.side)

    def _dev_stop(self, c: Call) -> dict:           # a Speaker: one sound, or "" every sound and the speech
        return _configured(c, "stop", c.args.value)

    def _dev_speak(self, c: Call) -> dict:
        return _configured(c, "speak", c.args.text)
    def _dev_lock(self, c: Call) -> dict:             # a Connector: the lock state after it (passive: unchanged)
        return {"status": int(c.ctl.device.lock())}

    def _dev_unlock(self, c: Call) -> dict:
        return {"status": int(c.ctl.device.unlock())}

    def _dev_is_locked(self, c: Call) -> dict:
        return {"status": int(c.ctl.device.is_locked)}

    def _dev_get_channel(self, c: Call) -> dict:
        return {"value": int(c.ctl.device.channel)}

    def _dev_set_channel(self, c: Call) -> dict:
        return _configured(c, "set_channel", c.args.value)

    def _dev_get_range(self, c: Call) -> dict:
        return {"value": float(c.ctl.device.range)}

    def _dev_set_range(self, c: Call) -> dict:
        return _configured(c, "set_range", c.args.value)

    def _dev_get_buffer_size(self, c: Call) -> dict:
        return {"value": int(c.ctl.device.config.buffer_size)}

    def _dev_set(self, c: Call) -> dict:
        return _configured(c, "set", c.args.value, self.sim.time_ms)

    def _dev_get(self, c: Call) -> dict:
        return {"value": int(c.ctl.device.value)}

    def _dev_write(self, c: Call) -> dict:          # a Pen: from the next basic step
        c.ctl.device.set_write(c.args.value)
        return {"success": True}

    def _dev_set_ink_color(self, c: Call) -> dict:  # a Pen: 0xRRGGBB, density clamped to [0, 1]
        return _configured(c, "set_ink_color", c.args.color, c.args.density)

    def _dev_enable(self, c: Call) -> dict:
        self.topics.controller_enable(c.ctl.path, c.args.value)
        return {"success": True}

    def _dev_get_sampling_period(self, c: Call) -> dict:
        return {"value": c.ctl.controller_period}

    def _dev_get_lookup_table(self, c: Call) -> dict:
        return {"value": self._lookup_table(c.ctl.device)}

    def _dev_get_min_value(self, c: Call) -> dict:
        return {"value": float(c.ctl.device.table.min_value)}

    def _dev_get_max_value(self, c: Call) -> dict:
        return {"value": float(c.ctl.device.table.max_value)}

    def _dev_get_aperture(self, c: Call) -> dict:
        return {"value": float(c.ctl.device.config.aperture)}

    def _dev_get_type(self, c: Call) -> dict:  # DistanceSensor, TouchSensor, Brake: their type code
        return {"value": int(c.ctl.device.type_code)}

    def _dev_get_info(self, c: Call) -> dict:
        return self._lidar_info(c.ctl.device)

    def _dev_enable_point_cloud(self, c: Call) -> dict:
        self.topics.controller_point_cloud(c.ctl.path, c.args.value)
        return {"success": True}

    def _dev_is_point_cloud_enabled(self, c: Call) -> dict:
        return {"status": int(c.ctl.controller_point_cloud)}

    def _dev_get_frequency_info(self, c: Call) -> dict:
        return self._frequency_info(c.ctl.device)

    def _dev_set_frequency(self, c: Call) -> dict:
        return _configured(c, "set_frequency", c.args.value)

    def _layer(self, c: Call) -> int:
        n = c.ctl.device.config.number_of_layers
        if c.args.layer >= n:
            raise ServiceError(ErrorCode.INVALID_ARGUMENT, f"argument 'layer': {c.args.layer} outside [0, {n - 1}]")
        return c.args.layer

    def _dev_get_layer_range_image(self, c: Call) -> dict:
        layer = self._layer(c)
        dev = c.ctl.device
        row = dev.layer_range_image(layer)
        w = int(dev.config.horizontal_resolution)
        import numpy as np

        data = np.ascontiguousarray(row, dtype="<f4").tobytes()
        return {"image": image_msg(header(c.ctl.frame_id, dev.measured_at_ms), 1, w, data)}

    def _dev_get_layer_point_cloud(self, c: Call) -> dict:
        if not c.ctl.controller_point_cloud:
            raise ServiceError(ErrorCode.WRONG_STATE, f"the point cloud of {c.ctl.path} is not enabled (enable_point_cloud)")
        layer = self._layer(c)
        dev = c.ctl.device
        return {"pointCloud": point_cloud_msg(header(c.ctl.frame_id, dev.measured_at_ms), dev.layer_point_cloud(layer))}

    # ------------------------------------------------------------------ motor services
    def _motor_set_position(self, c: Call) -> dict:
        c.motor.set_position(c.args.value)
        return {"success": True}

    def _motor_set_velocity(self, c: Call) -> dict:
        c.motor.command_velocity(c.args.value)
        return {"success": True}

    def _motor_get_velocity(self, c: Call) -> dict:
        return {"value": float(c.motor.velocity)}

    def _motor_get_max_velocity(self, c: Call) -> dict:
        return {"value": float(c.motor.max_velocity)}

    def _motor_get_target_position(self, c: Call) -> dict:
        return {"value": float(c.motor.target_position)}
