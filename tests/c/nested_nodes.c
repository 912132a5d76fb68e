/* A Webots-style C supervisor reaching the nodes inside its robot and a solid
 * (tests/worlds/nested_nodes.wbt): by DEF and dotted path, by device, through parents and children;
 * the camera's world position before and after driving straight ahead, and in the robot's frame;
 * the left wheel's joint parameters (an SFNode) and their position after driving; the solid ARM's centre of
 * mass (with TIP's) before and after driving, and the robot's (no Physics: 0 0 0); the Pose BOARD inside the solid
 * SHELF (its type, parent, its solid's children count, its world position).
 * Prints "key values" lines for tests/test_c_client.py. */
#include <math.h>
#include <stdio.h>

#include <webots/motor.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

static void name(WbNodeRef n) {
  printf(" %s:%s:%s", wb_supervisor_node_get_type_name(n), wb_supervisor_node_get_def(n),
         wb_supervisor_field_get_sf_string(wb_supervisor_node_get_field(n, "name")));
}

int main(void) {
  wb_robot_init();
  int dt = (int)wb_robot_get_basic_time_step();
  wb_robot_step(dt);
  WbNodeRef cam = wb_supervisor_node_get_from_def("CAM");
  WbNodeRef tip = wb_supervisor_node_get_from_def("ROVER.ARM.TIP");
  printf("found");
  name(cam);
  name(tip);
  name(wb_supervisor_node_get_from_def("SHELF.BOARD.LID"));
  printf("\n");
  printf("parents %s %s %d\n", wb_supervisor_node_get_def(wb_supervisor_node_get_parent_node(cam)),
         wb_supervisor_node_get_def(wb_supervisor_node_get_parent_node(tip)),
         wb_supervisor_node_get_from_def("ROVER.CAM") == NULL);
  WbDeviceTag left = wb_robot_get_device("left wheel");
  WbNodeRef motor = wb_supervisor_node_get_from_device(left);
  printf("device %d %s %s %d\n", wb_supervisor_node_get_type(motor) == WB_NODE_ROTATIONAL_MOTOR,
         wb_supervisor_node_get_type_name(motor), wb_supervisor_node_get_def(wb_supervisor_node_get_parent_node(motor)),
         isnan(wb_supervisor_node_get_position(motor)[0]));
  printf("camera %d\n", wb_supervisor_node_get_type(wb_supervisor_node_get_from_device(wb_robot_get_device("cam"))) ==
                          WB_NODE_CAMERA);
  WbFieldRef children = wb_supervisor_node_get_field(wb_supervisor_node_get_self(), "children");
  printf("children");
  for (int i = 0; i < wb_supervisor_field_get_count(children); i++)
    printf(" %s", wb_supervisor_node_get_type_name(wb_supervisor_field_get_mf_node(children, i)));
  printf("\n");
  const double *t = wb_supervisor_field_get_sf_vec3f(wb_supervisor_node_get_field(tip, "translation"));
  printf("tip %.12f %.12f %.12f\n", t[0], t[1], t[2]);
  const double *p = wb_supervisor_node_get_position(cam);
  printf("before %.12f %.12f %.12f\n", p[0], p[1], p[2]);
  WbNodeRef arm = wb_supervisor_node_get_from_def("ARM");
  const double *c = wb_supervisor_node_get_center_of_mass(arm);
  printf("com_before %.12f %.12f %.12f\n", c[0], c[1], c[2]);
  c = wb_supervisor_node_get_center_of_mass(wb_supervisor_node_get_self()); /* no Physics: 0 0 0 */
  printf("com_robot %g %g %g\n", c[0], c[1], c[2]);
  WbDeviceTag right = wb_robot_get_device("right wheel");
  wb_motor_set_position(left, INFINITY);
  wb_motor_set_position(right, INFINITY);
  wb_motor_set_velocity(left, 2.0);
  wb_motor_set_velocity(right, 2.0);
  for (int i = 0; i < 10; i++)
    wb_robot_step(dt);
  p = wb_supervisor_node_get_position(cam);
  printf("after %.12f %.12f %.12f\n", p[0], p[1], p[2]);
  c = wb_supervisor_node_get_center_of_mass(arm);
  printf("com_after %.12f %.12f %.12f\n", c[0], c[1], c[2]);
  WbNodeRef joint = wb_supervisor_node_get_from_def("LEFT_JOINT");
  WbNodeRef params = wb_supervisor_field_get_sf_node(wb_supervisor_node_get_field(joint, "jointParameters"));
  printf("parameters %s %d %.12f\n", wb_supervisor_node_get_type_name(params),
         wb_supervisor_node_get_parent_node(params) == joint,
         wb_supervisor_field_get_sf_float(wb_supervisor_node_get_field(params, "position")));
  const double *m = wb_supervisor_node_get_pose(cam, wb_supervisor_node_get_self());
  printf("in_robot %.12f %.12f %.12f\n", m[3], m[7], m[11]);
  /* the Pose BOARD inside the top-level solid SHELF: LID's parent, SHELF's only child, at SHELF's pose composed with its own */
  WbNodeRef board = wb_supervisor_node_get_parent_node(wb_supervisor_node_get_from_def("SHELF.BOARD.LID"));
  WbNodeRef shelf = wb_supervisor_node_get_from_def("SHELF");
  const double *b = wb_supervisor_node_get_position(board);
  printf("board %s %s %d %d %.12f %.12f %.12f\n", wb_supervisor_node_get_type_name(board), wb_supervisor_node_get_def(board),
         wb_supervisor_node_get_parent_node(board) == shelf,
         wb_supervisor_field_get_count(wb_supervisor_node_get_field(shelf, "children")), b[0], b[1], b[2]);
  wb_supervisor_field_set_sf_vec3f(wb_supervisor_node_get_field(tip, "translation"), (double[3]){0, 0, 1});
  wb_robot_cleanup();
  return 0;
}
