/* Lidar range image and point cloud reader: lidar_reader NAME STEPS. Enables the lidar and its
 * point cloud at the basic step and prints tests/c/script.c's line per step, then a check line
 * "# points N layers_ok L stable S norm_bad B" where layers_ok counts layers whose per-layer
 * pointers are the right slices, stable is 1 while the pointers stay the same across steps and
 * norm_bad counts finite ranges that differ from |point| by more than 1e-5 relative. */
#include <math.h>
#include <stdlib.h>

#include <webots/lidar.h>
#include <webots/robot.h>

#include "common.h"

int main(int argc, char **argv) {
  if (argc < 3)
    return 2;
  wb_robot_init();
  WbDeviceTag lidar = wb_robot_get_device(argv[1]);
  int step = (int)wb_robot_get_basic_time_step(), steps = atoi(argv[2]);
  const float *null_before = wb_lidar_get_layer_range_image(lidar, 0); /* disabled: NULL + message */
  wb_lidar_enable(lidar, step);
  wb_lidar_enable_point_cloud(lidar);
  int w = wb_lidar_get_horizontal_resolution(lidar), layers = wb_lidar_get_number_of_layers(lidar);
  const float *first_image = NULL;
  const WbLidarPoint *first_cloud = NULL;
  for (int s = 0; s < steps; s++) {
    int status = wb_robot_step(step);
    printf("%.0f %d", wb_robot_get_time() * 1000.0, status);
    print_lidar(argv[1], lidar);
    printf("\n");
    if (status == -1)
      break;
    const float *image = wb_lidar_get_range_image(lidar);
    const WbLidarPoint *cloud = wb_lidar_get_point_cloud(lidar);
    if (first_image == NULL) {
      first_image = image;
      first_cloud = cloud;
    }
    int layers_ok = 0, norm_bad = 0;
    for (int l = 0; l < layers; l++)
      layers_ok += wb_lidar_get_layer_range_image(lidar, l) == image + l * w &&
                   wb_lidar_get_layer_point_cloud(lidar, l) == cloud + l * w;
    for (int j = 0; j < w * layers; j++) {
      if (!isfinite(image[j]))
        continue;
      double norm = sqrt((double)cloud[j].x * cloud[j].x + (double)cloud[j].y * cloud[j].y +
                         (double)cloud[j].z * cloud[j].z);
      norm_bad += fabs(norm - image[j]) > 1e-5 * (image[j] > 1 ? image[j] : 1) || cloud[j].layer_id != j / w;
    }
    printf("# points %d layers_ok %d stable %d norm_bad %d null_before %d bad_layer %d\n",
           wb_lidar_get_number_of_points(lidar), layers_ok, image == first_image && cloud == first_cloud, norm_bad,
           null_before == NULL, wb_lidar_get_layer_range_image(lidar, layers) == NULL);
  }
  wb_robot_cleanup();
  return 0;
}
