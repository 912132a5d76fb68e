/* Arm joints moved kinematically (tests/worlds/joints.yaml, robot arm); its Python twin is
 * tests/controllers/joints.py (same lines): joints STEPS. One line of the motors' answers, then per
 * step the float64 bits of the shoulder, wrist, lift and left wheel sensors; then a simulation
 * reset and one more step: the lift's target and reading. */
#include <math.h>
#include <stdlib.h>

#include <webots/motor.h>
#include <webots/position_sensor.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

#include "common.h"

int main(int argc, char **argv) {
  wb_robot_init();
  int steps = argc > 1 ? atoi(argv[1]) : 40, dt = (int)wb_robot_get_basic_time_step();
  WbDeviceTag shoulder = wb_robot_get_device("shoulder"), wrist = wb_robot_get_device("wrist");
  WbDeviceTag lift = wb_robot_get_device("lift"), wheel = wb_robot_get_device("left wheel motor");
  WbDeviceTag sensors[4] = {wb_motor_get_position_sensor(shoulder), wb_motor_get_position_sensor(wrist),
                            wb_motor_get_position_sensor(lift), wb_motor_get_position_sensor(wheel)};
  const char *names[4] = {"shoulder", "wrist", "lift", "wheel"};
  printf("%g %g %g %g %g %g %g %g %g %d %d %g %g\n", wb_motor_get_min_position(shoulder),
         wb_motor_get_max_position(shoulder), wb_motor_get_max_velocity(shoulder), wb_motor_get_max_torque(shoulder),
         wb_motor_get_available_torque(shoulder), wb_motor_get_acceleration(shoulder),
         wb_motor_get_target_position(shoulder), wb_motor_get_max_torque(wrist), wb_motor_get_max_force(lift),
         (int)wb_motor_get_type(lift), (int)wb_motor_get_type(shoulder), wb_motor_get_min_position(wheel),
         wb_motor_get_max_position(wheel));
  fflush(stdout);
  for (int i = 0; i < 4; i++)
    wb_position_sensor_enable(sensors[i], dt);
  wb_motor_set_position(shoulder, 2.0);
  wb_motor_set_acceleration(wrist, 5.0);
  wb_motor_set_position(wrist, -1.0);
  wb_motor_set_position(lift, 0.01);
  wb_motor_set_position(wheel, INFINITY);
  wb_motor_set_velocity(wheel, 2.0);
  printf("%g %g\n", wb_motor_get_target_position(shoulder), wb_motor_get_acceleration(wrist));
  fflush(stdout);
  for (int s = 0; s < steps; s++) {
    int status = wb_robot_step(dt);
    printf("%.0f %d", wb_robot_get_time() * 1000.0, status);
    for (int i = 0; i < 4; i++)
      print_bits(names[i], wb_position_sensor_get_value(sensors[i]));
    printf("\n");
    fflush(stdout);
    if (status == -1)
      break;
  }
  wb_supervisor_simulation_reset();
  wb_robot_step(dt);
  printf("reset %g %g %g\n", wb_motor_get_target_position(lift), wb_position_sensor_get_value(sensors[2]),
         wb_motor_get_target_position(shoulder));
  fflush(stdout);
  wb_robot_cleanup();
  return 0;
}
