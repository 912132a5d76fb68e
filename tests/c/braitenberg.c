/* The Braitenberg vehicle of sensorium/client/examples/braitenberg.py, ported to C line by line
 * (same arithmetic, same output format): braitenberg [STEPS]. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <webots/distance_sensor.h>
#include <webots/light_sensor.h>
#include <webots/motor.h>
#include <webots/robot.h>

#define MAX_SPEED 6.28
#define LIGHT_GAIN 4.0
#define IR_THRESHOLD 150.0
static const double IR_WEIGHTS_LEFT[8] = {-1.0, -0.8, -0.4, 0.0, 0.0, 0.4, 0.8, 1.0};
static const double IR_WEIGHTS_RIGHT[8] = {1.0, 0.8, 0.4, 0.0, 0.0, -0.4, -0.8, -1.0};

static double clip(double v) { return v < -MAX_SPEED ? -MAX_SPEED : (v > MAX_SPEED ? MAX_SPEED : v); }

static void wheel_speeds(double light_left, double light_right, const double *ir, double *left, double *right) {
  double total = light_left + light_right;
  if (total > 0) {
    *left = 0.5 * MAX_SPEED + LIGHT_GAIN * (light_right - light_left) / total;
    *right = 0.5 * MAX_SPEED + LIGHT_GAIN * (light_left - light_right) / total;
  } else
    *left = *right = 0.5 * MAX_SPEED;
  for (int i = 0; i < 8; i++)
    if (ir[i] == ir[i] && ir[i] > IR_THRESHOLD) {
      double push = (ir[i] - IR_THRESHOLD) / 1000.0 * MAX_SPEED;
      *left += IR_WEIGHTS_LEFT[i] * push;
      *right += IR_WEIGHTS_RIGHT[i] * push;
    }
  *left = clip(*left);
  *right = clip(*right);
}

int main(int argc, char **argv) {
  wb_robot_init();
  int timestep = (int)wb_robot_get_basic_time_step();
  int max_steps = argc > 1 ? atoi(argv[1]) : -1;
  WbDeviceTag eyes[2] = {wb_robot_get_device("ls0"), wb_robot_get_device("ls1")};
  WbDeviceTag proximity[8];
  for (int i = 0; i < 8; i++) {
    char name[8];
    snprintf(name, sizeof name, "ps%d", i);
    proximity[i] = wb_robot_get_device(name);
  }
  for (int i = 0; i < 2; i++)
    wb_light_sensor_enable(eyes[i], timestep);
  for (int i = 0; i < 8; i++)
    wb_distance_sensor_enable(proximity[i], timestep);
  WbDeviceTag left_motor = wb_robot_get_device("left wheel motor");
  WbDeviceTag right_motor = wb_robot_get_device("right wheel motor");
  WbDeviceTag motors[2] = {left_motor, right_motor};
  for (int i = 0; i < 2; i++)
    if (motors[i]) {
      wb_motor_set_position(motors[i], INFINITY);
      wb_motor_set_velocity(motors[i], 0.0);
    }
  int step = 0;
  while (wb_robot_step(timestep) != -1) {
    double light[2] = {wb_light_sensor_get_value(eyes[0]), wb_light_sensor_get_value(eyes[1])};
    double ir[8];
    for (int i = 0; i < 8; i++)
      ir[i] = wb_distance_sensor_get_value(proximity[i]);
    double left, right;
    wheel_speeds(light[0], light[1], ir, &left, &right);
    printf("t=%7.3f  ls0=%8.2f ls1=%8.2f  ps=[", wb_robot_get_time(), light[0], light[1]);
    for (int i = 0; i < 8; i++)
      printf(i ? " %6.1f" : "%6.1f", ir[i]);
    printf("]  wheels %+5.2f %+5.2f rad/s\n", left, right);
    fflush(stdout);
    if (left_motor && right_motor) {
      wb_motor_set_velocity(left_motor, left);
      wb_motor_set_velocity(right_motor, right);
    }
    step += 1;
    if (max_steps >= 0 && step >= max_steps)
      break;
  }
  wb_robot_cleanup();
  return 0;
}
