/* Calls every function of the library once per device and prints "key value" lines (doubles with
 * %.17g), then the error paths. Built by `make check` (against the static and the shared library)
 * and run by tests/test_c_client.py, which compares the lines with the Python client's values. */
#include <math.h>
#include <stdio.h>

#include <webots/device.h>
#include <webots/distance_sensor.h>
#include <webots/lidar.h>
#include <webots/led.h>
#include <webots/light_sensor.h>
#include <webots/motor.h>
#include <webots/nodes.h>
#include <webots/position_sensor.h>
#include <webots/robot.h>
#include <webots/types.h>

static void table(const char *key, const double *t, int rows) {
  printf("%s", key);
  for (int i = 0; i < 3 * rows; i++)
    printf(" %.17g", t[i]);
  printf("\n");
}

int main(void) {
  wb_robot_init();
  printf("robot.name %s\n", wb_robot_get_name());
  printf("robot.model %s\n", wb_robot_get_model());
  printf("robot.basic_time_step %.17g\n", wb_robot_get_basic_time_step());
  printf("robot.time %.17g\n", wb_robot_get_time());
  printf("robot.synchronization %d\n", (int)wb_robot_get_synchronization());
  printf("robot.supervisor %d\n", (int)wb_robot_get_supervisor());
  printf("robot.mode %d\n", (int)wb_robot_get_mode());
  printf("robot.custom_data %s\n", wb_robot_get_custom_data());
  int n = wb_robot_get_number_of_devices();
  printf("robot.number_of_devices %d\n", n);
  for (int i = 0; i < n; i++) {
    WbDeviceTag tag = wb_robot_get_device_by_index(i);
    const char *name = wb_device_get_name(tag);
    printf("device %d %s %s %d %s|\n", i, name, sensorium_device_get_type_name(tag),
           wb_robot_get_device(name) == tag, wb_device_get_model(tag));
    char key[200];
    switch (wb_device_get_node_type(tag)) {
      case WB_NODE_LIGHT_SENSOR:
        printf("%s.sampling_period %d\n", name, wb_light_sensor_get_sampling_period(tag));
        snprintf(key, sizeof key, "%s.lookup_table", name);
        table(key, wb_light_sensor_get_lookup_table(tag), wb_light_sensor_get_lookup_table_size(tag));
        break;
      case WB_NODE_DISTANCE_SENSOR:
        printf("%s.sampling_period %d\n", name, wb_distance_sensor_get_sampling_period(tag));
        printf("%s.min_value %.17g\n", name, wb_distance_sensor_get_min_value(tag));
        printf("%s.max_value %.17g\n", name, wb_distance_sensor_get_max_value(tag));
        printf("%s.aperture %.17g\n", name, wb_distance_sensor_get_aperture(tag));
        printf("%s.type %d\n", name, (int)wb_distance_sensor_get_type(tag));
        snprintf(key, sizeof key, "%s.lookup_table", name);
        table(key, wb_distance_sensor_get_lookup_table(tag), wb_distance_sensor_get_lookup_table_size(tag));
        break;
      case WB_NODE_LIDAR:
        printf("%s.sampling_period %d\n", name, wb_lidar_get_sampling_period(tag));
        printf("%s.horizontal_resolution %d\n", name, wb_lidar_get_horizontal_resolution(tag));
        printf("%s.number_of_layers %d\n", name, wb_lidar_get_number_of_layers(tag));
        printf("%s.fov %.17g\n", name, wb_lidar_get_fov(tag));
        printf("%s.vertical_fov %.17g\n", name, wb_lidar_get_vertical_fov(tag));
        printf("%s.min_range %.17g\n", name, wb_lidar_get_min_range(tag));
        printf("%s.max_range %.17g\n", name, wb_lidar_get_max_range(tag));
        printf("%s.frequency %.17g\n", name, wb_lidar_get_frequency(tag));
        printf("%s.min_frequency %.17g\n", name, wb_lidar_get_min_frequency(tag));
        printf("%s.max_frequency %.17g\n", name, wb_lidar_get_max_frequency(tag));
        printf("%s.point_cloud_enabled %d\n", name, (int)wb_lidar_is_point_cloud_enabled(tag));
        printf("%s.number_of_points %d\n", name, wb_lidar_get_number_of_points(tag));
        break;
      case WB_NODE_ROTATIONAL_MOTOR:
        printf("%s.max_velocity %.17g\n", name, wb_motor_get_max_velocity(tag));
        printf("%s.velocity %.17g\n", name, wb_motor_get_velocity(tag));
        printf("%s.target_position %.17g\n", name, wb_motor_get_target_position(tag));
        printf("%s.min_position %.17g\n", name, wb_motor_get_min_position(tag));
        printf("%s.max_position %.17g\n", name, wb_motor_get_max_position(tag));
        printf("%s.type %d\n", name, (int)wb_motor_get_type(tag));
        printf("%s.position_sensor %d\n", name, (int)wb_motor_get_position_sensor(tag));
        printf("%s.brake %d\n", name, (int)wb_motor_get_brake(tag));
        wb_motor_set_position(tag, INFINITY);
        wb_motor_set_velocity(tag, 2.0 * wb_motor_get_max_velocity(tag)); /* clamped, with a warning */
        printf("%s.clamped_velocity %.17g\n", name, wb_motor_get_velocity(tag));
        printf("%s.new_target %.17g\n", name, wb_motor_get_target_position(tag));
        break;
      case WB_NODE_POSITION_SENSOR:
        printf("%s.sampling_period %d\n", name, wb_position_sensor_get_sampling_period(tag));
        printf("%s.type %d\n", name, (int)wb_position_sensor_get_type(tag));
        printf("%s.motor %d\n", name, (int)wb_position_sensor_get_motor(tag));
        printf("%s.brake %d\n", name, (int)wb_position_sensor_get_brake(tag));
        break;
      case WB_NODE_LED:
        printf("%s.led %d\n", name, wb_led_get(tag));
        break;
      default:
        printf("%s.unknown_type\n", name);
    }
  }
  /* error paths: one message each on stderr, a neutral value here */
  printf("error.no_device %d\n", (int)wb_robot_get_device("no such device"));
  printf("error.by_index %d\n", (int)wb_robot_get_device_by_index(n));
  printf("error.bad_tag_value %d\n", isnan(wb_distance_sensor_get_value(9999)) ? 1 : 0);
  printf("error.bad_tag_name %d\n", wb_device_get_name(0) == NULL);
  WbDeviceTag first = wb_robot_get_device_by_index(0);
  printf("error.wrong_kind %d\n", wb_device_get_node_type(first) == WB_NODE_LIDAR
                                      ? wb_light_sensor_get_lookup_table(first) == NULL
                                      : wb_lidar_get_range_image(first) == NULL);
  int status = wb_robot_step(-32); /* negative: refused */
  printf("error.bad_step %d\n", status);
  printf("robot.step %d\n", wb_robot_step((int)wb_robot_get_basic_time_step()));
  printf("robot.time_after %.17g\n", wb_robot_get_time());
  /* step_begin, a request while the step is pending (its reply may come first), step_end */
  int begun = wb_robot_step_begin((int)wb_robot_get_basic_time_step());
  if (wb_device_get_node_type(first) == WB_NODE_DISTANCE_SENSOR)
    wb_distance_sensor_enable(first, (int)wb_robot_get_basic_time_step());
  else
    wb_lidar_enable(first, (int)wb_robot_get_basic_time_step());
  int again = wb_robot_step_begin(1); /* refused: one is pending */
  int ended = wb_robot_step_end();
  printf("pipelined %d,%d,%d,%.17g\n", begun, again, ended, wb_robot_get_time());
  printf("no_pending %d\n", wb_robot_step_end());
  wb_robot_cleanup();
  return 0;
}
