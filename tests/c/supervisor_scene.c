/* A Webots-style C supervisor (tests/worlds/supervisor_scene.yaml): walks the root's children, reads
 * identities and fields, switches a light and reads velocities, printing "key values" lines for
 * tests/test_c_client.py (the same checkpoints as tests/controllers/supervisor_scene.py). */
#include <math.h>
#include <stdio.h>

#include <webots/light_sensor.h>
#include <webots/motor.h>
#include <webots/nodes.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

static void vec(const char *key, const double *v, int n) {
  printf("%s", key);
  for (int i = 0; i < n; i++)
    printf(" %.17g", v != NULL ? v[i] : NAN);
  printf("\n");
}

int main(void) {
  wb_robot_init();
  int dt = (int)wb_robot_get_basic_time_step();
  WbDeviceTag eye = wb_robot_get_device("eye");
  wb_light_sensor_enable(eye, dt);

  WbNodeRef root = wb_supervisor_node_get_root();
  WbFieldRef children = wb_supervisor_node_get_field(root, "children");
  int count = wb_supervisor_field_get_count(children);
  printf("root %d %s %d %d %d %s\n", wb_supervisor_node_get_id(root), wb_supervisor_node_get_type_name(root),
         wb_supervisor_node_get_type(root) == WB_NODE_GROUP, wb_supervisor_node_get_parent_node(root) == NULL, count,
         wb_supervisor_field_get_type_name(children));
  for (int i = 0; i < count; i++) {
    WbNodeRef n = wb_supervisor_field_get_mf_node(children, i);
    WbFieldRef name = wb_supervisor_node_get_field(n, "name");
    printf("node %d %s %s '%s' %s %d\n", wb_supervisor_node_get_id(n), wb_supervisor_node_get_type_name(n),
           wb_supervisor_node_get_base_type_name(n), wb_supervisor_node_get_def(n),
           name != NULL ? wb_supervisor_field_get_sf_string(name) : "(none)",
           wb_supervisor_node_get_id(wb_supervisor_node_get_parent_node(n)));
  }
  WbNodeRef me = wb_supervisor_node_get_self();
  printf("me %d %d %d %s %s %d\n", wb_supervisor_node_get_from_def("JUDGE") == me,
         wb_supervisor_node_get_from_id(1) == me, wb_supervisor_field_get_mf_node(children, -5) == me,
         wb_supervisor_field_get_sf_string(wb_supervisor_node_get_field(me, "customData")),
         wb_supervisor_field_get_sf_string(wb_supervisor_node_get_field(me, "model")),
         (int)wb_supervisor_field_get_sf_bool(wb_supervisor_node_get_field(me, "supervisor")));
  printf("missing %d %d %d %d\n", wb_supervisor_node_get_from_def("NOPE") == NULL,
         wb_supervisor_node_get_from_id(99) == NULL, wb_supervisor_node_get_field(me, "mass") == NULL,
         wb_supervisor_field_get_mf_node(children, 7) == NULL);

  WbNodeRef lamp = wb_supervisor_node_get_from_def("lamp");
  WbFieldRef on = wb_supervisor_node_get_field(lamp, "on");
  WbFieldRef intensity = wb_supervisor_node_get_field(lamp, "intensity");
  WbFieldRef attenuation = wb_supervisor_node_get_field(lamp, "attenuation");
  wb_robot_step(dt);
  double before = wb_light_sensor_get_value(eye);
  wb_supervisor_field_set_sf_bool(on, false);
  wb_robot_step(dt);
  double off = wb_light_sensor_get_value(eye);
  wb_supervisor_field_set_sf_bool(on, true);
  wb_supervisor_field_set_sf_float(intensity, 8.0);
  const double inverse_square[3] = {0.0, 0.0, 1.0};
  wb_supervisor_field_set_sf_vec3f(attenuation, inverse_square);
  wb_robot_step(dt);
  double after = wb_light_sensor_get_value(eye);
  printf("lights %.17g %.17g %.17g %d %.17g %d\n", before, off, after, (int)wb_supervisor_field_get_sf_bool(on),
         wb_supervisor_field_get_sf_float(intensity), (int)wb_supervisor_field_get_sf_bool(intensity));
  vec("color", wb_supervisor_field_get_sf_color(wb_supervisor_node_get_field(lamp, "color")), 3);

  WbDeviceTag left = wb_robot_get_device("left wheel motor"), right = wb_robot_get_device("right wheel motor");
  wb_motor_set_position(left, INFINITY);
  wb_motor_set_position(right, INFINITY);
  wb_motor_set_velocity(left, 2.0);
  wb_motor_set_velocity(right, 4.0);
  int steps = 0;
  for (; steps < 25; steps++)
    wb_robot_step(dt);
  printf("steps %d\n", steps);
  vec("velocity", wb_supervisor_node_get_velocity(me), 6);
  wb_supervisor_node_reset_physics(me); /* nothing to clear without physics: the wheels keep driving */
  wb_supervisor_simulation_reset_physics();
  wb_robot_step(dt);
  vec("after_reset", wb_supervisor_node_get_velocity(me), 6);
  vec("crate", wb_supervisor_node_get_velocity(wb_supervisor_node_get_from_def("CRATE")), 6);
  vec("null", wb_supervisor_node_get_velocity(NULL), 6);

  /* poses (Webots' 4x4 row-major transforms): the judge's in the world, the crate's seen from the
     judge; a light has none; from a light or the root: the world's frame (Webots' rule) */
  WbNodeRef crate = wb_supervisor_node_get_from_def("CRATE");
  wb_supervisor_node_enable_pose_tracking(crate, dt, me); /* accepted: get_pose asks at each call here */
  vec("position", wb_supervisor_node_get_position(me), 3);
  vec("orientation", wb_supervisor_node_get_orientation(me), 9);
  vec("pose", wb_supervisor_node_get_pose(me, NULL), 16);
  vec("crate_from_me", wb_supervisor_node_get_pose(crate, me), 16);
  vec("me_from_lamp", wb_supervisor_node_get_pose(me, lamp), 16);
  vec("crate_from_root", wb_supervisor_node_get_pose(crate, root), 16);
  vec("lamp_pose", wb_supervisor_node_get_pose(lamp, NULL), 16);
  vec("null_pose", wb_supervisor_node_get_pose(NULL, me), 16);
  wb_robot_cleanup();
  return 0;
}
