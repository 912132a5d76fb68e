/* Walks the PROTO chain of the node DEF DEEP with wb_supervisor_node_get_proto() and
 * wb_supervisor_proto_get_parent() until it ends, as tests/controllers/supervisor_proto_chain.py. */
#include <stdio.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

int main(void) {
  wb_robot_init();
  wb_robot_step((int)wb_robot_get_basic_time_step());
  WbProtoRef proto = wb_supervisor_node_get_proto(wb_supervisor_node_get_from_def("DEEP"));
  while (proto != NULL) {
    printf("%s %d %d\n", wb_supervisor_proto_get_type_name(proto), (int)wb_supervisor_proto_is_derived(proto),
           wb_supervisor_proto_get_number_of_fields(proto));
    proto = wb_supervisor_proto_get_parent(proto);
  }
  printf("end\n");
  fflush(stdout);
  wb_robot_cleanup();
  return 0;
}
