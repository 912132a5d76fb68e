/* Sensorium C controller library: generic device functions. */
#ifndef WB_DEVICE_H
#define WB_DEVICE_H

#include "nodes.h"
#include "types.h"

#ifdef __cplusplus
extern "C" {
#endif

const char *wb_device_get_name(WbDeviceTag tag);
const char *wb_device_get_model(WbDeviceTag tag); /* the world's "model" field, "" when it has none */
WbNodeType wb_device_get_node_type(WbDeviceTag tag);
WbNodeType wb_device_get_type(WbDeviceTag tag); /* deprecated in Webots: wb_device_get_node_type */

/* Sensorium extension: the device's node type name ("DistanceSensor", "Lidar", ...). */
const char *sensorium_device_get_type_name(WbDeviceTag tag);

#ifdef __cplusplus
}
#endif

#endif /* WB_DEVICE_H */
