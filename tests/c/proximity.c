/* Infra-red and sonar reader: proximity NAME... enables each distance sensor at the basic time
 * step, prints its constants once ("# NAME type min max aperture rows table...") and then
 * tests/c/script.c's line for STEPS (env STEPS, default 5) steps. */
#include <stdlib.h>

#include <webots/distance_sensor.h>
#include <webots/robot.h>

#include "common.h"

int main(int argc, char **argv) {
  wb_robot_init();
  int step = (int)wb_robot_get_basic_time_step();
  int steps = getenv("STEPS") ? atoi(getenv("STEPS")) : 5;
  WbDeviceTag tags[32];
  int n = argc - 1 < 32 ? argc - 1 : 32;
  for (int i = 0; i < n; i++) {
    tags[i] = wb_robot_get_device(argv[i + 1]);
    wb_distance_sensor_enable(tags[i], step);
    printf("# %s %d %.17g %.17g %.17g %d", argv[i + 1], (int)wb_distance_sensor_get_type(tags[i]),
           wb_distance_sensor_get_min_value(tags[i]), wb_distance_sensor_get_max_value(tags[i]),
           wb_distance_sensor_get_aperture(tags[i]), wb_distance_sensor_get_lookup_table_size(tags[i]));
    const double *table = wb_distance_sensor_get_lookup_table(tags[i]);
    for (int k = 0; k < 3 * wb_distance_sensor_get_lookup_table_size(tags[i]); k++)
      printf(" %.17g", table[k]);
    printf("\n");
  }
  for (int s = 0; s < steps; s++) {
    int status = wb_robot_step(step);
    printf("%.0f %d", wb_robot_get_time() * 1000.0, status);
    for (int i = 0; i < n; i++)
      print_bits(argv[i + 1], wb_distance_sensor_get_value(tags[i]));
    printf("\n");
    if (status == -1)
      break;
  }
  wb_robot_cleanup();
  return 0;
}
