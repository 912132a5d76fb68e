/* Sensorium C controller library: GPS. Position, speed and speed vector arrive with the step reply
 * (NaN before the first measurement); the coordinate system comes from the attach description. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <webots/gps.h>

#include "internal.h"

void wb_gps_enable(WbDeviceTag tag, int sampling_period) {
  sn_sensor_enable(tag, SN_GPS, sampling_period, "wb_gps_enable");
}

void wb_gps_disable(WbDeviceTag tag) { sn_sensor_enable(tag, SN_GPS, 0, "wb_gps_disable"); }

int wb_gps_get_sampling_period(WbDeviceTag tag) { return sn_sensor_period(tag, SN_GPS, "wb_gps_get_sampling_period"); }

const double *wb_gps_get_values(WbDeviceTag tag) {
  sn_device *d = sn_sensor_reading(tag, SN_GPS, "wb_gps_get_values", "wb_gps_enable");
  return d ? d->gps_values : sn_no_values();
}

double wb_gps_get_speed(WbDeviceTag tag) {
  sn_device *d = sn_sensor_reading(tag, SN_GPS, "wb_gps_get_speed", "wb_gps_enable");
  return d ? d->gps_speed : NAN;
}

const double *wb_gps_get_speed_vector(WbDeviceTag tag) {
  sn_device *d = sn_sensor_reading(tag, SN_GPS, "wb_gps_get_speed_vector", "wb_gps_enable");
  return d ? d->gps_speed_vector : sn_no_values();
}

WbGpsCoordinateSystem wb_gps_get_coordinate_system(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_GPS, "wb_gps_get_coordinate_system");
  return d && d->coordinate_system == 1 ? WB_GPS_WGS84_COORDINATE : WB_GPS_LOCAL_COORDINATE;
}

/* C's (int) of a double as x86-64 converts it: truncated toward zero, and INT_MIN (the "integer
 * indefinite") for NaN, infinities and values out of int's range, which C leaves undefined. */
static int c_int(double v) {
  return v > -2147483649.0 && v < 2147483648.0 ? (int)v : INT_MIN;
}

const char *wb_gps_convert_to_degrees_minutes_seconds(double decimal_degrees) {
  /* libController's text: whole degrees, minutes and seconds, each truncated toward zero (so each
   * carries the angle's sign), in a string the caller frees, as Webots' does */
  const int degrees = c_int(decimal_degrees);
  const int minutes = c_int((decimal_degrees - degrees) * 60);
  const int seconds = c_int(((decimal_degrees - degrees) * 60 - minutes) * 60);
  char *text = malloc(64);
  if (text != NULL)
    snprintf(text, 64, "%d\xc2\xb0 %d\xe2\x80\xb2 %d\xe2\x80\xb3", degrees, minutes, seconds);
  return text;
}
