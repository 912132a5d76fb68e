/* Sensorium C controller library: generic device functions, LightSensor and DistanceSensor. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <webots/device.h>
#include <webots/distance_sensor.h>
#include <webots/light_sensor.h>

#include "internal.h"

/* ------------------------------------------------------------------ device */

const char *wb_device_get_name(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_OTHER, "wb_device_get_name");
  return d ? d->name : NULL;
}

const char *wb_device_get_model(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_OTHER, "wb_device_get_model");
  return d ? d->model : NULL;
}

const char *sensorium_device_get_type_name(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_OTHER, "sensorium_device_get_type_name");
  return d ? d->type_name : NULL;
}

WbNodeType wb_device_get_node_type(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_OTHER, "wb_device_get_node_type");
  if (d == NULL)
    return WB_NODE_NO_NODE;
  if (d->node_type != WB_NODE_NO_NODE)
    return (WbNodeType)d->node_type;
  switch (d->kind) {
    case SN_LIGHT: return WB_NODE_LIGHT_SENSOR;
    case SN_DISTANCE: return WB_NODE_DISTANCE_SENSOR;
    case SN_LIDAR: return WB_NODE_LIDAR;
    case SN_MOTOR: return WB_NODE_ROTATIONAL_MOTOR;
    case SN_POSITION: return WB_NODE_POSITION_SENSOR;
    case SN_LED: return WB_NODE_LED;
    default: return WB_NODE_NO_NODE;
  }
}

/* Webots' device type names and their node types */
static const struct {
  const char *name;
  WbNodeType node;
} NODE_TYPES[] = {
    {"Accelerometer", WB_NODE_ACCELEROMETER},
    {"Altimeter", WB_NODE_ALTIMETER},
    {"Brake", WB_NODE_BRAKE},
    {"Camera", WB_NODE_CAMERA},
    {"Compass", WB_NODE_COMPASS},
    {"Connector", WB_NODE_CONNECTOR},
    {"Display", WB_NODE_DISPLAY},
    {"DistanceSensor", WB_NODE_DISTANCE_SENSOR},
    {"Emitter", WB_NODE_EMITTER},
    {"GPS", WB_NODE_GPS},
    {"Gyro", WB_NODE_GYRO},
    {"InertialUnit", WB_NODE_INERTIAL_UNIT},
    {"LED", WB_NODE_LED},
    {"Lidar", WB_NODE_LIDAR},
    {"LightSensor", WB_NODE_LIGHT_SENSOR},
    {"LinearMotor", WB_NODE_LINEAR_MOTOR},
    {"Pen", WB_NODE_PEN},
    {"PositionSensor", WB_NODE_POSITION_SENSOR},
    {"Radar", WB_NODE_RADAR},
    {"RangeFinder", WB_NODE_RANGE_FINDER},
    {"Receiver", WB_NODE_RECEIVER},
    {"RotationalMotor", WB_NODE_ROTATIONAL_MOTOR},
    {"Skin", WB_NODE_SKIN},
    {"Speaker", WB_NODE_SPEAKER},
    {"TouchSensor", WB_NODE_TOUCH_SENSOR},
    {"VacuumGripper", WB_NODE_VACUUM_GRIPPER},
    {"Microphone", WB_NODE_MICROPHONE},
    {"Radio", WB_NODE_RADIO},
    {"Robot", WB_NODE_ROBOT},
};

int sn_node_type_of(const char *type_name) {
  for (size_t i = 0; type_name && i < sizeof NODE_TYPES / sizeof NODE_TYPES[0]; i++)
    if (strcmp(NODE_TYPES[i].name, type_name) == 0)
      return NODE_TYPES[i].node;
  return WB_NODE_NO_NODE;
}

/* ------------------------------------------------------------------ every sensor */

void sn_sensor_enable(WbDeviceTag tag, sn_kind kind, int period, const char *func) {
  sn_device *d = sn_device_get(tag, kind, func);
  if (d != NULL)
    sn_device_enable(d, period, func);
}

