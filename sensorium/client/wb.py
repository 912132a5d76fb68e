"""Webots' C controller API (``wb_*`` functions over opaque device tags) on Sensorium.

    from sensorium.client.wb import *
    wb_robot_init()                                   # URL from SENSORIUM_/WEBOTS_CONTROLLER_URL
    ps0 = wb_robot_get_device("ps0")
    wb_distance_sensor_enable(ps0, 32)
    while wb_robot_step(32) != -1:
        print(wb_distance_sensor_get_value(ps0))

As in libController, readings arrive with the step reply (PROTOCOL.md §3.6) and are cached here:
a ``get_value`` costs no round trip, reads NaN before the first measurement and keeps the last
value after a ``disable``. ``enable``/``disable``/``set_frequency`` are RPCs. Constant getters
(lookup tables, ranges, resolutions…) come from the device descriptions of the ``attach`` reply.
Motor commands (``wb_motor_set_position``/``_velocity``) cost no round trip either: like
libController they are buffered and travel with the next step request (PROTOCOL.md §3.4), and
the motor getters answer from the client's copy.

Differences from Webots' C library, all on error paths: an invalid tag, a negative sampling
period, an out-of-range layer or frequency raise :class:`SensoriumError` instead of printing and
carrying on (a NaN position or velocity, a negative velocity in position control and an
out-of-range LED value are printed and ignored, as Webots does); reads of a disabled
device print Webots' message to stderr once per disable. A velocity above ``maxVelocity`` is
clamped here with Webots' warning (Webots clamps in the simulator).
The functions live in ``wb_robot`` (session, robot, keyboard), ``wb_sensors`` (light, distance,
lidar, encoders), ``wb_kinematic`` (GPS, InertialUnit, Compass, Accelerometer, Gyro, Altimeter,
TouchSensor), ``wb_radio`` (Emitter, Receiver), ``wb_camera`` (RangeFinder, Camera, Recognition), ``wb_display``, ``wb_pen``, ``wb_radar``, ``wb_speaker``, ``wb_vacuum`` (VacuumGripper), ``wb_connector`` (Connector, Brake), ``wb_motor`` (motors, LEDs), ``wb_motion`` (motion files, ``wbu_motion_*``), ``wb_movie`` (a Supervisor's movies), ``wb_input``
(joystick, mouse, waiting for user input, the battery sensor), ``wb_unsimulated`` (the devices Sensorium
lists without simulating: Webots' "no value" with one warning per device) and ``wb_supervisor``;
this module re-exports them all. One process drives one robot through
these functions; :class:`RobotClient` is the same thing as
an object, for programs (and tests) that want several.
"""

from __future__ import annotations

from sensorium.client import (
    wb_camera,
    wb_connector,
    wb_display,
    wb_input,
    wb_kinematic,
    wb_motion,
    wb_motor,
    wb_movie,
    wb_pen,
    wb_radar,
    wb_radio,
    wb_robot,
    wb_sensors,
    wb_speaker,
    wb_supervisor,
    wb_unsimulated,
    wb_vacuum,
)
from sensorium.client.connection import SensoriumError  # noqa: F401
from sensorium.client.wb_camera import *  # noqa: F403
from sensorium.client.wb_camera import (  # noqa: F401
    CAMERA,
    RANGE_FINDER,
    camera_bytes,
    range_finder_bytes,
    recognition_objects,
    segmentation_bytes,
)
from sensorium.client.wb_connector import *  # noqa: F403
from sensorium.client.wb_display import *  # noqa: F403
from sensorium.client.wb_input import *  # noqa: F403
from sensorium.client.wb_kinematic import *  # noqa: F403
from sensorium.client.wb_motion import *  # noqa: F403
from sensorium.client.wb_motor import *  # noqa: F403
from sensorium.client.wb_movie import *  # noqa: F403
from sensorium.client.wb_pen import *  # noqa: F403
from sensorium.client.wb_radar import *  # noqa: F403
from sensorium.client.wb_radio import *  # noqa: F403
from sensorium.client.wb_robot import *  # noqa: F403
from sensorium.client.wb_robot import (  # noqa: F401 - used by the controller classes and tests
    DISTANCE_SENSOR,
    LED,
    LIDAR,
    LIGHT_SENSOR,
    POSITION_SENSOR,
    ROTATIONAL_MOTOR,
    DeviceState,
    RobotClient,
    c_string,
    current,
)
from sensorium.client.wb_sensors import *  # noqa: F403
from sensorium.client.wb_sensors import lidar_cloud_bytes, lidar_range_bytes  # noqa: F401
from sensorium.client.wb_speaker import *  # noqa: F403
from sensorium.client.wb_supervisor import *  # noqa: F403
from sensorium.client.wb_unsimulated import *  # noqa: F403
from sensorium.client.wb_vacuum import *  # noqa: F403

_MODULES = (wb_robot, wb_sensors, wb_kinematic, wb_radio, wb_camera, wb_display, wb_pen, wb_radar, wb_motor, wb_input,
            wb_unsimulated, wb_supervisor, wb_speaker, wb_vacuum, wb_connector, wb_motion,
            wb_movie)
globals().update({n: v for m in _MODULES for n, v in vars(m).items() if n.startswith(("wb_", "WB_", "wbu_"))})
__all__ = sorted({n for m in _MODULES for n in vars(m) if n.startswith(("wb_", "WB_", "wbu_"))}
                 | {"SensoriumError", "RobotClient", "WbMouseState"})
