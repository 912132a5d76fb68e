/* Sensorium C controller library: Radar. The targets arrive with the step reply at the radar's
 * sampling period (NULL and 0 before the first value; the last ones kept after a disable); the
 * range and fields of view come from the attach description, as Webots sends them once at start. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <webots/radar.h>

#include "internal.h"

void sn_radar_apply(sn_device *dev, const msgpack_object *targets) {
  if (targets == NULL || targets->type != MSGPACK_OBJECT_ARRAY)
    return;
  uint32_t n = targets->via.array.size / 4;
  if (targets->via.array.size % 4)
    fprintf(stderr, "Warning: radar '%s': %u target values, not a multiple of 4: the last ones ignored\n",
            sn_shown(dev->name),
            targets->via.array.size);
  free(dev->radar_targets); /* Webots' libController keeps a new array per measurement too */
  dev->radar_targets = NULL;
  dev->radar_count = 0;
  if (n == 0)
    return;
  dev->radar_targets = malloc(n * sizeof(WbRadarTarget));
  if (dev->radar_targets == NULL)
    return;
  for (uint32_t i = 0; i < n; i++) {
    double v[4];
    for (int k = 0; k < 4; k++)
      if (!sn_as_double(&targets->via.array.ptr[4 * i + k], &v[k]))
        v[k] = NAN;
    WbRadarTarget *t = &dev->radar_targets[i];
    t->distance = v[0];
    t->received_power = v[1];
    t->speed = v[2];
    t->azimuth = v[3];
  }
  dev->radar_count = (int)n;
}

void wb_radar_enable(WbDeviceTag tag, int sampling_period) {
  sn_sensor_enable(tag, SN_RADAR, sampling_period, "wb_radar_enable");
}

void wb_radar_disable(WbDeviceTag tag) { sn_sensor_enable(tag, SN_RADAR, 0, "wb_radar_disable"); }

int wb_radar_get_sampling_period(WbDeviceTag tag) {
  return sn_sensor_period(tag, SN_RADAR, "wb_radar_get_sampling_period");
}

int wb_radar_get_number_of_targets(WbDeviceTag tag) {
  sn_device *d = sn_sensor_reading(tag, SN_RADAR, "wb_radar_get_number_of_targets", "wb_radar_enable");
  return d ? d->radar_count : 0;
}

const WbRadarTarget *wb_radar_get_targets(WbDeviceTag tag) {
  sn_device *d = sn_sensor_reading(tag, SN_RADAR, "wb_radar_get_targets", "wb_radar_enable");
  return d ? d->radar_targets : NULL;
}

double wb_radar_get_min_range(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_RADAR, "wb_radar_get_min_range");
  return d ? d->min_range : NAN;
}

double wb_radar_get_max_range(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_RADAR, "wb_radar_get_max_range");
  return d ? d->max_range : NAN;
}

double wb_radar_get_horizontal_fov(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_RADAR, "wb_radar_get_horizontal_fov");
  return d ? d->fov : NAN;
}

double wb_radar_get_vertical_fov(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_RADAR, "wb_radar_get_vertical_fov");
  return d ? d->vertical_fov : NAN;
}
