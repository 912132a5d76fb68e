// webots::Motion (the header-only C++ layer over utils/motion.h) on tests/worlds/motion.yaml, robot
// leg: motion_cpp DIR. A file that is not there gives an invalid Motion; DIR/wave.motion played
// forwards prints the "forward" lines of tests/controllers/motion_player.py, the same bits.
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <string>

#include <webots/Motor.hpp>
#include <webots/PositionSensor.hpp>
#include <webots/Robot.hpp>
#include <webots/utils/Motion.hpp>

using namespace webots;

static void bits(double v) {
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  std::printf(" %016" PRIx64, b);
}

int main(int argc, char **argv) {
  Robot *robot = new Robot();
  std::string folder = argc > 1 ? argv[1] : ".";
  int dt = static_cast<int>(robot->getBasicTimeStep());
  Motor *motors[3] = {robot->getMotor("hip"), robot->getMotor("knee"), robot->getMotor("slide")};
  PositionSensor *hip = robot->getPositionSensor("hip sensor");
  hip->enable(dt);
  {
    Motion absent(folder + "/absent.motion");
    std::printf("absent %d\n", absent.isValid() ? 1 : 0);
  }
  Motion *wave = new Motion(folder + "/wave.motion");
  std::printf("wave %d %d %d\n", wave->getDuration(), wave->getTime(), wave->isOver() ? 1 : 0);
  wave->play();
  for (int s = 0; s < 33 && robot->step(dt) != -1; s++) {
    int time = wave->getTime(), over = wave->isOver() ? 1 : 0;
    std::printf("forward %.0f %d %d", robot->getTime() * 1000.0, time, over);
    for (int i = 0; i < 3; i++)
      bits(motors[i]->getTargetPosition());
    bits(hip->getValue());
    std::printf("\n");
    std::fflush(stdout);
  }
  delete wave;
  delete robot;
  return 0;
}
