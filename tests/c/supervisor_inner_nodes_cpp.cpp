// The C++ twin of tests/controllers/supervisor_inner_nodes.py through webots::Supervisor, Node and Field
// (tests/worlds/supervisor_inner_nodes.wbt): the same imports, inner nodes reached by DEF and through fields,
// colour and transparency set, positions read, the wall removed; prints the Python controller's lines.
#include <cstdio>
#include <string>

#include <webots/Camera.hpp>
#include <webots/Supervisor.hpp>

using namespace webots;

static void centre(const Camera *camera, const char *label) {  // the BGRA pixel (2, 2) as R G B
  const unsigned char *image = camera->getImage();
  const int k = 4 * (2 * camera->getWidth() + 2);
  std::printf("%s %d %d %d\n", label, image[k + 2], image[k + 1], image[k]);
}

static void position(const char *label, const Node *node) {
  const double *p = node->getPosition();
  std::printf("%s %.6f %.6f %.6f\n", label, p[0], p[1], p[2]);
}

int main() {
  Supervisor *robot = new Supervisor();
  const int dt = static_cast<int>(robot->getBasicTimeStep());
  Camera *camera = robot->getCamera("cam");
  camera->enable(dt);
  Field *root = robot->getRoot()->getField("children");
  root->importMFNodeFromString(
    -1, "DEF BOX Solid { translation 2 0 0 name \"wall\" children [ Shape { appearance PBRAppearance { baseColor 1 0 0 "
        "roughness 1 metalness 0 } geometry Box { size 0.1 20 20 } } DEF INNER Solid { translation 0.3 -0.4 1.5 "
        "rotation 0 1 0 0.7 name \"inner\" children [ DEF KNOB Shape { appearance Appearance { material Material { "
        "diffuseColor 0 0 1 } } geometry Sphere { radius 0.05 } } ] } ] }");
  root->importMFNodeFromString(-1, "DEF CRATE Solid { translation -1 3 0.5 rotation 0 0 1 0.5 name \"crate\" children [ "
                                   "DEF LID Solid { translation 0.2 0.1 0.3 rotation 1 0 0 0.25 name \"lid\" } ] }");
  robot->step(dt);
  Node *box = robot->getFromDef("BOX");
  Field *children = box->getField("children");
  Node *shape = children->getMFNode(0), *inner = children->getMFNode(1);
  std::printf("children %d %s %s\n", children->getCount(), shape->getTypeName().c_str(), inner->getTypeName().c_str());
  Node *found = robot->getFromDef("BOX.INNER");
  std::printf("inner %s %s %d\n", found->getDef().c_str(), found->getField("name")->getSFString().c_str(),
              found->getId() == inner->getId());
  position("position", found);
  position("lid", robot->getFromDef("CRATE.LID"));
  centre(camera, "before");
  Node *appearance = shape->getField("appearance")->getSFNode();
  const double colour[3] = {0.2, 0.6, 0.9};
  appearance->getField("baseColor")->setSFColor(colour);
  robot->step(dt);
  centre(camera, "after");
  Field *transparency = appearance->getField("transparency");
  const double chain[3] = {1.0, 0.5, 0.0};
  const char *labels[3] = {"hidden", "half", "shown"};
  for (int i = 0; i < 3; i++) {
    transparency->setSFFloat(chain[i]);
    robot->step(dt);
    centre(camera, labels[i]);
  }
  const int ids[2] = {inner->getId(), robot->getFromDef("BOX.INNER.KNOB")->getId()};
  box->remove();
  robot->step(dt);
  std::printf("removed %d %d\n", robot->getFromId(ids[0]) == NULL, robot->getFromId(ids[1]) == NULL);
  delete robot;
  return 0;
}
