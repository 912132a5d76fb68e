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
WbDeviceTag wb_motor_get_brake(WbDeviceTag tag);               /* 0: no Brake devices */

#ifdef __cplusplus
}
#endif

#endif /* WB_MOTOR_H */
