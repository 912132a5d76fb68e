/* Sensorium C controller library: the state wb_mouse_get_state() returns (Webots' layout). */
#ifndef WB_MOUSE_STATE_H
#define WB_MOUSE_STATE_H

#ifndef __cplusplus
#include <stdbool.h>
#endif

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  bool left;
  bool middle;
  bool right;
  double u; /* position in the 3D view, 0..1; NaN when the mouse is outside it */
  double v;
  double x; /* the 3D point under the mouse (3D position enabled); NaN otherwise */
  double y;
  double z;
} WbMouseState;

#ifdef __cplusplus
}
#endif

#endif /* WB_MOUSE_STATE_H */
