/* A supervisor randomising a PROTO obstacle from C (tests/worlds/proto/supervisor_proto_regen.wbt): the sequence
 * of tests/controllers/supervisor_proto_regen.py, the same lines (numbers as %.17g). */
#include <stdio.h>

#include <webots/lidar.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

static void numbers(const double *v, int n) {
  for (int i = 0; i < n; i++)
    printf(" %.17g", v ? v[i] : -999.0);
}

static float centre(WbDeviceTag lidar) {
  const float *image = wb_lidar_get_range_image(lidar);
  return image ? image[16] : -999.0f;
}

int main(void) {
  wb_robot_init();
  int step = (int)wb_robot_get_basic_time_step();
  WbDeviceTag lidar = wb_robot_get_device("lidar");
  wb_lidar_enable(lidar, step);
  wb_robot_step(step);
  WbNodeRef obst = wb_supervisor_node_get_from_def("OBST");
  WbFieldRef size = wb_supervisor_node_get_field(obst, "size");
  printf("before %.8g", centre(lidar));
  numbers(wb_supervisor_field_get_sf_vec3f(size), 3);
  int first = wb_supervisor_node_get_id(obst);
  const double bigger[3] = {0.6, 0.4, 0.3}, moved[3] = {1.5, 0.2, 0.0}, color[3] = {0.9, 0.1, 0.2};
  const double huge[3] = {4e9, 0.6, 0.6};
  wb_supervisor_field_set_sf_vec3f(size, bigger); /* the obstacle is built again with that size */
  wb_robot_step(step);
  WbNodeRef again = wb_supervisor_node_get_from_def("OBST");
  printf("\nsize %.8g", centre(lidar));
  numbers(wb_supervisor_field_get_sf_vec3f(size), 3);
  printf(" same %d def %s\n", wb_supervisor_node_get_id(again) == first, wb_supervisor_node_get_def(again));
  wb_supervisor_field_set_sf_vec3f(wb_supervisor_node_get_field(obst, "translation"), moved);
  wb_supervisor_field_set_sf_color(wb_supervisor_node_get_field(obst, "color"), color);
  wb_robot_step(step);
  printf("moved");
  numbers(wb_supervisor_node_get_position(obst), 3);
  WbFieldRef posts = wb_supervisor_node_get_field(obst, "posts");
  wb_supervisor_field_insert_mf_float(posts, -1, 0.5);
  wb_robot_step(step);
  printf("\nposts %d %.17g\n", wb_supervisor_field_get_count(posts), wb_supervisor_field_get_mf_float(posts, 0));
  wb_supervisor_field_set_sf_bool(wb_supervisor_node_get_field(obst, "round"), true);
  wb_robot_step(step);
  printf("round %d %.17g\n", wb_supervisor_field_get_sf_bool(wb_supervisor_node_get_field(obst, "round")),
         wb_supervisor_field_get_mf_float(posts, 0));
  WbFieldRef material = wb_supervisor_node_get_field(obst, "material");
  wb_supervisor_field_set_sf_string(material, "stone");
  wb_robot_step(step);
  printf("material %s\n", wb_supervisor_field_get_sf_string(material));
  wb_supervisor_field_set_sf_vec3f(size, huge); /* beyond the world's limits: one line, nothing changed */
  wb_robot_step(step);
  printf("refused");
  numbers(wb_supervisor_field_get_sf_vec3f(size), 3);
  wb_supervisor_simulation_reset();
  wb_robot_step(step);
  printf("\nreset");
  numbers(wb_supervisor_field_get_sf_vec3f(wb_supervisor_node_get_field(obst, "translation")), 3);
  const double *now = wb_supervisor_field_get_sf_vec3f(size);
  printf(" %.17g\n", now ? now[0] : -999.0);
  fflush(stdout);
  wb_robot_cleanup();
  return 0;
}
