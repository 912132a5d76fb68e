/* Sensorium C controller library: node types (the subset of Webots' WbNodeType that Sensorium
 * devices and worlds use; names as in Webots, values Sensorium's own). */
#ifndef WB_NODES_H
#define WB_NODES_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
  WB_NODE_NO_NODE = 0,
  /* devices */
  WB_NODE_DISTANCE_SENSOR,
  WB_NODE_KEYBOARD,
  WB_NODE_LED,
  WB_NODE_LIDAR,
  WB_NODE_LIGHT_SENSOR,
  WB_NODE_LINEAR_MOTOR,
  WB_NODE_POSITION_SENSOR,
  WB_NODE_ROTATIONAL_MOTOR,
  /* robots and scene nodes */
  WB_NODE_ROBOT,
  WB_NODE_SOLID,
  WB_NODE_DIRECTIONAL_LIGHT,
  WB_NODE_POINT_LIGHT,
  WB_NODE_SPOT_LIGHT
} WbNodeType;

#ifdef __cplusplus
}
#endif

#endif /* WB_NODES_H */
