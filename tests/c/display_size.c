/* A Display from C (tests/worlds/display.yaml or .wbt): the sequence of
 * tests/controllers/display_size.py; prints "NAME WIDTH HEIGHT" and what the loops did. */
#include <stdio.h>

#include <webots/device.h>
#include <webots/display.h>
#include <webots/robot.h>

int main(void) {
  wb_robot_init();
  WbDeviceTag screen = wb_robot_get_device("screen"), small = wb_robot_get_device("small");
  wb_robot_step(16);
  WbDeviceTag both[2] = {screen, small};
  for (int i = 0; i < 2; i++)
    printf("%s %d %d\n", wb_device_get_name(both[i]), wb_display_get_width(both[i]), wb_display_get_height(both[i]));
  printf("properties %d %d\n", wb_display_get_width(screen), wb_display_get_height(screen));
  int pixels = 0;
  for (int x = 0; x < wb_display_get_width(screen); x++) /* the loop of Webots' samples: it runs now */
    for (int y = 0; y < wb_display_get_height(screen); y += 40) {
      wb_display_set_color(screen, 0xFF0000);
      wb_display_draw_pixel(screen, x, y);
      pixels++;
    }
  printf("pixels %d\n", pixels);
  wb_display_draw_text(screen, "hello", 0, 0);
  unsigned char data[16] = {0};
  WbImageRef ref = wb_display_image_new(screen, 2, 2, data, WB_IMAGE_RGBA);
  WbImageRef copy = wb_display_image_copy(screen, 0, 0, 10, 10);
  wb_display_image_paste(screen, ref, 0, 0, false);
  wb_display_image_save(screen, NULL, "screen.png");
  wb_display_image_save(screen, copy, "copy.png");
  printf("refs %d %d %d\n", ref != NULL, copy != NULL, ref != copy);
  wb_display_image_delete(screen, ref);
  wb_display_image_delete(screen, copy);
  wb_robot_step(16);
  printf("done\n");
  wb_robot_cleanup();
  return 0;
}
