// Sensorium C++ controller layer: header-only classes over the C functions (Webots' C++ names).
#ifndef WEBOTS_DEVICE_HPP
#define WEBOTS_DEVICE_HPP

#include <string>

#include <webots/device.h>
#include <webots/robot.h>

namespace webots {

class Device {
public:
  explicit Device(WbDeviceTag tag) : tag_(tag) {}
  // Webots' by-name constructor (its classes' `explicit Camera(const std::string &name)`): the robot's device of that name
  explicit Device(const std::string &name) : tag_(wb_robot_get_device(name.c_str())) {}
  virtual ~Device() {}
  std::string getName() const {
    const char *name = wb_device_get_name(tag_);
    return name ? name : "";
  }
  std::string getModel() const {
    const char *model = wb_device_get_model(tag_);
    return model ? model : "";
  }
  int getNodeType() const { return wb_device_get_node_type(tag_); }
  WbDeviceTag getTag() const { return tag_; }
  static bool hasType(int tag, int type) { return wb_device_get_node_type(static_cast<WbDeviceTag>(tag)) == type; }

protected:
  WbDeviceTag tag_;

private:
  Device(const Device &);
  Device &operator=(const Device &);
};

}  // namespace webots

#endif
