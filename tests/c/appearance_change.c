/* A Webots-style C supervisor changing a wall's colour and its camera seeing it
 * (tests/worlds/appearance_change.wbt): the wall's Shape reached through its solid's children, its
 * PBRAppearance through the Shape's appearance field (wb_supervisor_field_get_sf_node), its baseColor
 * set; a Material found by DEF. Prints the lines tests/controllers/appearance_change.py prints. */
#include <stdio.h>

#include <webots/camera.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

static WbDeviceTag camera;

static void centre(void) {
  const unsigned char *image = wb_camera_get_image(camera);
  int k = 4 * (2 * wb_camera_get_width(camera) + 2);
  printf(" %d %d %d", image[k + 2], image[k + 1], image[k]);
}

static void numbers(const double *v, int n) {
  for (int i = 0; i < n; i++)
    printf(" %g", v[i]);
}

int main(void) {
  wb_robot_init();
  int dt = (int)wb_robot_get_basic_time_step();
  camera = wb_robot_get_device("cam");
  wb_camera_enable(camera, dt);
  wb_robot_step(dt);
  printf("before");
  centre();
  printf("\n");
  WbFieldRef children = wb_supervisor_node_get_field(wb_supervisor_node_get_from_def("WALL"), "children");
  WbNodeRef shape = wb_supervisor_field_get_mf_node(children, 0);
  WbNodeRef appearance = wb_supervisor_field_get_sf_node(wb_supervisor_node_get_field(shape, "appearance"));
  WbNodeRef box = wb_supervisor_field_get_sf_node(wb_supervisor_node_get_field(shape, "geometry"));
  printf("nodes %s %s %s %s %d %d %d\n", wb_supervisor_node_get_type_name(shape),
         wb_supervisor_node_get_type_name(appearance), wb_supervisor_node_get_def(appearance),
         wb_supervisor_node_get_type_name(box), wb_supervisor_node_get_type(appearance) == WB_NODE_PBR_APPEARANCE,
         wb_supervisor_node_get_type(box) == WB_NODE_BOX,
         wb_supervisor_node_get_id(wb_supervisor_node_get_parent_node(appearance)) == wb_supervisor_node_get_id(shape));
  printf("size");
  numbers(wb_supervisor_field_get_sf_vec3f(wb_supervisor_node_get_field(box, "size")), 3);
  printf("\n");
  WbFieldRef color = wb_supervisor_node_get_field(appearance, "baseColor");
  printf("color");
  numbers(wb_supervisor_field_get_sf_color(color), 3);
  printf(" %g\n", wb_supervisor_field_get_sf_float(wb_supervisor_node_get_field(appearance, "metalness")));
  const double blue[3] = {0.3, 0.6, 0.9};
  wb_supervisor_field_set_sf_color(color, blue);
  wb_robot_step(dt);
  printf("after");
  centre();
  numbers(wb_supervisor_field_get_sf_color(color), 3);
  printf("\n");
  WbNodeRef material = wb_supervisor_node_get_from_def("PANEL_MATERIAL");
  WbNodeRef ball =
    wb_supervisor_field_get_mf_node(wb_supervisor_node_get_field(wb_supervisor_node_get_from_def("PANEL"), "children"), 1);
  WbNodeRef panel_appearance = wb_supervisor_field_get_sf_node(wb_supervisor_node_get_field(ball, "appearance"));
  WbNodeRef reached = wb_supervisor_field_get_sf_node(wb_supervisor_node_get_field(panel_appearance, "material"));
  printf("reached %d %d %s\n", wb_supervisor_node_get_id(reached) == wb_supervisor_node_get_id(material),
         wb_supervisor_node_get_type(material) == WB_NODE_MATERIAL, wb_supervisor_node_get_base_type_name(reached));
  WbFieldRef diffuse = wb_supervisor_node_get_field(material, "diffuseColor");
  printf("material %s", wb_supervisor_node_get_type_name(material));
  numbers(wb_supervisor_field_get_sf_color(diffuse), 3);
  printf(" %g\n", wb_supervisor_field_get_sf_float(wb_supervisor_node_get_field(material, "transparency")));
  const double brown[3] = {0.5, 0.25, 0.125};
  wb_supervisor_field_set_sf_color(diffuse, brown);
  wb_robot_step(dt);
  printf("material");
  numbers(wb_supervisor_field_get_sf_color(diffuse), 3);
  printf("\n");
  wb_robot_cleanup();
  return 0;
}
