/* Light sensors with Webots' sampling rules: ls0 enabled at 96 ms and ls1 at 40 ms (not a multiple
 * of the 32 ms basic step: effective period 64 ms) at t=0, 8 steps of 32 ms, ls0 disabled after the
 * 6th. Prints tests/c/script.c's lines (the Python twin: script.py enable ls0 96 enable ls1 40
 * step 32 6 disable ls0 step 32 2). */
#include <webots/light_sensor.h>
#include <webots/robot.h>

#include "common.h"

int main(void) {
  wb_robot_init();
  WbDeviceTag ls0 = wb_robot_get_device("ls0"), ls1 = wb_robot_get_device("ls1");
  wb_light_sensor_enable(ls0, 96);
  wb_light_sensor_enable(ls1, 40);
  for (int i = 0; i < 8; i++) {
    int status = wb_robot_step(32);
    printf("%.0f %d", wb_robot_get_time() * 1000.0, status);
    print_bits("ls0", wb_light_sensor_get_value(ls0));
    print_bits("ls1", wb_light_sensor_get_value(ls1));
    printf("\n");
    if (status == -1)
      break;
    if (i == 5)
      wb_light_sensor_disable(ls0);
  }
  printf("# periods %d %d table %d\n", wb_light_sensor_get_sampling_period(ls0),
         wb_light_sensor_get_sampling_period(ls1), wb_light_sensor_get_lookup_table_size(ls0));
  wb_robot_cleanup();
  return 0;
}
