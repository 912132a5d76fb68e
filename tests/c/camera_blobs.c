/* The calls of Webots' camera sample controller (camera_motion_blur, camera_noise_mask), our own text:
 * enable "camera" at the basic step; turn in place (wheels -4/+4 rad/s) until the sums of R, G and B
 * over the image's centre (columns [w/3, 2w/3), rows [h/2, 3h/4)) show one colour over three times
 * each other; then print "blob COLOUR MS", save the image to $HOME/COLOUR_blob.png, stand 20 steps
 * (640 ms at 32 ms) and turn 20 more without looking. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/camera.h>
#include <webots/motor.h>
#include <webots/robot.h>
#include <webots/utils/system.h>

int main(void) {
  wb_robot_init();
  const int step = (int)wb_robot_get_basic_time_step();
  WbDeviceTag cam = wb_robot_get_device("camera");
  wb_camera_enable(cam, step);
  const int w = wb_camera_get_width(cam), h = wb_camera_get_height(cam);
  WbDeviceTag wheels[2] = {wb_robot_get_device("left wheel motor"), wb_robot_get_device("right wheel motor")};
  for (int i = 0; i < 2; i++) {
    wb_motor_set_position(wheels[i], INFINITY);
    wb_motor_set_velocity(wheels[i], 0.0);
  }
  const char *names[3] = {"red", "green", "blue"};
  int pause = 0;
  while (wb_robot_step(step) != -1) {
    const unsigned char *image = wb_camera_get_image(cam);
    double speed = 4.0;
    if (pause > 0)
      pause--;
    if (pause > 640 / step)
      speed = 0.0;
    else if (pause == 0 && image) {
      long sum[3] = {0, 0, 0};
      for (int x = w / 3; x < 2 * w / 3; x++)
        for (int y = h / 2; y < 3 * h / 4; y++) {
          sum[0] += wb_camera_image_get_red(image, w, x, y);
          sum[1] += wb_camera_image_get_green(image, w, x, y);
          sum[2] += wb_camera_image_get_blue(image, w, x, y);
        }
      for (int c = 0; c < 3; c++)
        if (sum[c] > 3 * sum[(c + 1) % 3] && sum[c] > 3 * sum[(c + 2) % 3]) {
          printf("blob %s %d\n", names[c], (int)lround(wb_robot_get_time() * 1000));
          fflush(stdout);
          char path[4096];
          snprintf(path, sizeof path, "%s/%s_blob.png", wbu_system_getenv("HOME"), names[c]);
          wb_camera_save_image(cam, path, 100);
          speed = 0.0;
          pause = 1280 / step;
          break;
        }
    }
    wb_motor_set_velocity(wheels[0], -speed);
    wb_motor_set_velocity(wheels[1], speed);
  }
  wb_robot_cleanup();
  return 0;
}
