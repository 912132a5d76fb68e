/* Sensorium C controller library: basic types of Webots' C API (written for Sensorium from the
 * documented API; see ../../README.md). */
#ifndef WB_TYPES_H
#define WB_TYPES_H

#ifndef __cplusplus
#include <stdbool.h>
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* A device handle: 1..N in the robot's device order (sensors, then motors); 0 is "no device". */
typedef unsigned short WbDeviceTag;

/* Supervisor handles (opaque). */
typedef struct WbNodeStructPrivate *WbNodeRef;
typedef struct WbFieldStructPrivate *WbFieldRef;

/* One lidar point: the device-frame position of a hit, its layer and its time offset (s). */
typedef struct {
  float x;
  float y;
  float z;
  int layer_id;
  float time;
} WbLidarPoint;

typedef enum { WB_ROTATIONAL = 0, WB_LINEAR } WbJointType;

#ifdef __cplusplus
}
#endif

#endif /* WB_TYPES_H */
