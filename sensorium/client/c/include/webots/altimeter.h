/* Sensorium C controller library: Altimeter (Webots' wb_altimeter_* functions).
 * Sensorium lists this device (name, model, type, index) but does not simulate it: every function
 * answers Webots' "no value" (NaN, a NaN vector, NULL, 0, "") and the first call per device prints one
 * warning line. */
#ifndef WB_ALTIMETER_H
#define WB_ALTIMETER_H

#include "types.h"

#ifdef __cplusplus
extern "C" {
#endif

void wb_altimeter_enable(WbDeviceTag tag, int sampling_period);
void wb_altimeter_disable(WbDeviceTag tag);
int wb_altimeter_get_sampling_period(WbDeviceTag tag);
double wb_altimeter_get_value(WbDeviceTag tag);

#ifdef __cplusplus
}
#endif

#endif /* WB_ALTIMETER_H */
