// Sensorium C++ controller layer: Pen (Webots' C++ names over the wb_pen_* functions).
#ifndef WEBOTS_PEN_HPP
#define WEBOTS_PEN_HPP

#include <string>

#include <webots/Device.hpp>
#include <webots/pen.h>

namespace webots {

class Pen : public Device {
public:
  explicit Pen(WbDeviceTag tag) : Device(tag) {}
  explicit Pen(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void write(bool write) { wb_pen_write(tag_, write); }
  void setInkColor(int color, double density) { wb_pen_set_ink_color(tag_, color, density); }
};

}  // namespace webots

#endif
