/* A careless controller of the vehicle library on tests/worlds/car_lights.yaml: NaN, infinite and
 * negative brake intensities, indicator periods of 0, negative, NaN, infinite and 1e-300 s, steering
 * angles NaN, infinite and 5e-324 rad, cruising speeds NaN and infinite. tests/controllers/car_hostile.py
 * prints the same lines (tests/test_vehicle_driver.py checks both). */
#include <math.h>
#include <stdio.h>

#include <webots/led.h>
#include <webots/motor.h>
#include <webots/robot.h>
#include <webots/vehicle/car.h>
#include <webots/vehicle/driver.h>

static int led(const char *name) {
  return wb_led_get(wb_robot_get_device(name));
}

static double rear(const char *name) {
  return wb_motor_get_velocity(wb_robot_get_device(name));
}

int main(void) {
  wbu_driver_init();
  wbu_driver_set_brake_intensity(0.25);
  wbu_driver_set_brake_intensity(NAN);
  printf("brake_nan %.17g %d\n", wbu_driver_get_brake_intensity(), (int)wbu_car_get_brake_lights());
  wbu_driver_set_brake_intensity(-0.5);
  printf("brake_negative %.17g %d %d\n", wbu_driver_get_brake_intensity(), (int)wbu_car_get_brake_lights(),
         led("brake_lights"));
  wbu_driver_set_brake_intensity(INFINITY);
  printf("brake_inf %.17g %d %d\n", wbu_driver_get_brake_intensity(), (int)wbu_car_get_brake_lights(),
         led("brake_lights"));
  const double periods[5] = {0.0, -1.0, NAN, INFINITY, -INFINITY};
  for (int i = 0; i < 5; i++)
    wbu_car_set_indicator_period(periods[i]);
  printf("period %.17g\n", wbu_car_get_indicator_period());
  wbu_driver_set_indicator(RIGHT);
  wbu_car_set_indicator_period(1e-300); /* positive: kept; every quotient past a double's integers is even */
  wbu_driver_step();
  wbu_driver_step();
  printf("tiny %.17g %d %d\n", wbu_car_get_indicator_period(), led("right_indicators"), led("left_indicators"));
  wbu_car_set_indicator_period(0.34);
  wbu_driver_set_cruising_speed(36);
  wbu_driver_set_steering_angle(0.2);
  const double angles[3] = {NAN, INFINITY, -INFINITY};
  for (int i = 0; i < 3; i++)
    wbu_driver_set_steering_angle(angles[i]);
  wbu_driver_set_cruising_speed(NAN);
  wbu_driver_set_cruising_speed(-INFINITY);
  printf("kept %.17g %.17g %.17g %.17g\n", wbu_driver_get_target_cruising_speed(),
         wb_motor_get_target_position(wb_robot_get_device("right_steer")), rear("right_rear_wheel"),
         rear("left_rear_wheel"));
  /* an angle whose cotangent is too large for a double: straight on, the wheels at the same speed */
  wbu_driver_set_steering_angle(5e-324);
  printf("denormal %.17g %.17g %.17g %.17g\n", wbu_car_get_right_steering_angle(), wbu_car_get_left_steering_angle(),
         rear("right_rear_wheel"), rear("left_rear_wheel"));
  wbu_driver_set_steering_angle(1.5707963267948966); /* the front wheels' radii cancel: the shares stay finite */
  printf("right_angle %.17g %.17g %.17g %.17g\n", wbu_car_get_right_steering_angle(), wbu_car_get_left_steering_angle(),
         rear("right_rear_wheel"), rear("left_rear_wheel"));
  wbu_driver_set_steering_angle(5e-324);
  for (int i = 0; i < 20; i++)
    wbu_driver_step();
  printf("rolled %.17g %.17g %d\n", wbu_car_get_wheel_encoder(WBU_CAR_WHEEL_FRONT_RIGHT),
         wbu_car_get_wheel_encoder(WBU_CAR_WHEEL_FRONT_LEFT), (int)isfinite(wbu_driver_get_current_speed()));
  fflush(stdout);
  wbu_driver_cleanup();
  return 0;
}
