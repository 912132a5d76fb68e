// Sensorium C++ controller layer: Brake (Webots' C++ names over the wb_brake_* functions).
#ifndef WEBOTS_BRAKE_HPP
#define WEBOTS_BRAKE_HPP

#include <string>

#include <webots/Device.hpp>
#include <webots/brake.h>

namespace webots {

namespace internal {
Device *deviceFromTag(WbDeviceTag tag);  // defined in Robot.hpp
}

class Brake : public Device {
public:
  enum Type { ROTATIONAL = WB_ROTATIONAL, LINEAR = WB_LINEAR };
  explicit Brake(WbDeviceTag tag) : Device(tag) {}
  void setDampingConstant(double dampingConstant) { wb_brake_set_damping_constant(tag_, dampingConstant); }
  Type getType() const { return static_cast<Type>(wb_brake_get_type(tag_)); }
  Device *getMotor() const { return internal::deviceFromTag(wb_brake_get_motor(tag_)); }
  Device *getPositionSensor() const { return internal::deviceFromTag(wb_brake_get_position_sensor(tag_)); }
};

}  // namespace webots

#endif
