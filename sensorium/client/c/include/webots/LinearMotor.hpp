// Sensorium C++ controller layer: LinearMotor (a Motor; see Motor.hpp).
#ifndef WEBOTS_LINEARMOTOR_HPP
#define WEBOTS_LINEARMOTOR_HPP

#include <webots/Motor.hpp>

namespace webots {

class LinearMotor : public Motor {
public:
  explicit LinearMotor(WbDeviceTag tag) : Motor(tag) {}
  explicit LinearMotor(const std::string &name) : Motor(name) {}  // Webots: prefer Robot::getDevice
};

}  // namespace webots

#endif
