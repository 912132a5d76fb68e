// Sensorium C++ controller layer: Compass (Webots' C++ names over the wb_compass_* functions).
#ifndef WEBOTS_COMPASS_HPP
#define WEBOTS_COMPASS_HPP

#include <string>

#include <webots/Device.hpp>
#include <webots/compass.h>

namespace webots {

class Compass : public Device {
public:
  explicit Compass(WbDeviceTag tag) : Device(tag) {}
  explicit Compass(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void enable(int samplingPeriod) { wb_compass_enable(tag_, samplingPeriod); }
  void disable() { wb_compass_disable(tag_); }
  int getSamplingPeriod() const { return wb_compass_get_sampling_period(tag_); }
  const double *getValues() const { return wb_compass_get_values(tag_); }
  int getLookupTableSize() const { return wb_compass_get_lookup_table_size(tag_); }
  const double *getLookupTable() const { return wb_compass_get_lookup_table(tag_); }
};

}  // namespace webots

#endif
