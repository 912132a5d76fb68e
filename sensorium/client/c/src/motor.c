/* Sensorium C controller library: RotationalMotor. Commands are buffered here and sent with the
 * next step request (PROTOCOL.md 3.4); the getters answer from this copy. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <webots/motor.h>
#include <webots/nodes.h>

#include "internal.h"

#define MOTOR(func) sn_device *d = sn_device_get(tag, SN_MOTOR, func)

/* The other motors of a joint motor's coupled group (Webots' "group::part" names), from its
 * attach entry: the i-th one, NULL when it is not (or no more) there. */
static sn_device *sibling(const sn_device *d, int i) {
  sn_robot *rb = sn_robot_get("wb_motor_set_position");
  for (int k = 0; rb != NULL && k < rb->n_devices; k++)
    if (rb->devices[k].kind == SN_MOTOR && strcmp(rb->devices[k].name, d->coupled[i]) == 0)
      return &rb->devices[k];
  return NULL;
}

/* WbMotor's warning for a target beyond a joint motor's limits: judged on the scaled target,
 * naming the value asked for. */
static void position_warning(const sn_device *m, double position) {
  double target = position * m->multiplier;
  if (!m->joint || m->min_position == m->max_position || isinf(position))
    return;
  if (target > m->max_position)
    fprintf(stderr, "WARNING: %s \"%s\": too big requested position: %g > %g\n", m->type_name, sn_shown(m->name), position,
            m->max_position);
  else if (target < m->min_position)
    fprintf(stderr, "WARNING: %s \"%s\": too low requested position: %g < %g\n", m->type_name, sn_shown(m->name), position,
            m->min_position);
}

void wb_motor_set_position(WbDeviceTag tag, double position) {
  MOTOR("wb_motor_set_position");
  if (d == NULL)
    return;
  if (isnan(position)) {
    fprintf(stderr, "Error: wb_motor_set_position() called with an invalid 'position' argument (NaN)\n");
    return;
  }
  /* a joint's motor: Webots clamps the target to its limits with a warning (WbMotor); the target
   * position answered stays the one requested, as libController's. A coupled group's other motors
   * take it too, each scaled by its multiplier (libController's copy of their targets). */
  position_warning(d, position);
  for (int i = 0; i < d->n_coupled; i++) {
    sn_device *s = sibling(d, i);
    if (s == NULL)
      continue;
    position_warning(s, position);
    s->target_position = isinf(position) ? position : position * s->multiplier;
  }
  d->target_position = position;
  d->cmd_position = true;
}

/* One motor's share of a velocity: scaled by its multiplier, clamped to its maxVelocity with
 * WbMotor's warning. */
static double scaled_velocity(const sn_device *m, double velocity) {
  double wanted = velocity * m->multiplier;
  if (fabs(wanted) > m->max_velocity) {
    fprintf(stderr, "WARNING: %s \"%s\": The requested velocity %g exceeds 'maxVelocity' = %g.\n", m->type_name,
            sn_shown(m->name), wanted, m->max_velocity);
    wanted = copysign(m->max_velocity, wanted);
  }
  return wanted;
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
            d->target_position); /* libController shows the target position */
    return;
  }
  double multiplier = d->multiplier != 0.0 ? d->multiplier : 1.0;
  double sent = scaled_velocity(d, velocity) / multiplier;
  for (int i = 0; i < d->n_coupled; i++) {
    sn_device *s = sibling(d, i);
    if (s != NULL)
      s->velocity = scaled_velocity(s, velocity);
  }
  d->velocity = sent;
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
  /* the joint type is the node's, whether Sensorium simulates the motor or not */
  sn_device *d = sn_device_get(tag, SN_OTHER, "wb_motor_get_type");
  if (d == NULL)
    return WB_ROTATIONAL;
  if (d->node_type != WB_NODE_ROTATIONAL_MOTOR && d->node_type != WB_NODE_LINEAR_MOTOR) {
    fprintf(stderr, "Error: wb_motor_get_type(): device tag %u is '%s', a %s\n", (unsigned)tag, sn_shown(d->name), d->type_name);
    return WB_ROTATIONAL;
  }
  return d->node_type == WB_NODE_LINEAR_MOTOR ? WB_LINEAR : WB_ROTATIONAL;
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
  return d ? sn_brake_of(d->name, true, "wb_motor_get_brake") : 0;
}

/* ------------------------------------------------------------------ what needs physics */

/* A drive's wheel turns at its commanded speed at once: these are accepted and ignored. A joint's
 * motor (maxForce in its description) moves as Webots moves it without physics: its acceleration
 * and available torque/force bound the speed ramp (sent with the next step); PID gains, forces
 * and torques are ignored and feedback reads NaN (Webots has none without a Physics node). */
static sn_device *physics(WbDeviceTag tag, const char *func) {
  sn_device *d = sn_device_get(tag, SN_MOTOR, func);
  if (d != NULL && !d->warned_physics) {
    d->warned_physics = true;
    if (d->joint)
      fprintf(stderr, "Warning: %s(): %s '%s' moves its joint kinematically (no physics): PID gains, forces and "
              "torques are ignored, force and torque feedback read NaN.\n", func, d->type_name, sn_shown(d->name));
    else
      fprintf(stderr, "Warning: %s(): %s '%s' is a kinematic wheel: accelerations, forces, torques and PID gains "
              "are ignored, force and torque feedback read NaN.\n", func, d->type_name, sn_shown(d->name));
  }
  return d;
}

