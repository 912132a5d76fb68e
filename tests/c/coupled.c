/* Coupled motors over the wire (tests/worlds/coupled.yaml, robot hand); its Python twin is
 * tests/controllers/coupled.py (same lines): coupled STEPS. The multipliers and grip::b's limits;
 * grip::a to 0.1 (grip::b follows at -2 times it), the elbow to 0.1 and a refused negative
 * velocity; per step the float64 bits of the three sensors; then grip::a's velocity 0.5 and target
 * 0.8 (clamped by both motors, with Webots' warnings) and STEPS more steps. */
#include <stdlib.h>

#include <webots/motor.h>
#include <webots/position_sensor.h>
#include <webots/robot.h>

#include "common.h"

static void run(int n, int dt, const WbDeviceTag *sensors) {
  const char *names[3] = {"a", "b", "elbow"};
  for (int s = 0; s < n; s++) {
    int status = wb_robot_step(dt);
    printf("%.0f %d", wb_robot_get_time() * 1000.0, status);
    for (int i = 0; i < 3; i++)
      print_bits(names[i], wb_position_sensor_get_value(sensors[i]));
    printf("\n");
    fflush(stdout);
  }
}

int main(int argc, char **argv) {
  wb_robot_init();
  int steps = argc > 1 ? atoi(argv[1]) : 8, dt = (int)wb_robot_get_basic_time_step();
  WbDeviceTag a = wb_robot_get_device("grip::a"), b = wb_robot_get_device("grip::b");
  WbDeviceTag elbow = wb_robot_get_device("elbow");
  WbDeviceTag sensors[3] = {wb_motor_get_position_sensor(a), wb_motor_get_position_sensor(b),
                            wb_motor_get_position_sensor(elbow)};
  printf("%g %g %g %g %g %g\n", wb_motor_get_multiplier(a), wb_motor_get_multiplier(b), wb_motor_get_multiplier(elbow),
         wb_motor_get_min_position(b), wb_motor_get_max_position(b), wb_motor_get_max_velocity(b));
  fflush(stdout);
  for (int i = 0; i < 3; i++)
    wb_position_sensor_enable(sensors[i], dt);
  wb_motor_set_position(a, 0.1);
  wb_motor_set_position(elbow, 0.1);
  wb_motor_set_velocity(elbow, -1.0);
  printf("%g %g %g\n", wb_motor_get_target_position(a), wb_motor_get_target_position(b), wb_motor_get_velocity(elbow));
  fflush(stdout);
  run(steps, dt, sensors);
  wb_motor_set_velocity(a, 0.5);
  wb_motor_set_position(a, 0.8);
  printf("%g %g %g %g\n", wb_motor_get_velocity(a), wb_motor_get_velocity(b), wb_motor_get_target_position(a),
         wb_motor_get_target_position(b));
  fflush(stdout);
  run(steps, dt, sensors);
  wb_robot_cleanup();
  return 0;
}
