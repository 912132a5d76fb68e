/* Sensorium C controller library: Connector and Brake.
 *
 * A connector's presence arrives with the step reply at its sampling period (-1 before the first
 * value; the last one kept after a disable); lock and unlock ask the server, which holds the lock
 * state (wb_connector_is_locked answers its last word). Nothing is physically joined: no physics.
 * A brake answers its joint's type and the tags of the motor and position sensor on its joint (0
 * when none) from its attach description; its damping constant has no effect (one warning). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <webots/brake.h>
#include <webots/connector.h>
#include <webots/robot.h>

#include "internal.h"

/* ------------------------------------------------------------------ Connector */
void wb_connector_enable_presence(WbDeviceTag tag, int sampling_period) {
  sn_sensor_enable(tag, SN_CONNECTOR, sampling_period, "wb_connector_enable_presence");
}

void wb_connector_disable_presence(WbDeviceTag tag) {
  sn_sensor_enable(tag, SN_CONNECTOR, 0, "wb_connector_disable_presence");
}

int wb_connector_get_presence_sampling_period(WbDeviceTag tag) {
  return sn_sensor_period(tag, SN_CONNECTOR, "wb_connector_get_presence_sampling_period");
}

int wb_connector_get_presence(WbDeviceTag tag) {
  sn_device *d = sn_sensor_reading(tag, SN_CONNECTOR, "wb_connector_get_presence", "wb_connector_enable_presence");
  return d == NULL || isnan(d->value) ? -1 : (int)d->value;
}

static void locking(WbDeviceTag tag, bool lock, const char *func) {
  sn_device *d = sn_device_get(tag, SN_CONNECTOR, func);
  if (d == NULL)
    return;
  if (d->connector_passive) { /* Webots' message; the state stays unlocked */
    fprintf(stderr, "Warning: %s(): connector '%s': passive connectors cannot lock.\n", func, sn_shown(d->name));
    return;
  }
  sn_robot *rb = sn_robot_get(func);
  if (rb->terminated) { /* no server any more: the local state only */
    d->is_locked = lock;
    return;
  }
  sn_reply rep;
  if (sn_device_call(rb, d, lock ? "lock" : "unlock", NULL, NULL, func, &rep) != 0)
    return;
  d->is_locked = sn_int_or(rep.result, "status", 0) != 0;
  sn_reply_free(&rep);
}

void wb_connector_lock(WbDeviceTag tag) { locking(tag, true, "wb_connector_lock"); }

void wb_connector_unlock(WbDeviceTag tag) { locking(tag, false, "wb_connector_unlock"); }

bool wb_connector_is_locked(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_CONNECTOR, "wb_connector_is_locked");
  return d != NULL && d->is_locked;
}

/* ------------------------------------------------------------------ Brake */
void wb_brake_set_damping_constant(WbDeviceTag tag, double damping_constant) {
  const char *func = "wb_brake_set_damping_constant";
  sn_device *d = sn_device_get(tag, SN_BRAKE, func);
  if (d == NULL)
    return;
  if (isnan(damping_constant)) {
    fprintf(stderr, "Error: %s() called with an invalid 'damping_constant' argument (NaN).\n", func);
    return;
  }
  if (!d->warned_damping) {
    d->warned_damping = true;
    fprintf(stderr, "Warning: %s(): brake '%s': Sensorium has no physics, the damping constant has no effect (its "
                    "joint moves as its motor drives it).\n", func, sn_shown(d->name));
  }
}

WbJointType wb_brake_get_type(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_BRAKE, "wb_brake_get_type");
  return d != NULL && d->joint_type == WB_LINEAR ? WB_LINEAR : WB_ROTATIONAL;
}

WbDeviceTag wb_brake_get_motor(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_BRAKE, "wb_brake_get_motor");
  return d != NULL && d->motor_name != NULL ? wb_robot_get_device(d->motor_name) : 0;
}

WbDeviceTag wb_brake_get_position_sensor(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_BRAKE, "wb_brake_get_position_sensor");
  return d != NULL && d->position_sensor_name != NULL ? wb_robot_get_device(d->position_sensor_name) : 0;
}

WbDeviceTag sn_brake_of(const char *name, bool of_motor, const char *func) {
  sn_robot *rb = sn_robot_get(func);
  for (int i = 0; i < rb->n_devices; i++) {
    const sn_device *b = &rb->devices[i];
    const char *n = of_motor ? b->motor_name : b->position_sensor_name;
    if (b->kind == SN_BRAKE && n != NULL && strcmp(n, name) == 0)
      return b->tag;
  }
  return 0;
}
