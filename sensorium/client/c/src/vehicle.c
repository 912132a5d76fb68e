/* Sensorium C controller library: Webots' car and driver libraries (vehicle/car.h, vehicle/driver.h)
 * over a car-like robot's ordinary motors. The car's geometry comes with the attach reply (the
 * world's ackermann_drive; Webots reads a Car's customData). wbu_driver_set_steering_angle() turns
 * the two steering motors to Webots' Ackermann angles, wbu_driver_set_cruising_speed() sets the
 * driven wheels' velocities by Webots' geometric differentials. The brake intensity, indicators,
 * hazard flashers, lights and the car's flags are the controller's commands, kept and answered as
 * Webots' library keeps them (the car's LEDs of Webots' names switched for them); the engine type
 * is the world's; the interior's motors Webots' library turns (steering wheel, speedometer needle,
 * wipers) are turned as it turns them. The car is kinematic (no engine, gearbox or torque control):
 * those functions print one line the first time and answer Webots' "no value". wbu_car_init()/
 * wbu_driver_init() on a robot without an ackermann_drive print one line and end the controller with
 * status 1. Before init every function answers "no value". */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/led.h>
#include <webots/motor.h>
#include <webots/position_sensor.h>
#include <webots/robot.h>
#include <webots/vehicle/car.h>
#include <webots/vehicle/driver.h>

#include "internal.h"

static struct {
  bool ready;                  /* wbu_car_init() done */
  const sn_car *geo;           /* the robot's drive (in its sn_robot) */
  WbDeviceTag steer[2];        /* right, left */
  WbDeviceTag steer_sensor[2]; /* 0: none */
  WbDeviceTag wheel[4];        /* Webots' order: front right, front left, rear right, rear left; 0: no motor */
  WbDeviceTag wheel_sensor[4]; /* right_front_sensor, ... (Webots' names); 0: none */
  double angle, right_angle, left_angle, cruising;
  WbuDriverControlMode mode;
  /* the controller's own commands Webots' library keeps, and the LEDs it switches for them */
  double brake, indicator_angle, indicator_period;
  WbuDriverIndicatorState indicator;
  bool hazard, dipped, antifog, backwards, limited_slip, auto_disabling;
  double free_last[4], free_speed[4]; /* a free wheel's encoder at the last driver step (NaN: none yet), its speed */
  WbDeviceTag lights[9]; /* LIGHTS' order; 0: the car has none */
  int lit[9];            /* what each was last set to (-1: never) */
  /* the interior's motors Webots' library turns (0: the car has none) and the wipers' mode */
  WbDeviceTag steering_wheel, speed_needle, wipers[2], wiper_sensor;
  WbuDriverWiperMode wiper_mode;
} g_car;

/* The LEDs Webots' car library switches when the car has them (Webots' VehicleLights names). */
enum { FRONT, ANTIFOG, RIGHT_IND, LEFT_IND, REAR, BACKWARDS, BRAKE, IN_RIGHT_IND, IN_LEFT_IND };
static const char *const LIGHTS[9] = {"front_lights",     "antifog_lights", "right_indicators",
                                      "left_indicators",  "rear_lights",    "backwards_lights",
                                      "brake_lights",     "interior_right_indicators", "interior_left_indicators"};
#define INDICATOR_PERIOD 0.34          /* s: Webots' default */
#define AUTO_DISABLING_THRESHOLD 0.1   /* rad: Webots' driver library's */
#define STEERING_WHEEL_RATIO 10.0      /* the steering wheel motor's position per radian of steering (Webots') */
#define SPEEDOMETER_MAX 220.0          /* km/h at the speed needle's maxPosition (Webots' speedometer texture) */

/* Switch the car's LED (and an indicator's interior one), if it has it. */
static void light(int which, bool on) {
  int both[2] = {which, which == RIGHT_IND ? IN_RIGHT_IND : which == LEFT_IND ? IN_LEFT_IND : -1};
  for (int k = 0; k < 2; k++) {
    int i = both[k];
    if (i < 0 || !g_car.lights[i] || g_car.lit[i] == (int)on)
      continue;
    wb_led_set(g_car.lights[i], on);
    g_car.lit[i] = on;
  }
}

