/* Sensorium C controller library: user input (joystick, mouse, wb_robot_wait_for_user_input_event),
 * the robot's battery sensor and the image pixel helpers. A headless server has no user: no key, button,
 * axis or click ever happens, so waiting for one runs the simulation for the whole timeout. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>

#include <webots/camera.h>
#include <webots/joystick.h>
#include <webots/mouse.h>
#include <webots/range_finder.h>
#include <webots/robot.h>

#include "internal.h"

static int g_joystick_period = 0, g_mouse_period = 0, g_battery_period = 0;
static bool g_mouse_3d = false;

static int checked_period(int period, const char *func) {
  if (period < 0) {
    fprintf(stderr, "Error: %s(): negative sampling period %d\n", func, period);
    return -1;
  }
  return period;
}

WbUserInputEvent wb_robot_wait_for_user_input_event(WbUserInputEvent event_type, int timeout) {
  sn_robot *rb = sn_robot_get("wb_robot_wait_for_user_input_event");
  (void)event_type; /* none of the events can happen headless */
  if (timeout < 0) {
    fprintf(stderr, "Error: wb_robot_wait_for_user_input_event(): negative timeout %d ms\n", timeout);
    return WB_EVENT_NO_EVENT;
  }
  /* Webots runs the simulation while it waits: whole basic time steps until the timeout is covered */
  int step = rb->basic_time_step;
  int steps = (timeout + step - 1) / step;
  if (steps == 0)
    return WB_EVENT_NO_EVENT;
  return wb_robot_step(steps * step) == -1 ? WB_EVENT_QUIT : WB_EVENT_NO_EVENT;
}

/* ------------------------------------------------------------------ battery */
/* The server samples the robot's battery (Robot.battery, README "Battery and Charger"); the period is
 * kept here too, for wb_robot_battery_sensor_get_sampling_period once the simulation ended. */
void wb_robot_battery_sensor_enable(int sampling_period) {
  sn_robot *rb = sn_robot_get("wb_robot_battery_sensor_enable");
  int p = checked_period(sampling_period, "wb_robot_battery_sensor_enable");
  if (p < 0 || rb->terminated)
    return;
  sn_reply rep;
  if (sn_device_call(rb, NULL, "robot/battery_sensor_enable", sn_arg_int, &p, "wb_robot_battery_sensor_enable",
                     &rep) != 0)
    return;
  sn_reply_free(&rep);
  g_battery_period = p;
}
void wb_robot_battery_sensor_disable(void) { wb_robot_battery_sensor_enable(0); }
int wb_robot_battery_sensor_get_sampling_period(void) { return g_battery_period; }
double wb_robot_battery_sensor_get_value(void) {
  sn_robot *rb = sn_robot_get("wb_robot_battery_sensor_get_value");
  if (rb->terminated)
    return NAN;
  sn_reply rep;
  if (sn_robot_call(rb, "robot/battery_sensor_get_value", 0, NULL, NULL, "wb_robot_battery_sensor_get_value", &rep) != 0)
    return NAN;
  double v = NAN;
  if (!sn_as_double(sn_get(rep.result, "value"), &v))
    v = NAN;
  sn_reply_free(&rep);
  return v;
}

/* ------------------------------------------------------------------ joystick */
void wb_joystick_enable(int sampling_period) {
  sn_robot_get("wb_joystick_enable");
  int p = checked_period(sampling_period, "wb_joystick_enable");
  if (p >= 0)
    g_joystick_period = p;
}
void wb_joystick_disable(void) { g_joystick_period = 0; }
int wb_joystick_get_sampling_period(void) { return g_joystick_period; }
bool wb_joystick_is_connected(void) { return false; }
const char *wb_joystick_get_model(void) { return NULL; }
int wb_joystick_get_number_of_axes(void) { return 0; }
int wb_joystick_get_axis_value(int axis) {
  (void)axis;
  return 0;
}
int wb_joystick_get_number_of_povs(void) { return 0; }
int wb_joystick_get_pov_value(int pov) {
  (void)pov;
  return 0;
}
int wb_joystick_get_pressed_button(void) { return -1; }
void wb_joystick_set_constant_force(int level) { (void)level; }
void wb_joystick_set_constant_force_duration(double duration) { (void)duration; }
void wb_joystick_set_auto_centering_gain(double gain) { (void)gain; }
void wb_joystick_set_resistance_gain(double gain) { (void)gain; }
void wb_joystick_set_force_axis(int axis) { (void)axis; }

/* ------------------------------------------------------------------ mouse */
void wb_mouse_enable(int sampling_period) {
  sn_robot_get("wb_mouse_enable");
  int p = checked_period(sampling_period, "wb_mouse_enable");
  if (p >= 0)
    g_mouse_period = p;
}
void wb_mouse_disable(void) { g_mouse_period = 0; }
int wb_mouse_get_sampling_period(void) { return g_mouse_period; }
void wb_mouse_enable_3d_position(void) { g_mouse_3d = true; }
void wb_mouse_disable_3d_position(void) { g_mouse_3d = false; }
bool wb_mouse_is_3d_position_enabled(void) { return g_mouse_3d; }
WbMouseState wb_mouse_get_state(void) {
  WbMouseState s = {false, false, false, NAN, NAN, NAN, NAN, NAN};
  if (g_mouse_period <= 0)
    fprintf(stderr, "Error: wb_mouse_get_state() called for a disabled device! Please use: wb_mouse_enable().\n");
  return s;
}

/* ------------------------------------------------------------------ image helpers (pure) */
static unsigned char channel(const unsigned char *image, int width, int x, int y, int c) {
  return image ? image[4 * ((size_t)y * (size_t)width + (size_t)x) + (size_t)c] : 0;
}
unsigned char wb_camera_image_get_blue(const unsigned char *image, int width, int x, int y) { return channel(image, width, x, y, 0); }
unsigned char wb_camera_image_get_green(const unsigned char *image, int width, int x, int y) { return channel(image, width, x, y, 1); }
unsigned char wb_camera_image_get_red(const unsigned char *image, int width, int x, int y) { return channel(image, width, x, y, 2); }
unsigned char wb_camera_image_get_gray(const unsigned char *image, int width, int x, int y) {
  return (unsigned char)((channel(image, width, x, y, 0) + channel(image, width, x, y, 1) + channel(image, width, x, y, 2)) / 3);
}
unsigned char wb_camera_image_get_grey(const unsigned char *image, int width, int x, int y) {
  return wb_camera_image_get_gray(image, width, x, y);
}
float wb_range_finder_image_get_depth(const float *image, int width, int x, int y) {
  return image ? image[(size_t)y * (size_t)width + (size_t)x] : NAN;
}
