/* Sensorium C controller library: Webots' motion files (utils/motion.h), played client side on the
 * robot's motors, one pose interpolation per wb_robot_step (src/motion.c). wbu_motion_new prints one
 * line and answers NULL for a file it cannot read or a damaged one; the other functions print
 * Webots' line for NULL and answer its "no value" (is_over: false, times and durations: -1). */
#ifndef WBU_MOTION_H
#define WBU_MOTION_H

#include "../types.h"

#ifdef __cplusplus
extern "C" {
#endif

WbMotionRef wbu_motion_new(const char *filename);
void wbu_motion_delete(WbMotionRef motion);
void wbu_motion_play(WbMotionRef motion);
void wbu_motion_stop(WbMotionRef motion);
void wbu_motion_set_loop(WbMotionRef motion, bool loop);
void wbu_motion_set_reverse(WbMotionRef motion, bool reverse);
bool wbu_motion_is_over(WbMotionRef motion);
int wbu_motion_get_duration(WbMotionRef motion);
int wbu_motion_get_time(WbMotionRef motion);
void wbu_motion_set_time(WbMotionRef motion, int time);

#ifdef __cplusplus
}
#endif

#endif /* WBU_MOTION_H */
