/* Shared by the transport benchmark's C processes: wait for "go" on stdin, time n calls, print
 * {"t0": [...], "t1": [...]} (CLOCK_MONOTONIC seconds: Python's time.monotonic, comparable across
 * processes) on stdout, as sensorium/benchmarks/transport_roles.py's Python roles do. */
#ifndef SENSORIUM_BENCH_TIMING_H
#define SENSORIUM_BENCH_TIMING_H

#define _POSIX_C_SOURCE 200809L /* clock_gettime under -std=c11 (include this header first) */

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double bench_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void bench_print(const char *key, const double *v, long n, const char *end) {
  printf("\"%s\": [", key);
  for (long i = 0; i < n; i++)
    printf(i ? ",%.9f" : "%.9f", v[i]);
  printf("]%s", end);
}

/* say "ready", wait for a line on stdin, run call() n times; 0 on success */
static int bench_run(long n, int (*call)(void *), void *arg) {
  double *t0 = malloc(sizeof(double) * (size_t)(n > 0 ? n : 1));
  double *t1 = malloc(sizeof(double) * (size_t)(n > 0 ? n : 1));
  char line[64];
  if (t0 == NULL || t1 == NULL)
    return 1;
  printf("ready\n");
  fflush(stdout);
  if (fgets(line, sizeof line, stdin) == NULL)
    return 1;
  for (long i = 0; i < n; i++) {
    t0[i] = bench_now();
    if (call(arg) != 0) {
      fprintf(stderr, "bench: call %ld failed\n", i);
      return 1;
    }
    t1[i] = bench_now();
  }
  printf("{");
  bench_print("t0", t0, n, ", ");
  bench_print("t1", t1, n, "}\n");
  fflush(stdout);
  free(t0);
  free(t1);
  return 0;
}

#endif
