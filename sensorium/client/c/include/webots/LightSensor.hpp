// Sensorium C++ controller layer: LightSensor.
#ifndef WEBOTS_LIGHT_SENSOR_HPP
#define WEBOTS_LIGHT_SENSOR_HPP

#include <webots/Device.hpp>
#include <webots/light_sensor.h>

namespace webots {

class LightSensor : public Device {
public:
  explicit LightSensor(WbDeviceTag tag) : Device(tag) {}
  explicit LightSensor(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void enable(int samplingPeriod) { wb_light_sensor_enable(tag_, samplingPeriod); }
  void disable() { wb_light_sensor_disable(tag_); }
  int getSamplingPeriod() const { return wb_light_sensor_get_sampling_period(tag_); }
  double getValue() const { return wb_light_sensor_get_value(tag_); }
  int getLookupTableSize() const { return wb_light_sensor_get_lookup_table_size(tag_); }
  const double *getLookupTable() const { return wb_light_sensor_get_lookup_table(tag_); }
};

}  // namespace webots

#endif
