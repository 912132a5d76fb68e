/* exportString, worldSave and removeSF from C (tests/worlds/export_world.wbt): the box moved and exported, its
 * text imported again, the world saved where $EXPORT_SAVE names, an imported point set's coord taken out and
 * filled again, the robot's distance sensor exported; refusals one line each. The same stdout as tests/controllers/supervisor_export.py. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

int main(void) {
  wb_robot_init();
  int step = (int)wb_robot_get_basic_time_step();
  wb_robot_step(step);
  WbNodeRef box = wb_supervisor_node_get_from_def("BOX");
  const double to[3] = {1, 0, 0.1}, unturned[4] = {0, 0, 1, 0};
  wb_supervisor_field_set_sf_vec3f(wb_supervisor_node_get_field(box, "translation"), to);
  wb_supervisor_field_set_sf_rotation(wb_supervisor_node_get_field(box, "rotation"), unturned);
  const char *text = wb_supervisor_node_export_string(box);
  printf("%s\n", text);
  WbFieldRef children = wb_supervisor_node_get_field(wb_supervisor_node_get_root(), "children");
  wb_supervisor_field_import_mf_node_from_string(children, -1, text);
  WbNodeRef clone = wb_supervisor_field_get_mf_node(children, -1);
  const double *at = wb_supervisor_node_get_position(clone);
  printf("clone %s %s %g %g %g\n", wb_supervisor_node_get_def(clone),
         wb_supervisor_field_get_sf_string(wb_supervisor_node_get_field(clone, "name")), at[0], at[1], at[2]);
  int none = wb_supervisor_world_save(NULL), txt = wb_supervisor_world_save("saved.txt");
  printf("save %d %d %d\n", none, txt, wb_supervisor_world_save(getenv("EXPORT_SAVE")));
  wb_supervisor_field_import_mf_node_from_string(
    children, -1, "DEF DOTS Shape { appearance Appearance { } geometry DEF SET PointSet { coord Coordinate { point [ 1 2 3 ] } } }");
  WbFieldRef coord = wb_supervisor_node_get_field(wb_supervisor_node_get_from_def("SET"), "coord");
  wb_supervisor_field_remove_sf(coord);
  printf("removed %d\n", wb_supervisor_field_get_sf_node(coord) == NULL);
  wb_supervisor_field_remove_sf(coord); /* empty: nothing (no line) */
  wb_supervisor_field_import_sf_node_from_string(coord, "Coordinate { point [ 4 5 6, 7 8 9 ] }");
  printf("again %d\n", wb_supervisor_field_get_count(wb_supervisor_node_get_field(wb_supervisor_field_get_sf_node(coord), "point")));
  wb_supervisor_field_remove_sf(wb_supervisor_node_get_field(wb_supervisor_node_get_from_def("DOTS"), "appearance"));
  wb_supervisor_field_remove_sf(wb_supervisor_node_get_field(box, "translation"));
  const char *inside = wb_supervisor_node_export_string(wb_supervisor_node_get_from_device(wb_robot_get_device("ds")));
  printf("inside %.*s\n", (int)strcspn(inside, "\n"), inside); /* its first line */
  wb_robot_step(step);
  wb_robot_cleanup();
  return 0;
}
