/* getFromProtoDef from C (tests/worlds/proto/supervisor_proto_def.wbt): the nodes of a PROTO instance's body
 * found by their DEF and read as any node, the scope of a nested PROTO instance, the NULLs. The same stdout as
 * tests/controllers/supervisor_proto_def.py. */
#include <stdio.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

static void g(const double *v, int n) {
  for (int i = 0; i < n; i++)
    printf(" %g", v[i]);
}

static int same(WbNodeRef a, WbNodeRef b) {
  return a != NULL && b != NULL && wb_supervisor_node_get_id(a) == wb_supervisor_node_get_id(b);
}

static WbFieldRef field(WbNodeRef n, const char *name) {
  return wb_supervisor_node_get_field(n, name);
}

int main(void) {
  wb_robot_init();
  wb_robot_step((int)wb_robot_get_basic_time_step());
  WbNodeRef rover = wb_supervisor_node_get_self();
  WbNodeRef shelf = wb_supervisor_node_get_from_def("SHELF");
  WbNodeRef box = wb_supervisor_node_get_from_def("BOX");

  WbNodeRef chassis = wb_supervisor_node_get_from_proto_def(rover, "CHASSIS");
  printf("chassis %s %d", wb_supervisor_node_get_type_name(chassis), same(wb_supervisor_node_get_parent_node(chassis), rover));
  g(wb_supervisor_field_get_sf_vec3f(field(chassis, "translation")), 3);
  WbNodeRef shape = wb_supervisor_node_get_from_proto_def(rover, "HULL_SHAPE");
  printf("\nshape %s %d\n", wb_supervisor_node_get_type_name(shape), same(wb_supervisor_node_get_parent_node(shape), chassis));
  WbNodeRef paint = wb_supervisor_node_get_from_proto_def(rover, "PAINT");
  printf("paint %s", wb_supervisor_node_get_type_name(paint));
  g(wb_supervisor_field_get_sf_color(field(paint, "baseColor")), 3);
  printf(" %g\n", wb_supervisor_field_get_sf_float(field(paint, "roughness")));
  WbNodeRef hull = wb_supervisor_node_get_from_proto_def(rover, "HULL");
  printf("hull %s", wb_supervisor_node_get_type_name(hull));
  g(wb_supervisor_field_get_sf_vec3f(field(hull, "size")), 3);
  WbNodeRef eye = wb_supervisor_node_get_from_proto_def(rover, "EYE");
  printf("\neye %s %s", wb_supervisor_node_get_type_name(eye), wb_supervisor_field_get_sf_string(field(eye, "name")));
  g(wb_supervisor_node_get_position(eye), 3);
  WbNodeRef arm = wb_supervisor_node_get_from_proto_def(rover, "ARM");
  printf("\narm %s %s %d\n", wb_supervisor_node_get_type_name(arm), wb_supervisor_node_get_base_type_name(arm),
         wb_supervisor_node_is_proto(arm));
  WbNodeRef tool = wb_supervisor_node_get_from_proto_def(rover, "TOOL");
  printf("tool %s", wb_supervisor_field_get_sf_string(field(tool, "name")));
  g(wb_supervisor_node_get_position(tool), 3);
  printf(" %d\n", same(tool, wb_supervisor_node_get_from_proto_def(arm, "TOOL")));
  printf("elbow %d %s %s %d\n", wb_supervisor_node_get_from_proto_def(rover, "ELBOW") == NULL,
         wb_supervisor_node_get_type_name(wb_supervisor_node_get_from_proto_def(arm, "ELBOW")),
         wb_supervisor_field_get_sf_string(field(wb_supervisor_node_get_from_proto_def(arm, "GRIP"), "name")),
         wb_supervisor_node_get_from_proto_def(arm, "CHASSIS") == NULL);
  printf("given %d\n", same(wb_supervisor_node_get_from_proto_def(rover, "GIVEN"), wb_supervisor_node_get_from_def("GIVEN")));
  WbNodeRef top = wb_supervisor_node_get_from_proto_def(rover, "TOP");
  WbNodeRef copy = wb_supervisor_field_get_mf_node(field(top, "children"), 0); /* the USE of HULL_SHAPE */
  printf("top %s %s %d %d\n", wb_supervisor_node_get_type_name(top), wb_supervisor_node_get_type_name(copy), same(copy, shape),
         same(wb_supervisor_node_get_parent_node(copy), top));
  printf("none %d %d %d %d %d %d\n", wb_supervisor_node_get_from_proto_def(rover, "NOPE") == NULL,
         wb_supervisor_node_get_from_proto_def(rover, "MASS") == NULL, wb_supervisor_node_get_from_proto_def(rover, "BOUND") == NULL,
         wb_supervisor_node_get_from_proto_def(rover, "ROVER") == NULL, wb_supervisor_node_get_from_proto_def(box, "INSIDE") == NULL,
         wb_supervisor_node_get_from_proto_def(rover, "") == NULL);
  WbNodeRef board = wb_supervisor_node_get_from_proto_def(shelf, "BOARD");
  printf("board %s %s", wb_supervisor_node_get_type_name(board), wb_supervisor_field_get_sf_string(field(board, "name")));
  g(wb_supervisor_node_get_position(board), 3);
  printf("\nleg %s", wb_supervisor_node_get_type_name(wb_supervisor_node_get_from_proto_def(shelf, "LEG")));
  g(wb_supervisor_field_get_sf_color(field(wb_supervisor_node_get_from_proto_def(shelf, "WOOD"), "diffuseColor")), 3);
  WbNodeRef bulb = wb_supervisor_node_get_from_proto_def(shelf, "BULB"); /* a light of the body: a node, under the shelf */
  printf("\nbulb %s %d", bulb ? wb_supervisor_node_get_type_name(bulb) : "NULL", same(wb_supervisor_node_get_parent_node(bulb), shelf));
  if (bulb)
    g(wb_supervisor_field_get_sf_vec3f(field(bulb, "location")), 3);
  printf("\n");
  wb_robot_cleanup();
  return 0;
}
