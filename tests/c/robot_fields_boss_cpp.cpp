// The C++ twin of tests/c/robot_fields_boss.c through webots::Supervisor and Field: robot ALPHA's
// controller set to "second" at 160 ms, its customData to "go" at 480, its controller to "nowhere" at 640
// and to "first" at 800; prints each value read back.
#include <cmath>
#include <cstdio>

#include <webots/Supervisor.hpp>

using namespace webots;

int main() {
  Supervisor *boss = new Supervisor();
  Node *alpha = boss->getFromDef("ALPHA");
  Field *controller = alpha->getField("controller"), *data = alpha->getField("customData");
  const long at[4] = {160, 480, 640, 800};
  Field *fields[4] = {controller, data, controller, controller};
  const char *values[4] = {"second", "go", "nowhere", "first"};
  while (boss->step(16) != -1) {
    const long t = std::lround(boss->getTime() * 1000);
    for (int i = 0; i < 4; i++)
      if (t == at[i]) {
        fields[i]->setSFString(values[i]);
        std::printf("boss set '%s' at %ld\n", fields[i]->getSFString().c_str(), t);
        std::fflush(stdout);
      }
  }
  delete boss;
  return 0;
}
