/* importSFNodeFromString from C (tests/worlds/visual_trail.wbt): an imported PointSet without points gets its
 * Coordinate and Color from node strings, then its points are edited; a full slot, a node of the wrong type, a
 * field not served and a string that does not read are one line each. The same stdout as
 * tests/controllers/supervisor_sf_import.py. */
#include <stdio.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

int main(void) {
  wb_robot_init();
  int step = (int)wb_robot_get_basic_time_step();
  wb_robot_step(step);
  WbFieldRef children = wb_supervisor_node_get_field(wb_supervisor_node_get_root(), "children");
  wb_supervisor_field_import_mf_node_from_string(children, -1, "DEF DOTS Shape { geometry DEF DOT_SET PointSet { } }");
  WbNodeRef dots = wb_supervisor_node_get_from_def("DOT_SET");
  WbFieldRef coord = wb_supervisor_node_get_field(dots, "coord");
  WbFieldRef color = wb_supervisor_node_get_field(dots, "color");
  printf("empty %d %d\n", wb_supervisor_field_get_sf_node(coord) == NULL, wb_supervisor_field_get_sf_node(color) == NULL);
  wb_supervisor_field_import_sf_node_from_string(coord, "DEF DOT_POINTS Coordinate { point [ 1 2 3, 4 5 6 ] }");
  WbNodeRef points_node = wb_supervisor_field_get_sf_node(coord);
  WbFieldRef points = wb_supervisor_node_get_field(points_node, "point");
  const double seven[3] = {7, 8, 9};
  wb_supervisor_field_insert_mf_vec3f(points, -1, seven);
  const double *last = wb_supervisor_field_get_mf_vec3f(points, -1);
  const double l0 = last[0], l1 = last[1], l2 = last[2];
  printf("coord %s %s %d %d %d %g %g %g\n", wb_supervisor_node_get_type_name(points_node), wb_supervisor_node_get_def(points_node),
         wb_supervisor_node_get_from_def("DOT_POINTS") == points_node, wb_supervisor_node_get_parent_node(points_node) == dots,
         wb_supervisor_field_get_count(points), l0, l1, l2);
  wb_supervisor_field_import_sf_node_from_string(coord, "Coordinate { }");
  wb_supervisor_field_import_sf_node_from_string(color, "Coordinate { }");
  wb_supervisor_field_import_sf_node_from_string(
    wb_supervisor_node_get_field(wb_supervisor_node_get_from_def("DOTS"), "appearance"), "Appearance { }");
  wb_supervisor_field_import_sf_node_from_string(color, "Color { color [ 1 0");
  wb_supervisor_field_import_sf_node_from_string(color, "Color { color [ 1 0 0.5 ] }");
  WbNodeRef c = wb_supervisor_field_get_sf_node(color);
  const double *rgb = wb_supervisor_field_get_mf_color(wb_supervisor_node_get_field(c, "color"), 0);
  const double r = rgb[0], g = rgb[1], b = rgb[2];
  printf("color %s %g %g %g %d\n", wb_supervisor_node_get_type_name(c), r, g, b, wb_supervisor_field_get_count(points));
  wb_robot_cleanup();
  return 0;
}
