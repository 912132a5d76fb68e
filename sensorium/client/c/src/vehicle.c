/* Sensorium C controller library: Webots' car and driver libraries (vehicle/car.h, vehicle/driver.h).
 * Sensorium drives a car-like robot kinematically (the world's ackermann_drive), and Python's
 * `from vehicle import Driver, Car` drives it; this C library does not implement the vehicle
 * library yet. So wbu_driver_init() and wbu_car_init() say so in one line (naming what works: the
 * car's motors through wb_motor_*, or the Python Driver) and end the controller with status 1,
 * before it connects to any server; every other function does nothing and answers Webots' "no
 * value". */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <webots/vehicle/car.h>
#include <webots/vehicle/driver.h>

static void refuse(const char *func) {
  fprintf(stderr,
          "Error: %s(): Sensorium's C vehicle library (Car, Driver) is not implemented: drive a car-like robot "
          "through its motors (wb_motor_* on right_steer, left_steer and its wheels) or from Python (from vehicle "
          "import Driver).\n",
          func);
  fflush(stderr);
  exit(1);
}

/* ------------------------------------------------------------------ driver */
bool wbu_driver_initialization_is_possible(void) {
  return false;
}

void wbu_driver_init(void) {
  refuse("wbu_driver_init");
}

void wbu_driver_cleanup(void) {
}

int wbu_driver_step(void) {
  return -1;
}

void wbu_driver_set_steering_angle(double steering_angle) {
  (void)steering_angle;
}

double wbu_driver_get_steering_angle(void) {
  return NAN;
}

void wbu_driver_set_cruising_speed(double speed) {
  (void)speed;
}

double wbu_driver_get_target_cruising_speed(void) {
  return NAN;
}

double wbu_driver_get_current_speed(void) {
  return NAN;
}

void wbu_driver_set_throttle(double throttle) {
  (void)throttle;
}

double wbu_driver_get_throttle(void) {
  return NAN;
}

void wbu_driver_set_brake_intensity(double intensity) {
  (void)intensity;
}

double wbu_driver_get_brake_intensity(void) {
  return NAN;
}

void wbu_driver_set_indicator(WbuDriverIndicatorState state) {
  (void)state;
}

void wbu_driver_set_hazard_flashers(bool state) {
  (void)state;
}

WbuDriverIndicatorState wbu_driver_get_indicator(void) {
  return OFF;
}

bool wbu_driver_get_hazard_flashers(void) {
  return false;
}

void wbu_driver_set_dipped_beams(bool state) {
  (void)state;
}

void wbu_driver_set_antifog_lights(bool state) {
  (void)state;
}

bool wbu_driver_get_dipped_beams(void) {
  return false;
}

bool wbu_driver_get_antifog_lights(void) {
  return false;
}

double wbu_driver_get_rpm(void) {
  return NAN;
}

int wbu_driver_get_gear(void) {
  return 0;
}

void wbu_driver_set_gear(int gear) {
  (void)gear;
}

int wbu_driver_get_gear_number(void) {
  return 0;
}

WbuDriverControlMode wbu_driver_get_control_mode(void) {
  return UNDEFINED_CONTROL_MODE;
}

void wbu_driver_set_wiper_mode(WbuDriverWiperMode mode) {
  (void)mode;
}

WbuDriverWiperMode wbu_driver_get_wiper_mode(void) {
  return DOWN;
}

void wbu_driver_set_brake(double brake) {
  (void)brake;
}

double wbu_driver_get_brake(void) {
  return NAN;
}

void wbu_driver_set_wipers_mode(wbu_wipers_mode mode) {
  (void)mode;
}

wbu_wipers_mode wbu_driver_get_wipers_mode(void) {
  return DOWN;
}

/* ------------------------------------------------------------------ car */
void wbu_car_init(void) {
  refuse("wbu_car_init");
}

void wbu_car_cleanup(void) {
}

WbuCarType wbu_car_get_type(void) {
  return WBU_CAR_TRACTION;
}

WbuCarEngineType wbu_car_get_engine_type(void) {
  return WBU_CAR_COMBUSTION_ENGINE;
}

void wbu_car_set_indicator_period(double period) {
  (void)period;
}

double wbu_car_get_indicator_period(void) {
  return NAN;
}

bool wbu_car_get_backwards_lights(void) {
  return false;
}

bool wbu_car_get_brake_lights(void) {
  return false;
}

double wbu_car_get_track_front(void) {
  return NAN;
}

double wbu_car_get_track_rear(void) {
  return NAN;
}

double wbu_car_get_wheelbase(void) {
  return NAN;
}

double wbu_car_get_front_wheel_radius(void) {
  return NAN;
}

double wbu_car_get_rear_wheel_radius(void) {
  return NAN;
}

double wbu_car_get_wheel_encoder(WbuCarWheelIndex wheel_index) {
  (void)wheel_index;
  return NAN;
}

double wbu_car_get_wheel_speed(WbuCarWheelIndex wheel_index) {
  (void)wheel_index;
  return NAN;
}

void wbu_car_set_left_steering_angle(double angle) {
  (void)angle;
}

void wbu_car_set_right_steering_angle(double angle) {
  (void)angle;
}

double wbu_car_get_right_steering_angle(void) {
  return NAN;
}

double wbu_car_get_left_steering_angle(void) {
  return NAN;
}

void wbu_car_enable_limited_slip_differential(bool enable) {
  (void)enable;
}

void wbu_car_enable_indicator_auto_disabling(bool enable) {
  (void)enable;
}
