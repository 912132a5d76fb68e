/* Image devices reader: image_reader NAME STEPS. Enables the named range finder or camera at the
 * basic step and prints a line per step: "T STATUS NAME=<hex of the image bytes>", then
 * "# info W H FOV ..." (%.17g) and "# save R" (the return of its save_image into a directory that
 * does not exist: -1). The twin of tests/controllers/image_reader.py. */
#include <stdlib.h>
#include <string.h>

#include <webots/camera.h>
#include <webots/device.h>
#include <webots/nodes.h>
#include <webots/range_finder.h>
#include <webots/robot.h>

#include "common.h"

int main(int argc, char **argv) {
  if (argc < 3)
    return 2;
  wb_robot_init();
  WbDeviceTag tag = wb_robot_get_device(argv[1]);
  int step = (int)wb_robot_get_basic_time_step(), steps = atoi(argv[2]);
  bool camera = wb_device_get_node_type(tag) == WB_NODE_CAMERA;
  if (camera) {
    printf("# null_before %d\n", wb_camera_get_image(tag) == NULL); /* disabled: NULL + message */
    wb_camera_enable(tag, step);
  } else
    wb_range_finder_enable(tag, step);
  int w = camera ? wb_camera_get_width(tag) : wb_range_finder_get_width(tag);
  int h = camera ? wb_camera_get_height(tag) : wb_range_finder_get_height(tag);
  for (int s = 0; s < steps; s++) {
    int status = wb_robot_step(step);
    printf("%.0f %d %s=", wb_robot_get_time() * 1000.0, status, argv[1]);
    if (camera)
      print_hex(wb_camera_get_image(tag), 4 * (size_t)w * (size_t)h);
    else
      print_hex(wb_range_finder_get_range_image(tag), 4 * (size_t)w * (size_t)h);
    printf("\n");
    if (status == -1)
      break;
  }
  if (camera) {
    const unsigned char *img = wb_camera_get_image(tag);
    printf("# info %d %d %.17g %.17g %.17g %d %d %d %d\n", w, h, wb_camera_get_fov(tag), wb_camera_get_near(tag),
           wb_camera_get_exposure(tag), wb_camera_image_get_red(img, w, w - 1, h - 1),
           wb_camera_image_get_green(img, w, w - 1, h - 1), wb_camera_image_get_blue(img, w, w - 1, h - 1),
           wb_camera_image_get_gray(img, w, w - 1, h - 1));
    wb_camera_set_exposure(tag, 2.0);
    printf("# exposure %.17g\n", wb_camera_get_exposure(tag));
    printf("# save %d\n", wb_camera_save_image(tag, "/nonexistent-dir/x.png", 100));
  } else {
    printf("# info %d %d %.17g %.17g %.17g\n", w, h, wb_range_finder_get_fov(tag), wb_range_finder_get_min_range(tag),
           wb_range_finder_get_max_range(tag));
    printf("# save %d\n", wb_range_finder_save_image(tag, "/nonexistent-dir/x.png", 100));
  }
  wb_robot_cleanup();
  return 0;
}
