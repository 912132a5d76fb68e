// Sensorium C++ controller layer: Altimeter (Webots' C++ names over the wb_altimeter_* functions).
#ifndef WEBOTS_ALTIMETER_HPP
#define WEBOTS_ALTIMETER_HPP

#include <string>

#include <webots/Device.hpp>
#include <webots/altimeter.h>

namespace webots {

class Altimeter : public Device {
public:
  explicit Altimeter(WbDeviceTag tag) : Device(tag) {}
  explicit Altimeter(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void enable(int samplingPeriod) { wb_altimeter_enable(tag_, samplingPeriod); }
  void disable() { wb_altimeter_disable(tag_); }
  int getSamplingPeriod() const { return wb_altimeter_get_sampling_period(tag_); }
  double getValue() const { return wb_altimeter_get_value(tag_); }
};

}  // namespace webots

#endif
