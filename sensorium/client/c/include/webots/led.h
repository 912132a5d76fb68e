/* Sensorium C controller library: LED. wb_led_set() is sent at once (one round trip). */
#ifndef WB_LED_H
#define WB_LED_H

#include "types.h"

#ifdef __cplusplus
extern "C" {
#endif

void wb_led_set(WbDeviceTag tag, int value); /* 0 off, 1..n colour n; gradual: 0xRRGGBB (no colour) or 0..255 */
int wb_led_get(WbDeviceTag tag);

#ifdef __cplusplus
}
#endif

#endif /* WB_LED_H */
