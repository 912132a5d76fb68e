// The Braitenberg vehicle of sensorium/client/examples/braitenberg.py written against the C++
// layer (webots::Robot, DistanceSensor, LightSensor, Motor): same arithmetic and output.
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <webots/DistanceSensor.hpp>
#include <webots/LightSensor.hpp>
#include <webots/Motor.hpp>
#include <webots/Robot.hpp>

using namespace webots;

static const double MAX_SPEED = 6.28, LIGHT_GAIN = 4.0, IR_THRESHOLD = 150.0;
static const double IR_WEIGHTS_LEFT[8] = {-1.0, -0.8, -0.4, 0.0, 0.0, 0.4, 0.8, 1.0};
static const double IR_WEIGHTS_RIGHT[8] = {1.0, 0.8, 0.4, 0.0, 0.0, -0.4, -0.8, -1.0};

static double clip(double v) { return v < -MAX_SPEED ? -MAX_SPEED : (v > MAX_SPEED ? MAX_SPEED : v); }

int main(int argc, char **argv) {
  Robot *robot = new Robot();
  int timestep = static_cast<int>(robot->getBasicTimeStep());
  int max_steps = argc > 1 ? std::atoi(argv[1]) : -1;
  LightSensor *eyes[2] = {robot->getLightSensor("ls0"), robot->getLightSensor("ls1")};
  DistanceSensor *proximity[8];
  for (int i = 0; i < 8; i++) {
    char name[8];
    std::snprintf(name, sizeof name, "ps%d", i);
    proximity[i] = robot->getDistanceSensor(name);
  }
  for (int i = 0; i < 2; i++)
    eyes[i]->enable(timestep);
  for (int i = 0; i < 8; i++)
    proximity[i]->enable(timestep);
  Motor *left_motor = robot->getMotor("left wheel motor"), *right_motor = robot->getMotor("right wheel motor");
  if (robot->getDevice("ps0") != proximity[0] || robot->getMotor("ps0") != 0 || left_motor->getPositionSensor() != 0)
    return 3;
  left_motor->setPosition(INFINITY);
  right_motor->setPosition(INFINITY);
  left_motor->setVelocity(0.0);
  right_motor->setVelocity(0.0);
  int step = 0;
  while (robot->step(timestep) != -1) {
    double light[2] = {eyes[0]->getValue(), eyes[1]->getValue()};
    double ir[8];
    for (int i = 0; i < 8; i++)
      ir[i] = proximity[i]->getValue();
    double total = light[0] + light[1], left, right;
    if (total > 0) {
      left = 0.5 * MAX_SPEED + LIGHT_GAIN * (light[1] - light[0]) / total;
      right = 0.5 * MAX_SPEED + LIGHT_GAIN * (light[0] - light[1]) / total;
    } else
      left = right = 0.5 * MAX_SPEED;
    for (int i = 0; i < 8; i++)
      if (ir[i] == ir[i] && ir[i] > IR_THRESHOLD) {
        double push = (ir[i] - IR_THRESHOLD) / 1000.0 * MAX_SPEED;
        left += IR_WEIGHTS_LEFT[i] * push;
        right += IR_WEIGHTS_RIGHT[i] * push;
      }
    left = clip(left);
    right = clip(right);
    std::printf("t=%7.3f  ls0=%8.2f ls1=%8.2f  ps=[", robot->getTime(), light[0], light[1]);
    for (int i = 0; i < 8; i++)
      std::printf(i ? " %6.1f" : "%6.1f", ir[i]);
    std::printf("]  wheels %+5.2f %+5.2f rad/s\n", left, right);
    std::fflush(stdout);
    left_motor->setVelocity(left);
    right_motor->setVelocity(right);
    if (max_steps >= 0 && ++step >= max_steps)
      break;
  }
  delete robot;
  return 0;
}
