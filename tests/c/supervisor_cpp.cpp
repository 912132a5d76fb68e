// The Supervisor C++ classes (tests/worlds/cdevices.yaml, robot rover): move buddy, read it back.
#include <cmath>
#include <cstdio>

#include <webots/LED.hpp>
#include <webots/PositionSensor.hpp>
#include <webots/Supervisor.hpp>

using namespace webots;

int main() {
  Supervisor *supervisor = new Supervisor();
  int dt = static_cast<int>(supervisor->getBasicTimeStep());
  Node *buddy = supervisor->getFromDef("buddy");
  if (buddy == 0 || supervisor->getFromDef("buddy") != buddy || supervisor->getFromDef("nobody") != 0)
    return 3;
  Field *translation = buddy->getField("translation");
  const double where[3] = {0.125, 0.25, 0.0};
  translation->setSFVec3f(where);
  supervisor->getLED("led0")->set(1);
  PositionSensor *encoder = supervisor->getPositionSensor("left wheel sensor");
  encoder->enable(dt);
  supervisor->getMotor("left wheel motor")->setPosition(1e9);
  supervisor->step(dt);
  const double *p = buddy->getPosition();
  std::printf("%s %d %.17g %.17g %.17g %d %s %d %d\n", supervisor->getModel().c_str(), translation->getType(), p[0],
              p[1], p[2], supervisor->getLED("led0")->get(), encoder->getMotor()->getName().c_str(),
              encoder->getMotor()->getPositionSensor() == encoder, supervisor->simulationGetMode());
  std::printf("%.17g\n", encoder->getValue());
  int size = -1;  // no physics contacts, no robot window
  supervisor->wwiSendText("hello window");
  bool none = buddy->getContactPoints(false, &size) == 0;
  std::printf("%d %d %s %d", buddy->getNumberOfContactPoints(true), none,
              std::isnan(buddy->getContactPoint(0)[2]) ? "nan" : "value", size);
  size = -1;
  none = supervisor->wwiReceive(&size) == 0;
  std::printf(" %d %s %d\n", static_cast<int>(supervisor->wwiReceiveText().size()), none ? "NULL" : "data", size);
  // beyond what Sensorium serves: Webots' methods, "no value"; then what it serves
  std::printf("%d %d %s %d %d %d\n", supervisor->getSelected() == 0, buddy->getType() == Node::ROBOT,
              translation->getTypeName().c_str(), translation->getCount(), buddy->getId() > 0,
              buddy->getField("translation") == translation);
  // the scene tree, identity and velocities through the C++ classes
  Field *children = supervisor->getRoot()->getField("children");
  std::printf("%d %s %s %s %s %g %d\n", children->getCount(), children->getMFNode(-1)->getTypeName().c_str(),
              children->getMFNode(3)->getField("name")->getSFString().c_str(),
              buddy->getParentNode()->getTypeName().c_str(), supervisor->getFromId(6)->getBaseTypeName().c_str(),
              buddy->getVelocity()[0], supervisor->getFromId(6)->getField("on")->getSFBool());
  delete supervisor;
  return 0;
}
