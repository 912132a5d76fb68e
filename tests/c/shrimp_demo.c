/* The calls of Webots' shrimp sample, our own text (tests/test_sweep15.py runs Webots' file instead when
 * WEBOTS_HOME has it): the Shrimp protocol's speed-and-direction command as wheel speeds and steering
 * angles (a 5000 rpm motor behind an 86:1 gear at full scale 127; the turn about one point 0.242 m ahead
 * of the back wheel), wheel 00's encoder (16 counts a turn, rounded up) read each 64 ms: speed 95
 * straight until 200 counts, 127 at -75 degrees until 270, then stop and wait. */
#include <math.h>
#include <stdio.h>

#include <webots/motor.h>
#include <webots/position_sensor.h>
#include <webots/robot.h>

#define STEP 64

static const double FORWARD[6] = {-1, 1, -1, 1, -1, -1};   /* each wheel motor's sign of a forward roll */
static WbDeviceTag wheels[6], encoders[6], front_hinge, back_hinge;

static void drive(int speed, int degrees) {
  const double back = degrees * M_PI / 180.0;
  const double back_speed = speed * 5000.0 * 2.0 * M_PI / (60.0 * 86.0 * 127.0);
  const double back_radius = 0.242 / cos(M_PI / 2.0 - fabs(back));
  const double rate = back_speed / back_radius;
  const double centre = fabs(back_radius) != 0.242 ? sqrt(back_radius * back_radius - 0.242 * 0.242) : 0.0;
  const double front_radius = hypot(centre, 0.271);
  const double front = (M_PI / 2.0 - asin(centre / front_radius)) * (degrees < 0 ? -1.0 : 1.0);
  const double inner = hypot(centre - 0.182, 0.089), outer = hypot(centre + 0.182, 0.089);
  double left = rate * (degrees > 0 ? outer : inner), right = rate * (degrees > 0 ? inner : outer);
  if (centre < 0.182) {                     /* the turning point inside the wheels: the near side backwards */
    if (degrees < 0)
      left = -left;
    else
      right = -right;
  }
  const double speeds[6] = {rate * front_radius, left, right, left, right, back_speed};
  for (int i = 0; i < 6; i++) {
    wb_motor_set_position(wheels[i], INFINITY);
    wb_motor_set_velocity(wheels[i], FORWARD[i] * speeds[i]);
  }
  wb_motor_set_position(front_hinge, -front);
  wb_motor_set_position(back_hinge, back);
}

static int counts(void) {
  return (int)ceil(FORWARD[0] * wb_position_sensor_get_value(encoders[0]) / (2.0 * M_PI) * 16.0);
}

static void drive_until(int speed, int degrees, int until) {
  drive(speed, degrees);
  wb_robot_step(STEP);
  int reached;
  do {
    reached = counts() >= until;
    wb_robot_step(STEP);
  } while (!reached);
}

int main(void) {
  wb_robot_init();
  char motor[] = "wheel motor 00", sensor[] = "wheel sensor 00";
  for (int i = 0; i < 6; i++) {
    motor[13] = sensor[14] = (char)('0' + i);
    wheels[i] = wb_robot_get_device(motor);
    encoders[i] = wb_robot_get_device(sensor);
    wb_position_sensor_enable(encoders[i], 32);
    wb_motor_set_velocity(wheels[i], 0.0);
    wb_motor_set_position(wheels[i], 0.0);
  }
  front_hinge = wb_robot_get_device("front wheel rotation");
  back_hinge = wb_robot_get_device("back wheel rotation");
  drive_until(95, 0, 200);
  drive_until(127, -75, 270);
  drive(0, 0);
  printf("demo done at %.3f s\n", wb_robot_get_time());
  while (wb_robot_step(STEP) != -1) {
  }
  wb_robot_cleanup();
  return 0;
}