static sn_device *joint_or_physics(WbDeviceTag tag, const char *func) {
  sn_device *d = sn_device_get(tag, SN_MOTOR, func);
  if (d != NULL && !d->joint) {
    physics(tag, func);
    return NULL;
  }
  return d;
}

void wb_motor_set_acceleration(WbDeviceTag tag, double acceleration) {
  sn_device *d = sn_device_get(tag, SN_MOTOR, "wb_motor_set_acceleration");
  if (d == NULL)
    return;
  if (!d->joint) {
    physics(tag, "wb_motor_set_acceleration");
    d->acceleration = acceleration;
    return;
  }
  if (isnan(acceleration) || isinf(acceleration) || (acceleration < 0.0 && acceleration != -1.0)) {
    fprintf(stderr, "Error: wb_motor_set_acceleration() called with negative 'acceleration' argument.\n");
    return;
  }
  d->acceleration = acceleration;
  d->cmd_acceleration = true;
}

static void set_available(WbDeviceTag tag, double value, const char *what, const char *func) {
  sn_device *d = joint_or_physics(tag, func);
  if (d == NULL)
    return;
  if (isnan(value) || isinf(value) || value < 0.0) {
    fprintf(stderr, "Error: %s() called with negative '%s' argument.\n", func, what);
    return;
  }
  d->available_force = value;
  d->cmd_available = true;
}

static double get_joint(WbDeviceTag tag, bool available, const char *func) {
  sn_device *d = joint_or_physics(tag, func);
  if (d == NULL)
    return NAN;
  return available ? d->available_force : d->max_force;
}
double wb_motor_get_acceleration(WbDeviceTag tag) {
  MOTOR("wb_motor_get_acceleration");
  return d ? d->acceleration : NAN;
}
void wb_motor_set_available_force(WbDeviceTag tag, double force) {
  set_available(tag, force, "force", "wb_motor_set_available_force");
}
double wb_motor_get_available_force(WbDeviceTag tag) {
  return get_joint(tag, true, "wb_motor_get_available_force");
}
double wb_motor_get_max_force(WbDeviceTag tag) {
  return get_joint(tag, false, "wb_motor_get_max_force");
}
void wb_motor_set_available_torque(WbDeviceTag tag, double torque) {
  set_available(tag, torque, "torque", "wb_motor_set_available_torque");
}
double wb_motor_get_available_torque(WbDeviceTag tag) {
  return get_joint(tag, true, "wb_motor_get_available_torque");
}
double wb_motor_get_max_torque(WbDeviceTag tag) {
  return get_joint(tag, false, "wb_motor_get_max_torque");
}
void wb_motor_set_control_pid(WbDeviceTag tag, double p, double i, double d) {
  (void)p;
  (void)i;
  (void)d;
  physics(tag, "wb_motor_set_control_pid");
}
double wb_motor_get_multiplier(WbDeviceTag tag) {
  MOTOR("wb_motor_get_multiplier");
  return d ? d->multiplier : NAN;
}
void wb_motor_set_force(WbDeviceTag tag, double force) {
  (void)force;
  physics(tag, "wb_motor_set_force");
}
void wb_motor_set_torque(WbDeviceTag tag, double torque) {
  (void)torque;
  physics(tag, "wb_motor_set_torque");
}

static void feedback_period(WbDeviceTag tag, bool torque, int period, const char *func) {
  sn_device *d = physics(tag, func);
  if (d == NULL)
    return;
  if (period < 0) {
    fprintf(stderr, "Error: %s(): negative sampling period %d\n", func, period);
    return;
  }
  if (torque)
    d->torque_feedback_period = period;
  else
    d->force_feedback_period = period;
}
void wb_motor_enable_force_feedback(WbDeviceTag tag, int sampling_period) {
  feedback_period(tag, false, sampling_period, "wb_motor_enable_force_feedback");
}
void wb_motor_disable_force_feedback(WbDeviceTag tag) { feedback_period(tag, false, 0, "wb_motor_disable_force_feedback"); }
int wb_motor_get_force_feedback_sampling_period(WbDeviceTag tag) {
  MOTOR("wb_motor_get_force_feedback_sampling_period");
  return d ? d->force_feedback_period : 0;
}
double wb_motor_get_force_feedback(WbDeviceTag tag) {
  physics(tag, "wb_motor_get_force_feedback");
  return NAN;
}
void wb_motor_enable_torque_feedback(WbDeviceTag tag, int sampling_period) {
  feedback_period(tag, true, sampling_period, "wb_motor_enable_torque_feedback");
}
void wb_motor_disable_torque_feedback(WbDeviceTag tag) { feedback_period(tag, true, 0, "wb_motor_disable_torque_feedback"); }
int wb_motor_get_torque_feedback_sampling_period(WbDeviceTag tag) {
  MOTOR("wb_motor_get_torque_feedback_sampling_period");
  return d ? d->torque_feedback_period : 0;
}
double wb_motor_get_torque_feedback(WbDeviceTag tag) {
  physics(tag, "wb_motor_get_torque_feedback");
  return NAN;
}
