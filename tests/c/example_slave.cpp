// The calls of Webots' C++ languages sample's `slave` controller (projects/languages/cpp), our own text
// against the C++ layer (sweep 34): 32 ms steps, the camera at 128 ms, ds0/ds1 and the receiver at 32 ms;
// each step it takes one order (a C string) and sets the wheels by its mode; it prints each order with
// the time and, each 16th step, its speeds.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>

#include <webots/Camera.hpp>
#include <webots/DistanceSensor.hpp>
#include <webots/Motor.hpp>
#include <webots/Receiver.hpp>
#include <webots/Robot.hpp>

using namespace webots;

static double bounded(double v) { return std::min(10.0, std::max(-10.0, v)); }

int main() {
  Robot *robot = new Robot();
  const int step = 32;
  robot->getCamera("camera")->enable(4 * step);
  Receiver *receiver = robot->getReceiver("receiver");
  receiver->enable(step);
  Motor *motors[2] = {robot->getMotor("left wheel motor"), robot->getMotor("right wheel motor")};
  for (Motor *m : motors) {
    m->setPosition(std::numeric_limits<double>::infinity());
    m->setVelocity(0.0);
  }
  DistanceSensor *ds[2] = {robot->getDistanceSensor("ds0"), robot->getDistanceSensor("ds1")};
  for (DistanceSensor *d : ds)
    d->enable(step);
  std::string mode("avoid obstacles");
  int steps = 0;
  while (robot->step(step) != -1) {
    if (receiver->getQueueLength() > 0) {
      mode = std::string(static_cast<const char *>(receiver->getData()));
      receiver->nextPacket();
      std::printf("I should %s! %.0f\n", mode.c_str(), robot->getTime() * 1000);
    }
    const double delta = ds[0]->getValue() - ds[1]->getValue();
    double left = 0.0, right = 0.0;
    if (mode == "avoid obstacles") {
      left = bounded(5.0 + 0.1 * delta);
      right = bounded(5.0 - 0.1 * delta);
    } else if (mode == "move forward") {
      left = right = 10.0;
    } else if (mode == "turn") {
      left = 5.0;
      right = -5.0;
    }
    motors[0]->setVelocity(left);
    motors[1]->setVelocity(right);
    if (++steps % 16 == 0)
      std::printf("speeds %.0f %g %g %g %g\n", robot->getTime() * 1000, left, right, ds[0]->getValue(),
                  ds[1]->getValue());
    std::fflush(stdout);
  }
  delete robot;
  return 0;
}
