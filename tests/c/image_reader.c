/* Image devices reader: image_reader NAME STEPS. Enables the named range finder (or camera) at the
 * basic step and prints a line per step: "T STATUS NAME=<hex of the image bytes>", then
 * "# info W H FOV MIN MAX" (%.17g) and "# save R" (the return of its save_image to /dev/null.png,
 * -1: a directory that cannot be written). The twin of tests/controllers/image_reader.py. */
#include <stdlib.h>

#include <webots/range_finder.h>
#include <webots/robot.h>

#include "common.h"

int main(int argc, char **argv) {
  if (argc < 3)
    return 2;
  wb_robot_init();
  WbDeviceTag tag = wb_robot_get_device(argv[1]);
  int step = (int)wb_robot_get_basic_time_step(), steps = atoi(argv[2]);
  wb_range_finder_enable(tag, step);
  int w = wb_range_finder_get_width(tag), h = wb_range_finder_get_height(tag);
  for (int s = 0; s < steps; s++) {
    int status = wb_robot_step(step);
    printf("%.0f %d %s=", wb_robot_get_time() * 1000.0, status, argv[1]);
    print_hex(wb_range_finder_get_range_image(tag), 4 * (size_t)w * (size_t)h);
    printf("\n");
    if (status == -1)
      break;
  }
  printf("# info %d %d %.17g %.17g %.17g\n", w, h, wb_range_finder_get_fov(tag), wb_range_finder_get_min_range(tag),
         wb_range_finder_get_max_range(tag));
  printf("# save %d\n", wb_range_finder_save_image(tag, "/nonexistent-dir/x.png", 100));
  wb_robot_cleanup();
  return 0;
}
