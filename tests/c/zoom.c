/* A camera with a Zoom (tests/test_camera_zoom.py's world): its range, Webots' two refusals of
 * setFov (outside [0, pi], outside the Zoom), then setFov(0.5) and the first lit column of the
 * centre row in the image before and after it. The Python twin is in the same test. */
#include <stdio.h>
#include <webots/camera.h>
#include <webots/robot.h>

static int first_lit(WbDeviceTag cam) {
  const unsigned char *img = wb_camera_get_image(cam);
  int w = wb_camera_get_width(cam), h = wb_camera_get_height(cam);
  for (int x = 0; x < w; x++)
    if (wb_camera_image_get_red(img, w, x, h / 2) > 0)
      return x;
  return -1;
}

int main(void) {
  wb_robot_init();
  WbDeviceTag cam = wb_robot_get_device("cam");
  printf("range %g %g %g\n", wb_camera_get_fov(cam), wb_camera_get_min_fov(cam), wb_camera_get_max_fov(cam));
  wb_camera_enable(cam, 16);
  wb_robot_step(16);
  printf("edge %d\n", first_lit(cam));
  wb_camera_set_fov(cam, 4.0);
  wb_camera_set_fov(cam, 0.3);
  printf("refused %g\n", wb_camera_get_fov(cam));
  wb_camera_set_fov(cam, 0.5);
  printf("fov %g\n", wb_camera_get_fov(cam));
  wb_robot_step(16);
  printf("edge %d\n", first_lit(cam));
  wb_robot_cleanup();
  return 0;
}
