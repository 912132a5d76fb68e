/* The calls of Webots' p-rob3 sample, our own text (tests/test_sweep15.py runs Webots' file instead when
 * WEBOTS_HOME has it): its first moves, each followed by its wait (stepping the basic time step while
 * start + seconds > the robot's time, in doubles), the gripper closed by a torque. */
#include <stdio.h>
#include <stdlib.h>

#include <webots/motor.h>
#include <webots/robot.h>

static void wait_for(double seconds) {
  const double start = wb_robot_get_time();
  do {
    if (wb_robot_step((int)wb_robot_get_basic_time_step()) == -1) {
      wb_robot_cleanup();
      exit(EXIT_SUCCESS);
    }
  } while (start + seconds > wb_robot_get_time());
}

int main(void) {
  wb_robot_init();
  WbDeviceTag m[7];
  const char *names[7] = {"motor 1", "motor 2", "motor 3", "motor 4", "motor 5", "motor 6", "gripper::right"};
  for (int i = 0; i < 7; i++)
    m[i] = wb_robot_get_device(names[i]);
  wb_motor_set_position(m[4], -1.95);
  wait_for(0.5);
  wb_motor_set_position(m[1], 1.55);
  wb_motor_set_position(m[2], 1.12);
  wb_motor_set_position(m[6], 0.5);
  wait_for(2.0);
  wb_motor_set_position(m[4], -1.09);
  wait_for(2.0);
  wb_motor_set_torque(m[6], -0.2);
  wait_for(0.5);
  wb_motor_set_position(m[1], -0.92);
  wait_for(0.3);
  wb_motor_set_position(m[2], 1.88);
  wb_motor_set_position(m[4], 1.5);
  wait_for(2.0);
  wb_motor_set_position(m[0], -1.5708);
  wait_for(60.0);
  wb_robot_cleanup();
  return 0;
}
