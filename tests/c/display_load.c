/* wb_display_image_load from C (tests/worlds/display.yaml): each image named on the command line
 * (in $DISPLAY_IN) is loaded, pasted unblended at (0, 0) on "screen" and the display saved as
 * $DISPLAY_OUT/<name>.png and $DISPLAY_OUT/<name>.jpg; prints "loaded NAME" or "unreadable NAME",
 * then "done". Webots' display sample loads its emoticons this way. */
#include <stdio.h>
#include <stdlib.h>

#include <webots/display.h>
#include <webots/robot.h>

int main(int argc, char **argv) {
  const char *in = getenv("DISPLAY_IN"), *out = getenv("DISPLAY_OUT");
  if (in == NULL || out == NULL)
    return 2;
  wb_robot_init();
  WbDeviceTag screen = wb_robot_get_device("screen");
  wb_robot_step(16);
  char path[4096];
  for (int i = 1; i < argc; i++) {
    snprintf(path, sizeof path, "%s/%s", in, argv[i]);
    WbImageRef ir = wb_display_image_load(screen, path);
    if (ir == NULL) {
      printf("unreadable %s\n", argv[i]);
      continue;
    }
    wb_display_image_paste(screen, ir, 0, 0, false);
    snprintf(path, sizeof path, "%s/%s.png", out, argv[i]);
    wb_display_image_save(screen, NULL, path);
    snprintf(path, sizeof path, "%s/%s.jpg", out, argv[i]);
    wb_display_image_save(screen, NULL, path);
    wb_display_image_delete(screen, ir);
    printf("loaded %s\n", argv[i]);
  }
  wb_robot_step(16);
  printf("done\n");
  wb_robot_cleanup();
  return 0;
}
