/* Helpers shared by the test controllers: print readings in tests/c/script.c's line format. */
#ifndef TESTS_C_COMMON_H
#define TESTS_C_COMMON_H

#include <inttypes.h>
#include <stdio.h>
#include <string.h>

#include <webots/lidar.h>

static inline void print_bits(const char *name, double v) {
  uint64_t bits;
  memcpy(&bits, &v, sizeof bits);
  printf(" %s=%016" PRIx64, name, bits);
}

static inline void print_hex(const void *p, size_t n) {
  const unsigned char *b = p;
  for (size_t i = 0; i < n; i++)
    printf("%02x", b[i]);
}

static inline void print_lidar(const char *name, WbDeviceTag tag) {
  int n = wb_lidar_get_horizontal_resolution(tag) * wb_lidar_get_number_of_layers(tag);
  printf(" %s.range=", name);
  print_hex(wb_lidar_get_range_image(tag), 4 * (size_t)n);
  if (wb_lidar_is_point_cloud_enabled(tag)) {
    const WbLidarPoint *pc = wb_lidar_get_point_cloud(tag);
    printf(" %s.cloud=", name);
    for (int j = 0; j < n; j++) {
      print_hex(&pc[j].x, 4);
      print_hex(&pc[j].y, 4);
      print_hex(&pc[j].z, 4);
      print_hex(&pc[j].layer_id, 4);
      print_hex(&pc[j].time, 4);
    }
  }
}

#endif
