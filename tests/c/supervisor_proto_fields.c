/* PROTO instances' own fields from C (tests/worlds/proto/supervisor_proto_fields.wbt): the sequence of
 * tests/controllers/supervisor_proto_fields.py, the same lines (numbers as %.17g). */
#include <stdio.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

static void numbers(const double *v, int n) {
  for (int i = 0; i < n; i++)
    printf(" %.17g", v ? v[i] : -999.0);
}

int main(void) {
  wb_robot_init();
  int step = (int)wb_robot_get_basic_time_step();
  wb_robot_step(step);
  WbNodeRef me = wb_supervisor_node_get_self();
  WbProtoRef proto = wb_supervisor_node_get_proto(me);
  printf("proto %s %d %d\n", wb_supervisor_proto_get_type_name(proto), wb_supervisor_proto_is_derived(proto),
         wb_supervisor_proto_get_number_of_fields(proto));
  printf("node_count %d\n", wb_supervisor_node_get_number_of_fields(me));
  WbFieldRef reach = wb_supervisor_node_get_field(me, "reach");
  printf("reach %s %.17g\n", wb_supervisor_field_get_type_name(reach), wb_supervisor_field_get_sf_float(reach));
  printf("level %d\n", wb_supervisor_field_get_sf_int32(wb_supervisor_node_get_field(me, "level")));
  printf("active %d\n", wb_supervisor_field_get_sf_bool(wb_supervisor_node_get_field(me, "active")));
  printf("footprint");
  numbers(wb_supervisor_field_get_sf_vec2f(wb_supervisor_node_get_field(me, "footprint")), 2);
  printf("\ncolor");
  numbers(wb_supervisor_field_get_sf_color(wb_supervisor_node_get_field(me, "color")), 3);
  WbFieldRef gains = wb_supervisor_node_get_field(me, "gains");
  printf("\ngains %d %.17g %.17g\n", wb_supervisor_field_get_count(gains), wb_supervisor_field_get_mf_float(gains, 0),
         wb_supervisor_field_get_mf_float(gains, 1));
  WbFieldRef waypoints = wb_supervisor_node_get_field(me, "waypoints");
  printf("waypoints %d", wb_supervisor_field_get_count(waypoints));
  numbers(wb_supervisor_field_get_mf_vec3f(waypoints, -1), 3);
  WbFieldRef tags = wb_supervisor_node_get_field(me, "tags");
  printf("\ntags %d %s\n", wb_supervisor_field_get_count(tags), wb_supervisor_field_get_mf_string(tags, 0));
  WbFieldRef ids = wb_supervisor_node_get_field(me, "ids");
  printf("ids %d %d %d\n", wb_supervisor_field_get_count(ids), wb_supervisor_field_get_mf_int32(ids, 0),
         wb_supervisor_field_get_mf_int32(ids, 1));
  WbFieldRef flags = wb_supervisor_node_get_field(me, "flags");
  printf("flags %d %d %d\n", wb_supervisor_field_get_count(flags), wb_supervisor_field_get_mf_bool(flags, 0),
         wb_supervisor_field_get_mf_bool(flags, 1));
  WbFieldRef slot = wb_supervisor_node_get_field(me, "bodySlot");
  printf("slot %s %d\n", wb_supervisor_field_get_type_name(slot), wb_supervisor_field_get_count(slot));
  printf("byindex %s %s\n", wb_supervisor_field_get_name(wb_supervisor_node_get_field_by_index(me, 3)),
         wb_supervisor_field_get_type_name(wb_supervisor_proto_get_field_by_index(proto, 13)));
  printf("base %s %d\n", wb_supervisor_field_get_sf_string(wb_supervisor_node_get_base_node_field(me, "controller")),
         wb_supervisor_field_get_sf_bool(wb_supervisor_node_get_base_node_field(me, "supervisor")));
  printf("none %s\n", wb_supervisor_node_get_field(me, "controller") == NULL ? "null" : "field");
  WbProtoRef big = wb_supervisor_node_get_proto(wb_supervisor_node_get_from_def("BIG"));
  printf("big %s %d %d\n", wb_supervisor_proto_get_type_name(big), wb_supervisor_proto_is_derived(big),
         wb_supervisor_proto_get_number_of_fields(big));
  WbProtoRef parent = wb_supervisor_proto_get_parent(big);
  printf("parent %s %d %d", wb_supervisor_proto_get_type_name(parent), wb_supervisor_proto_is_derived(parent),
         wb_supervisor_proto_get_number_of_fields(parent));
  numbers(wb_supervisor_field_get_sf_vec3f(wb_supervisor_proto_get_field(parent, "size")), 3);
  printf("\ngrand %s\n", wb_supervisor_proto_get_parent(parent) == NULL ? "null" : "proto");
  WbNodeRef crate = wb_supervisor_node_get_from_def("CRATE");
  printf("crate");
  numbers(wb_supervisor_field_get_sf_vec3f(wb_supervisor_node_get_field(crate, "size")), 3);
  printf("\nbox %s\n", wb_supervisor_node_get_proto(wb_supervisor_node_get_from_def("BOX")) == NULL ? "null" : "proto");
  WbNodeRef tag = wb_supervisor_node_get_from_def("TAG");
  printf("tag %s %.17g", wb_supervisor_node_get_type_name(tag),
         wb_supervisor_field_get_sf_float(wb_supervisor_node_get_field(tag, "weight")));
  numbers(wb_supervisor_field_get_sf_vec3f(wb_supervisor_node_get_field(tag, "translation")), 3);
  const double moved[3] = {1.5, 0.0, 0.1}, bigger[3] = {1.0, 1.0, 1.0};
  wb_supervisor_field_set_sf_vec3f(wb_supervisor_node_get_field(crate, "translation"), moved);
  wb_supervisor_field_set_sf_vec3f(wb_supervisor_node_get_field(crate, "size"), bigger); /* built again, where it was moved */
  wb_robot_step(step);
  printf("\nset");
  numbers(wb_supervisor_field_get_sf_vec3f(wb_supervisor_node_get_base_node_field(crate, "translation")), 3);
  numbers(wb_supervisor_field_get_sf_vec3f(wb_supervisor_node_get_field(crate, "size")), 3);
  printf("\n");
  fflush(stdout);
  wb_robot_cleanup();
  return 0;
}
