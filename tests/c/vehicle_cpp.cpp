// Webots' C++ vehicle classes: constructing a Car (or, with an argument, a Driver) prints the vehicle
// library's one line and exits with status 1 before the Supervisor base looks for a server.
#include <cstdio>

#include <webots/utils/AnsiCodes.hpp>
#include <webots/utils/Motion.hpp>
#include <webots/vehicle/Car.hpp>

int main(int argc, char **) {
  std::printf("%s%d %d%s\n", ANSI_BOLD, webots::Car::WHEEL_NB, webots::Driver::FAST, ANSI_RESET);
  std::fflush(stdout);
  if (argc > 1) {
    webots::Driver driver;
    driver.setSteeringAngle(0.1);
  } else {
    webots::Car car;
    car.setLeftSteeringAngle(0.1);
  }
  std::printf("constructed\n");
  return 0;
}
