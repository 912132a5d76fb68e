/* Fields by index from C (tests/worlds/proto/supervisor_proto_harden.wbt): a base node's
 * wb_supervisor_node_get_number_of_fields/get_field_by_index and any node's
 * get_number_of_base_node_fields/get_base_node_field_by_index list the fields served here in Webots' declaration
 * order. The same stdout as tests/controllers/supervisor_field_index.py. */
#include <stdio.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

static void names(const char *what, WbNodeRef node, bool base) {
  int n = base ? wb_supervisor_node_get_number_of_base_node_fields(node) : wb_supervisor_node_get_number_of_fields(node);
  printf("%s %d", what, n);
  for (int i = 0; i < n; i++) {
    WbFieldRef f = base ? wb_supervisor_node_get_base_node_field_by_index(node, i) : wb_supervisor_node_get_field_by_index(node, i);
    printf(" %s", wb_supervisor_field_get_name(f));
  }
  printf("\n");
}

int main(void) {
  wb_robot_init();
  int step = (int)wb_robot_get_basic_time_step();
  wb_robot_step(step);
  WbNodeRef keeper = wb_supervisor_node_get_self();
  WbNodeRef box = wb_supervisor_node_get_from_def("BOX");
  WbNodeRef info = wb_supervisor_field_get_mf_node(wb_supervisor_node_get_field(wb_supervisor_node_get_root(), "children"), 0);
  names("box", box, false);
  names("boxbase", box, true);
  names("info", info, false);
  printf("keeper %d", wb_supervisor_node_get_number_of_fields(keeper));
  names("", keeper, true);
  WbFieldRef controller = wb_supervisor_node_get_base_node_field_by_index(keeper, 6);
  printf("controller %s %s\n", wb_supervisor_field_get_type_name(controller), wb_supervisor_field_get_sf_string(controller));
  const double *t = wb_supervisor_field_get_sf_vec3f(wb_supervisor_node_get_field_by_index(box, 0));
  printf("translation %g %g %g\n", t[0], t[1], t[2]);
  printf("bad %d %d\n", wb_supervisor_node_get_field_by_index(box, 6) == NULL,
         wb_supervisor_node_get_base_node_field_by_index(box, -1) == NULL);
  /* Keeper's body has no DEF BODY (NULL, no line); a base node is no PROTO; an empty DEF (lines) */
  printf("protodef %d %d %d %d\n", wb_supervisor_node_get_from_proto_def(keeper, "BODY") == NULL,
         wb_supervisor_node_get_from_proto_def(keeper, "BODY") == NULL, wb_supervisor_node_get_from_proto_def(box, "BODY") == NULL,
         wb_supervisor_node_get_from_proto_def(keeper, "") == NULL);
  wb_robot_cleanup();
  return 0;
}
