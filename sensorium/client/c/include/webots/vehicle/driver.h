/* Sensorium C controller library: Webots' driver library (vehicle/driver.h, for the Car PROTO and its
 * descendants) over a car-like robot's motors (the world's ackermann_drive; src/vehicle.c): steering
 * angle and cruising speed as Webots computes them; the brake intensity, indicators and lights kept
 * and answered as Webots' library keeps them. No engine, gearbox, torque control or wipers: those
 * functions print one line the first time and answer Webots' "no value". wbu_driver_init() on
 * a robot without an ackermann_drive prints one line and exits with status 1. Before init every
 * function answers "no value" (NaN, 0, false, the first enumerator; wbu_driver_step(): -1). */
#ifndef WBU_DRIVER_H
#define WBU_DRIVER_H

#include "../types.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum { OFF, RIGHT, LEFT } WbuDriverIndicatorState;
typedef enum { UNDEFINED_CONTROL_MODE = -1, SPEED = 0, TORQUE } WbuDriverControlMode;
typedef enum { DOWN, SLOW, NORMAL, FAST } WbuDriverWiperMode;

bool wbu_driver_initialization_is_possible(void);

void wbu_driver_init(void);
void wbu_driver_cleanup(void);
int wbu_driver_step(void);

/* steering angle (rad): positive turns right */
void wbu_driver_set_steering_angle(double steering_angle);
double wbu_driver_get_steering_angle(void);

void wbu_driver_set_cruising_speed(double speed);
double wbu_driver_get_target_cruising_speed(void);
double wbu_driver_get_current_speed(void);

void wbu_driver_set_throttle(double throttle);
double wbu_driver_get_throttle(void);

void wbu_driver_set_brake_intensity(double intensity);
double wbu_driver_get_brake_intensity(void);

void wbu_driver_set_indicator(WbuDriverIndicatorState state);
void wbu_driver_set_hazard_flashers(bool state);
WbuDriverIndicatorState wbu_driver_get_indicator(void);
bool wbu_driver_get_hazard_flashers(void);

void wbu_driver_set_dipped_beams(bool state);
void wbu_driver_set_antifog_lights(bool state);
bool wbu_driver_get_dipped_beams(void);
bool wbu_driver_get_antifog_lights(void);

double wbu_driver_get_rpm(void);
int wbu_driver_get_gear(void);
void wbu_driver_set_gear(int gear);
int wbu_driver_get_gear_number(void);
WbuDriverControlMode wbu_driver_get_control_mode(void);

void wbu_driver_set_wiper_mode(WbuDriverWiperMode mode);
WbuDriverWiperMode wbu_driver_get_wiper_mode(void);

/* Webots' older names, kept as Webots keeps them */
void wbu_driver_set_brake(double brake) WB_DEPRECATED;
double wbu_driver_get_brake(void) WB_DEPRECATED;
typedef WbuDriverWiperMode wbu_wipers_mode;
typedef WbuDriverIndicatorState wbu_indicator_state;
typedef WbuDriverControlMode wbu_control_mode;
void wbu_driver_set_wipers_mode(wbu_wipers_mode mode) WB_DEPRECATED;
wbu_wipers_mode wbu_driver_get_wipers_mode(void) WB_DEPRECATED;

#ifdef __cplusplus
}
#endif

#endif /* WBU_DRIVER_H */
