/* Sensorium C controller library: Pen (Webots' wb_pen_* functions).
 * The server simulates the pen: every basic step while it writes, it inks the first visual shape its
 * -z axis meets (nearer than maxDistance), and infra-red distance sensors read that ink. */
#ifndef WB_PEN_H
#define WB_PEN_H

#include "types.h"

#ifdef __cplusplus
extern "C" {
#endif

void wb_pen_write(WbDeviceTag tag, bool write);
void wb_pen_set_ink_color(WbDeviceTag tag, int color, double density);

#ifdef __cplusplus
}
#endif

#endif /* WB_PEN_H */
