/* getStaticBalance of tests/worlds/static_balance.wbt's solids, before, during and after BOX's fall
 * (tests/test_supervisor_balance.py; tests/controllers/static_balance.py prints the same). */
#include <stdio.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

int main(void) {
  wb_robot_init();
  int dt = (int)wb_robot_get_basic_time_step();
  wb_robot_step(dt);
  WbNodeRef box = wb_supervisor_node_get_from_def("BOX");
  printf("balance %d %d %d\n", wb_supervisor_node_get_static_balance(box),
         wb_supervisor_node_get_static_balance(wb_supervisor_node_get_from_def("OUTSIDE")),
         wb_supervisor_node_get_static_balance(wb_supervisor_node_get_from_def("BARE")));
  wb_supervisor_field_set_sf_vec3f(wb_supervisor_node_get_field(box, "translation"), (double[3]){0, 0, 0.55});
  printf("air %d\n", wb_supervisor_node_get_static_balance(box));
  for (int i = 0; i < 20; i++)
    wb_robot_step(dt);
  printf("landed %d\n", wb_supervisor_node_get_static_balance(box));
  printf("root %d\n", wb_supervisor_node_get_static_balance(wb_supervisor_node_get_root()));
  wb_robot_cleanup();
  return 0;
}
