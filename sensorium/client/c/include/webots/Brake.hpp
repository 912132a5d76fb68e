// Sensorium C++ controller layer: Brake (Webots' C++ names over the wb_brake_* functions).
#ifndef WEBOTS_BRAKE_HPP
#define WEBOTS_BRAKE_HPP

#include <string>

#include <webots/Device.hpp>
#include <webots/brake.h>

namespace webots {

class Motor;
class PositionSensor;
namespace internal {
Device *deviceFromTag(WbDeviceTag tag);  // defined in Robot.hpp
}

class Brake : public Device {
public:
  enum Type { ROTATIONAL = WB_ROTATIONAL, LINEAR = WB_LINEAR };
  enum { ANGULAR = WB_ROTATIONAL };  // Webots' older name, kept since R2018b
  explicit Brake(WbDeviceTag tag) : Device(tag) {}
  explicit Brake(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void setDampingConstant(double dampingConstant) const { wb_brake_set_damping_constant(tag_, dampingConstant); }
  Type getType() const { return static_cast<Type>(wb_brake_get_type(tag_)); }
  inline Motor *getMotor() const;
  inline PositionSensor *getPositionSensor() const;
};

}  // namespace webots

#include <webots/Motor.hpp>  // Motor's and PositionSensor's classes are complete below

namespace webots {
inline Motor *Brake::getMotor() const { return static_cast<Motor *>(internal::deviceFromTag(wb_brake_get_motor(tag_))); }
inline PositionSensor *Brake::getPositionSensor() const {
  return static_cast<PositionSensor *>(internal::deviceFromTag(wb_brake_get_position_sensor(tag_)));
}
}  // namespace webots

#endif
