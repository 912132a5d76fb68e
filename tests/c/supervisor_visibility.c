/* setVisibility from C (tests/worlds/supervisor_visibility.yaml): the sequence of
 * tests/controllers/supervisor_visibility.py, the same lines. */
#include <math.h>
#include <stdio.h>

#include <webots/camera.h>
#include <webots/lidar.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

static WbDeviceTag lidar, cam, other;

static int red(WbDeviceTag camera) {
  return wb_camera_image_get_red(wb_camera_get_image(camera), wb_camera_get_width(camera), 4, 3);
}

static void centre(const char *what) {
  printf("%s %d %d\n", what, (int)lround(wb_lidar_get_range_image(lidar)[2]), red(cam));
}

int main(void) {
  wb_robot_init();
  int step = (int)wb_robot_get_basic_time_step();
  lidar = wb_robot_get_device("lidar");
  cam = wb_robot_get_device("cam");
  other = wb_robot_get_device("other");
  wb_lidar_enable(lidar, step);
  wb_camera_enable(cam, step);
  wb_camera_enable(other, step);
  wb_robot_step(step);
  centre("before");
  WbNodeRef crate = wb_supervisor_node_get_from_def("CRATE");
  wb_supervisor_node_set_visibility(crate, wb_supervisor_node_get_from_device(cam), false);
  wb_supervisor_node_set_visibility(crate, wb_supervisor_node_get_from_device(lidar), false);
  wb_robot_step(step);
  centre("hidden");
  printf("other %d\n", red(other));
  wb_supervisor_node_set_visibility(crate, wb_supervisor_node_get_from_device(cam), true);
  wb_supervisor_node_set_visibility(crate, wb_supervisor_node_get_from_device(lidar), true);
  wb_robot_step(step);
  centre("again");
  wb_supervisor_node_set_visibility(crate, crate, false); /* the crate is no device: Webots' line */
  printf("bad from\n");
  wb_robot_cleanup();
  return 0;
}
