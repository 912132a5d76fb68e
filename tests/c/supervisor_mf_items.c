/* Webots' item setters and inserters of every MF type from C (tests/worlds/proto/supervisor_proto_harden.wbt):
 * on the robot's PROTO fields (read-only here) each call gets the server's read-only line and nothing changes; on
 * the top-level solid Lengthy's the items change (it is built again); the library's own checks (a zero rotation axis, NaN, the wrong type, a NULL string) answer Webots'
 * lines without a request. The same stdout as tests/controllers/supervisor_mf_items.py. */
#include <math.h>
#include <stdio.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

int main(void) {
  wb_robot_init();
  int step = (int)wb_robot_get_basic_time_step();
  wb_robot_step(step);
  WbNodeRef keeper = wb_supervisor_node_get_self();
  WbNodeRef lengthy = wb_supervisor_node_get_from_def("LONG");
  WbFieldRef gains = wb_supervisor_node_get_field(keeper, "gains");
  WbFieldRef tags = wb_supervisor_node_get_field(keeper, "tags");
  WbFieldRef flags = wb_supervisor_node_get_field(keeper, "flags");
  WbFieldRef corners = wb_supervisor_node_get_field(lengthy, "corners");
  WbFieldRef turns = wb_supervisor_node_get_field(lengthy, "turns");
  const double corner[2] = {3, 4}, turn[4] = {1, 0, 0, 0.5}, zero_axis[4] = {0, 0, 0, 0.5};

  wb_supervisor_field_set_mf_float(gains, 0, 9.0);
  wb_supervisor_field_insert_mf_float(gains, -1, 9.0);
  wb_supervisor_field_set_mf_string(tags, 0, "z");
  wb_supervisor_field_insert_mf_string(tags, 0, "z");
  wb_supervisor_field_set_mf_bool(flags, 1, true);
  wb_supervisor_field_insert_mf_bool(flags, 0, false);
  wb_supervisor_field_set_mf_vec2f(corners, 0, corner);
  wb_supervisor_field_insert_mf_vec2f(corners, -1, corner);
  wb_supervisor_field_set_mf_rotation(turns, 0, turn);
  wb_supervisor_field_insert_mf_rotation(turns, 0, turn);
  wb_supervisor_field_set_mf_rotation(turns, 0, zero_axis); /* a zero axis: the library's line, no request */
  wb_supervisor_field_set_mf_float(gains, 0, NAN);          /* NaN: the library's line */
  wb_supervisor_field_set_mf_bool(gains, 0, true);          /* the wrong type: Webots' line */
  printf("counts %d %d %d %d %d\n", wb_supervisor_field_get_count(gains), wb_supervisor_field_get_count(tags),
         wb_supervisor_field_get_count(flags), wb_supervisor_field_get_count(corners), wb_supervisor_field_get_count(turns));
  const double *c = wb_supervisor_field_get_mf_vec2f(corners, 0);
  const double c0 = c[0], c1 = c[1];
  const double *t = wb_supervisor_field_get_mf_rotation(turns, 0);
  printf("values %g %g %s %d %d %g %g", wb_supervisor_field_get_mf_float(gains, 0), wb_supervisor_field_get_mf_float(gains, 1),
         wb_supervisor_field_get_mf_string(tags, 0), wb_supervisor_field_get_mf_bool(flags, 0),
         wb_supervisor_field_get_mf_bool(flags, 1), c0, c1);
  printf(" %g %g %g %g\n", t[0], t[1], t[2], t[3]);
  /* the SF setters: the robot's read-only here, Lengthy's built again */
  const double size2[2] = {1, 2};
  wb_supervisor_field_set_sf_int32(wb_supervisor_node_get_field(keeper, "level"), 4);
  wb_supervisor_field_set_sf_vec2f(wb_supervisor_node_get_field(lengthy, "size2"), size2);
  wb_supervisor_field_set_sf_string(wb_supervisor_node_get_field(keeper, "name"), "other");
  const double *s2 = wb_supervisor_field_get_sf_vec2f(wb_supervisor_node_get_field(lengthy, "size2"));
  const double s20 = s2[0], s21 = s2[1];
  printf("sf %d %g %g %s\n", wb_supervisor_field_get_sf_int32(wb_supervisor_node_get_field(keeper, "level")), s20, s21,
         wb_supervisor_field_get_sf_string(wb_supervisor_node_get_field(keeper, "name")));
  wb_robot_cleanup();
  return 0;
}
