/* Sensorium C controller library: the functions a controller calls to feed Webots' default robot
 * window (its devices' configuration, then their values each step). A headless server has no robot
 * window, so they send nothing (wb_robot_wwi_send's texts go to /<robot>/robot_window); a Webots controller that calls them
 * (the Thymio II and e-puck demos) compiles and runs unchanged. */
#ifndef WBU_DEFAULT_ROBOT_WINDOW_H
#define WBU_DEFAULT_ROBOT_WINDOW_H

#include "robot_wwi.h"

#ifdef __cplusplus
extern "C" {
#endif

void wbu_default_robot_window_configure(void);
void wbu_default_robot_window_update(void);
void wbu_default_robot_window_set_images_max_size(int max_width, int max_height);

#ifdef __cplusplus
}
#endif

#endif /* WBU_DEFAULT_ROBOT_WINDOW_H */
