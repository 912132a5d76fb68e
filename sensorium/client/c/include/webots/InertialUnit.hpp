// Sensorium C++ controller layer: InertialUnit (Webots' C++ names over the wb_inertial_unit_* functions).
#ifndef WEBOTS_INERTIAL_UNIT_HPP
#define WEBOTS_INERTIAL_UNIT_HPP

#include <string>

#include <webots/Device.hpp>
#include <webots/inertial_unit.h>

namespace webots {

class InertialUnit : public Device {
public:
  explicit InertialUnit(WbDeviceTag tag) : Device(tag) {}
  explicit InertialUnit(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void enable(int samplingPeriod) { wb_inertial_unit_enable(tag_, samplingPeriod); }
  void disable() { wb_inertial_unit_disable(tag_); }
  int getSamplingPeriod() const { return wb_inertial_unit_get_sampling_period(tag_); }
  double getNoise() const { return wb_inertial_unit_get_noise(tag_); }
  const double *getRollPitchYaw() const { return wb_inertial_unit_get_roll_pitch_yaw(tag_); }
  const double *getQuaternion() const { return wb_inertial_unit_get_quaternion(tag_); }
};

}  // namespace webots

#endif
