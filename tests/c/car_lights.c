/* The vehicle library's answers from the world and the controller's own commands (engine type,
 * brake and brake lights, reverse and backwards lights, indicators blinking and switching themselves
 * off, hazard flashers, dipped beams, antifog lights, the car's flags) and a free wheel's encoder,
 * on tests/worlds/car_lights.yaml; tests/test_c_client.py checks what it prints, and the Python
 * vehicle library prints the same lines (tests/test_vehicle_driver.py). */
#include <stdio.h>

#include <webots/led.h>
#include <webots/robot.h>
#include <webots/vehicle/car.h>
#include <webots/vehicle/driver.h>

static int led(const char *name) {
  return wb_led_get(wb_robot_get_device(name));
}

int main(void) {
  wbu_driver_init();
  printf("start %d %.17g %d %d %d %d\n", (int)wbu_car_get_engine_type(), wbu_car_get_indicator_period(),
         (int)wbu_car_get_brake_lights(), (int)wbu_car_get_backwards_lights(), (int)wbu_driver_get_indicator(),
         (int)wbu_driver_get_hazard_flashers());
  /* straight ahead at 36 km/h (10 m/s) for 50 steps: the free front wheels roll 8 m */
  wbu_driver_set_cruising_speed(36);
  for (int i = 0; i < 50; i++)
    wbu_driver_step();
  printf("rolled %.17g %.17g %.17g %.17g\n", wbu_car_get_wheel_encoder(WBU_CAR_WHEEL_FRONT_RIGHT),
         wbu_car_get_wheel_encoder(WBU_CAR_WHEEL_FRONT_LEFT), wbu_car_get_wheel_speed(WBU_CAR_WHEEL_FRONT_RIGHT),
         wbu_car_get_wheel_speed(WBU_CAR_WHEEL_FRONT_LEFT));
  /* the brake: clamped (one line), the brake lights while it is above 0 */
  wbu_driver_set_brake_intensity(1.5);
  printf("brake %.17g %d %d\n", wbu_driver_get_brake_intensity(), (int)wbu_car_get_brake_lights(), led("brake_lights"));
  wbu_driver_set_brake_intensity(0.0);
  printf("released %.17g %d %d\n", wbu_driver_get_brake_intensity(), (int)wbu_car_get_brake_lights(), led("brake_lights"));
  /* reverse: the backwards lights from the next step on */
  wbu_driver_set_cruising_speed(-5);
  printf("reverse %d\n", (int)wbu_car_get_backwards_lights());
  wbu_driver_step();
  printf("reversing %d %d\n", (int)wbu_car_get_backwards_lights(), led("backwards_lights"));
  wbu_driver_set_cruising_speed(0);
  wbu_driver_step();
  printf("stopped %d %d\n", (int)wbu_car_get_backwards_lights(), led("backwards_lights"));
  /* the right indicator blinks with a period of 4 steps; the time before each step decides */
  wbu_car_set_indicator_period(0.064);
  wbu_driver_set_indicator(RIGHT);
  printf("blink %.17g", wbu_car_get_indicator_period());
  for (int i = 0; i < 8; i++) {
    double t = wb_robot_get_time();
    wbu_driver_step();
    printf(" %.3f:%d%d", t, led("right_indicators"), led("left_indicators"));
  }
  printf("\n");
  /* auto-disabling: the indicator follows the steering to 0.3, survives 0.25, goes off at 0.19 */
  wbu_driver_set_steering_angle(0.3);
  wbu_driver_set_steering_angle(0.25);
  int kept = (int)wbu_driver_get_indicator();
  wbu_driver_set_steering_angle(0.19);
  printf("auto %d %d", kept, (int)wbu_driver_get_indicator());
  wbu_car_enable_indicator_auto_disabling(false);
  wbu_driver_set_indicator(LEFT);
  wbu_driver_set_steering_angle(0.5);
  printf(" %d\n", (int)wbu_driver_get_indicator());
  /* hazard flashers: both sides blink, whatever the indicator */
  wbu_driver_set_indicator(OFF);
  wbu_driver_set_hazard_flashers(true);
  printf("hazard %d", (int)wbu_driver_get_hazard_flashers());
  for (int i = 0; i < 4; i++) {
    double t = wb_robot_get_time();
    wbu_driver_step();
    printf(" %.3f:%d%d", t, led("right_indicators"), led("left_indicators"));
  }
  printf("\n");
  wbu_driver_set_dipped_beams(true);
  wbu_driver_set_antifog_lights(true);
  wbu_car_enable_limited_slip_differential(false);
  printf("lights %d %d %d %d %d\n", (int)wbu_driver_get_dipped_beams(), (int)wbu_driver_get_antifog_lights(),
         led("front_lights"), led("rear_lights"), led("antifog_lights"));
  fflush(stdout);
  wbu_driver_cleanup();
  wb_robot_cleanup();
  return 0;
}
