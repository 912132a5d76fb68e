/* wb_display_image_load of one large image from C (tests/worlds/display.yaml): the file
 * $DISPLAY_IN/<argv[1]> is loaded once and pasted unblended on "screen" at (-x, -y) for each pair
 * x y that follows, the display saved each time as $DISPLAY_OUT/<x>_<y>.png, so the saved files show
 * the image's parts; prints "loaded NAME" or "unreadable NAME", then "done". Webots'
 * sick_terrain_scanning sample loads a 2048 x 2048 background so. */
#include <stdio.h>
#include <stdlib.h>

#include <webots/display.h>
#include <webots/robot.h>

int main(int argc, char **argv) {
  const char *in = getenv("DISPLAY_IN"), *out = getenv("DISPLAY_OUT");
  if (in == NULL || out == NULL || argc < 2)
    return 2;
  wb_robot_init();
  WbDeviceTag screen = wb_robot_get_device("screen");
  wb_robot_step(16);
  char path[4096];
  snprintf(path, sizeof path, "%s/%s", in, argv[1]);
  WbImageRef ir = wb_display_image_load(screen, path);
  printf("%s %s\n", ir == NULL ? "unreadable" : "loaded", argv[1]);
  for (int i = 2; ir != NULL && i + 1 < argc; i += 2) {
    const int x = atoi(argv[i]), y = atoi(argv[i + 1]);
    wb_display_image_paste(screen, ir, -x, -y, false);
    snprintf(path, sizeof path, "%s/%d_%d.png", out, x, y);
    wb_display_image_save(screen, NULL, path);
  }
  if (ir != NULL)
    wb_display_image_delete(screen, ir);
  wb_robot_step(16);
  printf("done\n");
  wb_robot_cleanup();
  return 0;
}
