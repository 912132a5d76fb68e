/* Scripted C controller for the tests and the conformance session (the Python twin is
 * tests/controllers/script.py; both print the same lines):
 *
 *   script OP... with OP one of
 *     enable NAME PERIOD | disable NAME | pc NAME | nopc NAME | pos NAME RAD | vel NAME RAD_S
 *     send NAME HEX | channel NAME C | range NAME M | next NAME   (emitters, receivers)
 *     step DURATION COUNT            (COUNT steps; one line each)
 *     sleep MS                       (compute for MS wall-clock ms: the heartbeat keeps the session)
 *
 * A line: "T STATUS" then, for every device used so far (in order of first use), " NAME=<float64
 * bits, 16 hex digits>[,<bits>...]" (a vector sensor's values in getter order), a lidar's
 * " NAME.range=<hex bytes>" and, while its point cloud is enabled, " NAME.cloud=<hex of the 20-byte
 * records>", an emitter's " NAME.sent=<1/0 per send since the last line>", a receiver's
 * " NAME=<queue length>" and, when it has one, ":<data hex>/<signal bits>/<direction bits>" of its
 * head packet (sensorium/schemas/conformance/README.md). After status -1 it stops. */
#define _POSIX_C_SOURCE 200809L
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <webots/accelerometer.h>
#include <webots/altimeter.h>
#include <webots/compass.h>
#include <webots/device.h>
#include <webots/distance_sensor.h>
#include <webots/emitter.h>
#include <webots/gps.h>
#include <webots/gyro.h>
#include <webots/inertial_unit.h>
#include <webots/lidar.h>
#include <webots/light_sensor.h>
#include <webots/motor.h>
#include <webots/position_sensor.h>
#include <webots/receiver.h>
#include <webots/robot.h>
#include <webots/touch_sensor.h>

static WbDeviceTag seen[256];
static char sent[256][64]; /* an emitter's send results since the last line */
static int n_seen = 0;

static int remember(WbDeviceTag tag) {
  for (int i = 0; i < n_seen; i++)
    if (seen[i] == tag)
      return i;
  if (n_seen == 256) {
    fprintf(stderr, "script: too many devices\n");
    exit(2);
  }
  sent[n_seen][0] = '\0';
  seen[n_seen] = tag;
  return n_seen++;
}

static WbDeviceTag find(const char *name) {
  WbDeviceTag tag = wb_robot_get_device(name);
  if (tag == 0) {
    fprintf(stderr, "script: no device '%s'\n", name);
    exit(2);
  }
  return tag;
}

static WbDeviceTag device(const char *name) {
  WbDeviceTag tag = find(name);
  remember(tag);
  return tag;
}

