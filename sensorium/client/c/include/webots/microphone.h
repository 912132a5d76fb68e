/* Sensorium C controller library: Microphone (Webots' wb_microphone_* functions).
 * Sensorium lists this device (name, model, type, index) but does not simulate it (there is no sound):
 * every function answers Webots' "no value" (sample data NULL, sizes and periods 0) and the first call
 * per device prints one warning line. */
#ifndef WB_MICROPHONE_H
#define WB_MICROPHONE_H

#include "types.h"

#ifdef __cplusplus
extern "C" {
#endif

void wb_microphone_enable(WbDeviceTag tag, int sampling_period);
void wb_microphone_disable(WbDeviceTag tag);
int wb_microphone_get_sampling_period(WbDeviceTag tag);

const void *wb_microphone_get_sample_data(WbDeviceTag tag);
int wb_microphone_get_sample_size(WbDeviceTag tag);

#ifdef __cplusplus
}
#endif

#endif /* WB_MICROPHONE_H */
