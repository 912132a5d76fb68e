/* A Webots-style C supervisor changing a wall's texture and its camera seeing it (tests/test_supervisor_texture.py,
 * which writes the world and its images): the ImageTexture found by DEF, its url set
 * (wb_supervisor_field_set_mf_string), emptied (wb_supervisor_field_remove_mf), given again
 * (wb_supervisor_field_insert_mf_string) and set to a file that does not exist (set, with one warning line:
 * the wall is drawn untextured, as in Webots). Prints the lines tests/controllers/texture_change.py prints. */
#include <stdio.h>
#include <string.h>

#include <webots/camera.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

static WbDeviceTag camera;

static void centre(unsigned char out[3]) {
  const unsigned char *image = wb_camera_get_image(camera);
  int k = 4 * (4 * wb_camera_get_width(camera) + 4);
  out[0] = image[k + 2];
  out[1] = image[k + 1];
  out[2] = image[k];
}

int main(void) {
  wb_robot_init();
  int dt = (int)wb_robot_get_basic_time_step();
  camera = wb_robot_get_device("cam");
  wb_camera_enable(camera, dt);
  wb_robot_step(dt);
  WbFieldRef url = wb_supervisor_node_get_field(wb_supervisor_node_get_from_def("TEX"), "url");
  unsigned char first[3], now[3];
  centre(first);
  printf("before %s %d %d %d\n", wb_supervisor_field_get_mf_string(url, 0), first[0], first[1], first[2]);
  wb_supervisor_field_set_mf_string(url, 0, "b.png");
  wb_robot_step(dt);
  centre(now);
  printf("set %s %d\n", wb_supervisor_field_get_mf_string(url, 0), memcmp(now, first, 3) != 0);
  wb_supervisor_field_remove_mf(url, 0);
  wb_robot_step(dt);
  centre(now);
  printf("removed %d %d %d %d\n", wb_supervisor_field_get_count(url), now[0], now[1], now[2]);
  wb_supervisor_field_insert_mf_string(url, 0, "a.png");
  wb_robot_step(dt);
  centre(now);
  printf("inserted %s %d %d %d\n", wb_supervisor_field_get_mf_string(url, 0), now[0], now[1], now[2]);
  wb_supervisor_field_set_mf_string(url, 0, "nope.png");
  wb_robot_step(dt);
  centre(now);
  printf("missing %s %d %d %d\n", wb_supervisor_field_get_mf_string(url, 0), now[0], now[1], now[2]);
  wb_robot_cleanup();
  return 0;
}
