/* Image devices reader: image_reader NAME STEPS. Enables the named range finder or camera at the
 * basic step and prints a line per step: "T STATUS NAME=<hex of the image bytes>", then
 * "# info W H FOV ..." (%.17g) and "# save R" (the return of its save_image into a directory that
 * does not exist: -1); for a range finder, given a directory DIR as a third argument, also
 * "# hdr R" (saving DIR/depth.hdr) and "# tiff R" (DIR/depth.tiff: Webots' -1).
 * The twin of tests/controllers/image_reader.py. */
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
    if (wb_camera_has_recognition(tag)) {
      wb_camera_recognition_enable(tag, step);
      wb_camera_recognition_enable_segmentation(tag);
    }
  } else
    wb_range_finder_enable(tag, step);
  int w = camera ? wb_camera_get_width(tag) : wb_range_finder_get_width(tag);
  int h = camera ? wb_camera_get_height(tag) : wb_range_finder_get_height(tag);
  for (int s = 0; s < steps; s++) {
    int status = wb_robot_step(step);
    printf("%.0f %d %s=", wb_robot_get_time() * 1000.0, status, argv[1]);
    if (camera) {
      print_hex(wb_camera_get_image(tag), 4 * (size_t)w * (size_t)h);
      if (wb_camera_has_recognition(tag)) {
        printf(" seg=");
        print_hex(wb_camera_recognition_get_segmentation_image(tag), 4 * (size_t)w * (size_t)h);
        int n = wb_camera_recognition_get_number_of_objects(tag);
        const WbCameraRecognitionObject *o = wb_camera_recognition_get_objects(tag);
        printf(" objects=%d", n);
        for (int i = 0; i < n; i++) {
          printf(" [%d %s", o[i].id, o[i].model);
          print_bits("p0", o[i].position[0]);
          print_bits("p1", o[i].position[1]);
          print_bits("p2", o[i].position[2]);
          print_bits("a", o[i].orientation[3]);
          print_bits("s0", o[i].size[0]);
          print_bits("s1", o[i].size[1]);
          printf(" %d %d %d %d %d", o[i].position_on_image[0], o[i].position_on_image[1], o[i].size_on_image[0],
                 o[i].size_on_image[1], o[i].number_of_colors);
          for (int k = 0; k < 3 * o[i].number_of_colors; k++)
            print_bits("c", o[i].colors[k]);
          printf("]");
        }
      }
    } else
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
    if (argc > 3) {
      char path[4096];
      snprintf(path, sizeof path, "%s/depth.hdr", argv[3]);
      printf("# hdr %d\n", wb_range_finder_save_image(tag, path, 100));
      snprintf(path, sizeof path, "%s/depth.tiff", argv[3]);
      printf("# tiff %d\n", wb_range_finder_save_image(tag, path, 100));
    }
  }
  wb_robot_cleanup();
  return 0;
}
