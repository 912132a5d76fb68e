/* The calls of Webots' boebot controller, our own text (tests/test_sweep18.py runs Webots' file instead when
 * WEBOTS_HOME has it): every 64 ms the two infra-red readings, each truncated to an int, make a two-bit state
 * (left << 1 | right): 3 forward at 8 rad/s, 1 a right turn and 2 a left turn in place at 10 rad/s, 0 (or a
 * back-off under way) backwards at (-10, -20) for 11 steps; the LEDs show which side sees something. */
#include <math.h>

#include <webots/distance_sensor.h>
#include <webots/led.h>
#include <webots/light_sensor.h>
#include <webots/motor.h>
#include <webots/robot.h>

#define STEP 64

int main(void) {
  wb_robot_init();
  const WbDeviceTag sensors[2] = {wb_robot_get_device("lds"), wb_robot_get_device("rds")};
  const WbDeviceTag lights[2] = {wb_robot_get_device("lls"), wb_robot_get_device("rls")};
  const WbDeviceTag leds[2] = {wb_robot_get_device("left_led"), wb_robot_get_device("right_led")};
  const WbDeviceTag wheels[2] = {wb_robot_get_device("left wheel motor"), wb_robot_get_device("right wheel motor")};
  for (int i = 0; i < 2; ++i) {
    wb_distance_sensor_enable(sensors[i], STEP);
    wb_light_sensor_enable(lights[i], STEP);
    wb_motor_set_position(wheels[i], INFINITY);
    wb_motor_set_velocity(wheels[i], 0.0);
  }
  int backing = 0;
  while (wb_robot_step(STEP) != -1) {
    const int clear_left = (int)wb_distance_sensor_get_value(sensors[0]);
    const int clear_right = (int)wb_distance_sensor_get_value(sensors[1]);
    const int state = backing ? 0 : (clear_left << 1 | clear_right);
    double speed[2];
    int lit[2];
    if (state == 0) {
      speed[0] = -10.0, speed[1] = -20.0, lit[0] = lit[1] = 1;
      backing = backing ? backing - 1 : 10;
    } else if (state == 1) {
      speed[0] = 10.0, speed[1] = -10.0, lit[0] = 1, lit[1] = 0;
    } else if (state == 2) {
      speed[0] = -10.0, speed[1] = 10.0, lit[0] = 0, lit[1] = 1;
    } else {
      speed[0] = speed[1] = 8.0, lit[0] = lit[1] = 0;
    }
    for (int i = 0; i < 2; ++i) {
      wb_led_set(leds[i], lit[i]);
      wb_motor_set_velocity(wheels[i], speed[i]);
    }
  }
  wb_robot_cleanup();
  return 0;
}
