/* A Webots-style C supervisor resetting its arm (tests/test_supervisor_states.py on
   tests/worlds/nested_joints.wbt), as tests/controllers/arm_resets.py does: setJointPosition on the
   shoulder, the slider driven out and the robot's state saved, loadState("__init__"), loadState of the
   saved state, then bad calls (each one error line, nothing changed). Prints one JSON line. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <webots/motor.h>
#include <webots/position_sensor.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

static void vec(const char *key, const double *v, const char *sep) {
  printf("\"%s\": [%.17g, %.17g, %.17g]%s", key, v[0], v[1], v[2], sep);
}

int main(void) {
  wb_robot_init();
  const int timestep = (int)wb_robot_get_basic_time_step();
  wb_robot_step(timestep);

  WbNodeRef me = wb_supervisor_node_get_self();
  WbNodeRef shoulder = wb_supervisor_node_get_from_def("SHOULDER");
  WbNodeRef link = wb_supervisor_node_get_from_def("LINK");
  WbNodeRef carriage = wb_supervisor_node_get_from_def("CARRIAGE");
  printf("{");

  wb_supervisor_node_set_joint_position(shoulder, 1.5707963267948966, 1); /* pi / 2 */
  vec("set", wb_supervisor_node_get_position(link), ", ");
  WbDeviceTag sensor = wb_robot_get_device("shoulder sensor");
  wb_position_sensor_enable(sensor, timestep);
  wb_robot_step(timestep);
  printf("\"sensor\": %.17g, ", wb_position_sensor_get_value(sensor));

  WbDeviceTag slide = wb_robot_get_device("slide"), slide_sensor = wb_robot_get_device("slide sensor");
  wb_motor_set_position(slide, 0.35);
  wb_position_sensor_enable(slide_sensor, timestep);
  for (int i = 0; i < 2000; i++) /* a generous limit: the slider is there within a second */
    if (wb_robot_step(timestep) == -1 || wb_position_sensor_get_value(slide_sensor) == 0.35)
      break;
  double reach[3];
  memcpy(reach, wb_supervisor_node_get_position(carriage), sizeof reach);
  vec("reach", reach, ", ");
  wb_supervisor_node_save_state(me, "reach");

  const double before = wb_robot_get_time();
  wb_supervisor_node_load_state(me, "__init__");
  vec("init", wb_supervisor_node_get_position(link), ", ");
  vec("robot", wb_supervisor_node_get_position(me), ", ");
  wb_robot_step(timestep);
  printf("\"times\": [%.17g, %.17g], ", before, wb_robot_get_time());

  wb_supervisor_node_load_state(me, "reach");
  vec("back", wb_supervisor_node_get_position(carriage), ", ");

  wb_supervisor_node_set_joint_position(shoulder, 1.0, 0);
  wb_supervisor_node_set_joint_position(shoulder, 1.0, 2);
  wb_supervisor_node_set_joint_position(link, 1.0, 1);
  wb_supervisor_node_set_joint_position(shoulder, NAN, 1);
  wb_supervisor_node_load_state(me, "nope");
  char *big = malloc((1 << 20) + 1);
  if (big == NULL)
    return 1;
  memset(big, 'x', 1 << 20);
  big[1 << 20] = '\0';
  wb_supervisor_node_load_state(me, big);
  free(big);
  vec("after_bad", wb_supervisor_node_get_position(carriage), "}\n");
  fflush(stdout);
  wb_robot_cleanup();
  return 0;
}
