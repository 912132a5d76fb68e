/* A Webots-style C supervisor removing nodes (tests/worlds/supervisor_remove.yaml, its closed forms):
 * the distance sensor reads the crate, then the wall behind it once the crate is removed; the light
 * sensor loses the bulb's term; the removed nodes answer NULL (their poses NaN, their type names ""); a robot and
 * the root are refused.
 * Prints "key values" lines for tests/test_c_client.py. */
#include <stdio.h>

#include <webots/distance_sensor.h>
#include <webots/light_sensor.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

int main(void) {
  wb_robot_init();
  int dt = (int)wb_robot_get_basic_time_step();
  WbDeviceTag ds = wb_robot_get_device("ds"), eye = wb_robot_get_device("eye");
  wb_distance_sensor_enable(ds, dt);
  wb_light_sensor_enable(eye, dt);
  WbFieldRef children = wb_supervisor_node_get_field(wb_supervisor_node_get_root(), "children");

  wb_robot_step(dt);
  printf("before %.17g %.17g %d\n", wb_distance_sensor_get_value(ds), wb_light_sensor_get_value(eye),
         wb_supervisor_field_get_count(children));
  WbNodeRef crate = wb_supervisor_node_get_from_def("CRATE");
  int crate_id = wb_supervisor_node_get_id(crate);
  wb_supervisor_node_remove(crate);
  wb_supervisor_node_remove(wb_supervisor_node_get_from_def("bulb"));
  wb_robot_step(dt);
  printf("after %.17g %.17g %d\n", wb_distance_sensor_get_value(ds), wb_light_sensor_get_value(eye),
         wb_supervisor_field_get_count(children));
  printf("gone %d %d %d %d\n", crate_id, wb_supervisor_node_get_from_def("CRATE") == NULL,
         wb_supervisor_node_get_from_id(crate_id) == NULL,
         wb_supervisor_node_get_id(wb_supervisor_node_get_from_def("GATE")));
  wb_supervisor_node_remove(wb_supervisor_node_get_from_def("rover")); /* refused: one line */
  wb_supervisor_node_remove(wb_supervisor_node_get_root());            /* refused: one line */
  wb_supervisor_node_remove(NULL);                                     /* Webots' NULL line */
  wb_robot_set_custom_data("changed");                                 /* the reset restores it */
  wb_supervisor_simulation_reset();
  wb_robot_step(dt);
  printf("reset %.17g %d\n", wb_distance_sensor_get_value(ds), wb_supervisor_field_get_count(children));
  /* Webots never answers NULL for a pose: a removed or NULL node reads NaNs (and gets one line) */
  const double *p = wb_supervisor_node_get_position(crate), *o = wb_supervisor_node_get_orientation(crate);
  const double *q = wb_supervisor_node_get_position(NULL), *r = wb_supervisor_node_get_orientation(NULL);
  printf("removed_pose %g %g %g %g %g %g\n", p[0], p[2], o[0], o[8], q[1], r[4]);
  printf("custom_data [%s]\n", wb_robot_get_custom_data());
  /* a removed node's identity: Webots' line and its "no value" each, not what the node was */
  WbNodeRef gate = wb_supervisor_node_get_from_def("GATE");
  printf("stale [%s] [%s] %d [%s] %d %d live %s %s\n", wb_supervisor_node_get_type_name(crate),
         wb_supervisor_node_get_base_type_name(crate), (int)wb_supervisor_node_get_type(crate),
         wb_supervisor_node_get_def(crate), wb_supervisor_node_get_parent_node(crate) == NULL,
         wb_supervisor_node_get_id(crate),
         wb_supervisor_node_get_type_name(gate), wb_supervisor_node_get_def(gate));
  wb_robot_cleanup();
  return 0;
}
