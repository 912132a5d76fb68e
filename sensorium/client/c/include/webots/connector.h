/* Sensorium C controller library: Connector (Webots' wb_connector_* functions).
 * Sensorium lists this device (name, model, type, index) but does not simulate it: every function
 * answers Webots' "no value" (NaN, a NaN vector, NULL, 0, "") and the first call per device prints one
 * warning line. */
#ifndef WB_CONNECTOR_H
#define WB_CONNECTOR_H

#include "types.h"

#ifdef __cplusplus
extern "C" {
#endif

void wb_connector_enable_presence(WbDeviceTag tag, int sampling_period);
void wb_connector_disable_presence(WbDeviceTag tag);
int wb_connector_get_presence_sampling_period(WbDeviceTag tag);
int wb_connector_get_presence(WbDeviceTag tag);
void wb_connector_lock(WbDeviceTag tag);
void wb_connector_unlock(WbDeviceTag tag);
bool wb_connector_is_locked(WbDeviceTag tag);

#ifdef __cplusplus
}
#endif

#endif /* WB_CONNECTOR_H */
