/* The robot and device API on a robot with listed-only devices (tests/worlds/c_api.yaml, "gadget"):
 * Webots' device order, node types and models; listed-only devices answer "no value"; step(0) delivers
 * without advancing time; waiting for user input runs the simulation for the timeout; tasks and
 * mutexes. */
#define _POSIX_C_SOURCE 200809L
#include <string.h>
#include <time.h>

#include <webots/camera.h>
#include <webots/device.h>
#include <webots/display.h>
#include <webots/led.h>
#include <webots/motor.h>
#include <webots/nodes.h>
#include <webots/radar.h>

#include "ts.h"

static WbMutexRef g_mutex;
static int g_result = 0;

static void task(void *param) { /* Webots' wb_robot_task_new: runs in its own thread */
  wb_robot_mutex_lock(g_mutex);
  g_result = *(const int *)param;
  wb_robot_mutex_unlock(g_mutex);
}

int main(void) {
  ts_setup();
  ts_assert_string_equal(wb_robot_get_model(), "Gadget 1.0", "robot model");
  ts_assert_double_equal(wb_robot_get_basic_time_step(), 16.0, "basic time step");
  ts_assert_int_equal(wb_robot_get_number_of_devices(), 5, "every device, simulated or not");
  const char *names[] = {"camera", "led", "radar", "display", "lift"};
  const WbNodeType types[] = {WB_NODE_CAMERA, WB_NODE_LED, WB_NODE_RADAR, WB_NODE_DISPLAY, WB_NODE_LINEAR_MOTOR};
  for (int i = 0; i < 5; i++) {
    WbDeviceTag tag = wb_robot_get_device_by_index(i);
    ts_assert_string_equal(wb_device_get_name(tag), names[i], "device %d's name", i);
    ts_assert_int_equal(wb_device_get_node_type(tag), types[i], "device %d's node type", i);
    ts_assert_int_equal(wb_robot_get_device(names[i]), tag, "device %d by name", i);
  }
  ts_assert_int_equal(wb_robot_get_device_by_index(5), 0, "no device past the last");
  ts_assert_int_equal(wb_robot_get_device("nothing"), 0, "no such device");
  ts_assert_string_equal(wb_device_get_model(wb_robot_get_device("radar")), "ARS 408", "a device's model");
  /* the simulated radar: no target before its first value, its range the world's (Webots' default) */
  WbDeviceTag radar = wb_robot_get_device("radar"), display = wb_robot_get_device("display");
  WbDeviceTag lift = wb_robot_get_device("lift");
  wb_radar_enable(radar, 16);
  ts_assert_int_equal(wb_radar_get_number_of_targets(radar), 0, "no radar target");
  ts_assert_pointer_null(wb_radar_get_targets(radar), "no radar targets array");
  ts_assert_double_equal(wb_radar_get_max_range(radar), 50.0, "radar range: the world's");
  /* the display draws (its size the world's); the linear motor moves its slider */
  wb_display_draw_text(display, "hello", 0, 0);
  ts_assert_int_equal(wb_display_get_width(display), 64, "display width: the world's (Webots' default)");
  wb_motor_set_velocity(lift, 1.0);
  ts_assert_int_equal(wb_motor_get_type(lift), WB_LINEAR, "a linear motor's type");
  ts_assert_double_equal(wb_motor_get_velocity(lift), 1.0, "a linear motor moves its slider: its velocity");
  ts_assert_double_equal(wb_motor_get_max_force(lift), 10.0, "a linear motor's maxForce: Webots' default");
  /* the simulated LED */
  WbDeviceTag led = wb_robot_get_device("led");
  wb_led_set(led, 1);
  ts_assert_int_equal(wb_led_get(led), 1, "LED on");
  /* step(0): no time passes */
  ts_assert_int_equal(wb_robot_step(0), 0, "step(0)");
  ts_assert_double_equal(wb_robot_get_time(), 0.0, "step(0) does not advance time");
  ts_assert_int_equal(wb_robot_step(16), 0, "one step");
  ts_assert_double_equal(wb_robot_get_time(), 0.016, "16 ms");
  /* nobody types or clicks: the simulation runs for the timeout, rounded up to whole steps */
  WbUserInputEvent e = wb_robot_wait_for_user_input_event(WB_EVENT_KEYBOARD | WB_EVENT_JOYSTICK_BUTTON, 40);
  ts_assert_int_equal(e, WB_EVENT_NO_EVENT, "no user input event");
  ts_assert_double_in_delta(wb_robot_get_time(), 0.016 + 0.048, 1e-12, "waited 48 ms");
  ts_assert_boolean_equal(isinf(INFINITY), true, "INFINITY");
  /* no Webots project here (the URDF is the server's); tasks and mutexes are threads */
  ts_assert_string_equal(wb_robot_get_project_path(), "", "no project path");
  static const char urdf_head[] = "<?xml version=\"1.0\"?>\n<robot name=\"gadget\">\n  <link name=\"q_base_link\">";
  ts_assert_int_equal(strncmp(wb_robot_get_urdf("q_"), urdf_head, strlen(urdf_head)), 0, "the URDF, prefixed");
  g_mutex = wb_robot_mutex_new();
  static const int answer = 42;
  wb_robot_task_new(task, (void *)&answer);
  int seen = 0;
  for (int k = 0; k < 10000 && seen != 42; k++) {
    wb_robot_mutex_lock(g_mutex);
    seen = g_result;
    wb_robot_mutex_unlock(g_mutex);
    struct timespec ms = {0, 1000000L};
    nanosleep(&ms, NULL);
  }
  wb_robot_mutex_delete(g_mutex);
  ts_assert_int_equal(seen, 42, "the task ran");
  ts_send_success();
  return 0;
}
