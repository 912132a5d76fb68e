/* Sensorium C controller library: RotationalMotor (a wheel of a differential drive). Commands
 * are buffered and travel with the next wb_robot_step(), as in Webots; the getters answer from the
 * controller's copy of the commands. */
#ifndef WB_MOTOR_H
#define WB_MOTOR_H

#include "types.h"

#ifdef __cplusplus
extern "C" {
#endif

void wb_motor_set_position(WbDeviceTag tag, double position);  /* INFINITY: velocity control */
void wb_motor_set_velocity(WbDeviceTag tag, double velocity);  /* clamped to max velocity */
double wb_motor_get_target_position(WbDeviceTag tag);
double wb_motor_get_min_position(WbDeviceTag tag);
double wb_motor_get_max_position(WbDeviceTag tag);
double wb_motor_get_velocity(WbDeviceTag tag);
double wb_motor_get_max_velocity(WbDeviceTag tag);
WbJointType wb_motor_get_type(WbDeviceTag tag);
WbDeviceTag wb_motor_get_position_sensor(WbDeviceTag tag);     /* 0 if the wheel has none */
WbDeviceTag wb_motor_get_brake(WbDeviceTag tag);               /* 0: no Brake on its joint */

/* What needs physics: a kinematic wheel turns at its commanded speed at once. The setters are
 * accepted and ignored, the getters answer Webots' default (-1 acceleration) or NaN; one warning
 * line per motor. wb_motor_get_multiplier answers the motor's multiplier (1 for a wheel): a joint
 * motor named "group::part" passes the positions and velocities it is given to the other joint
 * motors of its group, each scaled by its own multiplier (Webots' coupled motors). */
void wb_motor_set_acceleration(WbDeviceTag tag, double acceleration);
double wb_motor_get_acceleration(WbDeviceTag tag);
void wb_motor_set_available_force(WbDeviceTag tag, double force);
double wb_motor_get_available_force(WbDeviceTag tag);
double wb_motor_get_max_force(WbDeviceTag tag);
void wb_motor_set_available_torque(WbDeviceTag tag, double torque);
double wb_motor_get_available_torque(WbDeviceTag tag);
double wb_motor_get_max_torque(WbDeviceTag tag);
void wb_motor_set_control_pid(WbDeviceTag tag, double p, double i, double d);
double wb_motor_get_multiplier(WbDeviceTag tag);
void wb_motor_set_force(WbDeviceTag tag, double force);
void wb_motor_set_torque(WbDeviceTag tag, double torque);
void wb_motor_enable_force_feedback(WbDeviceTag tag, int sampling_period);
void wb_motor_disable_force_feedback(WbDeviceTag tag);
int wb_motor_get_force_feedback_sampling_period(WbDeviceTag tag);
double wb_motor_get_force_feedback(WbDeviceTag tag);
void wb_motor_enable_torque_feedback(WbDeviceTag tag, int sampling_period);
void wb_motor_disable_torque_feedback(WbDeviceTag tag);
int wb_motor_get_torque_feedback_sampling_period(WbDeviceTag tag);
double wb_motor_get_torque_feedback(WbDeviceTag tag);

#ifdef __cplusplus
}
#endif

#endif /* WB_MOTOR_H */
