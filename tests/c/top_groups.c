/* A Webots-style C supervisor walking a top-level DEF Pose of solids (tests/worlds/top_groups.wbt),
 * as Webots' robotbenchmark referees walk their DEF Groups of obstacles. Prints "key values" lines
 * for tests/test_c_client.py. */
#include <stdio.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

int main(void) {
  wb_robot_init();
  wb_robot_step((int)wb_robot_get_basic_time_step());
  WbNodeRef trio = wb_supervisor_node_get_from_def("TRIO");
  WbFieldRef children = wb_supervisor_node_get_field(trio, "children");
  printf("group %d %s %d\n", wb_supervisor_node_get_type(trio) == WB_NODE_POSE, wb_supervisor_node_get_type_name(trio),
         wb_supervisor_field_get_count(children));
  for (int i = 0; i < wb_supervisor_field_get_count(children); i++) {
    const double *p = wb_supervisor_node_get_position(wb_supervisor_field_get_mf_node(children, i));
    printf("at %.9f %.9f %.9f\n", p[0], p[1], p[2]);
  }
  printf("same %d\n", wb_supervisor_field_get_mf_node(children, 1) == wb_supervisor_node_get_from_def("MID"));
  const double *t = wb_supervisor_field_get_sf_vec3f(wb_supervisor_node_get_field(trio, "translation"));
  printf("translation %g %g %g\n", t[0], t[1], t[2]);
  wb_robot_cleanup();
  return 0;
}
