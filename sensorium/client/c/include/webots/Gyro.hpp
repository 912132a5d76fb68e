// Sensorium C++ controller layer: Gyro (Webots' C++ names over the wb_gyro_* functions).
#ifndef WEBOTS_GYRO_HPP
#define WEBOTS_GYRO_HPP

#include <string>

#include <webots/Device.hpp>
#include <webots/gyro.h>

namespace webots {

class Gyro : public Device {
public:
  explicit Gyro(WbDeviceTag tag) : Device(tag) {}
  explicit Gyro(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void enable(int samplingPeriod) { wb_gyro_enable(tag_, samplingPeriod); }
  void disable() { wb_gyro_disable(tag_); }
  int getSamplingPeriod() const { return wb_gyro_get_sampling_period(tag_); }
  const double *getValues() const { return wb_gyro_get_values(tag_); }
  int getLookupTableSize() const { return wb_gyro_get_lookup_table_size(tag_); }
  const double *getLookupTable() const { return wb_gyro_get_lookup_table(tag_); }
};

}  // namespace webots

#endif
