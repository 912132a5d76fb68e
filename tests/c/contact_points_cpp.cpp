// getContactPoints through our C++ layer (webots::Node) on tests/worlds/contact_points.wbt: the same lines
// as tests/controllers/contact_points.py and tests/c/contact_points.c (tests/test_supervisor_contacts.py).
#include <cstdio>

#include <webots/Field.hpp>
#include <webots/Node.hpp>
#include <webots/Supervisor.hpp>

using namespace webots;

static Supervisor *s;

static void show(const char *label, Node *node, bool descendants) {
  int size = -1;
  ContactPoint *points = node->getContactPoints(descendants, &size);
  std::printf("%s %d\n", label, size);
  for (int i = 0; i < size; i++)
    std::printf("%.4f %.4f %.4f %s\n", points[i].point[0], points[i].point[1], points[i].point[2],
                s->getFromId(points[i].node_id)->getDef().c_str());
}

int main() {
  s = new Supervisor();
  int dt = (int)s->getBasicTimeStep();
  s->step(dt);
  Node *box = s->getFromDef("BOX"), *cart = s->getFromDef("CART");
  show("box", box, false);
  show("ball", s->getFromDef("BALL"), false);
  show("cart own", cart, false);
  show("cart all", cart, true);
  cart->enableContactPointsTracking(dt, true);
  int all = cart->getNumberOfContactPoints(true);
  std::printf("count %d %d\n", all, cart->getNumberOfContactPoints(false));
  int n = cart->getNumberOfContactPoints(true);
  const double *last = cart->getContactPoint(n - 1);
  std::printf("last %.4f %.4f %.4f", last[0], last[1], last[2]);
  std::printf(" %s\n", cart->getContactPointNode(n - 1)->getDef().c_str());
  const double *past = cart->getContactPoint(n);
  std::printf("past %.4f %.4f %.4f", past[0], past[1], past[2]);
  std::printf(" %s\n", cart->getContactPointNode(n) == NULL ? "None" : "node");
  cart->disableContactPointsTracking();
  const double up[3] = {1, 0, 0.55};
  box->getField("translation")->setSFVec3f(up);
  show("air", box, true);
  int size = -1;
  box->getContactPoints(false, &size);  // Webots' library answers a step's first query again
  std::printf("same step %d\n", size);
  s->step(dt);
  box->getContactPoints(false, &size);  // asked again: in the air, falling
  std::printf("next step %d\n", size);
  show("root", s->getRoot(), true);
  delete s;
  return 0;
}
