/* Scripted C controller for the tests and the conformance session (the Python twin is
 * tests/controllers/script.py; both print the same lines):
 *
 *   script OP... with OP one of
 *     enable NAME PERIOD | disable NAME | pc NAME | nopc NAME | pos NAME RAD | vel NAME RAD_S
 *     step DURATION COUNT            (COUNT steps; one line each)
 *     sleep MS                       (compute for MS wall-clock ms: the heartbeat keeps the session)
 *
 * A line: "T STATUS" then, for every sensor enabled so far (in order of first enable),
 * " NAME=<float64 bits, 16 hex digits>" or, for a lidar, " NAME.range=<hex bytes>" and, while its
 * point cloud is enabled, " NAME.cloud=<hex of the 20-byte records>". After status -1 it stops. */
#define _POSIX_C_SOURCE 200809L
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <webots/device.h>
#include <webots/distance_sensor.h>
#include <webots/lidar.h>
#include <webots/light_sensor.h>
#include <webots/motor.h>
#include <webots/position_sensor.h>
#include <webots/robot.h>

static WbDeviceTag seen[256];
static int n_seen = 0;

static WbDeviceTag device(const char *name) {
  WbDeviceTag tag = wb_robot_get_device(name);
  if (tag == 0) {
    fprintf(stderr, "script: no device '%s'\n", name);
    exit(2);
  }
  return tag;
}

static void remember(WbDeviceTag tag) {
  for (int i = 0; i < n_seen; i++)
    if (seen[i] == tag)
      return;
  if (n_seen < 256)
    seen[n_seen++] = tag;
}

static void hex_bytes(const void *p, size_t n) {
  const unsigned char *b = p;
  for (size_t i = 0; i < n; i++)
    printf("%02x", b[i]);
}

static void print_line(int status) {
  printf("%.0f %d", wb_robot_get_time() * 1000.0, status);
  for (int i = 0; i < n_seen; i++) {
    WbDeviceTag tag = seen[i];
    const char *name = wb_device_get_name(tag);
    WbNodeType type = wb_device_get_node_type(tag);
    if (type == WB_NODE_LIDAR) {
      int n = wb_lidar_get_horizontal_resolution(tag) * wb_lidar_get_number_of_layers(tag);
      printf(" %s.range=", name);
      hex_bytes(wb_lidar_get_range_image(tag), 4 * (size_t)n);
      if (wb_lidar_is_point_cloud_enabled(tag) && wb_lidar_get_sampling_period(tag) > 0) {
        const WbLidarPoint *pc = wb_lidar_get_point_cloud(tag);
        printf(" %s.cloud=", name);
        for (int j = 0; j < n; j++) { /* the wire's record: x y z (f4) layer (i4) time (f4) */
          hex_bytes(&pc[j].x, 4);
          hex_bytes(&pc[j].y, 4);
          hex_bytes(&pc[j].z, 4);
          hex_bytes(&pc[j].layer_id, 4);
          hex_bytes(&pc[j].time, 4);
        }
      }
    } else {
      double v = type == WB_NODE_LIGHT_SENSOR      ? wb_light_sensor_get_value(tag)
                 : type == WB_NODE_POSITION_SENSOR ? wb_position_sensor_get_value(tag)
                                                   : wb_distance_sensor_get_value(tag);
      uint64_t bits;
      memcpy(&bits, &v, sizeof bits);
      printf(" %s=%016" PRIx64, name, bits);
    }
  }
  printf("\n");
  fflush(stdout);
}

static void need(int argc, int i, int n, const char *op) {
  if (i + n >= argc) {
    fprintf(stderr, "script: '%s' needs %d argument(s)\n", op, n);
    exit(2);
  }
}

int main(int argc, char **argv) {
  wb_robot_init();
  for (int i = 1; i < argc; i++) {
    const char *op = argv[i];
    if (strcmp(op, "enable") == 0 || strcmp(op, "disable") == 0) {
      int on = op[0] == 'e';
      need(argc, i, on ? 2 : 1, op);
      WbDeviceTag tag = device(argv[i + 1]);
      int period = on ? atoi(argv[i + 2]) : 0;
      switch (wb_device_get_node_type(tag)) {
        case WB_NODE_LIGHT_SENSOR: on ? wb_light_sensor_enable(tag, period) : wb_light_sensor_disable(tag); break;
        case WB_NODE_DISTANCE_SENSOR:
          on ? wb_distance_sensor_enable(tag, period) : wb_distance_sensor_disable(tag);
          break;
        case WB_NODE_LIDAR: on ? wb_lidar_enable(tag, period) : wb_lidar_disable(tag); break;
        case WB_NODE_POSITION_SENSOR:
          on ? wb_position_sensor_enable(tag, period) : wb_position_sensor_disable(tag);
          break;
        default: fprintf(stderr, "script: '%s' is not a sensor\n", argv[i + 1]); return 2;
      }
      remember(tag);
      i += on ? 2 : 1;
    } else if (strcmp(op, "pc") == 0 || strcmp(op, "nopc") == 0) {
      need(argc, i, 1, op);
      if (op[0] == 'p')
        wb_lidar_enable_point_cloud(device(argv[i + 1]));
      else
        wb_lidar_disable_point_cloud(device(argv[i + 1]));
      i += 1;
    } else if (strcmp(op, "pos") == 0 || strcmp(op, "vel") == 0) {
      need(argc, i, 2, op);
      double v = strtod(argv[i + 2], NULL);
      if (op[0] == 'p')
        wb_motor_set_position(device(argv[i + 1]), v);
      else
        wb_motor_set_velocity(device(argv[i + 1]), v);
      i += 2;
    } else if (strcmp(op, "sleep") == 0) {
      need(argc, i, 1, op);
      long ms = atol(argv[i + 1]);
      struct timespec ts = {ms / 1000, (ms % 1000) * 1000000L};
      nanosleep(&ts, NULL);
      i += 1;
    } else if (strcmp(op, "step") == 0) {
      need(argc, i, 2, op);
      int duration = atoi(argv[i + 1]), count = atoi(argv[i + 2]);
      for (int k = 0; k < count; k++) {
        int status = wb_robot_step(duration);
        print_line(status);
        if (status == -1) {
          wb_robot_cleanup();
          return 0;
        }
      }
      i += 2;
    } else {
      fprintf(stderr, "script: unknown op '%s'\n", op);
      return 2;
    }
  }
  wb_robot_cleanup();
  return 0;
}
