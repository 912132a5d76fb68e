/* The Pen from C (tests/worlds/pen.yaml): ink switched on and off and recoloured between steps, the
 * infra-red sensor under the pen reading it; prints "ink STEP VALUE" (%.17g), as
 * tests/controllers/pen_ink.py does. */
#include <math.h>
#include <stdio.h>

#include <webots/distance_sensor.h>
#include <webots/pen.h>
#include <webots/robot.h>

static void show(int k, WbDeviceTag ir) {
  printf("ink %d %.17g\n", k, wb_distance_sensor_get_value(ir));
}

int main(void) {
  wb_robot_init();
  WbDeviceTag pen = wb_robot_get_device("pen"), ir = wb_robot_get_device("over");
  wb_distance_sensor_enable(ir, 16);
  wb_robot_step(16);
  show(0, ir);                                /* the white floor */
  wb_pen_set_ink_color(pen, 0xFF0000, NAN);   /* printed and ignored */
  wb_pen_set_ink_color(pen, 0x336699, 0.5);
  wb_pen_write(pen, true);
  wb_robot_step(16);
  show(1, ir);                                /* one stroke of density 0.5 */
  wb_pen_write(pen, false);
  wb_pen_set_ink_color(pen, 0x7F000000, 3.0); /* black (bits above 24 ignored), density clamped to 1 */
  wb_robot_step(16);
  show(2, ir);                                /* not writing: unchanged */
  wb_pen_write(pen, true);
  wb_robot_step(16);
  show(3, ir);                                /* black over it, density capped at 1 */
  wb_pen_write(ir, true);                     /* not a pen: Webots' error line, nothing else */
  wb_robot_cleanup();
  return 0;
}
