// Sensorium C++ controller layer: RotationalMotor (a Motor; see Motor.hpp).
#ifndef WEBOTS_ROTATIONALMOTOR_HPP
#define WEBOTS_ROTATIONALMOTOR_HPP

#include <webots/Motor.hpp>

namespace webots {

class RotationalMotor : public Motor {
public:
  explicit RotationalMotor(WbDeviceTag tag) : Motor(tag) {}
  explicit RotationalMotor(const std::string &name) : Motor(name) {}  // Webots: prefer Robot::getDevice
};

}  // namespace webots

#endif
