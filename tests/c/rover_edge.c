/* The calls of Webots' Mindstorms Rover controller, our own text (tests/test_sweep18.py runs Webots' file
 * instead when WEBOTS_HOME has it): every 64 ms, a bumper (S1, S3) touching starts a 1000-step avoidance
 * (back, straight, a left curve until the ground sensor S2 reads the line, over 43); otherwise S2 over 43
 * turns right (1, 0.2 rad/s), under it left (0.2, 1). */
#include <math.h>

#include <webots/distance_sensor.h>
#include <webots/motor.h>
#include <webots/robot.h>
#include <webots/touch_sensor.h>

#define STEP 64

int main(void) {
  wb_robot_init();
  const WbDeviceTag bumpers[2] = {wb_robot_get_device("S1"), wb_robot_get_device("S3")};
  const WbDeviceTag ground = wb_robot_get_device("S2");
  const WbDeviceTag wheels[2] = {wb_robot_get_device("left wheel motor"), wb_robot_get_device("right wheel motor")};
  for (int i = 0; i < 2; ++i) {
    wb_touch_sensor_enable(bumpers[i], STEP);
    wb_motor_set_position(wheels[i], INFINITY);
    wb_motor_set_velocity(wheels[i], 0.0);
  }
  wb_distance_sensor_enable(ground, STEP);
  int avoiding = 0;
  while (wb_robot_step(STEP) != -1) {
    const int on_line = wb_distance_sensor_get_value(ground) > 43;
    double speed[2];
    if (avoiding == 0) {
      if (wb_touch_sensor_get_value(bumpers[0]) > 0 || wb_touch_sensor_get_value(bumpers[1]) > 0) {
        speed[0] = -0.6, speed[1] = -1.0, avoiding = 1000;
      } else if (on_line) {
        speed[0] = 1.0, speed[1] = 0.2;
      } else {
        speed[0] = 0.2, speed[1] = 1.0;
      }
    } else {
      if (avoiding > 800) {
        speed[0] = -0.6, speed[1] = -1.0;
      } else if (avoiding > 600) {
        speed[0] = 1.0, speed[1] = 1.0;
      } else {
        speed[0] = avoiding > 70 ? 0.7 : 1.0, speed[1] = 1.0;
        if (on_line)
          avoiding = 1;
      }
      --avoiding;
    }
    for (int i = 0; i < 2; ++i)
      wb_motor_set_velocity(wheels[i], speed[i]);
  }
  wb_robot_cleanup();
  return 0;
}
