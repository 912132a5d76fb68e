/* Sensorium C controller library: the sensors measured from the kinematic motion (InertialUnit,
 * Compass, Accelerometer, Gyro, Altimeter, TouchSensor; GPS is gps.c). Readings arrive with the step
 * reply (NaN before the first measurement, the last one kept after a disable); vector getters return
 * the device's own array, valid until the next step. */
#include <math.h>
#include <stdio.h>

#include <webots/accelerometer.h>
#include <webots/altimeter.h>
#include <webots/compass.h>
#include <webots/gyro.h>
#include <webots/inertial_unit.h>
#include <webots/touch_sensor.h>

#include "internal.h"

static int table_size(WbDeviceTag tag, sn_kind kind, const char *func) {
  sn_device *d = sn_device_get(tag, kind, func);
  return d ? d->lookup_rows : 0;
}

static const double *table(WbDeviceTag tag, sn_kind kind, const char *func) {
  sn_device *d = sn_device_get(tag, kind, func);
  return d ? d->lookup_table : sn_no_values();
}

/* ------------------------------------------------------------------ InertialUnit */
void wb_inertial_unit_enable(WbDeviceTag tag, int sampling_period) {
  sn_sensor_enable(tag, SN_IMU, sampling_period, "wb_inertial_unit_enable");
}
void wb_inertial_unit_disable(WbDeviceTag tag) { sn_sensor_enable(tag, SN_IMU, 0, "wb_inertial_unit_disable"); }
int wb_inertial_unit_get_sampling_period(WbDeviceTag tag) {
  return sn_sensor_period(tag, SN_IMU, "wb_inertial_unit_get_sampling_period");
}
double wb_inertial_unit_get_noise(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_IMU, "wb_inertial_unit_get_noise");
  return d ? d->noise : NAN;
}
const double *wb_inertial_unit_get_roll_pitch_yaw(WbDeviceTag tag) {
  sn_device *d = sn_sensor_reading(tag, SN_IMU, "wb_inertial_unit_get_roll_pitch_yaw", "wb_inertial_unit_enable");
  return d ? d->roll_pitch_yaw : sn_no_values();
}
const double *wb_inertial_unit_get_quaternion(WbDeviceTag tag) {
  sn_device *d = sn_sensor_reading(tag, SN_IMU, "wb_inertial_unit_get_quaternion", "wb_inertial_unit_enable");
  return d ? d->quaternion : sn_no_values();
}

/* ------------------------------------------------------------------ Compass */
void wb_compass_enable(WbDeviceTag tag, int sampling_period) {
  sn_sensor_enable(tag, SN_COMPASS, sampling_period, "wb_compass_enable");
}
void wb_compass_disable(WbDeviceTag tag) { sn_sensor_enable(tag, SN_COMPASS, 0, "wb_compass_disable"); }
int wb_compass_get_sampling_period(WbDeviceTag tag) {
  return sn_sensor_period(tag, SN_COMPASS, "wb_compass_get_sampling_period");
}
const double *wb_compass_get_values(WbDeviceTag tag) {
  sn_device *d = sn_sensor_reading(tag, SN_COMPASS, "wb_compass_get_values", "wb_compass_enable");
  return d ? d->values : sn_no_values();
}
int wb_compass_get_lookup_table_size(WbDeviceTag tag) {
  return table_size(tag, SN_COMPASS, "wb_compass_get_lookup_table_size");
}
const double *wb_compass_get_lookup_table(WbDeviceTag tag) {
  return table(tag, SN_COMPASS, "wb_compass_get_lookup_table");
}

/* ------------------------------------------------------------------ Accelerometer */
void wb_accelerometer_enable(WbDeviceTag tag, int sampling_period) {
  sn_sensor_enable(tag, SN_ACCELEROMETER, sampling_period, "wb_accelerometer_enable");
}
void wb_accelerometer_disable(WbDeviceTag tag) {
  sn_sensor_enable(tag, SN_ACCELEROMETER, 0, "wb_accelerometer_disable");
}
int wb_accelerometer_get_sampling_period(WbDeviceTag tag) {
  return sn_sensor_period(tag, SN_ACCELEROMETER, "wb_accelerometer_get_sampling_period");
}
const double *wb_accelerometer_get_values(WbDeviceTag tag) {
  sn_device *d = sn_sensor_reading(tag, SN_ACCELEROMETER, "wb_accelerometer_get_values", "wb_accelerometer_enable");
  return d ? d->values : sn_no_values();
}
int wb_accelerometer_get_lookup_table_size(WbDeviceTag tag) {
  return table_size(tag, SN_ACCELEROMETER, "wb_accelerometer_get_lookup_table_size");
}
const double *wb_accelerometer_get_lookup_table(WbDeviceTag tag) {
  return table(tag, SN_ACCELEROMETER, "wb_accelerometer_get_lookup_table");
}

