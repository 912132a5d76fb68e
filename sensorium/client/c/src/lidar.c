/* Sensorium C controller library: Lidar. The range image and point cloud live in per-device
 * buffers filled at each step (zeros before the first measurement), so the pointers handed out
 * stay valid until the next step and beyond, until wb_robot_cleanup(). */
#include <math.h>
#include <stdio.h>

#include <webots/lidar.h>

#include "internal.h"

#define LIDAR(func) sn_device *d = sn_device_get(tag, SN_LIDAR, func)

void wb_lidar_enable(WbDeviceTag tag, int sampling_period) {
  sn_sensor_enable(tag, SN_LIDAR, sampling_period, "wb_lidar_enable");
}

void wb_lidar_disable(WbDeviceTag tag) { sn_sensor_enable(tag, SN_LIDAR, 0, "wb_lidar_disable"); }

int wb_lidar_get_sampling_period(WbDeviceTag tag) {
  return sn_sensor_period(tag, SN_LIDAR, "wb_lidar_get_sampling_period");
}

static void point_cloud(WbDeviceTag tag, bool on, const char *func) {
  LIDAR(func);
  if (d == NULL)
    return;
  if (!sn_device_set(d, "enable_point_cloud", sn_arg_bool, &on, func))
    return;
  d->point_cloud_enabled = on;
  d->warned = false;
}

void wb_lidar_enable_point_cloud(WbDeviceTag tag) { point_cloud(tag, true, "wb_lidar_enable_point_cloud"); }

void wb_lidar_disable_point_cloud(WbDeviceTag tag) { point_cloud(tag, false, "wb_lidar_disable_point_cloud"); }

bool wb_lidar_is_point_cloud_enabled(WbDeviceTag tag) {
  LIDAR("wb_lidar_is_point_cloud_enabled");
  return d ? d->point_cloud_enabled : false;
}

static bool layer_ok(const sn_device *d, int layer, const char *func) {
  if (layer < 0 || layer >= d->layers) {
    fprintf(stderr, "Error: %s(): layer %d outside [0, %d]\n", func, layer, d->layers - 1);
    return false;
  }
  return true;
}

/* Webots' rule: a disabled lidar prints an error; the whole image is still the cached one. */
const float *wb_lidar_get_range_image(WbDeviceTag tag) {
  sn_device *d = sn_sensor_reading(tag, SN_LIDAR, "wb_lidar_get_range_image", "wb_lidar_enable");
  return d ? d->range_image : NULL;
}

const float *wb_lidar_get_layer_range_image(WbDeviceTag tag, int layer) {
  const char *func = "wb_lidar_get_layer_range_image";
  LIDAR(func);
  if (d == NULL || !layer_ok(d, layer, func))
    return NULL;
  if (d->sampling_period <= 0) {
    sn_warn_disabled(d, func, "wb_lidar_enable", NULL);
    return NULL;
  }
  return d->range_image + (size_t)layer * (size_t)d->width;
}

static bool cloud_usable(sn_device *d, const char *func) {
  if (!d->point_cloud_enabled) {
    sn_warn_disabled(d, func, "wb_lidar_enable_point_cloud", "a lidar with point cloud disabled");
    return false;
  }
  if (d->sampling_period <= 0) {
    sn_warn_disabled(d, func, "wb_lidar_enable", NULL);
    return false;
  }
  return true;
}

const WbLidarPoint *wb_lidar_get_point_cloud(WbDeviceTag tag) {
  LIDAR("wb_lidar_get_point_cloud");
  if (d == NULL || !cloud_usable(d, "wb_lidar_get_point_cloud"))
    return NULL;
  return d->point_cloud;
}

const WbLidarPoint *wb_lidar_get_layer_point_cloud(WbDeviceTag tag, int layer) {
  const char *func = "wb_lidar_get_layer_point_cloud";
  LIDAR(func);
  if (d == NULL || !layer_ok(d, layer, func) || !cloud_usable(d, func))
    return NULL;
  return d->point_cloud + (size_t)layer * (size_t)d->width;
}

int wb_lidar_get_number_of_points(WbDeviceTag tag) {
  LIDAR("wb_lidar_get_number_of_points");
  if (d == NULL || !cloud_usable(d, "wb_lidar_get_number_of_points"))
    return 0;
  return d->width * d->layers;
}

int wb_lidar_get_horizontal_resolution(WbDeviceTag tag) {
  LIDAR("wb_lidar_get_horizontal_resolution");
  return d ? d->width : 0;
}

int wb_lidar_get_number_of_layers(WbDeviceTag tag) {
  LIDAR("wb_lidar_get_number_of_layers");
  return d ? d->layers : 0;
}

double wb_lidar_get_min_frequency(WbDeviceTag tag) {
  LIDAR("wb_lidar_get_min_frequency");
  return d ? d->min_frequency : NAN;
}

double wb_lidar_get_max_frequency(WbDeviceTag tag) {
  LIDAR("wb_lidar_get_max_frequency");
  return d ? d->max_frequency : NAN;
}

double wb_lidar_get_frequency(WbDeviceTag tag) {
  LIDAR("wb_lidar_get_frequency");
  return d ? d->frequency : NAN;
}

void wb_lidar_set_frequency(WbDeviceTag tag, double frequency) {
  const char *func = "wb_lidar_set_frequency";
  LIDAR(func);
  if (d == NULL)
    return;
  if (!(frequency >= d->min_frequency && frequency <= d->max_frequency)) {
    fprintf(stderr, "Error: %s(): frequency %g outside [%g, %g] Hz\n", func, frequency, d->min_frequency,
            d->max_frequency);
    return;
  }
  if (!sn_device_set(d, "set_frequency", sn_arg_double, &frequency, func))
    return;
  d->frequency = frequency;
}

double wb_lidar_get_fov(WbDeviceTag tag) {
  LIDAR("wb_lidar_get_fov");
  return d ? d->fov : NAN;
}

double wb_lidar_get_vertical_fov(WbDeviceTag tag) {
  LIDAR("wb_lidar_get_vertical_fov");
  return d ? d->vertical_fov : NAN;
}

double wb_lidar_get_min_range(WbDeviceTag tag) {
  LIDAR("wb_lidar_get_min_range");
  return d ? d->min_range : NAN;
}

double wb_lidar_get_max_range(WbDeviceTag tag) {
  LIDAR("wb_lidar_get_max_range");
  return d ? d->max_range : NAN;
}
