// Sensorium C++ controller layer: RangeFinder (Webots' C++ names over the wb_range_finder_* functions).
#ifndef WEBOTS_RANGE_FINDER_HPP
#define WEBOTS_RANGE_FINDER_HPP

#include <string>

#include <webots/Device.hpp>
#include <webots/range_finder.h>

namespace webots {

class RangeFinder : public Device {
public:
  explicit RangeFinder(WbDeviceTag tag) : Device(tag) {}
  explicit RangeFinder(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void enable(int samplingPeriod) { wb_range_finder_enable(tag_, samplingPeriod); }
  void disable() { wb_range_finder_disable(tag_); }
  int getSamplingPeriod() const { return wb_range_finder_get_sampling_period(tag_); }
  const float *getRangeImage() const { return wb_range_finder_get_range_image(tag_); }
  int getWidth() const { return wb_range_finder_get_width(tag_); }
  int getHeight() const { return wb_range_finder_get_height(tag_); }
  double getFov() const { return wb_range_finder_get_fov(tag_); }
  double getMinRange() const { return wb_range_finder_get_min_range(tag_); }
  double getMaxRange() const { return wb_range_finder_get_max_range(tag_); }
  int saveImage(const std::string &filename, int quality) const { return wb_range_finder_save_image(tag_, filename.c_str(), quality); }
  static float rangeImageGetDepth(const float *image, int width, int x, int y) {
    return wb_range_finder_image_get_depth(image, width, x, y);
  }
};

}  // namespace webots

#endif
