/* moveViewpoint from C (tests/worlds/move_viewpoint.wbt): the sequence of
 * tests/controllers/supervisor_move_viewpoint.py, the same lines. */
#include <stdio.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

static WbFieldRef position;

static void show(const char *what) {
  const double *p = wb_supervisor_field_get_sf_vec3f(position);
  printf("%s %.3f %.3f %.3f\n", what, p[0], p[1], p[2]);
}

int main(void) {
  wb_robot_init();
  int step = (int)wb_robot_get_basic_time_step();
  position = wb_supervisor_node_get_field(wb_supervisor_node_get_from_def("VIEW"), "position");
  wb_robot_step(step);
  show("before");
  wb_supervisor_node_move_viewpoint(wb_supervisor_node_get_from_def("BALL"));
  show("after");
  wb_supervisor_simulation_reset();
  wb_robot_step(step);
  show("reset");
  wb_robot_cleanup();
  return 0;
}
