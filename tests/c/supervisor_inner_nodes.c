/* The C twin of tests/controllers/supervisor_inner_nodes.py (tests/worlds/supervisor_inner_nodes.wbt): a
 * wall and a crate imported; the wall's Shape reached through its children, its PBRAppearance through the
 * Shape's appearance field, its baseColor set and seen by the camera, its transparency set to 1 (the wall
 * hidden), 0.5 and 0 (shown again); an inner solid found by a dotted DEF, its position read; the wall
 * removed, its inner nodes then NULL by id. Prints the Python controller's lines, for
 * tests/test_supervisor_inner_nodes.py. */
#include <stdio.h>

#include <webots/camera.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

static WbDeviceTag camera;

static void centre(const char *label) { /* the BGRA pixel (2, 2) as R G B */
  const unsigned char *image = wb_camera_get_image(camera);
  const int k = 4 * (2 * wb_camera_get_width(camera) + 2);
  printf("%s %d %d %d\n", label, image[k + 2], image[k + 1], image[k]);
}

static void position(const char *label, WbNodeRef node) {
  const double *p = wb_supervisor_node_get_position(node);
  printf("%s %.6f %.6f %.6f\n", label, p[0], p[1], p[2]);
}

int main(void) {
  wb_robot_init();
  const int dt = (int)wb_robot_get_basic_time_step();
  camera = wb_robot_get_device("cam");
  wb_camera_enable(camera, dt);
  WbFieldRef root = wb_supervisor_node_get_field(wb_supervisor_node_get_root(), "children");
  wb_supervisor_field_import_mf_node_from_string(
    root, -1,
    "DEF BOX Solid { translation 2 0 0 name \"wall\" children [ Shape { appearance PBRAppearance { baseColor 1 0 0 "
    "roughness 1 metalness 0 } geometry Box { size 0.1 20 20 } } DEF INNER Solid { translation 0.3 -0.4 1.5 "
    "rotation 0 1 0 0.7 name \"inner\" children [ DEF KNOB Shape { appearance Appearance { material Material { "
    "diffuseColor 0 0 1 } } geometry Sphere { radius 0.05 } } ] } ] }");
  wb_supervisor_field_import_mf_node_from_string(
    root, -1,
    "DEF CRATE Solid { translation -1 3 0.5 rotation 0 0 1 0.5 name \"crate\" children [ DEF LID Solid { "
    "translation 0.2 0.1 0.3 rotation 1 0 0 0.25 name \"lid\" } ] }");
  wb_robot_step(dt);
  WbNodeRef box = wb_supervisor_node_get_from_def("BOX");
  WbFieldRef children = wb_supervisor_node_get_field(box, "children");
  WbNodeRef shape = wb_supervisor_field_get_mf_node(children, 0), inner = wb_supervisor_field_get_mf_node(children, 1);
  printf("children %d %s %s\n", wb_supervisor_field_get_count(children), wb_supervisor_node_get_type_name(shape),
         wb_supervisor_node_get_type_name(inner));
  WbNodeRef found = wb_supervisor_node_get_from_def("BOX.INNER");
  printf("inner %s %s %d\n", wb_supervisor_node_get_def(found),
         wb_supervisor_field_get_sf_string(wb_supervisor_node_get_field(found, "name")),
         wb_supervisor_node_get_id(found) == wb_supervisor_node_get_id(inner));
  position("position", found);
  position("lid", wb_supervisor_node_get_from_def("CRATE.LID"));
  centre("before");
  WbNodeRef appearance = wb_supervisor_field_get_sf_node(wb_supervisor_node_get_field(shape, "appearance"));
  const double colour[3] = {0.2, 0.6, 0.9};
  wb_supervisor_field_set_sf_color(wb_supervisor_node_get_field(appearance, "baseColor"), colour);
  wb_robot_step(dt);
  centre("after");
  WbFieldRef transparency = wb_supervisor_node_get_field(appearance, "transparency");
  const double chain[3] = {1.0, 0.5, 0.0};
  const char *labels[3] = {"hidden", "half", "shown"};
  for (int i = 0; i < 3; i++) {
    wb_supervisor_field_set_sf_float(transparency, chain[i]);
    wb_robot_step(dt);
    centre(labels[i]);
  }
  WbNodeRef knob = wb_supervisor_node_get_from_def("BOX.INNER.KNOB");
  const int ids[2] = {wb_supervisor_node_get_id(inner), wb_supervisor_node_get_id(knob)};
  wb_supervisor_node_remove(box);
  wb_robot_step(dt);
  printf("removed %d %d\n", wb_supervisor_node_get_from_id(ids[0]) == NULL, wb_supervisor_node_get_from_id(ids[1]) == NULL);
  wb_robot_cleanup();
  return 0;
}
