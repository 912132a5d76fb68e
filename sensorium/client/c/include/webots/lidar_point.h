/* Sensorium C controller library: WbLidarPoint, shared by lidar.h and the C++ layer (Lidar.hpp), in
 * its own header as in Webots so a controller may include it alone. */
#ifndef WB_LIDAR_POINT_H
#define WB_LIDAR_POINT_H

/* One point of a lidar's cloud: where the ray hit in the lidar's frame (m), its layer, and its
 * time (s) within the scan (0 for a fixed lidar). */
typedef struct {
  float x;
  float y;
  float z;
  int layer_id;
  float time;
} WbLidarPoint;

#endif /* WB_LIDAR_POINT_H */
