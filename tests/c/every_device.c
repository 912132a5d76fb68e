/* The C client's every-device check (our own, in Webots' test style): devices by index with Webots'
 * node types and models, a listed-only device answering "no value" with one warning, the GPS
 * reading, wb_robot_wait_for_user_input_event stepping its timeout, INFINITY from types.h. */
#include <math.h>
#include <stdio.h>

#include <webots/display.h>
#include <webots/gps.h>
#include <webots/joystick.h>
#include <webots/motor.h>
#include <webots/mouse.h>
#include <webots/nodes.h>
#include <webots/radar.h>
#include <webots/robot.h>
#include <webots/speaker.h>

int main(void) {
  wb_robot_init();
  int n = wb_robot_get_number_of_devices();
  for (int i = 0; i < n; i++) {
    WbDeviceTag t = wb_robot_get_device_by_index(i);
    printf("device %d %s %d %s\n", i, wb_device_get_name(t), (int)wb_device_get_node_type(t), wb_device_get_model(t));
  }
  WbDeviceTag radar = wb_robot_get_device("radar"), gps = wb_robot_get_device("gps");
  WbDeviceTag display = wb_robot_get_device("display");
  wb_radar_enable(radar, 16);
  wb_gps_enable(gps, 16);
  wb_robot_step(16);
  printf("radar %d %d %d\n", wb_radar_get_number_of_targets(radar), wb_radar_get_targets(radar) == NULL,
         isnan(wb_radar_get_max_range(radar)));
  printf("display %d %d\n", wb_display_get_width(display), wb_display_get_height(display));
  const double *p = wb_gps_get_values(gps);
  printf("gps %.17g %.17g %.17g %d\n", p[0], p[1], p[2], (int)wb_gps_get_coordinate_system(gps));
  printf("joystick %d mouse %d\n", wb_joystick_is_connected(), isnan(wb_mouse_get_state().u));
  double t0 = wb_robot_get_time();
  WbUserInputEvent e = wb_robot_wait_for_user_input_event(WB_EVENT_KEYBOARD | WB_EVENT_MOUSE_CLICK, 100);
  printf("wait %d %.0f\n", (int)e, (wb_robot_get_time() - t0) * 1000);
  printf("infinity %d\n", isinf(INFINITY));
  wb_robot_cleanup();
  return 0;
}
