// Sensorium C++ controller layer: DistanceSensor.
#ifndef WEBOTS_DISTANCE_SENSOR_HPP
#define WEBOTS_DISTANCE_SENSOR_HPP

#include <webots/Device.hpp>
#include <webots/distance_sensor.h>

namespace webots {

class DistanceSensor : public Device {
public:
  enum Type { GENERIC = 0, INFRA_RED, SONAR, LASER };
  explicit DistanceSensor(WbDeviceTag tag) : Device(tag) {}
  explicit DistanceSensor(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void enable(int samplingPeriod) { wb_distance_sensor_enable(tag_, samplingPeriod); }
  void disable() { wb_distance_sensor_disable(tag_); }
  int getSamplingPeriod() const { return wb_distance_sensor_get_sampling_period(tag_); }
  double getValue() const { return wb_distance_sensor_get_value(tag_); }
  double getMaxValue() const { return wb_distance_sensor_get_max_value(tag_); }
  double getMinValue() const { return wb_distance_sensor_get_min_value(tag_); }
  double getAperture() const { return wb_distance_sensor_get_aperture(tag_); }
  int getLookupTableSize() const { return wb_distance_sensor_get_lookup_table_size(tag_); }
  const double *getLookupTable() const { return wb_distance_sensor_get_lookup_table(tag_); }
  Type getType() const { return static_cast<Type>(wb_distance_sensor_get_type(tag_)); }
};

}  // namespace webots

#endif
