/* A Display from C (tests/worlds/display.yaml or .wbt): the sequence of
 * tests/controllers/display_size.py (it draws, then saves the display and a copied image as PNG
 * files in $DISPLAY_OUT); prints what it did. */
#include <stdio.h>
#include <stdlib.h>

#include <webots/device.h>
#include <webots/display.h>
#include <webots/robot.h>

int main(void) {
  const char *out = getenv("DISPLAY_OUT");
  if (out == NULL)
    return 2;
  wb_robot_init();
  WbDeviceTag screen = wb_robot_get_device("screen"), small = wb_robot_get_device("small");
  wb_robot_step(16);
  WbDeviceTag both[2] = {screen, small};
  for (int i = 0; i < 2; i++)
    printf("%s %d %d\n", wb_device_get_name(both[i]), wb_display_get_width(both[i]), wb_display_get_height(both[i]));
  printf("properties %d %d\n", wb_display_get_width(screen), wb_display_get_height(screen));
  int pixels = 0;
  for (int x = 0; x < wb_display_get_width(screen); x++) /* the loop of Webots' samples */
    for (int y = 0; y < wb_display_get_height(screen); y += 40) {
      wb_display_set_color(screen, 0xFF0000);
      wb_display_draw_pixel(screen, x, y);
      pixels++;
    }
  printf("pixels %d\n", pixels);
  wb_display_set_color(screen, 0xFF0000);
  wb_display_draw_line(screen, 0, 0, 50, 20);
  wb_display_set_color(screen, 0x00FF00);
  wb_display_fill_rectangle(screen, 60, 10, 30, 20);
  wb_display_set_color(screen, 0x0000FF);
  wb_display_draw_oval(screen, 150, 100, 40, 25);
  wb_display_fill_oval(screen, 250, 60, 20, 30);
  wb_display_set_alpha(screen, 0.5);
  wb_display_set_opacity(screen, 0.6);
  wb_display_set_color(screen, 0xFFFF00);
  const int px[5] = {10, 100, 80, 30, 5}, py[5] = {150, 160, 230, 220, 190};
  wb_display_fill_polygon(screen, px, py, 5);
  wb_display_set_opacity(screen, 1.0);
  wb_display_set_alpha(screen, 1.0);
  wb_display_draw_rectangle(screen, 200, 150, 60, 40);
  const int tx[3] = {200, 230, 215}, ty[3] = {60, 60, 90};
  wb_display_draw_polygon(screen, tx, ty, 3);
  wb_display_draw_text(screen, "Sensorium", 100, 200);
  const unsigned char data[16] = {255, 0, 0, 128, 0, 255, 0, 255, 0, 0, 255, 64, 255, 255, 255, 0};
  WbImageRef ref = wb_display_image_new(screen, 2, 2, data, WB_IMAGE_RGBA);
  wb_display_image_paste(screen, ref, 300, 220, true);
  WbImageRef copy = wb_display_image_copy(screen, 60, 10, 30, 20);
  wb_display_image_paste(screen, copy, 0, 100, false);
  for (int y = 0; y < 64; y++) /* a colour per pixel: more than one request carries */
    for (int x = 0; x < 64; x++) {
      wb_display_set_color(small, (x << 18) | (y << 10) | 0x40);
      wb_display_draw_pixel(small, x, y);
    }
  wb_robot_step(16);
  char path[4096];
  snprintf(path, sizeof path, "%s/screen.png", out);
  wb_display_image_save(screen, NULL, path);
  snprintf(path, sizeof path, "%s/copy.png", out);
  wb_display_image_save(screen, copy, path);
  snprintf(path, sizeof path, "%s/small.png", out);
  wb_display_image_save(small, NULL, path);
  printf("refs %d %d %d\n", ref != NULL, copy != NULL, ref != copy);
  wb_display_image_delete(screen, ref);
  wb_display_image_delete(screen, copy);
  wb_robot_step(16);
  printf("done\n");
  wb_robot_cleanup();
  return 0;
}
