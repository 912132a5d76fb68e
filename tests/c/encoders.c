/* Braitenberg driver with wheel encoders (tests/worlds/cdevices.yaml, robot rover); its Python twin
 * is tests/controllers/encoders.py (same arithmetic, same lines): encoders STEPS.
 * 10 steps at 2.0 / 1.0 rad/s, then light-seeking with infra-red avoidance whose gains depend on
 * how far each wheel has turned (the encoders feed back into the commands). A line per step:
 * "T STATUS" and the float64 bits of both encoders, ps0, ps7, ls0, ls1. */
#include <math.h>
#include <stdlib.h>

#include <webots/distance_sensor.h>
#include <webots/light_sensor.h>
#include <webots/motor.h>
#include <webots/position_sensor.h>
#include <webots/robot.h>

#include "common.h"

int main(int argc, char **argv) {
  wb_robot_init();
  int steps = argc > 1 ? atoi(argv[1]) : 40, dt = (int)wb_robot_get_basic_time_step();
  WbDeviceTag lm = wb_robot_get_device("left wheel motor"), rm = wb_robot_get_device("right wheel motor");
  WbDeviceTag le = wb_motor_get_position_sensor(lm), re = wb_motor_get_position_sensor(rm);
  WbDeviceTag ps[2] = {wb_robot_get_device("ps0"), wb_robot_get_device("ps7")};
  WbDeviceTag ls[2] = {wb_robot_get_device("ls0"), wb_robot_get_device("ls1")};
  if (!le || !re || wb_position_sensor_get_motor(le) != lm || wb_position_sensor_get_brake(le) != 0)
    return 3;
  wb_position_sensor_enable(le, dt);
  wb_position_sensor_enable(re, dt);
  for (int i = 0; i < 2; i++) {
    wb_distance_sensor_enable(ps[i], dt);
    wb_light_sensor_enable(ls[i], 2 * dt);
  }
  wb_motor_set_position(lm, INFINITY);
  wb_motor_set_position(rm, INFINITY);
  wb_motor_set_velocity(lm, 2.0);
  wb_motor_set_velocity(rm, 1.0);
  for (int s = 0; s < steps; s++) {
    int status = wb_robot_step(dt);
    double a = wb_position_sensor_get_value(le), b = wb_position_sensor_get_value(re);
    double d0 = wb_distance_sensor_get_value(ps[0]), d7 = wb_distance_sensor_get_value(ps[1]);
    double l0 = wb_light_sensor_get_value(ls[0]), l1 = wb_light_sensor_get_value(ls[1]);
    printf("%.0f %d", wb_robot_get_time() * 1000.0, status);
    print_bits("left", a);
    print_bits("right", b);
    print_bits("ps0", d0);
    print_bits("ps7", d7);
    print_bits("ls0", l0);
    print_bits("ls1", l1);
    printf("\n");
    fflush(stdout);
    if (status == -1)
      break;
    if (s >= 9) {
      double total = l0 + l1, left = 3.0, right = 3.0;
      if (total == total && total > 0) {
        left += 2.0 * (l1 - l0) / total;
        right += 2.0 * (l0 - l1) / total;
      }
      if (d0 == d0 && d0 > 200.0)
        left -= (d0 - 200.0) / 500.0;
      if (d7 == d7 && d7 > 200.0)
        right -= (d7 - 200.0) / 500.0;
      double turned = fabs(a - b); /* encoders: damp the turn as the wheel angles diverge */
      left -= 0.1 * turned;
      right -= 0.1 * turned;
      wb_motor_set_velocity(lm, left);
      wb_motor_set_velocity(rm, right);
    }
  }
  wb_robot_cleanup();
  return 0;
}
