/* A Webots-style C supervisor walking the root's children (tests/worlds/root_children.wbt): each
 * child's type name and DEF in file order, the first one WorldInfo with its gravity, then a node
 * imported at a position. Prints "key values" lines for tests/test_c_client.py. */
#include <stdio.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

static void walk(const char *key, WbFieldRef children) {
  printf("%s", key);
  for (int i = 0; i < wb_supervisor_field_get_count(children); i++) {
    WbNodeRef n = wb_supervisor_field_get_mf_node(children, i);
    printf(" %s:%s", wb_supervisor_node_get_type_name(n), wb_supervisor_node_get_def(n));
  }
  printf("\n");
}

int main(void) {
  wb_robot_init();
  int dt = (int)wb_robot_get_basic_time_step();
  WbFieldRef children = wb_supervisor_node_get_field(wb_supervisor_node_get_root(), "children");
  wb_robot_step(dt);
  walk("children", children);
  WbNodeRef info = wb_supervisor_field_get_mf_node(children, 0);
  printf("info %d %.17g %.17g %s\n", wb_supervisor_node_get_type(info) == WB_NODE_WORLD_INFO,
         wb_supervisor_field_get_sf_float(wb_supervisor_node_get_field(info, "gravity")),
         wb_supervisor_field_get_sf_float(wb_supervisor_node_get_field(info, "basicTimeStep")),
         wb_supervisor_field_get_sf_string(wb_supervisor_node_get_field(info, "gpsCoordinateSystem")));
  const double *view = wb_supervisor_field_get_sf_vec3f(
    wb_supervisor_node_get_field(wb_supervisor_field_get_mf_node(children, 1), "position"));
  printf("view %g %g %g\n", view[0], view[1], view[2]);
  wb_supervisor_field_import_mf_node_from_string(children, 3, "DEF BALL Solid { name \"ball\" }");
  wb_robot_step(dt);
  walk("imported", children);
  wb_supervisor_node_remove(wb_supervisor_node_get_from_def("BALL"));
  wb_robot_step(dt);
  walk("removed", children);
  wb_robot_cleanup();
  return 0;
}
