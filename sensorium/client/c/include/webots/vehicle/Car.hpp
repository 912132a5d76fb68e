// Sensorium C++ controller layer: Car over vehicle/car.h (see Driver.hpp): constructing a Car on a
// robot that is not a car prints wbu_car_init()'s one line and ends the process with status 1.
#ifndef WEBOTS_CAR_HPP
#define WEBOTS_CAR_HPP

#include <webots/vehicle/Driver.hpp>
#include <webots/vehicle/car.h>

namespace webots {

class Car : public Driver {
public:
  typedef enum { TRACTION = WBU_CAR_TRACTION, PROPULSION = WBU_CAR_PROPULSION, FOUR_BY_FOUR = WBU_CAR_FOUR_BY_FOUR } Type;
  typedef enum {
    COMBUSTION_ENGINE = WBU_CAR_COMBUSTION_ENGINE,
    ELECTRIC_ENGINE = WBU_CAR_ELECTRIC_ENGINE,
    PARALLEL_HYBRID_ENGINE = WBU_CAR_PARALLEL_HYBRID_ENGINE,
    POWER_SPLIT_HYBRID_ENGINE = WBU_CAR_POWER_SPLIT_HYBRID_ENGINE
  } EngineType;
  typedef enum {
    WHEEL_FRONT_RIGHT = WBU_CAR_WHEEL_FRONT_RIGHT,
    WHEEL_FRONT_LEFT = WBU_CAR_WHEEL_FRONT_LEFT,
    WHEEL_REAR_RIGHT = WBU_CAR_WHEEL_REAR_RIGHT,
    WHEEL_REAR_LEFT = WBU_CAR_WHEEL_REAR_LEFT,
    WHEEL_NB = WBU_CAR_WHEEL_NB
  } WheelIndex;

  Car() : Driver(wbu_car_init) {}
  virtual ~Car() { wbu_car_cleanup(); }

  Type getType() { return static_cast<Type>(wbu_car_get_type()); }
  EngineType getEngineType() { return static_cast<EngineType>(wbu_car_get_engine_type()); }
  void setIndicatorPeriod(double period) { wbu_car_set_indicator_period(period); }
  double getIndicatorPeriod() { return wbu_car_get_indicator_period(); }
  bool getBackwardsLights() { return wbu_car_get_backwards_lights(); }
  bool getBrakeLights() { return wbu_car_get_brake_lights(); }
  double getTrackFront() { return wbu_car_get_track_front(); }
  double getTrackRear() { return wbu_car_get_track_rear(); }
  double getWheelbase() { return wbu_car_get_wheelbase(); }
  double getFrontWheelRadius() { return wbu_car_get_front_wheel_radius(); }
  double getRearWheelRadius() { return wbu_car_get_rear_wheel_radius(); }
  double getWheelEncoder(WheelIndex wheel) { return wbu_car_get_wheel_encoder(static_cast<WbuCarWheelIndex>(wheel)); }
  double getWheelSpeed(WheelIndex wheel) { return wbu_car_get_wheel_speed(static_cast<WbuCarWheelIndex>(wheel)); }
  void setLeftSteeringAngle(double angle) { wbu_car_set_left_steering_angle(angle); }
  void setRightSteeringAngle(double angle) { wbu_car_set_right_steering_angle(angle); }
  double getRightSteeringAngle() { return wbu_car_get_right_steering_angle(); }
  double getLeftSteeringAngle() { return wbu_car_get_left_steering_angle(); }
  void enableLimitedSlipDifferential(bool enable) { wbu_car_enable_limited_slip_differential(enable); }
  void enableIndicatorAutoDisabling(bool enable) { wbu_car_enable_indicator_auto_disabling(enable); }
};

}  // namespace webots

#endif  // WEBOTS_CAR_HPP