static void unmodelled(const char *func, bool *said) {
  if (*said)
    return;
  *said = true;
  fprintf(stderr,
          "Warning: %s(): not simulated (Sensorium's car is kinematic, a bicycle model of its steering and wheel "
          "motors: no engine, gearbox or torque control); it answers Webots' \"no value\".\n",
          func);
  fflush(stderr);
}
#define UNMODELLED()             \
  do {                           \
    static bool said_;           \
    if (g_car.ready)             \
      unmodelled(__func__, &said_); \
  } while (0)

/* A device of the robot by name, 0 when it has none (no error line: Webots' car library looks its
 * optional devices up quietly). */
static WbDeviceTag quiet_device(const sn_robot *rb, const char *name, sn_kind kind) {
  for (int i = 0; i < rb->n_devices; i++)
    if (rb->devices[i].kind == kind && rb->devices[i].simulated && strcmp(rb->devices[i].name, name) == 0)
      return rb->devices[i].tag;
  return 0;
}

/* A number in a warning line (NaN of either sign as NaN, as the Python library prints it). */
/* One warning line for a number a function refuses ("NaN" as Python spells it); ``then`` ends the line. */
static void refused(const char *function, const char *argument, double x, const char *then) {
  char text[32];
  if (isnan(x))
    snprintf(text, sizeof text, "NaN");
  else
    snprintf(text, sizeof text, "%g", x);
  fprintf(stderr, "Warning: %s() called with an invalid '%s' argument (%s)%s\n", function, argument, text, then);
  fflush(stderr);
}

/* A differential's share of the right wheel from its wheels' turn radii; 0.5 (straight on) where an
 * angle too small for a double makes them infinite. */
static double share_of(double r, double l) {
  double ratio = isfinite(r) && isfinite(l) ? r / (l + r) : NAN;
  return isfinite(ratio) ? ratio : 0.5;
}

static void ackermann(double angle, double *right, double *left) {
  if (angle == 0.0) {
    *right = *left = 0.0;
    return;
  }
  double cot = 1.0 / tan(angle), half = g_car.geo->track_front / (2.0 * g_car.geo->wheelbase);
  *right = atan(1.0 / (cot - half));
  *left = atan(1.0 / (cot + half));
}

/* ------------------------------------------------------------------ car */
/* wbu_car_init() and wbu_driver_init() (func: which one, for the refusal line). */
static void car_init(const char *func) {
  if (g_car.ready)
    return;
  wb_robot_init();
  sn_robot *rb = sn_robot_get(func);
  if (!rb->car.present) {
    fprintf(stderr,
            "Error: %s(): robot '%s' has no ackermann_drive: Sensorium's vehicle library drives a car-like robot whose "
            "world entry has one (README \"World files\"; a .wbt car is mapped when its steering and wheel joints "
            "are a car's).\n",
            func, sn_shown(rb->name));
    fflush(stderr);
    exit(1);
  }
  g_car.geo = &rb->car;
  static const char *const sensors[4] = {"right_front_sensor", "left_front_sensor", "right_rear_sensor",
                                         "left_rear_sensor"};
  int step = rb->basic_time_step;
  for (int i = 0; i < 2; i++) {
    g_car.steer[i] = quiet_device(rb, rb->car.motors[i], SN_MOTOR);
    g_car.steer_sensor[i] = g_car.steer[i] ? wb_motor_get_position_sensor(g_car.steer[i]) : 0;
    if (g_car.steer_sensor[i])
      wb_position_sensor_enable(g_car.steer_sensor[i], step);
  }
  for (int i = 0; i < 4; i++) {
    bool front = i < 2;
    bool driven = rb->car.type == WBU_CAR_FOUR_BY_FOUR || (front ? rb->car.type == WBU_CAR_TRACTION
                                                                 : rb->car.type == WBU_CAR_PROPULSION);
    g_car.wheel[i] = driven ? quiet_device(rb, rb->car.motors[2 + i], SN_MOTOR) : 0;
    g_car.wheel_sensor[i] = quiet_device(rb, sensors[i], SN_POSITION);
    if (g_car.wheel_sensor[i])
      wb_position_sensor_enable(g_car.wheel_sensor[i], step);
    if (g_car.wheel[i]) { /* velocity control at rest (Webots' wbu_car_init) */
      wb_motor_set_position(g_car.wheel[i], INFINITY);
      wb_motor_set_velocity(g_car.wheel[i], 0.0);
    }
  }
  for (int i = 0; i < 4; i++) {
    g_car.free_last[i] = NAN;
    g_car.free_speed[i] = 0.0;
  }
  for (int i = 0; i < 9; i++) {
    g_car.lights[i] = quiet_device(rb, LIGHTS[i], SN_LED);
    g_car.lit[i] = -1;
  }
  g_car.steering_wheel = quiet_device(rb, "steering_wheel_motor", SN_MOTOR);
  g_car.speed_needle = quiet_device(rb, "speed_needle_motor", SN_MOTOR);
  g_car.wipers[0] = quiet_device(rb, "right_wiper_motor", SN_MOTOR);
  g_car.wipers[1] = quiet_device(rb, "left_wiper_motor", SN_MOTOR);
  g_car.wiper_sensor = quiet_device(rb, "wiper_sensor", SN_POSITION);
  if (g_car.wiper_sensor)
    wb_position_sensor_enable(g_car.wiper_sensor, step);
  g_car.wiper_mode = DOWN;
  g_car.indicator_period = INDICATOR_PERIOD;
  g_car.limited_slip = g_car.auto_disabling = true;
  g_car.mode = UNDEFINED_CONTROL_MODE;
  g_car.ready = true;
}

