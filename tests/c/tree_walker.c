/* A Webots-style C supervisor walking its robot's tree (tests/test_supervisor_nested_joints.py on
   tests/worlds/nested_joints.wbt), as tests/controllers/tree_walker.py does: every children and device
   field and each joint's endPoint, probing each node for them; one line per node (depth, type, DEF),
   then the link's boundingObject (Webots has it, Sensorium does not serve it). */
#include <stdio.h>
#include <webots/motor.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

static void walk(WbNodeRef node, int depth) {
  WbFieldRef params = wb_supervisor_node_get_field(node, "jointParameters");
  WbNodeRef p = params ? wb_supervisor_field_get_sf_node(params) : NULL;
  if (p)
    printf("%d %s %s %.3f\n", depth, wb_supervisor_node_get_type_name(node), wb_supervisor_node_get_def(node),
           wb_supervisor_field_get_sf_float(wb_supervisor_node_get_field(p, "position")));
  else
    printf("%d %s %s\n", depth, wb_supervisor_node_get_type_name(node), wb_supervisor_node_get_def(node));
  const char *names[] = {"children", "device"};
  for (int k = 0; k < 2; k++) {
    WbFieldRef field = wb_supervisor_node_get_field(node, names[k]);
    if (field != NULL)
      for (int i = 0; i < wb_supervisor_field_get_count(field); i++)
        walk(wb_supervisor_field_get_mf_node(field, i), depth + 1);
  }
  WbFieldRef end = wb_supervisor_node_get_field(node, "endPoint");
  if (end != NULL && wb_supervisor_field_get_sf_node(end) != NULL)
    walk(wb_supervisor_field_get_sf_node(end), depth + 1);
}

int main(void) {
  wb_robot_init();
  const int step = (int)wb_robot_get_basic_time_step();
  wb_motor_set_position(wb_robot_get_device("shoulder"), 0.5);
  for (int i = 0; i < 10; i++)
    wb_robot_step(step);
  walk(wb_supervisor_node_get_self(), 0);
  printf("boundingObject %s\n",
         wb_supervisor_node_get_field(wb_supervisor_node_get_from_def("LINK"), "boundingObject") ? "found" : "None");
  wb_robot_cleanup();
  return 0;
}
