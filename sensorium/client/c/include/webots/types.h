/* Sensorium C controller library: basic types of Webots' C API (written for Sensorium from the
 * documented API; see ../../README.md). */
#ifndef WB_TYPES_H
#define WB_TYPES_H

#include <math.h> /* INFINITY, NAN: Webots controllers write wb_motor_set_position(m, INFINITY) */
#ifndef __cplusplus
#include <stdbool.h>
#endif
#ifndef INFINITY
#define INFINITY (__builtin_inf())
#endif
#ifndef NAN
#define NAN (__builtin_nan(""))
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* Marks the functions Webots keeps only for old controllers (a call warns, as with Webots). */
#if defined(__GNUC__) || defined(__clang__)
#define WB_DEPRECATED __attribute__((deprecated))
#else
#define WB_DEPRECATED
#endif

/* A device handle: 1..N in the robot's device order (sensors, then motors); 0 is "no device". */
typedef unsigned short WbDeviceTag;

/* Supervisor handles (opaque). */
typedef struct WbNodeStructPrivate *WbNodeRef;
typedef struct WbFieldStructPrivate *WbFieldRef;
/* Display images, motion files and proto handles (opaque; Sensorium hands out none). */
typedef struct WbImageStructPrivate *WbImageRef;
typedef struct WbMotionStructPrivate *WbMotionRef;
typedef struct WbProtoInfoStructPrivate *WbProtoRef;

#define WB_ANGULAR 0  // Webots' older name of WB_ROTATIONAL, kept since R2018b
typedef enum { WB_ROTATIONAL = 0, WB_LINEAR } WbJointType;

/* The user input events wb_robot_wait_for_user_input_event() waits for (flags, or-ed). */
typedef enum {
  WB_EVENT_QUIT = -1,
  WB_EVENT_NO_EVENT = 0,
  WB_EVENT_MOUSE_CLICK = 1,
  WB_EVENT_MOUSE_MOVE = 2,
  WB_EVENT_KEYBOARD = 4,
  WB_EVENT_JOYSTICK_BUTTON = 8,
  WB_EVENT_JOYSTICK_AXIS = 16,
  WB_EVENT_JOYSTICK_POV = 32
} WbUserInputEvent;

#ifdef __cplusplus
}
#endif

#endif /* WB_TYPES_H */
