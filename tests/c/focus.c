/* A camera with a Focus node and one without (tests/test_camera_focus.py's world): the Focus values,
 * Webots' refusal of a focal distance outside its range, one inside it read back; the Python twin is in
 * the same test. */
#include <stdio.h>
#include <webots/camera.h>
#include <webots/robot.h>

int main(void) {
  wb_robot_init();
  WbDeviceTag cam = wb_robot_get_device("cam"), plain = wb_robot_get_device("plain");
  printf("focus %g %g %g %g\n", wb_camera_get_focal_length(cam), wb_camera_get_focal_distance(cam),
         wb_camera_get_min_focal_distance(cam), wb_camera_get_max_focal_distance(cam));
  wb_camera_set_focal_distance(cam, 1.5);
  printf("refused %g\n", wb_camera_get_focal_distance(cam));
  wb_camera_set_focal_distance(cam, 0.75);
  printf("set %g\n", wb_camera_get_focal_distance(cam));
  wb_camera_set_focal_distance(plain, 0.3);
  printf("plain %g %g\n", wb_camera_get_focal_length(plain), wb_camera_get_focal_distance(plain));
  wb_robot_step(16);
  wb_robot_cleanup();
  return 0;
}
