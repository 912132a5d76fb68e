// Sensorium C++ controller layer: Radar (Webots' C++ names over the wb_radar_* functions).
#ifndef WEBOTS_RADAR_HPP
#define WEBOTS_RADAR_HPP

#include <string>

#include <webots/Device.hpp>
#include <webots/radar.h>

namespace webots {

typedef WbRadarTarget RadarTarget;

class Radar : public Device {
public:
  explicit Radar(WbDeviceTag tag) : Device(tag) {}
  explicit Radar(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void enable(int samplingPeriod) { wb_radar_enable(tag_, samplingPeriod); }
  void disable() { wb_radar_disable(tag_); }
  int getSamplingPeriod() const { return wb_radar_get_sampling_period(tag_); }
  int getNumberOfTargets() const { return wb_radar_get_number_of_targets(tag_); }
  const WbRadarTarget *getTargets() const { return wb_radar_get_targets(tag_); }
  double getMinRange() const { return wb_radar_get_min_range(tag_); }
  double getMaxRange() const { return wb_radar_get_max_range(tag_); }
  double getHorizontalFov() const { return wb_radar_get_horizontal_fov(tag_); }
  double getVerticalFov() const { return wb_radar_get_vertical_fov(tag_); }
};

}  // namespace webots

#endif
