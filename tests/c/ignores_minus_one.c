/* A controller whose loop ignores wb_robot_step's -1, as Webots' khepera_gripper sample does (it loops
 * while the step is not 1): prints each step's status. libController ends such a controller at the step
 * after the -1 (status 0). The twin of tests/controllers/ignores_minus_one.py. */
#include <stdio.h>

#include <webots/robot.h>

int main(void) {
  wb_robot_init();
  const int step = (int)wb_robot_get_basic_time_step();
  for (;;) {
    printf("%d\n", wb_robot_step(step));
    fflush(stdout);
  }
}
