/* A test harness, no controller: the C library's motion file parser (src/motion.c, included whole so
 * its static parse() is reachable) run on each file named on the command line, without a robot. For
 * each file it prints "file <name>", then either "ok <motors> <poses>", one "t <ms>" line per pose and
 * one "v <hex bits>" line per value, or the one line the library printed (stderr goes to stdout).
 * tests/test_fuzz_motion.py compares this with the Python client's parse_motion. */
#include <unistd.h>

#include "motion.c"
#include "utils.c" /* sn_shown, for its error lines */

/* what motion.c calls outside parsing; never reached here */
sn_robot *sn_robot_get(const char *func) {
  (void)func;
  return NULL;
}

void wb_motor_set_position(WbDeviceTag tag, double position) {
  (void)tag;
  (void)position;
}

int main(int argc, char **argv) {
  setvbuf(stdout, NULL, _IONBF, 0);
  setvbuf(stderr, NULL, _IONBF, 0);
  dup2(1, 2);
  for (int i = 1; i < argc; i++) {
    printf("file %s\n", argv[i]);
    FILE *f = fopen(argv[i], "rb");
    if (f == NULL) {
      printf("cannot open\n");
      continue;
    }
    reader *r = calloc(1, sizeof *r);
    WbMotionRef m = calloc(1, sizeof *m);
    if (r == NULL || m == NULL)
      return 2;
    r->f = f;
    r->filename = argv[i];
    if (parse(r, m)) {
      printf("ok %d %d\n", m->n_motors, m->n_poses);
      for (int k = 0; k < m->n_motors; k++)
        printf("m %s\n", m->motors[k]);
      for (int k = 0; k < m->n_poses; k++)
        printf("t %d\n", m->times[k]);
      for (long k = 0; k < (long)m->n_poses * m->n_motors; k++) {
        uint64_t bits;
        memcpy(&bits, &m->values[k], sizeof bits);
        printf("v %016llx\n", (unsigned long long)bits);
      }
    }
    fclose(f);
    free(r);
    motion_free(m);
  }
  return 0;
}
