/* Sensorium C controller library: VacuumGripper. The presence (the pump on and the gripper's
 * bounding shapes touching a solid: README "The VacuumGripper") arrives with the step reply at its
 * sampling period, false before the first value, with Webots' message when read while disabled.
 * turn_on/turn_off are one RPC each, answered before the next step starts (libController sends
 * them with the next step request: the next presence reads them either way); is_on answers this
 * controller's copy at once, as libController's does, starting from the world's isOn. */
#include <math.h>
#include <stdbool.h>

#include <webots/vacuum_gripper.h>

#include "internal.h"

void wb_vacuum_gripper_enable_presence(WbDeviceTag tag, int sampling_period) {
  sn_sensor_enable(tag, SN_VACUUM, sampling_period, "wb_vacuum_gripper_enable_presence");
}

void wb_vacuum_gripper_disable_presence(WbDeviceTag tag) {
  sn_sensor_enable(tag, SN_VACUUM, 0, "wb_vacuum_gripper_disable_presence");
}

int wb_vacuum_gripper_get_presence_sampling_period(WbDeviceTag tag) {
  return sn_sensor_period(tag, SN_VACUUM, "wb_vacuum_gripper_get_presence_sampling_period");
}

bool wb_vacuum_gripper_get_presence(WbDeviceTag tag) {
  sn_device *d = sn_sensor_reading(tag, SN_VACUUM, "wb_vacuum_gripper_get_presence", "wb_vacuum_gripper_enable_presence");
  return d != NULL && !isnan(d->value) && d->value != 0.0;
}

static void turn(WbDeviceTag tag, bool on, const char *func) {
  sn_device *d = sn_device_get(tag, SN_VACUUM, func);
  if (d != NULL && sn_device_set(d, "set_on", sn_arg_bool, &on, func))
    d->pump_on = on;
}

void wb_vacuum_gripper_turn_on(WbDeviceTag tag) { turn(tag, true, "wb_vacuum_gripper_turn_on"); }

void wb_vacuum_gripper_turn_off(WbDeviceTag tag) { turn(tag, false, "wb_vacuum_gripper_turn_off"); }

bool wb_vacuum_gripper_is_on(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_VACUUM, "wb_vacuum_gripper_is_on");
  return d != NULL && d->pump_on;
}
