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
class Brake;
namespace internal {
Device *deviceFromTag(WbDeviceTag tag);  // defined in Robot.hpp
}

class Motor : public Device {
public:
  enum Type { ROTATIONAL = WB_ROTATIONAL, LINEAR = WB_LINEAR };
  explicit Motor(WbDeviceTag tag) : Device(tag) {}
  explicit Motor(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void setPosition(double position) { wb_motor_set_position(tag_, position); }
  void setVelocity(double velocity) { wb_motor_set_velocity(tag_, velocity); }
  double getTargetPosition() const { return wb_motor_get_target_position(tag_); }
  double getMinPosition() const { return wb_motor_get_min_position(tag_); }
  double getMaxPosition() const { return wb_motor_get_max_position(tag_); }
  double getVelocity() const { return wb_motor_get_velocity(tag_); }
  double getMaxVelocity() const { return wb_motor_get_max_velocity(tag_); }
  Type getType() const { return static_cast<Type>(wb_motor_get_type(tag_)); }
  inline PositionSensor *getPositionSensor() const;
  inline Brake *getBrake() const;
  // what needs physics: ignored, NaN (kinematic wheels; see webots/motor.h)
  void setAcceleration(double acceleration) { wb_motor_set_acceleration(tag_, acceleration); }
  double getAcceleration() const { return wb_motor_get_acceleration(tag_); }
  void setAvailableForce(double force) { wb_motor_set_available_force(tag_, force); }
  double getAvailableForce() const { return wb_motor_get_available_force(tag_); }
  double getMaxForce() const { return wb_motor_get_max_force(tag_); }
  void setAvailableTorque(double torque) { wb_motor_set_available_torque(tag_, torque); }
  double getAvailableTorque() const { return wb_motor_get_available_torque(tag_); }
  double getMaxTorque() const { return wb_motor_get_max_torque(tag_); }
  void setControlPID(double p, double i, double d) { wb_motor_set_control_pid(tag_, p, i, d); }
  double getMultiplier() const { return wb_motor_get_multiplier(tag_); }
  void setForce(double force) { wb_motor_set_force(tag_, force); }
  void setTorque(double torque) { wb_motor_set_torque(tag_, torque); }
  void enableForceFeedback(int samplingPeriod) { wb_motor_enable_force_feedback(tag_, samplingPeriod); }
  void disableForceFeedback() { wb_motor_disable_force_feedback(tag_); }
  int getForceFeedbackSamplingPeriod() const { return wb_motor_get_force_feedback_sampling_period(tag_); }
  double getForceFeedback() const { return wb_motor_get_force_feedback(tag_); }
  void enableTorqueFeedback(int samplingPeriod) { wb_motor_enable_torque_feedback(tag_, samplingPeriod); }
  void disableTorqueFeedback() { wb_motor_disable_torque_feedback(tag_); }
  int getTorqueFeedbackSamplingPeriod() const { return wb_motor_get_torque_feedback_sampling_period(tag_); }
  double getTorqueFeedback() const { return wb_motor_get_torque_feedback(tag_); }
};

class PositionSensor : public Device {
public:
  enum Type { ROTATIONAL = WB_ROTATIONAL, LINEAR = WB_LINEAR };
  enum { ANGULAR = WB_ROTATIONAL };  // Webots' older name, kept since R2018b
  explicit PositionSensor(WbDeviceTag tag) : Device(tag) {}
  explicit PositionSensor(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void enable(int samplingPeriod) { wb_position_sensor_enable(tag_, samplingPeriod); }
  void disable() { wb_position_sensor_disable(tag_); }
  int getSamplingPeriod() const { return wb_position_sensor_get_sampling_period(tag_); }
  double getValue() const { return wb_position_sensor_get_value(tag_); }
  Type getType() const { return static_cast<Type>(wb_position_sensor_get_type(tag_)); }
  Motor *getMotor() const { return static_cast<Motor *>(internal::deviceFromTag(wb_position_sensor_get_motor(tag_))); }
  inline Brake *getBrake() const;
};

inline PositionSensor *Motor::getPositionSensor() const {
  return static_cast<PositionSensor *>(internal::deviceFromTag(wb_motor_get_position_sensor(tag_)));
}

}  // namespace webots

#include <webots/Brake.hpp>  // Brake's class is complete below (whichever of the two headers came first)

namespace webots {
inline Brake *Motor::getBrake() const { return static_cast<Brake *>(internal::deviceFromTag(wb_motor_get_brake(tag_))); }
inline Brake *PositionSensor::getBrake() const {
  return static_cast<Brake *>(internal::deviceFromTag(wb_position_sensor_get_brake(tag_)));
}
}  // namespace webots

#endif
