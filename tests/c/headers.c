/* The Webots headers a controller could not include before (lidar_point.h, contact_point.h, console.h,
 * microphone.h, radio.h, utils/string.h, utils/system.h, vehicle/car.h, vehicle/driver.h), used as a
 * controller uses them. Prints "key value" lines that tests/test_c_client.py checks.
 *   headers            what needs no server: types, console, strings, system, radio messages, the
 *                      vehicle functions' "no value"
 *   headers online     then attaches to the server: Microphone and Radio (listed, not simulated), the
 *                      supervisor's contact points, the robot window's messages (none) and the default
 *                      robot window's functions (Webots' Thymio II demo calls them: no window, no effect), Supervisor
 *                      functions Sensorium does not serve, wb_supervisor_simulation_quit() (the server
 *                      exits; the next step answers -1, the one after ends the process with status 0)
 *   headers driver|car wbu_driver_init() / wbu_car_init(): one line, exit status 1 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/console.h>
#include <webots/contact_point.h>
#include <webots/lidar_point.h>
#include <webots/microphone.h>
#include <webots/plugins/robot_window/default.h>
#include <webots/plugins/robot_window/robot_wwi.h>
#include <webots/radio.h>
#include <webots/robot.h>
#include <webots/supervisor.h>
#include <webots/utils/string.h>
#include <webots/utils/system.h>
#include <webots/vehicle/car.h>
#include <webots/vehicle/driver.h>

static const char *or_null(const char *s) {
  return s != NULL ? s : "(null)";
}

static void offline(void) {
  WbLidarPoint p = {1.5f, -2.0f, 0.25f, 3, 0.125f};
  printf("lidar_point %g %g %g %d %g\n", p.x, p.y, p.z, p.layer_id, p.time);
  WbContactPoint c = {{1.0, -2.0, 3.5}, 7};
  printf("contact_point %g %g %g %d\n", c.point[0], c.point[1], c.point[2], c.node_id);

  wb_console_print("console to stdout\n", WB_STDOUT);
  wb_console_print("console to stderr\n", WB_STDERR);
  wb_console_print("lost\n", 3);

  char text[] = "a,b\\,c,,d";
  char *rest = text, *token;
  printf("strsep");
  while ((token = wbu_string_strsep(&rest, ",")) != NULL)
    printf(" [%s]", token);
  printf(" %s\n", rest == NULL ? "end" : "more");
  char value[] = "one two one";
  char *replaced = wbu_string_replace(value, "one", "three");
  char *removed = wbu_string_replace(value, "one ", NULL);
  printf("replace [%s] [%s] %s %s\n", replaced, removed, or_null(wbu_string_replace(value, "", "x")),
         or_null(wbu_string_replace(NULL, "a", "b")));
  free(replaced);
  free(removed);

  printf("getenv %s %s\n", or_null(wbu_system_getenv("HEADERS_TEST_VALUE")),
         or_null(wbu_system_getenv("HEADERS_TEST_UNSET")));
  printf("short_path %s tmpdir %s instance %s\n", wbu_system_short_path("/a b/c"), wbu_system_tmpdir(),
         or_null(wbu_system_webots_instance_path(true)));

  WbRadioMessage m = wb_radio_message_new(5, "hello", "bob");
  printf("radio_message %d %s %s %s\n", wb_radio_message_get_length(m), wb_radio_message_get_body(m),
         wb_radio_message_get_destination(m), wb_radio_message_new(-1, "x", "y") == NULL ? "refused" : "made");
  wb_radio_message_delete(m);

  printf("driver %d %d %g %d %d\n", (int)wbu_driver_initialization_is_possible(), wbu_driver_step(),
         wbu_driver_get_steering_angle(), (int)wbu_driver_get_control_mode(), (int)wbu_driver_get_indicator());
  printf("car %g %g %d\n", wbu_car_get_wheelbase(), wbu_car_get_wheel_speed(WBU_CAR_WHEEL_REAR_LEFT),
         (int)wbu_car_get_type());
}

static void online(void) {
  wb_robot_init();
  WbDeviceTag mic = wb_robot_get_device("mic"), radio = wb_robot_get_device("radio");
  printf("tags %d %d %s\n", (int)mic, (int)radio, wb_device_get_model(mic));
  wb_microphone_enable(mic, 16);
  wb_robot_step(16);
  printf("microphone %d %s %d\n", wb_microphone_get_sampling_period(mic),
         wb_microphone_get_sample_data(mic) == NULL ? "NULL" : "data", wb_microphone_get_sample_size(mic));
  wb_microphone_disable(mic);
  wb_radio_enable(radio, 16);
  wb_radio_set_channel(radio, 4);
  WbRadioMessage m = wb_radio_message_new(2, "hi", "peer");
  wb_radio_send(radio, m, 0.0);
  wb_radio_message_delete(m);
  printf("radio %d %d %g %g %s\n", wb_radio_get_channel(radio), wb_radio_get_bitrate(radio),
         wb_radio_get_frequency(radio), wb_radio_get_tx_power(radio), or_null(wb_radio_get_address(radio)));
  wb_microphone_enable(radio, 16); /* a Radio is no Microphone: one error line */
  WbNodeRef self = wb_supervisor_node_get_self();
  int size = -1;
  const WbContactPoint *points = wb_supervisor_node_get_contact_points(self, true, &size);
  wb_supervisor_node_enable_contact_points_tracking(self, 16, true);
  const double *first = wb_supervisor_node_get_contact_point(self, 0);
  printf("contacts %d %d %s %s %s\n", wb_supervisor_node_get_number_of_contact_points(self, true), size,
         points == NULL ? "NULL" : "points", isnan(first[0]) ? "nan" : "value",
         wb_supervisor_node_get_contact_point_node(self, 0) == NULL ? "NULL" : "node");
  wb_supervisor_node_disable_contact_points_tracking(self);
  wb_robot_wwi_send_text("to the window");
  size = -1;
  const char *received = wb_robot_wwi_receive(&size);
  printf("wwi %s %s %d\n", or_null(wb_robot_wwi_receive_text()), or_null(received), size);
  wbu_default_robot_window_set_images_max_size(64, 48);
  wbu_default_robot_window_configure();
  wbu_default_robot_window_update();
  printf("default window %s\n", or_null(wb_robot_wwi_receive_text()));
  printf("step %d\n", wb_robot_step(16));
  /* Supervisor functions beyond Sensorium's subset: declared, one error line each, "no value" */
  WbNodeRef selected = wb_supervisor_node_get_selected();
  wb_supervisor_node_get_selected();
  WbFieldRef rotation = wb_supervisor_node_get_field(self, "rotation");
  const double *com = wb_supervisor_node_get_center_of_mass(self); /* served: 0 0 0 without Physics */
  printf("supervisor %s %d %s %d %d %g %g %g %s %d %d\n", selected == NULL ? "NULL" : "node",
         wb_supervisor_node_get_id(self) > 0, wb_supervisor_field_get_type_name(rotation),
         wb_supervisor_field_get_count(rotation), wb_supervisor_node_get_number_of_fields(self),
         com[0], com[1], com[2], wb_supervisor_node_export_string(self),
         (int)!wb_supervisor_virtual_reality_headset_is_used(), (int)wb_supervisor_field_get_mf_int32(rotation, 0));
  wb_supervisor_simulation_quit(3);
  printf("after quit %d\n", wb_robot_step(16)); /* -1, then the next step ends the process (libController) */
  fflush(stdout);
  wb_robot_step(16);
  printf("not reached\n");
  wb_robot_cleanup();
}

int main(int argc, char **argv) {
  const char *mode = argc > 1 ? argv[1] : "";
  if (strcmp(mode, "driver") == 0)
    wbu_driver_init();
  else if (strcmp(mode, "car") == 0)
    wbu_car_init();
  else {
    offline();
    if (strcmp(mode, "online") == 0)
      online();
    return 0;
  }
  printf("the vehicle library returned\n");
  return 0;
}
