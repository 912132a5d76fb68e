/* Webots' driver library turning a car's interior, as autonomous_vehicle.c's calls make it (sweep 29's
 * BmwX5 stand-in, tests/data/sweep29/city.wbt): 50 km/h, the wipers in SLOW mode, the steering at -0.05 rad
 * from the 20th step; each step prints the steering wheel's and speed needle's target positions and the
 * wiper sensor, which tests/test_sweep29.py checks against Webots' library's closed form. */
#include <stdio.h>

#include <webots/motor.h>
#include <webots/position_sensor.h>
#include <webots/robot.h>
#include <webots/vehicle/driver.h>

int main(void) {
  wbu_driver_init();
  WbDeviceTag wheel = wb_robot_get_device("steering_wheel_motor");
  WbDeviceTag needle = wb_robot_get_device("speed_needle_motor");
  WbDeviceTag wiper = wb_robot_get_device("wiper_sensor");
  wbu_driver_set_cruising_speed(50.0);
  wbu_driver_set_wiper_mode(SLOW);
  printf("mode %d %d\n", (int)wbu_driver_get_wiper_mode(), (int)wbu_driver_get_wipers_mode());
  int k = 0;
  while (wbu_driver_step() != -1) {
    if (++k == 20)
      wbu_driver_set_steering_angle(-0.05);
    printf("%d %.17g %.17g %.17g\n", k, wb_motor_get_target_position(wheel), wb_motor_get_target_position(needle),
           wb_position_sensor_get_value(wiper));
    fflush(stdout);
  }
  wbu_driver_cleanup();
  return 0;
}
