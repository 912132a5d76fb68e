// Sensorium C++ controller layer: Robot. One Robot per process (as in Webots); it owns the device
// objects it hands out. Header-only over the C library: link with -lController.
#ifndef WEBOTS_ROBOT_HPP
#define WEBOTS_ROBOT_HPP

#include <map>
#include <string>

#include <webots/Accelerometer.hpp>
#include <webots/Altimeter.hpp>
#include <webots/Brake.hpp>
#include <webots/Camera.hpp>
#include <webots/Compass.hpp>
#include <webots/Connector.hpp>
#include <webots/Display.hpp>
#include <webots/Emitter.hpp>
#include <webots/GPS.hpp>
#include <webots/Gyro.hpp>
#include <webots/InertialUnit.hpp>
#include <webots/Pen.hpp>
#include <webots/Radar.hpp>
#include <webots/RangeFinder.hpp>
#include <webots/Receiver.hpp>
#include <webots/Skin.hpp>
#include <webots/Speaker.hpp>
#include <webots/TouchSensor.hpp>
#include <webots/VacuumGripper.hpp>
#include <webots/Device.hpp>
#include <webots/Joystick.hpp>
#include <webots/LinearMotor.hpp>
#include <webots/Mouse.hpp>
#include <webots/RotationalMotor.hpp>
#include <webots/DistanceSensor.hpp>
#include <webots/Keyboard.hpp>
#include <webots/LED.hpp>
#include <webots/Lidar.hpp>
#include <webots/LightSensor.hpp>
#include <webots/Motor.hpp>
#include <webots/plugins/robot_window/robot_wwi.h>
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
    case WB_NODE_ROTATIONAL_MOTOR: d = new RotationalMotor(tag); break;
    case WB_NODE_LINEAR_MOTOR: d = new LinearMotor(tag); break;
    case WB_NODE_ACCELEROMETER: d = new Accelerometer(tag); break;
    case WB_NODE_ALTIMETER: d = new Altimeter(tag); break;
    case WB_NODE_BRAKE: d = new Brake(tag); break;
    case WB_NODE_CAMERA: d = new Camera(tag); break;
    case WB_NODE_COMPASS: d = new Compass(tag); break;
    case WB_NODE_CONNECTOR: d = new Connector(tag); break;
    case WB_NODE_DISPLAY: d = new Display(tag); break;
    case WB_NODE_EMITTER: d = new Emitter(tag); break;
    case WB_NODE_GYRO: d = new Gyro(tag); break;
    case WB_NODE_INERTIAL_UNIT: d = new InertialUnit(tag); break;
    case WB_NODE_PEN: d = new Pen(tag); break;
    case WB_NODE_RADAR: d = new Radar(tag); break;
    case WB_NODE_RANGE_FINDER: d = new RangeFinder(tag); break;
    case WB_NODE_RECEIVER: d = new Receiver(tag); break;
    case WB_NODE_SKIN: d = new Skin(tag); break;
    case WB_NODE_SPEAKER: d = new Speaker(tag); break;
    case WB_NODE_TOUCH_SENSOR: d = new TouchSensor(tag); break;
    case WB_NODE_VACUUM_GRIPPER: d = new VacuumGripper(tag); break;
    case WB_NODE_GPS: d = new GPS(tag); break;
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
  enum UserInputEvent {
    EVENT_QUIT = WB_EVENT_QUIT, EVENT_NO_EVENT = WB_EVENT_NO_EVENT, EVENT_MOUSE_CLICK = WB_EVENT_MOUSE_CLICK,
    EVENT_MOUSE_MOVE = WB_EVENT_MOUSE_MOVE, EVENT_KEYBOARD = WB_EVENT_KEYBOARD,
    EVENT_JOYSTICK_BUTTON = WB_EVENT_JOYSTICK_BUTTON, EVENT_JOYSTICK_AXIS = WB_EVENT_JOYSTICK_AXIS,
    EVENT_JOYSTICK_POV = WB_EVENT_JOYSTICK_POV
  };
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
  void setMode(Mode mode, const char *arg) { wb_robot_set_mode(static_cast<WbRobotMode>(mode), arg); }
  std::string getProjectPath() const { return wb_robot_get_project_path(); }
  std::string getWorldPath() const { return wb_robot_get_world_path(); }
  std::string getUrdf(std::string prefix = "") const { return wb_robot_get_urdf(prefix.c_str()); }
  int getNumberOfDevices() const { return wb_robot_get_number_of_devices(); }
  Device *getDeviceByIndex(int index) { return internal::deviceFromTag(wb_robot_get_device_by_index(index)); }
  Device *getDevice(const std::string &name) { return internal::deviceFromTag(wb_robot_get_device(name.c_str())); }
  // robot window messages: to the server's topic /<robot>/robot_window and from `sensorium window`,
  // see plugins/robot_window/robot_wwi.h
  void wwiSend(const char *data, int size) { wb_robot_wwi_send(data, size); }
  void wwiSendText(const std::string &text) { wb_robot_wwi_send(text.c_str(), static_cast<int>(text.size()) + 1); }
  const char *wwiReceive(int *size) { return wb_robot_wwi_receive(size); }
  std::string wwiReceiveText() {
    const char *text = wb_robot_wwi_receive_text();
    return text != NULL ? text : "";
  }
  void *windowCustomFunction(void *) { return NULL; }  // no robot window here: nothing to call
  // deprecated since Webots 2018a (the custom data)
  std::string getData() const { return wb_robot_get_custom_data(); }
  void setData(const std::string &data) { wb_robot_set_custom_data(data.c_str()); }
  DistanceSensor *getDistanceSensor(const std::string &name) { return typed<DistanceSensor>(name, WB_NODE_DISTANCE_SENSOR); }
  LightSensor *getLightSensor(const std::string &name) { return typed<LightSensor>(name, WB_NODE_LIGHT_SENSOR); }
  Lidar *getLidar(const std::string &name) { return typed<Lidar>(name, WB_NODE_LIDAR); }
  Motor *getMotor(const std::string &name) {
    WbDeviceTag tag = wb_robot_get_device(name.c_str());
    int type = tag ? wb_device_get_node_type(tag) : WB_NODE_NO_NODE;
    return type == WB_NODE_ROTATIONAL_MOTOR || type == WB_NODE_LINEAR_MOTOR ? static_cast<Motor *>(internal::deviceFromTag(tag)) : 0;
  }
  PositionSensor *getPositionSensor(const std::string &name) {
    return typed<PositionSensor>(name, WB_NODE_POSITION_SENSOR);
  }
  LED *getLED(const std::string &name) { return typed<LED>(name, WB_NODE_LED); }
  Accelerometer *getAccelerometer(const std::string &name) { return typed<Accelerometer>(name, WB_NODE_ACCELEROMETER); }
  Altimeter *getAltimeter(const std::string &name) { return typed<Altimeter>(name, WB_NODE_ALTIMETER); }
  Brake *getBrake(const std::string &name) { return typed<Brake>(name, WB_NODE_BRAKE); }
  Camera *getCamera(const std::string &name) { return typed<Camera>(name, WB_NODE_CAMERA); }
  Compass *getCompass(const std::string &name) { return typed<Compass>(name, WB_NODE_COMPASS); }
  Connector *getConnector(const std::string &name) { return typed<Connector>(name, WB_NODE_CONNECTOR); }
  Display *getDisplay(const std::string &name) { return typed<Display>(name, WB_NODE_DISPLAY); }
  Emitter *getEmitter(const std::string &name) { return typed<Emitter>(name, WB_NODE_EMITTER); }
  Gyro *getGyro(const std::string &name) { return typed<Gyro>(name, WB_NODE_GYRO); }
  InertialUnit *getInertialUnit(const std::string &name) { return typed<InertialUnit>(name, WB_NODE_INERTIAL_UNIT); }
  Pen *getPen(const std::string &name) { return typed<Pen>(name, WB_NODE_PEN); }
  Radar *getRadar(const std::string &name) { return typed<Radar>(name, WB_NODE_RADAR); }
  RangeFinder *getRangeFinder(const std::string &name) { return typed<RangeFinder>(name, WB_NODE_RANGE_FINDER); }
  Receiver *getReceiver(const std::string &name) { return typed<Receiver>(name, WB_NODE_RECEIVER); }
  Skin *getSkin(const std::string &name) { return typed<Skin>(name, WB_NODE_SKIN); }
  Speaker *getSpeaker(const std::string &name) { return typed<Speaker>(name, WB_NODE_SPEAKER); }
  TouchSensor *getTouchSensor(const std::string &name) { return typed<TouchSensor>(name, WB_NODE_TOUCH_SENSOR); }
  VacuumGripper *getVacuumGripper(const std::string &name) { return typed<VacuumGripper>(name, WB_NODE_VACUUM_GRIPPER); }
  GPS *getGPS(const std::string &name) { return typed<GPS>(name, WB_NODE_GPS); }
  Keyboard *getKeyboard() { return &keyboard_; }
  Joystick *getJoystick() { return &joystick_; }
  Mouse *getMouse() { return &mouse_; }
  UserInputEvent waitForUserInputEvent(UserInputEvent eventType, int timeout) {
    return static_cast<UserInputEvent>(wb_robot_wait_for_user_input_event(static_cast<WbUserInputEvent>(eventType), timeout));
  }
  void batterySensorEnable(int samplingPeriod) { wb_robot_battery_sensor_enable(samplingPeriod); }
  void batterySensorDisable() { wb_robot_battery_sensor_disable(); }
  int batterySensorGetSamplingPeriod() const { return wb_robot_battery_sensor_get_sampling_period(); }
  double batterySensorGetValue() const { return wb_robot_battery_sensor_get_value(); }

private:
  template <class T> T *typed(const std::string &name, WbNodeType type) {
    WbDeviceTag tag = wb_robot_get_device(name.c_str());
    if (tag == 0 || wb_device_get_node_type(tag) != type)
      return 0;
    return static_cast<T *>(internal::deviceFromTag(tag));
  }
  Keyboard keyboard_;
  Joystick joystick_;
  Mouse mouse_;
  Robot(const Robot &);
  Robot &operator=(const Robot &);
};

}  // namespace webots

#endif
