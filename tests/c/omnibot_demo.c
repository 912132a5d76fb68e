/* A youBot-style demo on tests/worlds/proto/omnibot.wbt, written as Webots' youbot controller and its
 * youbot_control library drive the youBot (tests/test_omnibot.py checks the lines): 32 ms steps,
 * waits that step until the time has passed, the four wheels in velocity control (wheel1 front
 * right, wheel2 front left, wheel3 rear right, wheel4 rear left) with the library's fixed patterns
 * (forward, strafe left, its "turn left") and its base_move inverse kinematics, the arm by positions
 * with arm2's velocity lowered, the gripper through one of its coupled motors. After each phase:
 * "PHASE time x y yaw" (GPS and compass); at the end the joints' sensors. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <webots/compass.h>
#include <webots/gps.h>
#include <webots/motor.h>
#include <webots/position_sensor.h>
#include <webots/robot.h>

#define STEP 32
#define R 0.048
#define LX 0.2
#define LY 0.15
#define HALF_PI 1.5707963267948966

static WbDeviceTag wheels[4], arm[5], claw, gps, compass;

static void step(void) {
  if (wb_robot_step(STEP) == -1) {
    wb_robot_cleanup();
    exit(EXIT_FAILURE);
  }
}

static void wait_for(double seconds) {
  double start = wb_robot_get_time();
  do
    step();
  while (start + seconds > wb_robot_get_time());
}

static void wheel_speeds(double fr, double fl, double rr, double rl) {
  double v[4] = {fr, fl, rr, rl};
  for (int i = 0; i < 4; i++) {
    wb_motor_set_position(wheels[i], INFINITY);
    wb_motor_set_velocity(wheels[i], v[i]);
  }
}

static void move(double vx, double vy, double omega) {   /* the library's base_move */
  wheel_speeds((vx + vy + (LX + LY) * omega) / R, (vx - vy - (LX + LY) * omega) / R,
               (vx - vy + (LX + LY) * omega) / R, (vx + vy - (LX + LY) * omega) / R);
}

static void arm_to(double a2, double a3, double a4, double a5) {
  wb_motor_set_position(arm[1], a2);
  wb_motor_set_position(arm[2], a3);
  wb_motor_set_position(arm[3], a4);
  wb_motor_set_position(arm[4], a5);
}

static void report(const char *phase) {
  const double *g = wb_gps_get_values(gps), *north = wb_compass_get_values(compass);
  printf("%s %.3f %.12f %.12f %.12f\n", phase, wb_robot_get_time(), g[0], g[1], atan2(north[0], north[1]));
  fflush(stdout);
}

int main(void) {
  char name[16];
  wb_robot_init();
  for (int i = 0; i < 4; i++) {
    snprintf(name, sizeof name, "wheel%d", i + 1);
    wheels[i] = wb_robot_get_device(name);
  }
  for (int i = 0; i < 5; i++) {
    snprintf(name, sizeof name, "arm%d", i + 1);
    arm[i] = wb_robot_get_device(name);
  }
  claw = wb_robot_get_device("claw::left");
  gps = wb_robot_get_device("gps");
  compass = wb_robot_get_device("compass");
  wb_gps_enable(gps, STEP);
  wb_compass_enable(compass, STEP);
  WbDeviceTag sensors[7];
  const char *sensor_names[7] = {"arm1sensor", "arm2sensor", "arm3sensor", "arm4sensor", "arm5sensor",
                                 "claw left sensor", "claw right sensor"};
  for (int i = 0; i < 7; i++) {
    sensors[i] = wb_robot_get_device(sensor_names[i]);
    wb_position_sensor_enable(sensors[i], STEP);
  }

  wb_motor_set_velocity(arm[1], 0.5);     /* as arm_init */
  arm_to(1.2, -2.0, 1.5, 0.0);
  wb_motor_set_position(arm[0], 0.0);
  wb_motor_set_velocity(claw, 0.03);      /* as gripper_init: both fingers follow */
  wait_for(2.0);
  report("start");

  wb_motor_set_position(claw, 0.02);      /* release */
  arm_to(0.0, -0.8, -1.2, 0.0);
  wheel_speeds(4.0, 4.0, 4.0, 4.0);       /* base_forwards */
  wait_for(1.0);
  report("forward");
  wheel_speeds(4.0, -4.0, -4.0, 4.0);     /* base_strafe_left */
  wait_for(1.0);
  report("strafe");
  wheel_speeds(-4.0, 4.0, -4.0, 4.0);     /* base_turn_left */
  wait_for(1.0);
  report("turn");
  move(0.1, 0.05, 0.3);                   /* base_move */
  wait_for(1.0);
  report("move");
  wheel_speeds(0.0, 0.0, 0.0, 0.0);       /* base_reset */
  wb_motor_set_position(claw, 0.0);       /* grip */
  wb_motor_set_position(arm[0], HALF_PI);  /* ARM_RIGHT */
  wait_for(3.0);
  report("stop");
  printf("joints");
  for (int i = 0; i < 7; i++)
    printf(" %.12f", wb_position_sensor_get_value(sensors[i]));
  printf("\n");
  wb_robot_cleanup();
  return 0;
}