static void bits(const double *v, int n) {
  for (int i = 0; i < n; i++) {
    uint64_t u;
    memcpy(&u, &v[i], sizeof u);
    printf("%s%016" PRIx64, i ? "," : "", u);
  }
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
    } else if (type == WB_NODE_EMITTER) {
      printf(" %s.sent=%s", name, sent[i]);
      sent[i][0] = '\0';
    } else if (type == WB_NODE_RECEIVER) {
      int n = wb_receiver_get_queue_length(tag);
      printf(" %s=%d", name, n);
      if (n > 0) {
        printf(":");
        hex_bytes(wb_receiver_get_data(tag), (size_t)wb_receiver_get_data_size(tag));
        double s = wb_receiver_get_signal_strength(tag);
        printf("/");
        bits(&s, 1);
        printf("/");
        bits(wb_receiver_get_emitter_direction(tag), 3);
      }
    } else {
      double v[7];
      int n = 1;
      switch (type) {
        case WB_NODE_LIGHT_SENSOR: v[0] = wb_light_sensor_get_value(tag); break;
        case WB_NODE_POSITION_SENSOR: v[0] = wb_position_sensor_get_value(tag); break;
        case WB_NODE_ALTIMETER: v[0] = wb_altimeter_get_value(tag); break;
        case WB_NODE_TOUCH_SENSOR: v[0] = wb_touch_sensor_get_value(tag); break;
        case WB_NODE_COMPASS: memcpy(v, wb_compass_get_values(tag), 3 * sizeof(double)); n = 3; break;
        case WB_NODE_ACCELEROMETER: memcpy(v, wb_accelerometer_get_values(tag), 3 * sizeof(double)); n = 3; break;
        case WB_NODE_GYRO: memcpy(v, wb_gyro_get_values(tag), 3 * sizeof(double)); n = 3; break;
        case WB_NODE_GPS:
          memcpy(v, wb_gps_get_values(tag), 3 * sizeof(double));
          v[3] = wb_gps_get_speed(tag);
          memcpy(v + 4, wb_gps_get_speed_vector(tag), 3 * sizeof(double));
          n = 7;
          break;
        case WB_NODE_INERTIAL_UNIT:
          memcpy(v, wb_inertial_unit_get_roll_pitch_yaw(tag), 3 * sizeof(double));
          memcpy(v + 3, wb_inertial_unit_get_quaternion(tag), 4 * sizeof(double));
          n = 7;
          break;
        default: v[0] = wb_distance_sensor_get_value(tag); break;
      }
      printf(" %s=", name);
      bits(v, n);
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
        case WB_NODE_GPS: on ? wb_gps_enable(tag, period) : wb_gps_disable(tag); break;
        case WB_NODE_INERTIAL_UNIT: on ? wb_inertial_unit_enable(tag, period) : wb_inertial_unit_disable(tag); break;
        case WB_NODE_COMPASS: on ? wb_compass_enable(tag, period) : wb_compass_disable(tag); break;
        case WB_NODE_ACCELEROMETER: on ? wb_accelerometer_enable(tag, period) : wb_accelerometer_disable(tag); break;
        case WB_NODE_GYRO: on ? wb_gyro_enable(tag, period) : wb_gyro_disable(tag); break;
        case WB_NODE_ALTIMETER: on ? wb_altimeter_enable(tag, period) : wb_altimeter_disable(tag); break;
        case WB_NODE_TOUCH_SENSOR: on ? wb_touch_sensor_enable(tag, period) : wb_touch_sensor_disable(tag); break;
        case WB_NODE_RECEIVER: on ? wb_receiver_enable(tag, period) : wb_receiver_disable(tag); break;
        default: fprintf(stderr, "script: '%s' is not a sensor\n", argv[i + 1]); return 2;
      }
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
        wb_motor_set_position(find(argv[i + 1]), v);
      else
        wb_motor_set_velocity(find(argv[i + 1]), v);
      i += 2;
    } else if (strcmp(op, "send") == 0) {
      need(argc, i, 2, op);
      WbDeviceTag tag = device(argv[i + 1]);
      const char *hex = argv[i + 2];
      size_t n = strlen(hex) / 2;
      unsigned char data[4096];
      if (n > sizeof data) {
        fprintf(stderr, "script: packet too long\n");
        return 2;
      }
      for (size_t k = 0; k < n; k++) {
        unsigned int byte;
        sscanf(hex + 2 * k, "%2x", &byte);
        data[k] = (unsigned char)byte;
      }
      char *results = sent[remember(tag)];
      size_t used = strlen(results);
      if (used + 1 < sizeof sent[0]) {
        results[used] = wb_emitter_send(tag, data, (int)n) ? '1' : '0';
        results[used + 1] = '\0';
      }
      i += 2;
    } else if (strcmp(op, "channel") == 0) {
      need(argc, i, 2, op);
      WbDeviceTag tag = device(argv[i + 1]);
      if (wb_device_get_node_type(tag) == WB_NODE_EMITTER)
        wb_emitter_set_channel(tag, atoi(argv[i + 2]));
      else
        wb_receiver_set_channel(tag, atoi(argv[i + 2]));
      i += 2;
    } else if (strcmp(op, "range") == 0) {
      need(argc, i, 2, op);
      wb_emitter_set_range(device(argv[i + 1]), strtod(argv[i + 2], NULL));
      i += 2;
    } else if (strcmp(op, "next") == 0) {
      need(argc, i, 1, op);
      wb_receiver_next_packet(device(argv[i + 1]));
      i += 1;
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
