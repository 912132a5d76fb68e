// Sensorium C++ controller layer: Accelerometer (Webots' C++ names over the wb_accelerometer_* functions).
#ifndef WEBOTS_ACCELEROMETER_HPP
#define WEBOTS_ACCELEROMETER_HPP

#include <string>

#include <webots/Device.hpp>
#include <webots/accelerometer.h>

namespace webots {

class Accelerometer : public Device {
public:
  explicit Accelerometer(WbDeviceTag tag) : Device(tag) {}
  explicit Accelerometer(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void enable(int samplingPeriod) { wb_accelerometer_enable(tag_, samplingPeriod); }
  void disable() { wb_accelerometer_disable(tag_); }
  int getSamplingPeriod() const { return wb_accelerometer_get_sampling_period(tag_); }
  const double *getValues() const { return wb_accelerometer_get_values(tag_); }
  int getLookupTableSize() const { return wb_accelerometer_get_lookup_table_size(tag_); }
  const double *getLookupTable() const { return wb_accelerometer_get_lookup_table(tag_); }
};

}  // namespace webots

#endif
