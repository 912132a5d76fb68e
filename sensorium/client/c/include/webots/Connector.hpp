// Sensorium C++ controller layer: Connector (Webots' C++ names over the wb_connector_* functions).
#ifndef WEBOTS_CONNECTOR_HPP
#define WEBOTS_CONNECTOR_HPP

#include <string>

#include <webots/Device.hpp>
#include <webots/connector.h>

namespace webots {

class Connector : public Device {
public:
  explicit Connector(WbDeviceTag tag) : Device(tag) {}
  explicit Connector(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void enablePresence(int samplingPeriod) { wb_connector_enable_presence(tag_, samplingPeriod); }
  void disablePresence() { wb_connector_disable_presence(tag_); }
  int getPresenceSamplingPeriod() const { return wb_connector_get_presence_sampling_period(tag_); }
  int getPresence() const { return wb_connector_get_presence(tag_); }
  void lock() { wb_connector_lock(tag_); }
  void unlock() { wb_connector_unlock(tag_); }
  bool isLocked() const { return wb_connector_is_locked(tag_); }
};

}  // namespace webots

#endif
