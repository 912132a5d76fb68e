// Sensorium C++ controller layer: Lidar (the arrays stay valid until the next step).
#ifndef WEBOTS_LIDAR_HPP
#define WEBOTS_LIDAR_HPP

#include <webots/Device.hpp>
#include <webots/lidar.h>

namespace webots {

typedef WbLidarPoint LidarPoint;

class Lidar : public Device {
public:
  explicit Lidar(WbDeviceTag tag) : Device(tag) {}
  explicit Lidar(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void enable(int samplingPeriod) { wb_lidar_enable(tag_, samplingPeriod); }
  void disable() { wb_lidar_disable(tag_); }
  void enablePointCloud() { wb_lidar_enable_point_cloud(tag_); }
  void disablePointCloud() { wb_lidar_disable_point_cloud(tag_); }
  bool isPointCloudEnabled() const { return wb_lidar_is_point_cloud_enabled(tag_); }
  int getSamplingPeriod() const { return wb_lidar_get_sampling_period(tag_); }
  const float *getRangeImage() const { return wb_lidar_get_range_image(tag_); }
  const float *getLayerRangeImage(int layer) const { return wb_lidar_get_layer_range_image(tag_, layer); }
  const LidarPoint *getPointCloud() const { return wb_lidar_get_point_cloud(tag_); }
  const LidarPoint *getLayerPointCloud(int layer) const { return wb_lidar_get_layer_point_cloud(tag_, layer); }
  int getNumberOfPoints() const { return wb_lidar_get_number_of_points(tag_); }
  int getHorizontalResolution() const { return wb_lidar_get_horizontal_resolution(tag_); }
  int getNumberOfLayers() const { return wb_lidar_get_number_of_layers(tag_); }
  double getMinFrequency() const { return wb_lidar_get_min_frequency(tag_); }
  double getMaxFrequency() const { return wb_lidar_get_max_frequency(tag_); }
  double getFrequency() const { return wb_lidar_get_frequency(tag_); }
  void setFrequency(double frequency) { wb_lidar_set_frequency(tag_, frequency); }
  double getFov() const { return wb_lidar_get_fov(tag_); }
  double getVerticalFov() const { return wb_lidar_get_vertical_fov(tag_); }
  double getMinRange() const { return wb_lidar_get_min_range(tag_); }
  double getMaxRange() const { return wb_lidar_get_max_range(tag_); }
};

}  // namespace webots

#endif
