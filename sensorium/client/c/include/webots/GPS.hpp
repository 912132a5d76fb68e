// Sensorium C++ controller layer: GPS (Webots' C++ names over the wb_gps_* functions).
#ifndef WEBOTS_GPS_HPP
#define WEBOTS_GPS_HPP

#include <cstdlib>
#include <string>

#include <webots/Device.hpp>
#include <webots/gps.h>

namespace webots {

class GPS : public Device {
public:
  enum CoordinateSystem { LOCAL = WB_GPS_LOCAL_COORDINATE, WGS84 = WB_GPS_WGS84_COORDINATE };
  explicit GPS(WbDeviceTag tag) : Device(tag) {}
  explicit GPS(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void enable(int samplingPeriod) { wb_gps_enable(tag_, samplingPeriod); }
  void disable() { wb_gps_disable(tag_); }
  int getSamplingPeriod() const { return wb_gps_get_sampling_period(tag_); }
  const double *getValues() const { return wb_gps_get_values(tag_); }
  double getSpeed() const { return wb_gps_get_speed(tag_); }
  const double *getSpeedVector() const { return wb_gps_get_speed_vector(tag_); }
  CoordinateSystem getCoordinateSystem() const { return static_cast<CoordinateSystem>(wb_gps_get_coordinate_system(tag_)); }
  static std::string convertToDegreesMinutesSeconds(double decimalDegrees) {
    const char *text = wb_gps_convert_to_degrees_minutes_seconds(decimalDegrees);  // the caller frees it
    const std::string result(text != NULL ? text : "");
    std::free(const_cast<char *>(text));
    return result;
  }
};

}  // namespace webots

#endif
