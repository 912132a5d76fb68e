// Sensorium C++ controller layer: Motor and PositionSensor (they refer to each other through the
// Robot's device table, so both live here; PositionSensor.hpp includes this header).
#ifndef WEBOTS_MOTOR_HPP
#define WEBOTS_MOTOR_HPP

#include <webots/Device.hpp>
#include <webots/motor.h>
#include <webots/position_sensor.h>

namespace webots {

class PositionSensor;
class Motor;
namespace internal {
Device *deviceFromTag(WbDeviceTag tag);  // defined in Robot.hpp
}

class Motor : public Device {
public:
  enum Type { ROTATIONAL = WB_ROTATIONAL, LINEAR = WB_LINEAR };
  explicit Motor(WbDeviceTag tag) : Device(tag) {}
  void setPosition(double position) { wb_motor_set_position(tag_, position); }
  void setVelocity(double velocity) { wb_motor_set_velocity(tag_, velocity); }
  double getTargetPosition() const { return wb_motor_get_target_position(tag_); }
  double getMinPosition() const { return wb_motor_get_min_position(tag_); }
  double getMaxPosition() const { return wb_motor_get_max_position(tag_); }
  double getVelocity() const { return wb_motor_get_velocity(tag_); }
  double getMaxVelocity() const { return wb_motor_get_max_velocity(tag_); }
  Type getType() const { return static_cast<Type>(wb_motor_get_type(tag_)); }
  inline PositionSensor *getPositionSensor() const;
  Device *getBrake() const { return 0; }
};

class PositionSensor : public Device {
public:
  enum Type { ROTATIONAL = WB_ROTATIONAL, LINEAR = WB_LINEAR };
  explicit PositionSensor(WbDeviceTag tag) : Device(tag) {}
  void enable(int samplingPeriod) { wb_position_sensor_enable(tag_, samplingPeriod); }
  void disable() { wb_position_sensor_disable(tag_); }
  int getSamplingPeriod() const { return wb_position_sensor_get_sampling_period(tag_); }
  double getValue() const { return wb_position_sensor_get_value(tag_); }
  Type getType() const { return static_cast<Type>(wb_position_sensor_get_type(tag_)); }
  Motor *getMotor() const { return static_cast<Motor *>(internal::deviceFromTag(wb_position_sensor_get_motor(tag_))); }
  Device *getBrake() const { return 0; }
};

inline PositionSensor *Motor::getPositionSensor() const {
  return static_cast<PositionSensor *>(internal::deviceFromTag(wb_motor_get_position_sensor(tag_)));
}

}  // namespace webots

#endif