int sn_sensor_period(WbDeviceTag tag, sn_kind kind, const char *func) {
  sn_device *d = sn_device_get(tag, kind, func);
  return d ? d->sampling_period : 0;
}

sn_device *sn_sensor_reading(WbDeviceTag tag, sn_kind kind, const char *func, const char *enabler) {
  sn_device *d = sn_device_get(tag, kind, func);
  if (d != NULL && d->sampling_period <= 0)
    sn_warn_disabled(d, func, enabler, NULL);
  return d;
}

/* ------------------------------------------------------------------ scalar sensors */

static double scalar_value(WbDeviceTag tag, sn_kind kind, const char *func, const char *enabler) {
  sn_device *d = sn_sensor_reading(tag, kind, func, enabler);
  return d ? d->value : NAN;
}

/* light sensor */
void wb_light_sensor_enable(WbDeviceTag tag, int sampling_period) {
  sn_sensor_enable(tag, SN_LIGHT, sampling_period, "wb_light_sensor_enable");
}

void wb_light_sensor_disable(WbDeviceTag tag) { sn_sensor_enable(tag, SN_LIGHT, 0, "wb_light_sensor_disable"); }

int wb_light_sensor_get_sampling_period(WbDeviceTag tag) {
  return sn_sensor_period(tag, SN_LIGHT, "wb_light_sensor_get_sampling_period");
}

double wb_light_sensor_get_value(WbDeviceTag tag) {
  return scalar_value(tag, SN_LIGHT, "wb_light_sensor_get_value", "wb_light_sensor_enable");
}

int wb_light_sensor_get_lookup_table_size(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_LIGHT, "wb_light_sensor_get_lookup_table_size");
  return d ? d->lookup_rows : 0;
}

const double *wb_light_sensor_get_lookup_table(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_LIGHT, "wb_light_sensor_get_lookup_table");
  return d ? d->lookup_table : NULL;
}

/* distance sensor */
void wb_distance_sensor_enable(WbDeviceTag tag, int sampling_period) {
  sn_sensor_enable(tag, SN_DISTANCE, sampling_period, "wb_distance_sensor_enable");
}

void wb_distance_sensor_disable(WbDeviceTag tag) {
  sn_sensor_enable(tag, SN_DISTANCE, 0, "wb_distance_sensor_disable");
}

int wb_distance_sensor_get_sampling_period(WbDeviceTag tag) {
  return sn_sensor_period(tag, SN_DISTANCE, "wb_distance_sensor_get_sampling_period");
}

double wb_distance_sensor_get_value(WbDeviceTag tag) {
  return scalar_value(tag, SN_DISTANCE, "wb_distance_sensor_get_value", "wb_distance_sensor_enable");
}

double wb_distance_sensor_get_max_value(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_DISTANCE, "wb_distance_sensor_get_max_value");
  return d ? d->max_value : NAN;
}

double wb_distance_sensor_get_min_value(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_DISTANCE, "wb_distance_sensor_get_min_value");
  return d ? d->min_value : NAN;
}

double wb_distance_sensor_get_aperture(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_DISTANCE, "wb_distance_sensor_get_aperture");
  return d ? d->aperture : NAN;
}

int wb_distance_sensor_get_lookup_table_size(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_DISTANCE, "wb_distance_sensor_get_lookup_table_size");
  return d ? d->lookup_rows : 0;
}

const double *wb_distance_sensor_get_lookup_table(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_DISTANCE, "wb_distance_sensor_get_lookup_table");
  return d ? d->lookup_table : NULL;
}

WbDistanceSensorType wb_distance_sensor_get_type(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_DISTANCE, "wb_distance_sensor_get_type");
  if (d == NULL || d->sensor_type < 0 || d->sensor_type > WB_DISTANCE_SENSOR_LASER)
    return WB_DISTANCE_SENSOR_GENERIC;
  return (WbDistanceSensorType)d->sensor_type;
}
