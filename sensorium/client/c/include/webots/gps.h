/* Sensorium C controller library: GPS (Webots' wb_gps_* functions).
 * Readings arrive with the step reply: NaN before the first measurement. */
#ifndef WB_GPS_H
#define WB_GPS_H

#include "types.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum { WB_GPS_LOCAL_COORDINATE = 0, WB_GPS_WGS84_COORDINATE } WbGpsCoordinateSystem;

void wb_gps_enable(WbDeviceTag tag, int sampling_period);
void wb_gps_disable(WbDeviceTag tag);
int wb_gps_get_sampling_period(WbDeviceTag tag);
const double *wb_gps_get_values(WbDeviceTag tag);
double wb_gps_get_speed(WbDeviceTag tag);
const double *wb_gps_get_speed_vector(WbDeviceTag tag);
WbGpsCoordinateSystem wb_gps_get_coordinate_system(WbDeviceTag tag);

/* "D° M′ S″" of a decimal angle in degrees; valid until the next call */
const char *wb_gps_convert_to_degrees_minutes_seconds(double decimal_degrees);

#ifdef __cplusplus
}
#endif

#endif /* WB_GPS_H */
