/* A car controller as a Webots user writes one (Webots' driver library): steer 0.2 rad, cruise at
 * 20 km/h, drive. Only the stop after 400 steps and the prints are the test's (tests/test_c_client.py
 * checks the car's pose against the closed-form circle). */
#include <stdio.h>

#include <webots/robot.h>
#include <webots/vehicle/car.h>
#include <webots/vehicle/driver.h>

int main(void) {
  wbu_driver_init();
  wbu_driver_set_steering_angle(0.2);
  wbu_driver_set_cruising_speed(20);
  wbu_driver_set_throttle(0.5); /* no engine model: one line, once */
  wbu_driver_set_throttle(0.7);
  int steps = 0;
  while (wbu_driver_step() != -1) {
    if (++steps == 400)
      break;
  }
  printf("driver %.17g %.17g %.17g %.17g %d %d\n", wbu_driver_get_current_speed(),
         wbu_driver_get_target_cruising_speed(), wbu_driver_get_steering_angle(), wb_robot_get_time(),
         (int)wbu_driver_get_control_mode(), wbu_driver_get_gear());
  printf("car %d %.17g %.17g %.17g %.17g %.17g %.17g\n", (int)wbu_car_get_type(), wbu_car_get_wheelbase(),
         wbu_car_get_track_front(), wbu_car_get_rear_wheel_radius(), wbu_car_get_right_steering_angle(),
         wbu_car_get_wheel_speed(WBU_CAR_WHEEL_REAR_LEFT), wbu_car_get_wheel_encoder(WBU_CAR_WHEEL_REAR_LEFT));
  fflush(stdout);
  wbu_driver_cleanup();
  wb_robot_cleanup();
  return 0;
}
