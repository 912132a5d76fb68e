// Sensorium C++ controller layer: Driver over vehicle/driver.h (a car-like robot's ackermann_drive).
// wbu_driver_init() runs before the Supervisor base is built: it attaches to the robot itself (the
// base's wb_robot_init() then finds it attached) and, on a robot that is not a car, prints one line
// and ends the process with status 1.
#ifndef WEBOTS_DRIVER_HPP
#define WEBOTS_DRIVER_HPP

#include <webots/Supervisor.hpp>
#include <webots/vehicle/driver.h>

namespace webots {

namespace internal {
// A base constructed before Supervisor (bases are built in declaration order): runs the vehicle
// library's init (which attaches, or refuses a robot that is not a car) first.
struct VehicleInit {
  explicit VehicleInit(void (*init)(void)) { init(); }
};
}  // namespace internal

class Driver : private internal::VehicleInit, public Supervisor {
public:
  typedef enum { INDICATOR_OFF = OFF, INDICATOR_RIGHT = RIGHT, INDICATOR_LEFT = LEFT } IndicatorState;
  typedef enum { SPEED = ::SPEED, TORQUE = ::TORQUE } ControlMode;
  typedef enum { DOWN = ::DOWN, SLOW = ::SLOW, NORMAL = ::NORMAL, FAST = ::FAST } WiperMode;

  Driver() : internal::VehicleInit(wbu_driver_init) { instance() = this; }
  virtual ~Driver() {
    wbu_driver_cleanup();
    if (instance() == this)
      instance() = 0;
  }
  static Driver *getDriverInstance() { return instance(); }
  // whether this controller's robot is a car the library drives (Webots: for webots_ros2)
  static bool isInitialisationPossible() { return wbu_driver_initialization_is_possible(); }

  int step() { return wbu_driver_step(); }

  void setSteeringAngle(double steeringAngle) { wbu_driver_set_steering_angle(steeringAngle); }
  double getSteeringAngle() { return wbu_driver_get_steering_angle(); }
  void setCruisingSpeed(double speed) { wbu_driver_set_cruising_speed(speed); }
  double getTargetCruisingSpeed() { return wbu_driver_get_target_cruising_speed(); }
  double getCurrentSpeed() { return wbu_driver_get_current_speed(); }
  void setThrottle(double throttle) { wbu_driver_set_throttle(throttle); }
  double getThrottle() { return wbu_driver_get_throttle(); }
  void setBrakeIntensity(double intensity) { wbu_driver_set_brake_intensity(intensity); }
  double getBrakeIntensity() { return wbu_driver_get_brake_intensity(); }
  void setIndicator(IndicatorState state) { wbu_driver_set_indicator(static_cast<WbuDriverIndicatorState>(state)); }
  void setHazardFlashers(bool state) { wbu_driver_set_hazard_flashers(state); }
  IndicatorState getIndicator() { return static_cast<IndicatorState>(wbu_driver_get_indicator()); }
  bool getHazardFlashers() { return wbu_driver_get_hazard_flashers(); }
  void setDippedBeams(bool state) { wbu_driver_set_dipped_beams(state); }
  void setAntifogLights(bool state) { wbu_driver_set_antifog_lights(state); }
  bool getDippedBeams() { return wbu_driver_get_dipped_beams(); }
  bool getAntifogLights() { return wbu_driver_get_antifog_lights(); }
  double getRpm() { return wbu_driver_get_rpm(); }
  int getGear() { return wbu_driver_get_gear(); }
  void setGear(int gear) { wbu_driver_set_gear(gear); }
  int getGearNumber() { return wbu_driver_get_gear_number(); }
  ControlMode getControlMode() { return static_cast<ControlMode>(wbu_driver_get_control_mode()); }
  void setWiperMode(WiperMode mode) { wbu_driver_set_wiper_mode(static_cast<WbuDriverWiperMode>(mode)); }
  WiperMode getWiperMode() { return static_cast<WiperMode>(wbu_driver_get_wiper_mode()); }
  // Webots' older names
  void setBrake(double brake) { wbu_driver_set_brake_intensity(brake); }
  void setWipersMode(WiperMode mode) { setWiperMode(mode); }
  WiperMode getWipersMode() { return getWiperMode(); }

protected:
  explicit Driver(void (*init)(void)) : internal::VehicleInit(init) {}  // Car: wbu_car_init

private:
  static Driver *&instance() {
    static Driver *created = 0;
    return created;
  }
};

}  // namespace webots

#endif  // WEBOTS_DRIVER_HPP
