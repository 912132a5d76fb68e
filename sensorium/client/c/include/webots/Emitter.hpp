// Sensorium C++ controller layer: Emitter (Webots' C++ names over the wb_emitter_* functions).
#ifndef WEBOTS_EMITTER_HPP
#define WEBOTS_EMITTER_HPP

#include <string>

#include <webots/Device.hpp>
#include <webots/emitter.h>

namespace webots {

class Emitter : public Device {
public:
  enum { CHANNEL_BROADCAST = WB_CHANNEL_BROADCAST };
  explicit Emitter(WbDeviceTag tag) : Device(tag) {}
  explicit Emitter(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  int send(const void *data, int size) { return wb_emitter_send(tag_, data, size); }
  int getBufferSize() const { return wb_emitter_get_buffer_size(tag_); }
  void setChannel(int channel) { wb_emitter_set_channel(tag_, channel); }
  int getChannel() const { return wb_emitter_get_channel(tag_); }
  double getRange() const { return wb_emitter_get_range(tag_); }
  void setRange(double range) { wb_emitter_set_range(tag_, range); }
};

}  // namespace webots

#endif
