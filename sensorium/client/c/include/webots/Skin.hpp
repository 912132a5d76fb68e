// Sensorium C++ controller layer: Skin (Webots' C++ names over the wb_skin_* functions).
#ifndef WEBOTS_SKIN_HPP
#define WEBOTS_SKIN_HPP

#include <string>

#include <webots/Device.hpp>
#include <webots/skin.h>

namespace webots {

class Skin : public Device {
public:
  explicit Skin(WbDeviceTag tag) : Device(tag) {}
  explicit Skin(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void setBoneOrientation(int index, const double orientation[4], bool absolute) { wb_skin_set_bone_orientation(tag_, index, orientation, absolute); }
  void setBonePosition(int index, const double position[3], bool absolute) { wb_skin_set_bone_position(tag_, index, position, absolute); }
  int getBoneCount() const { return wb_skin_get_bone_count(tag_); }
  std::string getBoneName(int index) const { return std::string(wb_skin_get_bone_name(tag_, index)); }
  const double *getBoneOrientation(int index, bool absolute) const { return wb_skin_get_bone_orientation(tag_, index, absolute); }
  const double *getBonePosition(int index, bool absolute) const { return wb_skin_get_bone_position(tag_, index, absolute); }
};

}  // namespace webots

#endif
