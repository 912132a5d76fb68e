/* Sensorium C controller library: RotationalMotor. Commands are buffered here and sent with the
 * next step request (PROTOCOL.md 3.4); the getters answer from this copy. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <webots/motor.h>

#include "internal.h"

#define MOTOR(func) sn_device *d = sn_device_get(tag, SN_MOTOR, func)

void wb_motor_set_position(WbDeviceTag tag, double position) {
  MOTOR("wb_motor_set_position");
  if (d == NULL)
    return;
  if (isnan(position)) {
    fprintf(stderr, "Error: wb_motor_set_position() called with an invalid 'position' argument (NaN)\n");
    return;
  }
  d->target_position = position;
  d->cmd_position = true;
}

void wb_motor_set_velocity(WbDeviceTag tag, double velocity) {
  MOTOR("wb_motor_set_velocity");
  if (d == NULL)
    return;
  if (isnan(velocity)) {
    fprintf(stderr, "Error: wb_motor_set_velocity() called with an invalid 'velocity' argument (NaN).\n");
    return;
  }
  if (velocity < 0.0 && !isinf(d->target_position)) {
    fprintf(stderr,
            "Error: wb_motor_set_velocity() called with negative 'velocity' argument in position control mode (%g).\n",
            velocity);
    return;
  }
  if (fabs(velocity) > d->max_velocity) {
    fprintf(stderr, "WARNING: %s \"%s\": The requested velocity %g exceeds 'maxVelocity' = %g.\n", d->type_name,
            d->name, velocity, d->max_velocity);
    velocity = copysign(d->max_velocity, velocity);
  }
  d->velocity = velocity;
  d->cmd_velocity = true;
}

double wb_motor_get_target_position(WbDeviceTag tag) {
  MOTOR("wb_motor_get_target_position");
  return d ? d->target_position : NAN;
}

double wb_motor_get_min_position(WbDeviceTag tag) {
  MOTOR("wb_motor_get_min_position");
  return d ? d->min_position : NAN;
}

double wb_motor_get_max_position(WbDeviceTag tag) {
  MOTOR("wb_motor_get_max_position");
  return d ? d->max_position : NAN;
}

double wb_motor_get_velocity(WbDeviceTag tag) {
  MOTOR("wb_motor_get_velocity");
  return d ? d->velocity : NAN;
}

double wb_motor_get_max_velocity(WbDeviceTag tag) {
  MOTOR("wb_motor_get_max_velocity");
  return d ? d->max_velocity : NAN;
}

WbJointType wb_motor_get_type(WbDeviceTag tag) {
  MOTOR("wb_motor_get_type");
  (void)d;
  return WB_ROTATIONAL;
}

WbDeviceTag wb_motor_get_position_sensor(WbDeviceTag tag) {
  MOTOR("wb_motor_get_position_sensor");
  if (d == NULL)
    return 0;
  sn_robot *rb = sn_robot_get("wb_motor_get_position_sensor");
  for (int i = 0; i < rb->n_devices; i++) {
    const sn_device *p = &rb->devices[i];
    if (p->kind == SN_POSITION && p->motor_name != NULL && strcmp(p->motor_name, d->name) == 0)
      return p->tag;
  }
  return 0;
}

WbDeviceTag wb_motor_get_brake(WbDeviceTag tag) {
  MOTOR("wb_motor_get_brake");
  (void)d;
  return 0;
}
