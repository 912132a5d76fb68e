// Sensorium C++ controller layer: LED.
#ifndef WEBOTS_LED_HPP
#define WEBOTS_LED_HPP

#include <webots/Device.hpp>
#include <webots/led.h>

namespace webots {

class LED : public Device {
public:
  explicit LED(WbDeviceTag tag) : Device(tag) {}
  explicit LED(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void set(int value) { wb_led_set(tag_, value); }
  int get() const { return wb_led_get(tag_); }
};

}  // namespace webots

#endif
