/* A supervisor taking pictures from C (tests/test_viewshot.py, tests/worlds/viewshot.wbt): the
 * sequence of tests/controllers/viewshot.py (two labels, a PNG and a JPEG in $VIEWSHOT_OUT, then the
 * refused arguments, one line each); prints "done". */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

int main(void) {
  const char *out = getenv("VIEWSHOT_OUT");
  if (out == NULL)
    return 2;
  char png[4096], jpg[4096], bmp[4096], bad[4096];
  snprintf(png, sizeof png, "%s/view.png", out);
  snprintf(jpg, sizeof jpg, "%s/view.jpg", out);
  snprintf(bmp, sizeof bmp, "%s/view.bmp", out);
  snprintf(bad, sizeof bad, "%s/bad.png", out);
  wb_robot_init();
  wb_robot_step(16);
  wb_supervisor_set_label(7, "Sensorium", 0.05, 0.05, 0.1, 0x0000FF, 0.0, "Arial");
  wb_supervisor_set_label(2, "old text", 0.5, 0.8, 0.05, 0xFFFF00, 0.5, "Impact");
  wb_supervisor_set_label(2, "half", 0.6, 0.85, 0.05, 0xFFFFFF, 0.5, "Impact");
  wb_supervisor_export_image(png, 100);
  wb_supervisor_export_image(jpg, 90);
  wb_supervisor_set_label(70000, "huge id", 0.1, 0.1, 0.1, 0xFF0000, 0.0, "Arial");
  wb_supervisor_set_label(3, "nan x", NAN, 0.1, 0.1, 0xFF0000, 0.0, "Arial");
  wb_supervisor_set_label(3, "bad colour", 0.1, 0.1, 0.1, -1, 0.0, "Arial");
  wb_supervisor_set_label(3, "tab\there", 0.1, 0.1, 0.1, 0xFF0000, 0.0, "Arial");
  wb_supervisor_export_image("", 100);
  wb_supervisor_export_image(bmp, 100);
  wb_supervisor_export_image(bad, 0);
  wb_robot_step(16);
  printf("done\n");
  wb_robot_cleanup();
  return 0;
}
