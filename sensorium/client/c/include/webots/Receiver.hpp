// Sensorium C++ controller layer: Receiver (Webots' C++ names over the wb_receiver_* functions).
#ifndef WEBOTS_RECEIVER_HPP
#define WEBOTS_RECEIVER_HPP

#include <string>

#include <webots/Device.hpp>
#include <webots/receiver.h>

namespace webots {

class Receiver : public Device {
public:
  enum { CHANNEL_BROADCAST = WB_CHANNEL_BROADCAST };
  explicit Receiver(WbDeviceTag tag) : Device(tag) {}
  explicit Receiver(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void enable(int samplingPeriod) { wb_receiver_enable(tag_, samplingPeriod); }
  void disable() { wb_receiver_disable(tag_); }
  int getSamplingPeriod() const { return wb_receiver_get_sampling_period(tag_); }
  void setChannel(int channel) { wb_receiver_set_channel(tag_, channel); }
  int getChannel() const { return wb_receiver_get_channel(tag_); }
  int getQueueLength() const { return wb_receiver_get_queue_length(tag_); }
  void nextPacket() { wb_receiver_next_packet(tag_); }
  int getDataSize() const { return wb_receiver_get_data_size(tag_); }
  const void *getData() const { return wb_receiver_get_data(tag_); }
  double getSignalStrength() const { return wb_receiver_get_signal_strength(tag_); }
  const double *getEmitterDirection() const { return wb_receiver_get_emitter_direction(tag_); }
};

}  // namespace webots

#endif
