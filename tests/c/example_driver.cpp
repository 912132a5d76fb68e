// The calls of Webots' C++ languages sample's `driver` Supervisor (projects/languages/cpp), our own text
// against the C++ layer (sweep 34). Headless, no key is ever pressed (getKey() is -1), so the keys a user
// would press come from a schedule (the step's time): 'F', 'T', 'S', 'R' then 'G', 'A', 'G'; each new order is
// sent null-terminated, 'R' moves ROBOT1 to (-0.3, -0.1, 0) and 'G' prints where ROBOT1 is.
#include <cstdio>
#include <cstring>
#include <string>

#include <webots/Emitter.hpp>
#include <webots/Field.hpp>
#include <webots/Keyboard.hpp>
#include <webots/Node.hpp>
#include <webots/Supervisor.hpp>

using namespace webots;

static int scheduled_key(int ms) {
  switch (ms) {
    case 512: return 'F';
    case 1024: return 'T';
    case 1536: return 'S';
    case 2048: return 'R';
    case 2176: return 'G';
    case 2560: return 'A';
    case 3072: return 'G';
    default: return -1;
  }
}

int main() {
  Supervisor *driver = new Supervisor();
  const int step = 128;
  Emitter *emitter = driver->getEmitter("emitter");
  Node *robot = driver->getFromDef("ROBOT1");
  if (!robot)
    return 1;
  Field *translation = robot->getField("translation");
  Keyboard *keyboard = driver->getKeyboard();
  keyboard->enable(step);
  const double place[3] = {-0.3, -0.1, 0.0};
  std::string previous, message;
  while (driver->step(step) != -1) {
    const int ms = static_cast<int>(driver->getTime() * 1000 + 0.5);
    int key = keyboard->getKey();
    if (key == -1)
      key = scheduled_key(ms);
    switch (key) {
      case 'A': message = "avoid obstacles"; break;
      case 'F': message = "move forward"; break;
      case 'S': message = "stop"; break;
      case 'T': message = "turn"; break;
      case 'G': {
        const double *at = translation->getSFVec3f();
        std::printf("ROBOT1 is located at (%.17g,%.17g)\n", at[0], at[1]);
        break;
      }
      case 'R':
        std::printf("Teleport ROBOT1 at (%g,%g)\n", place[0], place[1]);
        translation->setSFVec3f(place);
        break;
      default: message.clear();
    }
    if (!message.empty() && message != previous) {
      previous = message;
      std::printf("Please, %s %d\n", message.c_str(), ms);
      emitter->send(message.c_str(), static_cast<int>(std::strlen(message.c_str())) + 1);
    }
    std::fflush(stdout);
  }
  delete driver;
  return 0;
}
