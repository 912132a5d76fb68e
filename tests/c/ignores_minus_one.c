/* A controller whose loop ignores wb_robot_step's -1, as Webots' khepera_gripper sample does (it loops
 * while the step is not 1): prints each step's status. libController ends such a controller at the step
 * after the -1 (status 0). The twin of tests/controllers/ignores_minus_one.py.
 *   ignores_minus_one           the loop above
 *   ignores_minus_one cleanup   cleans up when a step answers -1 and loops on, reading the keyboard and
 *                               stepping, as Webots' nao_demo does: the first call after the cleanup
 *                               ends the process (status 0, nothing said)
 *   ignores_minus_one early     cleans up after the first step while the simulation runs, then steps:
 *                               one error line, status 1 */
#include <stdio.h>
#include <string.h>

#include <webots/keyboard.h>
#include <webots/robot.h>

int main(int argc, char **argv) {
  const char *mode = argc > 1 ? argv[1] : "";
  wb_robot_init();
  const int step = (int)wb_robot_get_basic_time_step();
  if (strcmp(mode, "early") == 0) {
    printf("%d\n", wb_robot_step(step));
    fflush(stdout);
    wb_robot_cleanup();
    printf("%d\n", wb_robot_step(step));
    return 0;
  }
  if (strcmp(mode, "cleanup") == 0)
    wb_keyboard_enable(step);
  for (;;) {
    const int status = wb_robot_step(step);
    printf("%d\n", status);
    fflush(stdout);
    if (strcmp(mode, "cleanup") == 0) {
      if (status == -1) {
        wb_robot_cleanup();
        printf("cleaned up\n");
        fflush(stdout);
      }
      wb_keyboard_get_key();
    }
  }
}
