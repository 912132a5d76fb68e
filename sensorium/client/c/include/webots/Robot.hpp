// Sensorium C++ controller layer: Robot. One Robot per process (as in Webots); it owns the device
// objects it hands out. Header-only over the C library: link with -lController.
#ifndef WEBOTS_ROBOT_HPP
#define WEBOTS_ROBOT_HPP

#include <map>
#include <string>

#include <webots/Device.hpp>
#include <webots/DistanceSensor.hpp>
#include <webots/Keyboard.hpp>
#include <webots/LED.hpp>
#include <webots/Lidar.hpp>
#include <webots/LightSensor.hpp>
#include <webots/Motor.hpp>
#include <webots/robot.h>

namespace webots {

namespace internal {
inline std::map<WbDeviceTag, Device *> &devices() {
  static std::map<WbDeviceTag, Device *> table;
  return table;
}

inline Device *deviceFromTag(WbDeviceTag tag) {
  if (tag == 0)
    return 0;
  std::map<WbDeviceTag, Device *>::iterator it = devices().find(tag);
  if (it != devices().end())
    return it->second;
  Device *d = 0;
  switch (wb_device_get_node_type(tag)) {
    case WB_NODE_DISTANCE_SENSOR: d = new DistanceSensor(tag); break;
    case WB_NODE_LIGHT_SENSOR: d = new LightSensor(tag); break;
    case WB_NODE_LIDAR: d = new Lidar(tag); break;
    case WB_NODE_ROTATIONAL_MOTOR: d = new Motor(tag); break;
    case WB_NODE_POSITION_SENSOR: d = new PositionSensor(tag); break;
    case WB_NODE_LED: d = new LED(tag); break;
    default: d = new Device(tag); break;
  }
  devices()[tag] = d;
  return d;
}
}  // namespace internal

class Robot {
public:
  enum Mode { MODE_SIMULATION = WB_MODE_SIMULATION, MODE_CROSS_COMPILATION, MODE_REMOTE_CONTROL };
  Robot() { wb_robot_init(); }
  virtual ~Robot() {
    std::map<WbDeviceTag, Device *> &table = internal::devices();
    for (std::map<WbDeviceTag, Device *>::iterator it = table.begin(); it != table.end(); ++it)
      delete it->second;
    table.clear();
    wb_robot_cleanup();
  }
  int step() { return wb_robot_step(static_cast<int>(wb_robot_get_basic_time_step())); }
  int step(int duration) { return wb_robot_step(duration); }
  int stepBegin(int duration) { return wb_robot_step_begin(duration); }
  int stepEnd() { return wb_robot_step_end(); }
  double getTime() const { return wb_robot_get_time(); }
  double getBasicTimeStep() const { return wb_robot_get_basic_time_step(); }
  std::string getName() const { return wb_robot_get_name(); }
  std::string getModel() const { return wb_robot_get_model(); }
  std::string getCustomData() const { return wb_robot_get_custom_data(); }
  void setCustomData(const std::string &data) { wb_robot_set_custom_data(data.c_str()); }
  bool getSynchronization() const { return wb_robot_get_synchronization(); }
  bool getSupervisor() const { return wb_robot_get_supervisor(); }
  Mode getMode() const { return static_cast<Mode>(wb_robot_get_mode()); }
  int getNumberOfDevices() const { return wb_robot_get_number_of_devices(); }
  Device *getDeviceByIndex(int index) { return internal::deviceFromTag(wb_robot_get_device_by_index(index)); }
  Device *getDevice(const std::string &name) { return internal::deviceFromTag(wb_robot_get_device(name.c_str())); }
  DistanceSensor *getDistanceSensor(const std::string &name) { return typed<DistanceSensor>(name, WB_NODE_DISTANCE_SENSOR); }
  LightSensor *getLightSensor(const std::string &name) { return typed<LightSensor>(name, WB_NODE_LIGHT_SENSOR); }
  Lidar *getLidar(const std::string &name) { return typed<Lidar>(name, WB_NODE_LIDAR); }
  Motor *getMotor(const std::string &name) { return typed<Motor>(name, WB_NODE_ROTATIONAL_MOTOR); }
  PositionSensor *getPositionSensor(const std::string &name) {
    return typed<PositionSensor>(name, WB_NODE_POSITION_SENSOR);
  }
  LED *getLED(const std::string &name) { return typed<LED>(name, WB_NODE_LED); }
  Keyboard *getKeyboard() { return &keyboard_; }

private:
  template <class T> T *typed(const std::string &name, WbNodeType type) {
    WbDeviceTag tag = wb_robot_get_device(name.c_str());
    if (tag == 0 || wb_device_get_node_type(tag) != type)
      return 0;
    return static_cast<T *>(internal::deviceFromTag(tag));
  }
  Keyboard keyboard_;
  Robot(const Robot &);
  Robot &operator=(const Robot &);
};

}  // namespace webots

#endif
