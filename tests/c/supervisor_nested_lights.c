/* A Webots-style C supervisor on tests/worlds/nested_lights.wbt (tests/test_supervisor_nested_lights.py):
 * finds the light HEADLIGHT inside the robot "carrier", reads its identity, parent and location, counts
 * children, switches it off and on, moves it in its Pose's frame and tries a negative intensity, printing
 * "key values" lines. */
#include <stdio.h>

#include <webots/light_sensor.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

int main(void) {
  wb_robot_init();
  int dt = (int)wb_robot_get_basic_time_step();
  WbDeviceTag ls = wb_robot_get_device("ls");
  wb_light_sensor_enable(ls, dt);

  WbNodeRef head = wb_supervisor_node_get_from_def("HEADLIGHT");
  WbNodeRef parent = wb_supervisor_node_get_parent_node(head);
  WbFieldRef location = wb_supervisor_node_get_field(head, "location");
  const double *at = wb_supervisor_field_get_sf_vec3f(location);
  printf("head %s %s %s %s %g %g %g %d\n", wb_supervisor_node_get_type_name(head),
         wb_supervisor_node_get_base_type_name(head), wb_supervisor_node_get_def(head), wb_supervisor_node_get_def(parent),
         at[0], at[1], at[2], wb_supervisor_node_get_from_id(wb_supervisor_node_get_id(head)) == head);
  WbNodeRef carrier = wb_supervisor_node_get_from_def("CARRIER");
  printf("count %d %d\n", wb_supervisor_field_get_count(wb_supervisor_node_get_field(carrier, "children")),
         wb_supervisor_field_get_count(wb_supervisor_node_get_field(parent, "children")));

  wb_robot_step(dt);
  double lit = wb_light_sensor_get_value(ls);
  WbFieldRef on = wb_supervisor_node_get_field(head, "on");
  wb_supervisor_field_set_sf_bool(on, false);
  wb_robot_step(dt);
  double off = wb_light_sensor_get_value(ls);
  wb_supervisor_field_set_sf_bool(on, true);
  const double further[3] = {0.0, 0.0, 1.0}; /* in the Pose's frame: the robot's x */
  wb_supervisor_field_set_sf_vec3f(location, further);
  wb_robot_step(dt);
  printf("ls %.17g %.17g %.17g\n", lit, off, wb_light_sensor_get_value(ls));

  WbFieldRef intensity = wb_supervisor_node_get_field(head, "intensity");
  wb_supervisor_field_set_sf_float(intensity, -1.0);
  wb_robot_step(dt);
  printf("bad %g\n", wb_supervisor_field_get_sf_float(intensity));
  wb_robot_cleanup();
  return 0;
}
