/* Webots' draw-trail pattern in C (tests/test_supervisor_visuals.py on tests/worlds/visual_trail.wbt): a Shape
 * holding an IndexedLineSet imported at the root, the target moved each step and its position written into
 * the trail's points and line indices, read back, a few items inserted and removed, bad requests refused.
 * Prints the lines tests/controllers/visual_trail.py prints. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

#define N 60
#define STEPS 50

static void numbers(const double *v, int n) {
  for (int i = 0; i < n; i++)
    printf(" %g", v[i]);
}

int main(void) {
  wb_robot_init();
  int dt = (int)wb_robot_get_basic_time_step();
  WbNodeRef old = wb_supervisor_node_get_from_def("TRAIL");
  if (old != NULL)
    wb_supervisor_node_remove(old);
  static char text[64 * N + 512];
  strcpy(text, "DEF TRAIL Shape { appearance Appearance { material Material { diffuseColor 0 1 0 emissiveColor 0 1 0 } } "
               "geometry DEF TRAIL_LINE_SET IndexedLineSet { coord Coordinate { point [ ");
  for (int i = 0; i < N; i++)
    strcat(text, i ? ", 0 0 0" : "0 0 0");
  strcat(text, " ] } coordIndex [ ");
  for (int i = 0; i < N; i++)
    strcat(text, i ? " 0 0 -1" : "0 0 -1");
  strcat(text, " ] } }");
  wb_supervisor_field_import_mf_node_from_string(wb_supervisor_node_get_field(wb_supervisor_node_get_root(), "children"),
                                                 -1, text);
  WbNodeRef trail = wb_supervisor_node_get_from_def("TRAIL");
  WbNodeRef line_set = wb_supervisor_node_get_from_def("TRAIL_LINE_SET");
  WbNodeRef coord = wb_supervisor_field_get_sf_node(wb_supervisor_node_get_field(line_set, "coord"));
  WbFieldRef points = wb_supervisor_node_get_field(coord, "point");
  WbFieldRef indices = wb_supervisor_node_get_field(line_set, "coordIndex");
  printf("nodes %s %s %s %d %d %d\n", wb_supervisor_node_get_type_name(trail), wb_supervisor_node_get_type_name(line_set),
         wb_supervisor_node_get_type_name(coord),
         wb_supervisor_node_get_id(wb_supervisor_node_get_parent_node(line_set)) == wb_supervisor_node_get_id(trail),
         wb_supervisor_field_get_count(points), wb_supervisor_field_get_count(indices));
  WbNodeRef appearance = wb_supervisor_field_get_sf_node(wb_supervisor_node_get_field(trail, "appearance"));
  WbNodeRef material = wb_supervisor_field_get_sf_node(wb_supervisor_node_get_field(appearance, "material"));
  printf("material %s", wb_supervisor_node_get_type_name(material));
  numbers(wb_supervisor_field_get_sf_color(wb_supervisor_node_get_field(material, "diffuseColor")), 3);
  printf(" %g\n", wb_supervisor_field_get_sf_float(wb_supervisor_node_get_field(material, "shininess")));
  WbNodeRef target = wb_supervisor_node_get_from_def("TARGET");
  WbFieldRef translation = wb_supervisor_node_get_field(target, "translation");
  static double seen[STEPS][3];
  for (int k = 0; k < STEPS; k++) {
    const double a = 0.1 * k;
    const double at[3] = {cos(a), 3 + sin(a), 0.1};
    wb_supervisor_field_set_sf_vec3f(translation, at);
    wb_robot_step(dt);
    const double *p = wb_supervisor_node_get_position(target);
    memcpy(seen[k], p, sizeof seen[k]);
    wb_supervisor_field_set_mf_vec3f(points, k, p);
    if (k > 0) {
      wb_supervisor_field_set_mf_int32(indices, 3 * (k - 1), k - 1);
      wb_supervisor_field_set_mf_int32(indices, 3 * (k - 1) + 1, k);
    }
  }
  int same = 1;
  for (int k = 0; k < STEPS; k++) {
    const double *v = wb_supervisor_field_get_mf_vec3f(points, k);
    same = same && v != NULL && v[0] == seen[k][0] && v[1] == seen[k][1] && v[2] == seen[k][2];
  }
  const double *last = wb_supervisor_field_get_mf_vec3f(points, STEPS);
  printf("same %d %d\n", same, last != NULL && last[0] == 0 && last[1] == 0 && last[2] == 0);
  printf("points");
  for (int k = 0; k < STEPS; k++) {
    const double *v = wb_supervisor_field_get_mf_vec3f(points, k);
    for (int i = 0; i < 3; i++)
      printf(" %.17g", v[i]);
  }
  printf("\nindices");
  for (int i = 0; i < 3 * STEPS; i++)
    printf(" %d", wb_supervisor_field_get_mf_int32(indices, i));
  printf("\n");
  const double inserted[3] = {9, 8, 7};
  wb_supervisor_field_insert_mf_vec3f(points, 0, inserted);
  wb_supervisor_field_remove_mf(points, -1);
  wb_supervisor_field_insert_mf_int32(indices, -1, 5);
  printf("edited %d", wb_supervisor_field_get_count(points));
  numbers(wb_supervisor_field_get_mf_vec3f(points, 0), 3);
  numbers(wb_supervisor_field_get_mf_vec3f(points, 1), 3);
  printf(" %d %d\n", wb_supervisor_field_get_count(indices), wb_supervisor_field_get_mf_int32(indices, -1));
  const double zero[3] = {0, 0, 0};
  wb_supervisor_field_set_mf_vec3f(points, N, zero);
  wb_supervisor_field_set_mf_int32(indices, 0, -7);
  printf("kept %d %d\n", wb_supervisor_field_get_count(points), wb_supervisor_field_get_mf_int32(indices, 0));
  wb_supervisor_node_remove(trail);
  wb_robot_step(dt);
  printf("removed %d %d\n", wb_supervisor_node_get_from_def("TRAIL") == NULL,
         wb_supervisor_node_get_from_def("TRAIL_LINE_SET") == NULL);
  wb_robot_cleanup();
  return 0;
}
