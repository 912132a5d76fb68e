/* GPS, Altimeter, InertialUnit, Compass, Accelerometer, Gyro and TouchSensor on a kinematic robot
 * (tests/worlds/c_api.yaml, robot "walker"): straight at 0.5 m/s, a turn in place at 2.5 rad/s, then
 * into the wall. Every expected value is a closed form of the motion (basic step 16 ms). */
#include <webots/accelerometer.h>
#include <webots/altimeter.h>
#include <webots/compass.h>
#include <webots/gps.h>
#include <webots/gyro.h>
#include <webots/inertial_unit.h>
#include <webots/motor.h>
#include <webots/touch_sensor.h>

#include "ts.h"

#define STEP 16
#define G 9.81

static void wheels(double left, double right) {
  WbDeviceTag l = wb_robot_get_device("left wheel motor"), r = wb_robot_get_device("right wheel motor");
  wb_motor_set_position(l, INFINITY);
  wb_motor_set_position(r, INFINITY);
  wb_motor_set_velocity(l, left);
  wb_motor_set_velocity(r, right);
}

int main(void) {
  ts_setup();
  WbDeviceTag gps = wb_robot_get_device("gps"), alt = wb_robot_get_device("altimeter");
  WbDeviceTag imu = wb_robot_get_device("imu"), compass = wb_robot_get_device("compass");
  WbDeviceTag acc = wb_robot_get_device("accelerometer"), gyro = wb_robot_get_device("gyro");
  WbDeviceTag bumper = wb_robot_get_device("bumper");
  wb_gps_enable(gps, STEP);
  wb_altimeter_enable(alt, STEP);
  wb_inertial_unit_enable(imu, STEP);
  wb_compass_enable(compass, STEP);
  wb_accelerometer_enable(acc, STEP);
  wb_gyro_enable(gyro, 2 * STEP);
  wb_touch_sensor_enable(bumper, STEP);
  ts_assert_int_equal(wb_gyro_get_sampling_period(gyro), 2 * STEP, "gyro period");
  ts_assert_double_equal(wb_gps_get_values(gps)[0], NAN, "GPS before the first value");
  ts_assert_double_equal(wb_altimeter_get_value(alt), NAN, "altimeter before the first value");

  /* at rest */
  wb_robot_step(STEP);
  ts_assert_vec3_in_delta(wb_gps_get_values(gps), 0.0, 0.0, 0.1, 0.0, "GPS at rest");
  ts_assert_double_equal(wb_gps_get_speed(gps), NAN, "GPS speed at the first value (no previous position)");
  ts_assert_double_equal(wb_altimeter_get_value(alt), 0.1, "altimeter = the device's height");
  ts_assert_vec3_in_delta(wb_accelerometer_get_values(acc), 0.0, 0.0, G, 0.0, "accelerometer at rest reads gravity");
  ts_assert_vec3_in_delta(wb_compass_get_values(compass), 0.0, 1.0, 0.0, 1e-15, "compass: north is +y (ENU)");
  ts_assert_vec3_in_delta(wb_inertial_unit_get_roll_pitch_yaw(imu), 0.0, 0.0, 0.0, 0.0, "IMU at rest");
  ts_assert_double_equal(wb_gyro_get_values(gyro)[2], NAN, "gyro: first value at 32 ms");
  ts_assert_double_equal(wb_touch_sensor_get_value(bumper), 0.0, "bumper: nothing touched");

  /* straight along +x at 5 rad/s x 0.1 m = 0.5 m/s: 8 mm per step */
  wheels(5.0, 5.0);
  for (int k = 1; k <= 4; k++) {
    wb_robot_step(STEP);
    ts_assert_double_in_delta(wb_gps_get_values(gps)[0], 0.008 * k, 1e-15, "GPS x after %d steps", k);
    if (k >= 2) {
      ts_assert_double_in_delta(wb_gps_get_speed(gps), 0.5, 1e-12, "GPS speed at step %d", k);
      ts_assert_vec3_in_delta(wb_gps_get_speed_vector(gps), 0.5, 0.0, 0.0, 1e-12, "GPS speed vector at step %d", k);
    }
    if (k >= 3) /* the second difference of constant speed: gravity alone */
      ts_assert_vec3_in_delta(wb_accelerometer_get_values(acc), 0.0, 0.0, G, 1e-9, "accelerometer at constant speed");
  }
  ts_assert_vec3_in_delta(wb_gyro_get_values(gyro), 0.0, 0.0, 0.0, 0.0, "gyro going straight");

  /* a turn in place: wheels at -/+2.5 rad/s, 0.25 m/s each, axle 0.2 m: 2.5 rad/s, 0.04 rad per step */
  wheels(-2.5, 2.5);
  double yaw = 0.0;
  for (int k = 1; k <= 6; k++) {
    wb_robot_step(STEP);
    yaw += 0.04;
    const double *rpy = wb_inertial_unit_get_roll_pitch_yaw(imu);
    ts_assert_double_in_delta(rpy[2], yaw, 1e-12, "IMU yaw after %d turning steps", k);
    const double *q = wb_inertial_unit_get_quaternion(imu);
    ts_assert_double_in_delta(q[2], sin(yaw / 2), 1e-12, "IMU quaternion z");
    ts_assert_double_in_delta(q[3], cos(yaw / 2), 1e-12, "IMU quaternion w");
    ts_assert_vec3_in_delta(wb_compass_get_values(compass), sin(yaw), cos(yaw), 0.0, 1e-12, "compass turning");
    if (k % 2 == 0) /* the gyro's 32 ms period */
      ts_assert_vec3_in_delta(wb_gyro_get_values(gyro), 0.0, 0.0, 2.5, 1e-9, "gyro: the turn rate");
    if (k >= 3) /* the device sits on the turning axis: no centripetal term */
      ts_assert_vec3_in_delta(wb_accelerometer_get_values(acc), 0.0, 0.0, G, 1e-9, "accelerometer turning in place");
  }

  /* back to heading 0 would take time: drive on along the current heading into the wall (x = 0.6) */
  wheels(10.0, 10.0);
  int touched = 0;
  for (int k = 0; k < 200 && !touched; k++) {
    wb_robot_step(STEP);
    touched = wb_touch_sensor_get_value(bumper) == 1.0;
  }
  ts_assert_boolean_equal(touched, true, "the bumper presses the wall");
  ts_assert_double_in_delta(wb_gps_get_values(gps)[0], 0.6 - 0.05, 1e-9, "stopped with the body (radius 0.05) at the wall face");
  wheels(-10.0, -10.0);
  wb_robot_step(STEP);
  ts_assert_double_equal(wb_touch_sensor_get_value(bumper), 0.0, "backing away releases the bumper");
  ts_send_success();
  return 0;
}
