/* Sensorium C controller library: Mouse (Webots' wb_mouse_* functions). A headless server has no 3D
 * view: no button is ever pressed and the positions are NaN. */
#ifndef WB_MOUSE_H
#define WB_MOUSE_H

#include "mouse_state.h"
#include "types.h"

#ifdef __cplusplus
extern "C" {
#endif

void wb_mouse_enable(int sampling_period);
void wb_mouse_disable(void);
int wb_mouse_get_sampling_period(void);
void wb_mouse_enable_3d_position(void);
void wb_mouse_disable_3d_position(void);
bool wb_mouse_is_3d_position_enabled(void);
WbMouseState wb_mouse_get_state(void);

#ifdef __cplusplus
}
#endif

#endif /* WB_MOUSE_H */