void wbu_car_init(void) {
  car_init("wbu_car_init");
}

void wbu_car_cleanup(void) {
  memset(&g_car, 0, sizeof g_car);
}

WbuCarType wbu_car_get_type(void) {
  return g_car.ready ? (WbuCarType)g_car.geo->type : WBU_CAR_TRACTION;
}

/* The world's engine type (a Webots Car's engineType); no engine runs here. */
WbuCarEngineType wbu_car_get_engine_type(void) {
  return g_car.ready ? (WbuCarEngineType)g_car.geo->engine : WBU_CAR_COMBUSTION_ENGINE;
}

void wbu_car_set_indicator_period(double period) {
  if (!g_car.ready)
    return;
  if (!(isfinite(period) && period > 0.0)) {
    refused("wbu_car_set_indicator_period", "period", period, ": it must be a positive number of seconds; ignored.");
    return;
  }
  g_car.indicator_period = period;
}

double wbu_car_get_indicator_period(void) {
  return g_car.ready ? g_car.indicator_period : NAN;
}

/* As Webots' driver decides it at each step: on while a negative cruising speed is set (reverse). */
bool wbu_car_get_backwards_lights(void) {
  return g_car.ready && g_car.backwards;
}

/* On while the brake intensity is above 0. */
bool wbu_car_get_brake_lights(void) {
  return g_car.ready && g_car.brake > 0.0;
}

double wbu_car_get_track_front(void) {
  return g_car.ready ? g_car.geo->track_front : NAN;
}

double wbu_car_get_track_rear(void) {
  return g_car.ready ? g_car.geo->track_rear : NAN;
}

double wbu_car_get_wheelbase(void) {
  return g_car.ready ? g_car.geo->wheelbase : NAN;
}

double wbu_car_get_front_wheel_radius(void) {
  return g_car.ready ? g_car.geo->front_wheel_radius : NAN;
}

double wbu_car_get_rear_wheel_radius(void) {
  return g_car.ready ? g_car.geo->rear_wheel_radius : NAN;
}

double wbu_car_get_wheel_encoder(WbuCarWheelIndex wheel_index) {
  if (!g_car.ready || (int)wheel_index < 0 || (int)wheel_index >= 4 || !g_car.wheel_sensor[wheel_index])
    return NAN;
  return wb_position_sensor_get_value(g_car.wheel_sensor[wheel_index]);
}

/* A driven wheel's speed (rad/s): its commanded velocity, which a kinematic wheel keeps; a free wheel's,
 * as Webots' driver works it out at each step: its encoder's change over the last step (0 until it
 * has read twice); NaN with neither motor nor encoder. */
double wbu_car_get_wheel_speed(WbuCarWheelIndex wheel_index) {
  if (!g_car.ready || (int)wheel_index < 0 || (int)wheel_index >= 4)
    return NAN;
  if (!g_car.wheel[wheel_index])
    return g_car.wheel_sensor[wheel_index] ? g_car.free_speed[wheel_index] : NAN;
  return wb_motor_get_velocity(g_car.wheel[wheel_index]);
}

void wbu_car_set_left_steering_angle(double angle) {
  if (!g_car.ready)
    return;
  g_car.left_angle = angle;
  wb_motor_set_position(g_car.steer[1], g_car.geo->sign * angle);
}

