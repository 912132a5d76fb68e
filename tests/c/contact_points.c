/* getContactPoints of tests/worlds/contact_points.wbt's nodes, and Webots' deprecated per-index functions
 * (tests/test_supervisor_contacts.py; tests/controllers/contact_points.py prints the same). */
#include <stdio.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

static void show(const char *label, WbNodeRef node, bool descendants) {
  int size = -1;
  WbContactPoint *points = wb_supervisor_node_get_contact_points(node, descendants, &size);
  printf("%s %d\n", label, size);
  for (int i = 0; i < size; i++)
    printf("%.4f %.4f %.4f %s\n", points[i].point[0], points[i].point[1], points[i].point[2],
           wb_supervisor_node_get_def(wb_supervisor_node_get_from_id(points[i].node_id)));
}

int main(void) {
  wb_robot_init();
  int dt = (int)wb_robot_get_basic_time_step();
  wb_robot_step(dt);
  WbNodeRef box = wb_supervisor_node_get_from_def("BOX"), cart = wb_supervisor_node_get_from_def("CART");
  show("box", box, false);
  show("ball", wb_supervisor_node_get_from_def("BALL"), false);
  show("cart own", cart, false);
  show("cart all", cart, true);
  wb_supervisor_node_enable_contact_points_tracking(cart, dt, true);
  printf("count %d %d\n", wb_supervisor_node_get_number_of_contact_points(cart, true),
         wb_supervisor_node_get_number_of_contact_points(cart, false));
  int n = wb_supervisor_node_get_number_of_contact_points(cart, true);
  const double *last = wb_supervisor_node_get_contact_point(cart, n - 1);
  printf("last %.4f %.4f %.4f %s\n", last[0], last[1], last[2],
         wb_supervisor_node_get_def(wb_supervisor_node_get_contact_point_node(cart, n - 1)));
  const double *past = wb_supervisor_node_get_contact_point(cart, n);
  printf("past %.4f %.4f %.4f %s\n", past[0], past[1], past[2],
         wb_supervisor_node_get_contact_point_node(cart, n) == NULL ? "None" : "node");
  wb_supervisor_node_disable_contact_points_tracking(cart);
  wb_supervisor_field_set_sf_vec3f(wb_supervisor_node_get_field(box, "translation"), (double[3]){1, 0, 0.55});
  show("air", box, true);
  int size = -1;
  wb_supervisor_node_get_contact_points(box, false, &size); /* Webots' library answers a step's first query again */
  printf("same step %d\n", size);
  wb_robot_step(dt);
  wb_supervisor_node_get_contact_points(box, false, &size); /* asked again: in the air, falling */
  printf("next step %d\n", size);
  show("root", wb_supervisor_node_get_root(), true);
  wb_robot_cleanup();
  return 0;
}
