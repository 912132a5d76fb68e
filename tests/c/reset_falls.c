/* The C twin of tests/controllers/reset_falls.py (tests/worlds/reset_falls.wbt, tests/test_reset_physics.py):
 * a falling box stopped by wb_supervisor_node_reset_physics and wb_supervisor_simulation_reset_physics falls
 * again from rest. Prints the same JSON line (numbers as %.17g). */
#include <math.h>
#include <stdio.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

static void list(const char *key, const double *v, int n, const char *after) {
  printf("\"%s\": [", key);
  for (int i = 0; i < n; i++)
    printf("%s%.17g", i ? ", " : "", v[i]);
  printf("]%s", after);
}

int main(void) {
  wb_robot_init();
  int dt = (int)wb_robot_get_basic_time_step();
  wb_robot_step(dt);
  WbNodeRef box = wb_supervisor_node_get_from_def("LOAD");
  WbNodeRef floor = wb_supervisor_node_get_from_def("FLOOR");
  WbFieldRef translation = wb_supervisor_node_get_field(box, "translation");
  const double up[3] = {0.2, 0.1, 1.0};
  double za[28], vza[28], v1a[6], kept[6], v1b[6], zb[29];

  wb_supervisor_field_set_sf_vec3f(translation, up);
  for (int k = 0; k < 10; k++)
    wb_robot_step(dt);
  double z1a = wb_supervisor_field_get_sf_vec3f(translation)[2];
  wb_supervisor_node_reset_physics(box);
  const double *v = wb_supervisor_node_get_velocity(box);
  for (int i = 0; i < 6; i++)
    v1a[i] = v[i];
  for (int k = 0; k < 28; k++) {
    wb_robot_step(dt);
    za[k] = wb_supervisor_field_get_sf_vec3f(translation)[2];
    vza[k] = wb_supervisor_node_get_velocity(box)[2];
  }

  wb_supervisor_field_set_sf_vec3f(translation, up);
  for (int k = 0; k < 6; k++) {
    if (k == 3) {
      wb_supervisor_node_reset_physics(floor);
      wb_supervisor_node_reset_physics(wb_supervisor_node_get_self());
    }
    wb_robot_step(dt);
    kept[k] = wb_supervisor_field_get_sf_vec3f(translation)[2];
  }
  double z1b = wb_supervisor_field_get_sf_vec3f(translation)[2];
  wb_supervisor_simulation_reset_physics();
  v = wb_supervisor_node_get_velocity(box);
  for (int i = 0; i < 6; i++)
    v1b[i] = v[i];
  for (int k = 0; k < 29; k++) {
    wb_robot_step(dt);
    zb[k] = wb_supervisor_field_get_sf_vec3f(translation)[2];
  }
  double v1c[6], zc[29];
  wb_supervisor_field_set_sf_vec3f(translation, up);
  for (int k = 0; k < 5; k++)
    wb_robot_step(dt);
  double z1c = wb_supervisor_field_get_sf_vec3f(translation)[2];
  const double zero[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  wb_supervisor_node_set_velocity(box, zero);
  v = wb_supervisor_node_get_velocity(box);
  for (int i = 0; i < 6; i++)
    v1c[i] = v[i];
  for (int k = 0; k < 29; k++) {
    if (k == 3) {
      const double bad[6] = {NAN, 0.0, 0.0, 0.0, 0.0, 0.0}, sideways[6] = {0.5, 0.0, 0.0, 0.0, 0.0, 0.0};
      wb_supervisor_node_set_velocity(box, bad);
      wb_supervisor_node_set_velocity(box, sideways);
    }
    wb_robot_step(dt);
    zc[k] = wb_supervisor_field_get_sf_vec3f(translation)[2];
  }
  const double *at = wb_supervisor_field_get_sf_vec3f(translation);
  printf("{\"a\": {\"z1\": %.17g, ", z1a);
  list("v1", v1a, 6, ", ");
  list("z", za, 28, ", ");
  list("vz", vza, 28, "}, ");
  printf("\"b\": {");
  list("z_kept", kept, 6, ", ");
  printf("\"z1\": %.17g, ", z1b);
  list("v1", v1b, 6, ", ");
  list("z", zb, 29, "}, ");
  printf("\"c\": {\"z1\": %.17g, ", z1c);
  list("v1", v1c, 6, ", ");
  list("z", zc, 29, "}, ");
  printf("\"xy\": [%.17g, %.17g], \"floor\": \"%s\"}\n", at[0], at[1], wb_supervisor_node_get_type_name(floor));
  fflush(stdout);
  wb_robot_cleanup();
  return 0;
}
