/* A camera wander making the calls of Webots' surveyor sample, our own text (tests/test_sweep15.py runs
 * Webots' file instead when WEBOTS_HOME has it): the colours of image rows 29-31 at the first step are
 * the open floor's; each step, when every pixel of the right half of row 31 is out of that range the way
 * ahead is blocked and the robot spins right in place (left wheels -0.3/0.014 rad/s, right +0.3/0.014),
 * else it goes straight on at 0.3 m/s (every wheel at -0.3/0.014: its wheels turn about -y). */
#include <math.h>
#include <stdio.h>

#include <webots/camera.h>
#include <webots/motor.h>
#include <webots/robot.h>

#define STEP 16
#define SPEED (0.3 / 0.014)

static WbDeviceTag wheels[10];

static void set_sides(double left, double right) {
  for (int i = 0; i < 10; i++)
    wb_motor_set_velocity(wheels[i], i < 5 ? left : right);
}

int main(void) {
  wb_robot_init();
  WbDeviceTag camera = wb_robot_get_device("camera");
  wb_camera_enable(camera, STEP);
  char name[] = "wheel_motor00";
  for (int i = 0; i < 10; i++) {
    name[12] = (char)('0' + i);
    wheels[i] = wb_robot_get_device(name);
    wb_motor_set_position(wheels[i], INFINITY);
    wb_motor_set_velocity(wheels[i], 0.0);
  }
  const int width = wb_camera_get_width(camera);
  wb_robot_step(STEP);
  const unsigned char *image = wb_camera_get_image(camera);
  int low[3] = {255, 255, 255}, high[3] = {0, 0, 0};
  for (int p = 29 * width; p < 32 * width; p++)
    for (int c = 0; c < 3; c++) {
      const int v = image[4 * p + c];
      low[c] = v < low[c] ? v : low[c];
      high[c] = v > high[c] ? v : high[c];
    }
  while (wb_robot_step(STEP) != -1) {
    image = wb_camera_get_image(camera);
    int blocked = 1;
    for (int x = width / 2; x < width && blocked; x++) {
      const unsigned char *px = image + 4 * (31 * width + x);
      int open = 1;
      for (int c = 0; c < 3; c++)
        open = open && px[c] >= low[c] && px[c] <= high[c];
      blocked = !open;
    }
    if (blocked)
      set_sides(-SPEED, SPEED);
    else
      set_sides(-SPEED, -SPEED);
  }
  wb_robot_cleanup();
  return 0;
}
