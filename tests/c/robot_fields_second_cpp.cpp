// A C++ robot controller reading its customData (webots::Robot::getCustomData) each step, started by a
// Supervisor setting its controller field (tests/test_run_robot_fields.py): prints when it starts, each new
// value it sees and when it ends, in simulated milliseconds.
#include <cmath>
#include <cstdio>
#include <string>

#include <webots/Robot.hpp>

using namespace webots;

int main() {
  Robot *robot = new Robot();
  std::string seen = robot->getCustomData();
  std::printf("second starts at %ld with '%s'\n", std::lround(robot->getTime() * 1000), seen.c_str());
  std::fflush(stdout);
  while (robot->step(16) != -1) {
    if (robot->getCustomData() != seen) {
      seen = robot->getCustomData();
      std::printf("second sees '%s' at %ld\n", seen.c_str(), std::lround(robot->getTime() * 1000));
      std::fflush(stdout);
    }
  }
  std::printf("second ends at %ld\n", std::lround(robot->getTime() * 1000));
  std::fflush(stdout);
  delete robot;
  return 0;
}
