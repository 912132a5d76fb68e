/* wb_supervisor_node_set_velocity with hostile arguments (tests/test_fuzz_set_velocity.py, tests/worlds/
 * reset_falls.wbt), built with sanitizers: a NULL node, a NULL velocity, NaN and infinities at each place,
 * zeros on the root and on the box's Shape (no Solids: Webots' warning each, nothing stopped), a denormal (not zero: the one warning), then
 * zeros with -0.0 on the falling box (resetPhysics). Prints one JSON line: the box's height after the lift and
 * 4 steps, its vertical velocity after the hostile calls (still falling) and after the zeros (0). */
#include <math.h>
#include <stdio.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

int main(void) {
  wb_robot_init();
  int dt = (int)wb_robot_get_basic_time_step();
  wb_robot_step(dt);
  WbNodeRef box = wb_supervisor_node_get_from_def("LOAD");
  WbNodeRef root = wb_supervisor_node_get_root();
  WbFieldRef translation = wb_supervisor_node_get_field(box, "translation");
  const double up[3] = {0.0, 0.0, 1.0};
  wb_supervisor_field_set_sf_vec3f(translation, up);
  for (int k = 0; k < 4; k++)
    wb_robot_step(dt);
  double z = wb_supervisor_field_get_sf_vec3f(translation)[2];
  const double zero[6] = {0.0, -0.0, 0.0, 0.0, -0.0, 0.0};
  wb_supervisor_node_set_velocity(NULL, zero);
  wb_supervisor_node_set_velocity(box, NULL);
  for (int i = 0; i < 6; i++) {
    double bad[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    bad[i] = i % 3 == 0 ? NAN : i % 3 == 1 ? INFINITY : -INFINITY;
    wb_supervisor_node_set_velocity(box, bad);
  }
  wb_supervisor_node_set_velocity(root, zero);
  WbNodeRef shape = wb_supervisor_field_get_mf_node(wb_supervisor_node_get_field(box, "children"), 0);
  wb_supervisor_node_set_velocity(shape, zero); /* a Shape is no Solid either: the same warning, nothing stopped */
  const double tiny[6] = {0.0, 0.0, 4.9406564584124654e-324, 0.0, 0.0, 0.0};
  wb_supervisor_node_set_velocity(box, tiny);
  wb_supervisor_node_set_velocity(box, tiny);
  double falling = wb_supervisor_node_get_velocity(box)[2];
  wb_supervisor_node_set_velocity(box, zero);
  double stopped = wb_supervisor_node_get_velocity(box)[2];
  printf("{\"z\": %.17g, \"falling\": %.17g, \"stopped\": %.17g}\n", z, falling, stopped);
  fflush(stdout);
  wb_robot_cleanup();
  return 0;
}
