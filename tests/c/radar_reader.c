/* A Radar from C (tests/worlds/radar.yaml): the sequence of tests/controllers/radar_reader.py;
 * prints values as the 16 hex digits of their float64 bits. */
#include <inttypes.h>
#include <stdio.h>
#include <string.h>

#include <webots/radar.h>
#include <webots/robot.h>

static void h(double v) {
  uint64_t bits;
  memcpy(&bits, &v, sizeof bits);
  printf(" %016" PRIx64, bits);
}

int main(void) {
  wb_robot_init();
  WbDeviceTag radar = wb_robot_get_device("radar");
  printf("fields");
  h(wb_radar_get_min_range(radar));
  h(wb_radar_get_max_range(radar));
  h(wb_radar_get_horizontal_fov(radar));
  h(wb_radar_get_vertical_fov(radar));
  printf("\n");
  wb_radar_enable(radar, 32);
  printf("before %d %d %d\n", wb_radar_get_number_of_targets(radar), wb_radar_get_targets(radar) == NULL ? 0 : -1,
         wb_radar_get_sampling_period(radar));
  for (int k = 0; k < 2; k++) {
    wb_robot_step(32);
    int n = wb_radar_get_number_of_targets(radar);
    const WbRadarTarget *targets = wb_radar_get_targets(radar);
    printf("targets %d\n", n);
    for (int i = 0; i < n; i++) {
      printf("target");
      h(targets[i].distance);
      h(targets[i].received_power);
      h(targets[i].speed);
      h(targets[i].azimuth);
      printf("\n");
    }
  }
  wb_robot_cleanup();
  return 0;
}
