/* Sensorium C controller library: PositionSensor (wheel encoders), LED and Keyboard. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <webots/keyboard.h>
#include <webots/led.h>
#include <webots/position_sensor.h>
#include <webots/robot.h>

#include "internal.h"

/* ------------------------------------------------------------------ position sensor */

#define POSITION(func) sn_device *d = sn_device_get(tag, SN_POSITION, func)

void wb_position_sensor_enable(WbDeviceTag tag, int sampling_period) {
  sn_sensor_enable(tag, SN_POSITION, sampling_period, "wb_position_sensor_enable");
}

void wb_position_sensor_disable(WbDeviceTag tag) {
  sn_sensor_enable(tag, SN_POSITION, 0, "wb_position_sensor_disable");
}

int wb_position_sensor_get_sampling_period(WbDeviceTag tag) {
  return sn_sensor_period(tag, SN_POSITION, "wb_position_sensor_get_sampling_period");
}

double wb_position_sensor_get_value(WbDeviceTag tag) {
  sn_device *d = sn_sensor_reading(tag, SN_POSITION, "wb_position_sensor_get_value", "wb_position_sensor_enable");
  return d ? d->value : NAN;
}

WbJointType wb_position_sensor_get_type(WbDeviceTag tag) {
  POSITION("wb_position_sensor_get_type");
  if (d == NULL || d->motor_name == NULL)
    return WB_ROTATIONAL;
  /* its joint's type, which is its motor's (a slider's or a Track's LinearMotor: linear) */
  sn_robot *rb = sn_robot_get("wb_position_sensor_get_type");
  for (int i = 0; i < rb->n_devices; i++)
    if (strcmp(rb->devices[i].name, d->motor_name) == 0)
      return rb->devices[i].node_type == WB_NODE_LINEAR_MOTOR ? WB_LINEAR : WB_ROTATIONAL;
  return WB_ROTATIONAL;
}

WbDeviceTag wb_position_sensor_get_motor(WbDeviceTag tag) {
  POSITION("wb_position_sensor_get_motor");
  return d && d->motor_name ? wb_robot_get_device(d->motor_name) : 0;
}

WbDeviceTag wb_position_sensor_get_brake(WbDeviceTag tag) {
  POSITION("wb_position_sensor_get_brake");
  return d ? sn_brake_of(d->name, false, "wb_position_sensor_get_brake") : 0;
}

/* ------------------------------------------------------------------ LED */

void wb_led_set(WbDeviceTag tag, int value) {
  sn_device *d = sn_device_get(tag, SN_LED, "wb_led_set");
  if (d == NULL)
    return;
  /* a gradual LED: 0xRRGGBB without a colour, else an intensity 0..255 of its colour (Webots' LED page) */
  int hi = d->led_gradual ? (d->led_colors == 0 ? 0xFFFFFF : 255) : d->led_colors;
  if (value < 0 || value > hi) {
    fprintf(stderr, "Error: wb_led_set(): value %d out of range [0, %d] for LED '%s'.\n", value, hi, sn_shown(d->name));
    return;
  }
  if (!sn_device_set(d, "set", sn_arg_int, &value, "wb_led_set"))
    return;
  d->led_value = value;
}

int wb_led_get(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_LED, "wb_led_get");
  return d ? d->led_value : 0;
}

/* ------------------------------------------------------------------ keyboard (never a key) */

void wb_keyboard_enable(int sampling_period) {
  sn_robot *rb = sn_robot_get("wb_keyboard_enable");
  if (sampling_period < 0) {
    fprintf(stderr, "Error: wb_keyboard_enable(): negative sampling period %d\n", sampling_period);
    return;
  }
  rb->keyboard_period = sampling_period;
}

void wb_keyboard_disable(void) { sn_robot_get("wb_keyboard_disable")->keyboard_period = 0; }

int wb_keyboard_get_sampling_period(void) { return sn_robot_get("wb_keyboard_get_sampling_period")->keyboard_period; }

int wb_keyboard_get_key(void) {
  sn_robot *rb = sn_robot_get("wb_keyboard_get_key");
  if (rb->keyboard_period <= 0)
    fprintf(stderr, "Error: wb_keyboard_get_key() called for a disabled device! Please use: wb_keyboard_enable().\n");
  return -1;
}
