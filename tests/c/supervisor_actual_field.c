/* getActualField from C (tests/worlds/proto/supervisor_proto_fields.wbt): the sequence of
 * tests/controllers/supervisor_actual_field.py, the same lines; the actual field is the very ref getField gives. */
#include <stdio.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

static const char *name(WbFieldRef f) {
  return f ? wb_supervisor_field_get_name(f) : "NULL";
}

int main(void) {
  wb_robot_init();
  wb_robot_step((int)wb_robot_get_basic_time_step());
  WbNodeRef big = wb_supervisor_node_get_from_def("BIG");
  WbFieldRef own = wb_supervisor_node_get_field(big, "translation");
  WbFieldRef base = wb_supervisor_node_get_base_node_field(big, "translation");
  WbFieldRef actual = wb_supervisor_field_get_actual_field(base);
  printf("base translation %s %d\n", name(actual), actual == own);
  WbProtoRef parent = wb_supervisor_proto_get_parent(wb_supervisor_node_get_proto(big));
  WbFieldRef crate = wb_supervisor_field_get_actual_field(wb_supervisor_proto_get_field(parent, "translation"));
  printf("crate translation %s %d\n", name(crate), crate == own);
  printf("crate size %s\n", name(wb_supervisor_field_get_actual_field(wb_supervisor_proto_get_field(parent, "size"))));
  printf("own translation %d\n", wb_supervisor_field_get_actual_field(own) == own);
  const double to[3] = {3.0, -0.5, 0.2};
  wb_supervisor_field_set_sf_vec3f(actual, to);
  const double *v = wb_supervisor_field_get_sf_vec3f(base);
  printf("base after set %.17g %.17g %.17g\n", v[0], v[1], v[2]);
  WbNodeRef box = wb_supervisor_node_get_from_def("BOX");
  printf("box translation %d\n", wb_supervisor_field_get_actual_field(wb_supervisor_node_get_base_node_field(box, "translation")) ==
                                   wb_supervisor_node_get_field(box, "translation"));
  WbFieldRef children = wb_supervisor_node_get_base_node_field(wb_supervisor_node_get_self(), "children");
  printf("keeper children %s\n", name(wb_supervisor_field_get_actual_field(children)));
  wb_robot_cleanup();
  return 0;
}
