/* The C twin of tests/test_run_robot_fields.py's Python boss under `sensorium run`: a Supervisor setting
 * robot ALPHA's controller field to "second" at 160 ms, its customData to "go" at 480, its controller to
 * "nowhere" (no such controller) at 640 and back to "first" at 800; prints each value read back. */
#include <math.h>
#include <stdio.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

int main(void) {
  wb_robot_init();
  WbNodeRef alpha = wb_supervisor_node_get_from_def("ALPHA");
  WbFieldRef controller = wb_supervisor_node_get_field(alpha, "controller");
  WbFieldRef data = wb_supervisor_node_get_field(alpha, "customData");
  const long at[4] = {160, 480, 640, 800};
  WbFieldRef fields[4] = {controller, data, controller, controller};
  const char *values[4] = {"second", "go", "nowhere", "first"};
  while (wb_robot_step(16) != -1) {
    const long t = lround(wb_robot_get_time() * 1000);
    for (int i = 0; i < 4; i++)
      if (t == at[i]) {
        wb_supervisor_field_set_sf_string(fields[i], values[i]);
        printf("boss set '%s' at %ld\n", wb_supervisor_field_get_sf_string(fields[i]), t);
        fflush(stdout);
      }
  }
  wb_robot_cleanup();
  return 0;
}
