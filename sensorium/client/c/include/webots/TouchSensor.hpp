// Sensorium C++ controller layer: TouchSensor (Webots' C++ names over the wb_touch_sensor_* functions).
#ifndef WEBOTS_TOUCH_SENSOR_HPP
#define WEBOTS_TOUCH_SENSOR_HPP

#include <string>

#include <webots/Device.hpp>
#include <webots/touch_sensor.h>

namespace webots {

class TouchSensor : public Device {
public:
  enum Type { BUMPER = WB_TOUCH_SENSOR_BUMPER, FORCE = WB_TOUCH_SENSOR_FORCE, FORCE3D = WB_TOUCH_SENSOR_FORCE3D };
  explicit TouchSensor(WbDeviceTag tag) : Device(tag) {}
  explicit TouchSensor(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void enable(int samplingPeriod) { wb_touch_sensor_enable(tag_, samplingPeriod); }
  void disable() { wb_touch_sensor_disable(tag_); }
  int getSamplingPeriod() const { return wb_touch_sensor_get_sampling_period(tag_); }
  double getValue() const { return wb_touch_sensor_get_value(tag_); }
  const double *getValues() const { return wb_touch_sensor_get_values(tag_); }
  Type getType() const { return static_cast<Type>(wb_touch_sensor_get_type(tag_)); }
  int getLookupTableSize() const { return wb_touch_sensor_get_lookup_table_size(tag_); }
  const double *getLookupTable() const { return wb_touch_sensor_get_lookup_table(tag_); }
};

}  // namespace webots

#endif