/* ------------------------------------------------------------------ Gyro */
void wb_gyro_enable(WbDeviceTag tag, int sampling_period) {
  sn_sensor_enable(tag, SN_GYRO, sampling_period, "wb_gyro_enable");
}
void wb_gyro_disable(WbDeviceTag tag) { sn_sensor_enable(tag, SN_GYRO, 0, "wb_gyro_disable"); }
int wb_gyro_get_sampling_period(WbDeviceTag tag) {
  return sn_sensor_period(tag, SN_GYRO, "wb_gyro_get_sampling_period");
}
const double *wb_gyro_get_values(WbDeviceTag tag) {
  sn_device *d = sn_sensor_reading(tag, SN_GYRO, "wb_gyro_get_values", "wb_gyro_enable");
  return d ? d->values : sn_no_values();
}
int wb_gyro_get_lookup_table_size(WbDeviceTag tag) { return table_size(tag, SN_GYRO, "wb_gyro_get_lookup_table_size"); }
const double *wb_gyro_get_lookup_table(WbDeviceTag tag) { return table(tag, SN_GYRO, "wb_gyro_get_lookup_table"); }

/* ------------------------------------------------------------------ Altimeter */
void wb_altimeter_enable(WbDeviceTag tag, int sampling_period) {
  sn_sensor_enable(tag, SN_ALTIMETER, sampling_period, "wb_altimeter_enable");
}
void wb_altimeter_disable(WbDeviceTag tag) { sn_sensor_enable(tag, SN_ALTIMETER, 0, "wb_altimeter_disable"); }
int wb_altimeter_get_sampling_period(WbDeviceTag tag) {
  return sn_sensor_period(tag, SN_ALTIMETER, "wb_altimeter_get_sampling_period");
}
double wb_altimeter_get_value(WbDeviceTag tag) {
  sn_device *d = sn_sensor_reading(tag, SN_ALTIMETER, "wb_altimeter_get_value", "wb_altimeter_enable");
  return d ? d->value : NAN;
}

/* ------------------------------------------------------------------ TouchSensor */
void wb_touch_sensor_enable(WbDeviceTag tag, int sampling_period) {
  sn_sensor_enable(tag, SN_TOUCH, sampling_period, "wb_touch_sensor_enable");
}
void wb_touch_sensor_disable(WbDeviceTag tag) { sn_sensor_enable(tag, SN_TOUCH, 0, "wb_touch_sensor_disable"); }
int wb_touch_sensor_get_sampling_period(WbDeviceTag tag) {
  return sn_sensor_period(tag, SN_TOUCH, "wb_touch_sensor_get_sampling_period");
}
WbTouchSensorType wb_touch_sensor_get_type(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_TOUCH, "wb_touch_sensor_get_type");
  return d ? (WbTouchSensorType)d->sensor_type : WB_TOUCH_SENSOR_BUMPER;
}
double wb_touch_sensor_get_value(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_TOUCH, "wb_touch_sensor_get_value");
  if (d == NULL)
    return NAN;
  if (d->sensor_type == WB_TOUCH_SENSOR_FORCE3D) {
    fprintf(stderr, "Error: wb_touch_sensor_get_value() must be used with a TouchSensor of type \"bumper\" or \"force\"\n"
                    "Error: you should use wb_touch_sensor_get_values() instead.\n");
    return NAN;
  }
  if (d->sampling_period <= 0)
    sn_warn_disabled(d, "wb_touch_sensor_get_value", "wb_touch_sensor_enable", NULL);
  return d->value;
}
const double *wb_touch_sensor_get_values(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_TOUCH, "wb_touch_sensor_get_values");
  if (d == NULL)
    return sn_no_values();
  if (d->sensor_type != WB_TOUCH_SENSOR_FORCE3D) {
    fprintf(stderr, "Error: wb_touch_sensor_get_values() must be used with a TouchSensor of type \"force-3d\"\n"
                    "Error: you should use wb_touch_sensor_get_value() instead.\n");
    return NULL;
  }
  if (d->sampling_period <= 0)
    sn_warn_disabled(d, "wb_touch_sensor_get_values", "wb_touch_sensor_enable", NULL);
  return d->values;
}
int wb_touch_sensor_get_lookup_table_size(WbDeviceTag tag) {
  return table_size(tag, SN_TOUCH, "wb_touch_sensor_get_lookup_table_size");
}
const double *wb_touch_sensor_get_lookup_table(WbDeviceTag tag) {
  return table(tag, SN_TOUCH, "wb_touch_sensor_get_lookup_table");
}
