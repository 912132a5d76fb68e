/* Prints the robot's URDF with the prefix "p_" (tests/test_urdf.py compares it with the server's),
 * then whether a second call gives the same string (the library owns it until the next call), then
 * takes one step. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/robot.h>

int main(void) {
  wb_robot_init();
  const char *first = wb_robot_get_urdf("p_");
  char *kept = strdup(first);
  const char *second = wb_robot_get_urdf("p_");
  fputs(second, stdout);
  printf("same %d\n", kept != NULL && strcmp(kept, second) == 0);
  fflush(stdout);
  wb_robot_step((int)wb_robot_get_basic_time_step()); /* attached until the test has seen it */
  free(kept);
  wb_robot_cleanup();
  return 0;
}
