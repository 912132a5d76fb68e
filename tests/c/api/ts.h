/* Assertions for the Webots-style API tests in this folder (written for Sensorium, in the manner of
 * Webots' own tests/api controllers): each test is a controller that checks what the API answers and
 * ends with ts_send_success() (prints "success", exit status 0); the first failed check prints
 * "failure: <what>" and exits with status 1. */
#ifndef SENSORIUM_TESTS_TS_H
#define SENSORIUM_TESTS_TS_H

#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/robot.h>

static void ts_fail(const char *fmt, va_list ap) {
  printf("failure: ");
  vprintf(fmt, ap);
  printf("\n");
  fflush(stdout);
  wb_robot_cleanup();
  exit(1);
}

static void ts_check(bool ok, const char *fmt, ...) {
  if (ok)
    return;
  va_list ap;
  va_start(ap, fmt);
  ts_fail(fmt, ap);
  va_end(ap);
}

#define ts_assert_boolean_equal(value, expected, ...) ts_check((bool)(value) == (bool)(expected), __VA_ARGS__)
#define ts_assert_int_equal(value, expected, ...) ts_check((value) == (expected), __VA_ARGS__)
#define ts_assert_pointer_null(value, ...) ts_check((value) == NULL, __VA_ARGS__)
#define ts_assert_string_equal(value, expected, ...) ts_check(strcmp((value), (expected)) == 0, __VA_ARGS__)
/* |value - expected| <= delta; NaN equals NaN (Webots' "no value") */
#define ts_assert_double_in_delta(value, expected, delta, ...)                                              \
  ts_check((isnan(value) && isnan(expected)) || fabs((double)(value) - (double)(expected)) <= (delta), __VA_ARGS__)
#define ts_assert_double_equal(value, expected, ...) ts_assert_double_in_delta(value, expected, 0.0, __VA_ARGS__)
#define ts_assert_vec3_in_delta(v, x, y, z, delta, ...)                                                     \
  ts_check((v) != NULL && fabs((v)[0] - (x)) <= (delta) && fabs((v)[1] - (y)) <= (delta) &&                  \
             fabs((v)[2] - (z)) <= (delta), __VA_ARGS__)

static void ts_setup(void) {
  wb_robot_init();
}

static void ts_send_success(void) {
  printf("success\n");
  fflush(stdout);
  wb_robot_cleanup();
  exit(0);
}

#endif