void wbu_car_set_right_steering_angle(double angle) {
  if (!g_car.ready)
    return;
  g_car.right_angle = angle;
  wb_motor_set_position(g_car.steer[0], g_car.geo->sign * angle);
}

double wbu_car_get_right_steering_angle(void) {
  return g_car.ready ? g_car.right_angle : NAN;
}

double wbu_car_get_left_steering_angle(void) {
  return g_car.ready ? g_car.left_angle : NAN;
}

/* Kept (Webots' library uses it in torque control only, which a kinematic car has not). */
void wbu_car_enable_limited_slip_differential(bool enable) {
  if (g_car.ready)
    g_car.limited_slip = enable;
}

void wbu_car_enable_indicator_auto_disabling(bool enable) {
  if (g_car.ready)
    g_car.auto_disabling = enable;
}

/* ------------------------------------------------------------------ driver */
bool wbu_driver_initialization_is_possible(void) {
  return g_car.ready;
}

void wbu_driver_init(void) {
  car_init("wbu_driver_init");
}

void wbu_driver_cleanup(void) {
  wbu_car_cleanup();
}

/* Before the step, as Webots' library: the indicators' LEDs blink (on for the first half of each
 * period, by the simulated time), the wipers sweep in any mode but DOWN (up to their maxPosition from
 * their minPosition and back; SLOW only in the first second of every four), the backwards lights are
 * on while a negative cruising speed is set and the speedometer's needle shows the current speed. */
int wbu_driver_step(void) {
  if (!g_car.ready)
    return -1;
  /* Webots': on while int(t / period) is even; a quotient past a double's integers is even */
  double q = wb_robot_get_time() / g_car.indicator_period;
  bool on = isfinite(q) ? fmod(floor(q), 2.0) == 0.0 : true;
  light(RIGHT_IND, on && (g_car.hazard || g_car.indicator == RIGHT));
  light(LEFT_IND, on && (g_car.hazard || g_car.indicator == LEFT));
  if (g_car.wipers[0] && g_car.wipers[1] && g_car.wiper_sensor && g_car.wiper_mode != DOWN) {
    double at = wb_position_sensor_get_value(g_car.wiper_sensor);
    if (at == wb_motor_get_min_position(g_car.wipers[0])) /* at rest down: up */
      for (int i = 0; i < 2; i++)
        wb_motor_set_position(g_car.wipers[i], wb_motor_get_max_position(g_car.wipers[i]));
    if (at == wb_motor_get_max_position(g_car.wipers[0]) ||
        (g_car.wiper_mode == SLOW && (int)wb_robot_get_time() % 4 != 0))
      for (int i = 0; i < 2; i++)
        wb_motor_set_position(g_car.wipers[i], wb_motor_get_min_position(g_car.wipers[i]));
  }
  g_car.backwards = g_car.mode == SPEED && g_car.cruising < 0.0;
  light(BACKWARDS, g_car.backwards);
  if (g_car.speed_needle) {
    double top = wb_motor_get_max_position(g_car.speed_needle), speed = fabs(wbu_driver_get_current_speed());
    wb_motor_set_position(g_car.speed_needle, speed <= SPEEDOMETER_MAX ? speed * top / SPEEDOMETER_MAX : top);
  }
  int ms = (int)wb_robot_get_basic_time_step();
  for (int i = 0; i < 4; i++) { /* a free wheel's speed: its encoder's change since the last step */
    if (g_car.wheel[i] || !g_car.wheel_sensor[i])
      continue;
    double now = wb_position_sensor_get_value(g_car.wheel_sensor[i]), last = g_car.free_last[i];
    g_car.free_speed[i] = isnan(now) || isnan(last) ? 0.0 : 1000.0 * (now - last) / ms;
    g_car.free_last[i] = now;
  }
  return wb_robot_step(ms);
}

