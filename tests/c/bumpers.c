/* Three bumpers from C: the sequence of tests/controllers/bumpers.py (forward, then stopped against
 * the wall; a line per step whose readings changed). */
#include <math.h>
#include <stdio.h>

#include <webots/motor.h>
#include <webots/robot.h>
#include <webots/touch_sensor.h>

int main(void) {
  wb_robot_init();
  const char *names[3] = {"bumper_left", "bumper_right", "bumper_rear"};
  WbDeviceTag bumpers[3];
  for (int i = 0; i < 3; i++) {
    bumpers[i] = wb_robot_get_device(names[i]);
    wb_touch_sensor_enable(bumpers[i], 16);
  }
  WbDeviceTag left = wb_robot_get_device("left wheel motor"), right = wb_robot_get_device("right wheel motor");
  wb_motor_set_position(left, INFINITY);
  wb_motor_set_position(right, INFINITY);
  wb_motor_set_velocity(left, 10.0);
  wb_motor_set_velocity(right, 10.0);
  double last[3] = {NAN, NAN, NAN};
  for (int k = 0; k < 155; k++) {
    if (k == 150) {
      wb_motor_set_velocity(left, 0.0);
      wb_motor_set_velocity(right, 0.0);
    }
    wb_robot_step(16);
    double now[3];
    int changed = 0;
    for (int i = 0; i < 3; i++) {
      now[i] = wb_touch_sensor_get_value(bumpers[i]);
      if (!(now[i] == last[i]))
        changed = 1;
    }
    if (changed)
      printf("%d %.17g %.17g %.17g\n", k, now[0], now[1], now[2]);
    for (int i = 0; i < 3; i++)
      last[i] = now[i];
  }
  printf("type %d %d %d\n", wb_touch_sensor_get_type(bumpers[0]), wb_touch_sensor_get_type(bumpers[1]),
         wb_touch_sensor_get_type(bumpers[2]));
  wb_robot_cleanup();
  return 0;
}
