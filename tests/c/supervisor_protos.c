/* A Webots-style C supervisor on tests/worlds/proto/supervisor_protos.wbt: the root's children's type
 * names, base type names and PROTO flags, a Viewpoint's and a Background's values, WorldInfo's random
 * seed, and a tracked field after a set. Prints "key values" lines for tests/test_c_client.py. */
#include <stdio.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

int main(void) {
  wb_robot_init();
  int dt = (int)wb_robot_get_basic_time_step();
  wb_robot_step(dt);
  WbFieldRef children = wb_supervisor_node_get_field(wb_supervisor_node_get_root(), "children");
  printf("names");
  for (int i = 0; i < wb_supervisor_field_get_count(children); i++) {
    WbNodeRef n = wb_supervisor_field_get_mf_node(children, i);
    printf(" %s:%s:%d", wb_supervisor_node_get_type_name(n), wb_supervisor_node_get_base_type_name(n),
           wb_supervisor_node_is_proto(n));
  }
  printf("\n");
  WbNodeRef self = wb_supervisor_node_get_self();
  printf("self %s %d\n", wb_supervisor_node_get_type_name(self), wb_supervisor_node_get_type(self) == WB_NODE_ROBOT);
  WbNodeRef view = wb_supervisor_node_get_from_def("VIEW");
  const double *p = wb_supervisor_field_get_sf_vec3f(wb_supervisor_node_get_field(view, "position"));
  printf("view %g %g %g", p[0], p[1], p[2]);
  const double *r = wb_supervisor_field_get_sf_rotation(wb_supervisor_node_get_field(view, "orientation"));
  printf(" %g %g %g %g %g %s\n", r[0], r[1], r[2], r[3],
         wb_supervisor_field_get_sf_float(wb_supervisor_node_get_field(view, "fieldOfView")),
         wb_supervisor_field_get_sf_string(wb_supervisor_node_get_field(view, "description")));
  WbNodeRef sky = wb_supervisor_node_get_from_def("SKY");
  WbFieldRef colors = wb_supervisor_node_get_field(sky, "skyColor");
  const double *c0 = wb_supervisor_field_get_mf_color(colors, 0);
  printf("sky %s %d %g %g %g", wb_supervisor_field_get_type_name(colors), wb_supervisor_field_get_count(colors),
         c0[0], c0[1], c0[2]);
  const double *c1 = wb_supervisor_field_get_mf_color(colors, -1);
  printf(" %g %g %g %g %d\n", c1[0], c1[1], c1[2],
         wb_supervisor_field_get_sf_float(wb_supervisor_node_get_field(sky, "luminosity")),
         wb_supervisor_field_get_mf_color(colors, 2) == NULL);
  WbNodeRef info = wb_supervisor_field_get_mf_node(children, 0);
  printf("seed %d\n", wb_supervisor_field_get_sf_int32(wb_supervisor_node_get_field(info, "randomSeed")));
  WbFieldRef crate = wb_supervisor_node_get_field(wb_supervisor_node_get_from_def("CRATE"), "translation");
  wb_supervisor_field_enable_sf_tracking(crate, dt);
  wb_supervisor_field_enable_sf_tracking(crate, -1);
  const double before = wb_supervisor_field_get_sf_vec3f(crate)[1];
  const double moved[3] = {1.0, 0.5, 0.1};
  wb_supervisor_field_set_sf_vec3f(crate, moved);
  wb_robot_step(dt);
  printf("tracked %g %g\n", before, wb_supervisor_field_get_sf_vec3f(crate)[1]);
  wb_supervisor_field_disable_sf_tracking(crate);
  wb_robot_cleanup();
  return 0;
}