void wbu_driver_set_steering_angle(double steering_angle) {
  if (!g_car.ready)
    return;
  if (!isfinite(steering_angle)) {
    refused("wbu_driver_set_steering_angle", "steering_angle", steering_angle, "");
    return;
  }
  if (g_car.steering_wheel) /* Webots' library turns the steering wheel with it */
    wb_motor_set_position(g_car.steering_wheel, STEERING_WHEEL_RATIO * steering_angle);
  g_car.angle = steering_angle;
  ackermann(steering_angle, &g_car.right_angle, &g_car.left_angle);
  wb_motor_set_position(g_car.steer[0], g_car.geo->sign * g_car.right_angle);
  wb_motor_set_position(g_car.steer[1], g_car.geo->sign * g_car.left_angle);
  if (g_car.mode == SPEED) /* the differential speeds follow the new angles */
    wbu_driver_set_cruising_speed(g_car.cruising);
  if (g_car.auto_disabling && g_car.indicator != OFF) {
    /* Webots' driver: an indicator follows the steering to its furthest turn its way, and goes off
     * once the steering has come back from there by the threshold */
    double toward = g_car.indicator == RIGHT ? 1.0 : -1.0, moved = toward * (steering_angle - g_car.indicator_angle);
    if (moved > 0.0)
      g_car.indicator_angle = steering_angle;
    else if (moved <= -AUTO_DISABLING_THRESHOLD)
      g_car.indicator = OFF;
  }
}

/* The mean of the steering encoders (Webots), of the motors' targets where a steering motor has none. */
double wbu_driver_get_steering_angle(void) {
  if (!g_car.ready)
    return NAN;
  double sum = 0.0;
  for (int i = 0; i < 2; i++) {
    double v = g_car.steer_sensor[i] ? wb_position_sensor_get_value(g_car.steer_sensor[i]) : NAN;
    sum += isnan(v) ? wb_motor_get_target_position(g_car.steer[i]) : v;
  }
  return g_car.geo->sign * sum / 2.0;
}

static double ratio_front(void) {
  if (g_car.angle == 0.0)
    return 0.5;
  return share_of(g_car.geo->wheelbase / sin(g_car.right_angle), g_car.geo->wheelbase / sin(g_car.left_angle));
}

static double ratio_rear(void) {
  if (g_car.angle == 0.0)
    return 0.5;
  double c = g_car.geo->wheelbase / tan(g_car.angle);
  return share_of(c - g_car.geo->track_rear / 2, c + g_car.geo->track_rear / 2);
}

static double ratio_central(void) {
  if (g_car.angle == 0.0)
    return 0.5;
  double front = g_car.geo->wheelbase / sin(g_car.angle), rear = g_car.geo->wheelbase / tan(g_car.angle);
  double share = isfinite(front) && isfinite(rear) ? front / (front + rear) : NAN;
  return g_car.geo->rear_wheel_radius / g_car.geo->front_wheel_radius * (isfinite(share) ? share : 0.5);
}

/* Webots' geometric differentials: each driven pair shares 2 * speed by its wheels' turn radii (a
 * 4x4's central differential splits front and rear); km/h to rad/s by the wheel radius. */
void wbu_driver_set_cruising_speed(double speed) {
  if (!g_car.ready)
    return;
  if (!isfinite(speed)) {
    refused("wbu_driver_set_cruising_speed", "speed", speed, ": ignored.");
    return;
  }
  double central = g_car.geo->type == WBU_CAR_FOUR_BY_FOUR ? ratio_central() : 0.5;
  double ratios[2] = {ratio_front(), ratio_rear()};
  double shares[2] = {2 * central, 2 * (1 - central)};
  double radii[2] = {g_car.geo->front_wheel_radius, g_car.geo->rear_wheel_radius};
  for (int axle = 0; axle < 2; axle++) {
    double share = g_car.geo->type == WBU_CAR_FOUR_BY_FOUR ? shares[axle] : 1.0;
    double right = 2 * speed * ratios[axle] * share, left = 2 * speed * (1 - ratios[axle]) * share;
    if (g_car.wheel[2 * axle])
      wb_motor_set_velocity(g_car.wheel[2 * axle], right / 3.6 / radii[axle]);
    if (g_car.wheel[2 * axle + 1])
      wb_motor_set_velocity(g_car.wheel[2 * axle + 1], left / 3.6 / radii[axle]);
  }
  g_car.cruising = speed;
  g_car.mode = SPEED;
}

double wbu_driver_get_target_cruising_speed(void) {
  return g_car.ready ? g_car.cruising : NAN;
}

/* km/h from the driven wheels (Webots: from their encoders over the last step; a kinematic wheel in
 * velocity control turns exactly at its command). */
double wbu_driver_get_current_speed(void) {
  if (!g_car.ready)
    return NAN;
  double radii[2] = {g_car.geo->front_wheel_radius, g_car.geo->rear_wheel_radius}, sum = 0.0;
  int axles = 0;
  for (int axle = 0; axle < 2; axle++) {
    if (!g_car.wheel[2 * axle])
      continue;
    sum += 0.5 * (wb_motor_get_velocity(g_car.wheel[2 * axle]) + wb_motor_get_velocity(g_car.wheel[2 * axle + 1])) *
           radii[axle];
    axles++;
  }
  return axles ? 3.6 * sum / axles : 0.0;
}

