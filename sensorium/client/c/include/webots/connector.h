/* Sensorium C controller library: Connector (Webots' wb_connector_* functions).
 * The presence of a peer connector at the sampling period (1, 0; -1 passive or before the first
 * value) and the lock state the server holds; nothing is physically joined (no physics). */
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
