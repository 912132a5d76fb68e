// getFromProtoDef through the C++ classes (tests/worlds/proto/supervisor_proto_def.wbt, robot rover): the node of
// a PROTO's body found by DEF, a nested instance's own scope, the NULLs (tests/test_supervisor_proto_def.py).
#include <cstdio>

#include <webots/Supervisor.hpp>

using namespace webots;

int main() {
  Supervisor *supervisor = new Supervisor();
  supervisor->step(static_cast<int>(supervisor->getBasicTimeStep()));
  Node *rover = supervisor->getSelf();
  Node *eye = rover->getFromProtoDef("EYE");
  Node *arm = rover->getFromProtoDef("ARM");
  const double *p = eye->getPosition();
  std::printf("%s %s %g %g %g\n", eye->getTypeName().c_str(), eye->getField("name")->getSFString().c_str(), p[0], p[1],
              p[2]);
  std::printf("%s %s %d %d %d\n", arm->getTypeName().c_str(), arm->getFromProtoDef("ELBOW")->getTypeName().c_str(),
              rover->getFromProtoDef("ELBOW") == 0, rover->getFromProtoDef("MASS") == 0,
              rover->getFromProtoDef("EYE") == eye);
  delete supervisor;
  return 0;
}