void wbu_driver_set_throttle(double throttle) {
  (void)throttle;
  UNMODELLED();
}

double wbu_driver_get_throttle(void) {
  UNMODELLED();
  return NAN;
}

/* Kept and answered (clamped to [0, 1] with Webots' line; NaN: one line, ignored), the brake lights on while it is
 * above 0; it does not slow the car here (the wheels follow their speed control). */
void wbu_driver_set_brake_intensity(double intensity) {
  if (!g_car.ready)
    return;
  if (isnan(intensity)) {
    fprintf(stderr, "Warning: wbu_driver_set_brake_intensity() called with an invalid 'intensity' argument (NaN): "
                    "ignored.\n");
    fflush(stderr);
    return;
  }
  if (intensity < 0.0 || intensity > 1.0) { /* Webots' lines */
    fprintf(stderr, intensity < 0.0 ? "Warning: 'intensity' should be bigger or equal to 0, used 0 instead.\n"
                                    : "Warning: 'intensity' should be smaller or equal to 1, used 1 instead.\n");
    fflush(stderr);
    intensity = intensity < 0.0 ? 0.0 : 1.0;
  }
  g_car.brake = intensity;
  light(BRAKE, intensity > 0.0);
}

double wbu_driver_get_brake_intensity(void) {
  return g_car.ready ? g_car.brake : NAN;
}

void wbu_driver_set_indicator(WbuDriverIndicatorState state) {
  if (!g_car.ready)
    return;
  g_car.indicator = state;
  g_car.indicator_angle = g_car.angle;
}

void wbu_driver_set_hazard_flashers(bool state) {
  if (g_car.ready)
    g_car.hazard = state;
}

WbuDriverIndicatorState wbu_driver_get_indicator(void) {
  return g_car.ready ? g_car.indicator : OFF;
}

bool wbu_driver_get_hazard_flashers(void) {
  return g_car.ready && g_car.hazard;
}

/* Kept, and the front and rear lights' LEDs switched (if the car has them). */
void wbu_driver_set_dipped_beams(bool state) {
  if (!g_car.ready)
    return;
  g_car.dipped = state;
  light(FRONT, state);
  light(REAR, state);
}

void wbu_driver_set_antifog_lights(bool state) {
  if (!g_car.ready)
    return;
  g_car.antifog = state;
  light(ANTIFOG, state);
}

bool wbu_driver_get_dipped_beams(void) {
  return g_car.ready && g_car.dipped;
}

bool wbu_driver_get_antifog_lights(void) {
  return g_car.ready && g_car.antifog;
}

double wbu_driver_get_rpm(void) {
  UNMODELLED();
  return NAN;
}

int wbu_driver_get_gear(void) {
  UNMODELLED();
  return 0;
}

void wbu_driver_set_gear(int gear) {
  (void)gear;
  UNMODELLED();
}

int wbu_driver_get_gear_number(void) {
  UNMODELLED();
  return 0;
}

WbuDriverControlMode wbu_driver_get_control_mode(void) {
  return g_car.ready ? g_car.mode : UNDEFINED_CONTROL_MODE;
}

/* Kept; the car's wipers sweep at each wbu_driver_step() as Webots' library sweeps them. */
void wbu_driver_set_wiper_mode(WbuDriverWiperMode mode) {
  if (g_car.ready)
    g_car.wiper_mode = mode;
}

WbuDriverWiperMode wbu_driver_get_wiper_mode(void) {
  return g_car.ready ? g_car.wiper_mode : DOWN;
}

/* Webots' deprecated names of the brake intensity's functions. */
void wbu_driver_set_brake(double brake) {
  wbu_driver_set_brake_intensity(brake);
}

double wbu_driver_get_brake(void) {
  return wbu_driver_get_brake_intensity();
}

void wbu_driver_set_wipers_mode(wbu_wipers_mode mode) {
  wbu_driver_set_wiper_mode((WbuDriverWiperMode)mode);
}

wbu_wipers_mode wbu_driver_get_wipers_mode(void) {
  return (wbu_wipers_mode)wbu_driver_get_wiper_mode();
}
