// Sensorium C++ controller layer: VacuumGripper (Webots' C++ names over the wb_vacuum_gripper_* functions).
#ifndef WEBOTS_VACUUM_GRIPPER_HPP
#define WEBOTS_VACUUM_GRIPPER_HPP

#include <string>

#include <webots/Device.hpp>
#include <webots/vacuum_gripper.h>

namespace webots {

class VacuumGripper : public Device {
public:
  explicit VacuumGripper(WbDeviceTag tag) : Device(tag) {}
  explicit VacuumGripper(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void enablePresence(int samplingPeriod) { wb_vacuum_gripper_enable_presence(tag_, samplingPeriod); }
  void disablePresence() { wb_vacuum_gripper_disable_presence(tag_); }
  int getPresenceSamplingPeriod() const { return wb_vacuum_gripper_get_presence_sampling_period(tag_); }
  bool getPresence() const { return wb_vacuum_gripper_get_presence(tag_); }
  void turnOn() { wb_vacuum_gripper_turn_on(tag_); }
  void turnOff() { wb_vacuum_gripper_turn_off(tag_); }
  bool isOn() const { return wb_vacuum_gripper_is_on(tag_); }
};

}  // namespace webots

#endif
