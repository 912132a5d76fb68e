/* A C controller for the transport benchmark: the client library's wb_robot_step() in lockstep.
 * Usage (robot from SENSORIUM_CONTROLLER_URL): controller STEPS DURATION_MS */
#include "timing.h" /* first: it sets _POSIX_C_SOURCE */
#include <webots/robot.h>

static int duration_ms;

static int step(void *arg) {
  (void)arg;
  return wb_robot_step(duration_ms) == -1;
}

int main(int argc, char **argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: controller STEPS DURATION_MS\n");
    return 2;
  }
  duration_ms = atoi(argv[2]);
  wb_robot_init();
  int rc = bench_run(atol(argv[1]), step, NULL);
  wb_robot_cleanup();
  return rc;
}
