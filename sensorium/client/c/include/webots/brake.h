/* Sensorium C controller library: Brake (Webots' wb_brake_* functions).
 * Its joint's type and the tags of the motor and position sensor on its joint (0 when none);
 * wb_brake_set_damping_constant has no effect (no physics: one warning line per brake). */
#ifndef WB_BRAKE_H
#define WB_BRAKE_H

#include "types.h"

#ifdef __cplusplus
extern "C" {
#endif

void wb_brake_set_damping_constant(WbDeviceTag tag, double damping_constant);
WbJointType wb_brake_get_type(WbDeviceTag tag);
WbDeviceTag wb_brake_get_motor(WbDeviceTag tag);
WbDeviceTag wb_brake_get_position_sensor(WbDeviceTag tag);

#ifdef __cplusplus
}
#endif

#endif /* WB_BRAKE_H */
