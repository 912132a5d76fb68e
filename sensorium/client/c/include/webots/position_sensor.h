/* Sensorium C controller library: PositionSensor (a wheel encoder: the angle of a differential
 * drive's wheel, rad; cached readings, NaN before the first one). */
#ifndef WB_POSITION_SENSOR_H
#define WB_POSITION_SENSOR_H

#include "types.h"

#ifdef __cplusplus
extern "C" {
#endif

void wb_position_sensor_enable(WbDeviceTag tag, int sampling_period);
void wb_position_sensor_disable(WbDeviceTag tag);
int wb_position_sensor_get_sampling_period(WbDeviceTag tag);
double wb_position_sensor_get_value(WbDeviceTag tag);
WbJointType wb_position_sensor_get_type(WbDeviceTag tag);
WbDeviceTag wb_position_sensor_get_motor(WbDeviceTag tag);
WbDeviceTag wb_position_sensor_get_brake(WbDeviceTag tag); /* 0: no Brake on its joint */

#ifdef __cplusplus
}
#endif

#endif /* WB_POSITION_SENSOR_H */
