/* Sensorium C controller library: the robot session (wb_robot_*), as the Python client's
 * RobotClient: attach, heartbeats, steps carrying motor commands and bringing readings back. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/nodes.h>
#include <webots/robot.h>

#include "internal.h"

static sn_robot *g_robot = NULL;
/* how the last robot was cleaned up: 0 never, 1 after the simulation had ended for it (a step
   answered -1), 2 while it still ran */
static int g_cleaned = 0;
static bool g_atexit = false;
static int g_timeout_ms = 10000; /* ordinary replies; steps wait as long as the lockstep needs */

static void fatal(const char *func, int code, const char *message) {
  fprintf(stderr, "Error: %s(): %s: %s\n", func, sn_error_name(code), message);
  fflush(stderr);
  exit(1);
}

sn_robot *sn_robot_get(const char *func) {
  if (g_robot == NULL) {
    /* a controller that cleans up once its step answered -1 and then goes on calling the API (Webots'
       nao_demo: terminate() calls wb_robot_cleanup() and its loop steps on) ends there, quietly, with
       status 0: the simulation ended for it, as the step after -1 ends it */
    if (g_cleaned == 1)
      exit(EXIT_SUCCESS);
    if (g_cleaned == 2)
      fprintf(stderr, "Error: %s(): no robot: called after wb_robot_cleanup()\n", func);
    else
      fprintf(stderr, "Error: %s(): no robot: call wb_robot_init() first\n", func);
    exit(1);
  }
  return g_robot;
}

static int timeout_from_env(void) {
  const char *s = getenv("SENSORIUM_CONTROLLER_TIMEOUT");
  if (s == NULL || *s == '\0')
    return 10000;
  char *end;
  double v = strtod(s, &end);
  if (*end != '\0' || !(v > 0) || v > 86400) {
    fprintf(stderr, "Error: wb_robot_init(): SENSORIUM_CONTROLLER_TIMEOUT='%s' is not a number of seconds > 0\n", sn_shown(s));
    exit(1);
  }
  return (int)(v * 1000);
}

/* ------------------------------------------------------------------ device descriptions */

static sn_kind kind_of(const char *type) {
  if (strcmp(type, "LightSensor") == 0)
    return SN_LIGHT;
  if (strcmp(type, "DistanceSensor") == 0)
    return SN_DISTANCE;
  if (strcmp(type, "Lidar") == 0)
    return SN_LIDAR;
  if (strcmp(type, "RotationalMotor") == 0 || strcmp(type, "LinearMotor") == 0)
    return SN_MOTOR;
  if (strcmp(type, "PositionSensor") == 0)
    return SN_POSITION;
  if (strcmp(type, "LED") == 0)
    return SN_LED;
  if (strcmp(type, "GPS") == 0)
    return SN_GPS;
  if (strcmp(type, "RangeFinder") == 0)
    return SN_RANGE_FINDER;
  if (strcmp(type, "Camera") == 0)
    return SN_CAMERA;
  if (strcmp(type, "InertialUnit") == 0)
    return SN_IMU;
  if (strcmp(type, "Compass") == 0)
    return SN_COMPASS;
  if (strcmp(type, "Accelerometer") == 0)
    return SN_ACCELEROMETER;
  if (strcmp(type, "Gyro") == 0)
    return SN_GYRO;
  if (strcmp(type, "Altimeter") == 0)
    return SN_ALTIMETER;
  if (strcmp(type, "TouchSensor") == 0)
    return SN_TOUCH;
  if (strcmp(type, "Emitter") == 0)
    return SN_EMITTER;
  if (strcmp(type, "Receiver") == 0)
    return SN_RECEIVER;
  if (strcmp(type, "Radar") == 0)
    return SN_RADAR;
  if (strcmp(type, "VacuumGripper") == 0)
    return SN_VACUUM;
  if (strcmp(type, "Speaker") == 0)
    return SN_SPEAKER;
  if (strcmp(type, "Connector") == 0)
    return SN_CONNECTOR;
  if (strcmp(type, "Brake") == 0)
    return SN_BRAKE;
  return SN_OTHER;
}

static void flatten(const msgpack_object *o, double *out, int *n, int cap) {
  if (o == NULL)
    return;
  if (o->type == MSGPACK_OBJECT_ARRAY) {
    for (uint32_t i = 0; i < o->via.array.size; i++)
      flatten(&o->via.array.ptr[i], out, n, cap);
  } else if (*n < cap) {
    double v;
    if (sn_as_double(o, &v))
      out[(*n)++] = v;
  }
}

static int count_leaves(const msgpack_object *o) {
  if (o == NULL)
    return 0;
  if (o->type != MSGPACK_OBJECT_ARRAY)
    return 1;
  int n = 0;
  for (uint32_t i = 0; i < o->via.array.size; i++)
    n += count_leaves(&o->via.array.ptr[i]);
  return n;
}

static int describe(sn_device *d, int index, const msgpack_object *desc) {
  memset(d, 0, sizeof *d);
  d->tag = (WbDeviceTag)(index + 1);
  d->name = sn_strdup_obj(sn_get(desc, "name"));
  d->type_name = sn_strdup_obj(sn_get(desc, "type"));
  if (d->name == NULL || d->type_name == NULL)
    return -1;
  d->model = sn_strdup_obj(sn_get(desc, "model"));
  if (d->model == NULL && (d->model = strdup("")) == NULL)
    return -1;
  d->node_type = sn_node_type_of(d->type_name);
  d->simulated = sn_bool_or(desc, "simulated", true); /* servers before the device list said nothing */
  d->kind = d->simulated ? kind_of(d->type_name) : SN_OTHER;
  for (int i = 0; i < 3; i++)
    d->gps_values[i] = d->gps_speed_vector[i] = d->values[i] = d->roll_pitch_yaw[i] = NAN;
  for (int i = 0; i < 4; i++)
    d->quaternion[i] = NAN;
  d->gps_speed = NAN;
  if (d->node_type == WB_NODE_DISPLAY) { /* its size is the world's */
    d->display_width = (int)sn_int_or(desc, "width", 0);
    d->display_height = (int)sn_int_or(desc, "height", 0);
  }
  d->noise = sn_double_or(desc, "noise", 0.0);
  d->channel = (int)sn_int_or(desc, "channel", 0);
  d->range = sn_double_or(desc, "range", -1.0);
  d->emitter_max_range = sn_double_or(desc, "max_range", -1.0);
  d->byte_rate = sn_double_or(desc, "byte_rate", -1.0);
  d->buffer_size = (int)sn_int_or(desc, "buffer_size", -1);
  const msgpack_object *allowed = sn_get(desc, "allowed_channels");
  if (allowed != NULL && allowed->type == MSGPACK_OBJECT_ARRAY && allowed->via.array.size > 0) {
    d->allowed = calloc(allowed->via.array.size, sizeof(int));
    if (d->allowed == NULL)
      return -1;
    for (uint32_t i = 0; i < allowed->via.array.size; i++) {
      int64_t c;
      if (sn_as_int64(&allowed->via.array.ptr[i], &c))
        d->allowed[d->n_allowed++] = (int)c;
    }
  }
  d->coordinate_system = (int)sn_int_or(desc, "coordinate_system", 0);
  d->sampling_period = (int)sn_int_or(desc, "sampling_period", 0);
  d->value = NAN;
  const msgpack_object *table = sn_get(desc, "lookup_table");
  if (table != NULL) {
    int cap = count_leaves(table);
    d->lookup_table = calloc(cap > 0 ? (size_t)cap : 1, sizeof(double));
    int n = 0;
    flatten(table, d->lookup_table, &n, cap);
    d->lookup_rows = n / 3;
  }
  d->min_value = sn_double_or(desc, "min_value", 0.0);
  d->max_value = sn_double_or(desc, "max_value", 0.0);
  d->aperture = sn_double_or(desc, "aperture", 0.0);
  d->sensor_type = (int)sn_int_or(desc, "sensor_type", 0);
  if (d->kind == SN_LIDAR) {
    d->width = (int)sn_int_or(desc, "horizontalResolution", 0);
    d->layers = (int)sn_int_or(desc, "numberOfLayers", 0);
    if (d->width <= 0 || d->layers <= 0 || (int64_t)d->width * d->layers > (1 << 24))
      return -1;
    d->fov = sn_double_or(desc, "fov", 0.0);
    d->vertical_fov = sn_double_or(desc, "verticalFov", 0.0);
    d->min_range = sn_double_or(desc, "minRange", 0.0);
    d->max_range = sn_double_or(desc, "maxRange", INFINITY);
    d->frequency = sn_double_or(desc, "frequency", 0.0);
    d->min_frequency = sn_double_or(desc, "minFrequency", 0.0);
    d->max_frequency = sn_double_or(desc, "maxFrequency", 0.0);
    d->point_cloud_enabled = sn_bool_or(desc, "point_cloud_enabled", false);
    size_t n = (size_t)d->width * (size_t)d->layers;
    d->range_image = calloc(n, sizeof(float));
    d->point_cloud = calloc(n, sizeof(WbLidarPoint));
    if (d->range_image == NULL || d->point_cloud == NULL)
      return -1;
  }
  if (d->kind == SN_RADAR) { /* wb_radar_get_min_range ... vertical_fov: the world's fields */
    d->min_range = sn_double_or(desc, "min_range", NAN);
    d->max_range = sn_double_or(desc, "max_range", NAN);
    d->fov = sn_double_or(desc, "horizontal_fov", NAN);
    d->vertical_fov = sn_double_or(desc, "vertical_fov", NAN);
  }
  if (d->kind == SN_VACUUM)
    d->pump_on = sn_bool_or(desc, "is_on", false);
  snprintf(d->engine, sizeof d->engine, "pico"); /* libController's speaker_create */
  snprintf(d->language, sizeof d->language, "en-US");
  if (d->kind == SN_CONNECTOR) { /* presence -1 until the first value; the lock state as loaded */
    d->value = -1.0;
    const msgpack_object *t = sn_get(desc, "connector_type");
    d->connector_passive = t != NULL && t->type == MSGPACK_OBJECT_STR && t->via.str.size == 7 &&
                           memcmp(t->via.str.ptr, "passive", 7) == 0;
    d->is_locked = sn_bool_or(desc, "is_locked", false);
  }
  if (d->kind == SN_BRAKE) {
    d->joint_type = (int)sn_int_or(desc, "joint_type", 0);
    d->position_sensor_name = sn_strdup_obj(sn_get(desc, "position_sensor"));
  }
  if (sn_imaging_describe(d, desc) != 0)
    return -1;
  d->motor_name = sn_strdup_obj(sn_get(desc, "motor"));
  d->led_value = (int)sn_int_or(desc, "value", 0);
  d->led_colors = count_leaves(sn_get(desc, "color")) / 3;
  d->led_gradual = sn_bool_or(desc, "gradual", false);
  d->max_velocity = sn_double_or(desc, "maxVelocity", 10.0);
  d->min_position = sn_double_or(desc, "minPosition", 0.0);
  d->max_position = sn_double_or(desc, "maxPosition", 0.0);
  d->target_position = sn_double_or(desc, "targetPosition", 0.0);
  d->velocity = sn_double_or(desc, "velocity", d->max_velocity);
  d->acceleration = sn_double_or(desc, "acceleration", -1.0); /* Webots' default: unlimited */
  d->joint = sn_get(desc, "maxForce") != NULL;
  d->max_force = sn_double_or(desc, "maxForce", NAN);
  d->available_force = d->max_force;
  d->initial_position = sn_double_or(desc, "initialPosition", 0.0);
  d->multiplier = sn_double_or(desc, "multiplier", 1.0);
  const msgpack_object *coupled = sn_get(desc, "coupled");
  if (coupled != NULL && coupled->type == MSGPACK_OBJECT_ARRAY && coupled->via.array.size > 0) {
    d->coupled = calloc(coupled->via.array.size, sizeof(char *));
    if (d->coupled == NULL)
      return -1;
    for (uint32_t i = 0; i < coupled->via.array.size; i++) {
      char *name = sn_strdup_obj(&coupled->via.array.ptr[i]);
      if (name != NULL)
        d->coupled[d->n_coupled++] = name;
    }
  }
  return 0;
}

static void free_robot(sn_robot *rb) {
  if (rb == NULL)
    return;
  for (int i = 0; i < rb->n_devices; i++) {
    sn_device *d = &rb->devices[i];
    free(d->name);
    free(d->type_name);
    free(d->model);
    free(d->lookup_table);
    free(d->range_image);
    free(d->point_cloud);
    free(d->motor_name);
    for (int k = 0; k < d->n_coupled; k++)
      free(d->coupled[k]);
    free(d->coupled);
    free(d->position_sensor_name);
    free(d->radar_targets);
    sn_imaging_free(d);
    sn_radio_free(d);
    sn_display_free(d);
    sn_speaker_free(d);
  }
  sn_supervisor_free(rb);
  free(rb->devices);
  free(rb->name);
  free(rb->session);
  free(rb->model);
  free(rb->custom_data);
  free(rb->wwi_inbox);
  free(rb->wwi_batch);
  for (int i = 0; i < 6; i++)
    free(rb->car.motors[i]);
  free(rb->prefix);
  sn_conn_close(rb->conn);
  free(rb);
}

/* ------------------------------------------------------------------ init / cleanup */

/* The attach reply's "ackermann_drive" (a map; nil or absent for a robot that is not a car). */
static void parse_car(sn_car *car, const msgpack_object *o) {
  static const char *const motors[6] = {"right_steer",      "left_steer",       "right_front_wheel",
                                        "left_front_wheel", "right_rear_wheel", "left_rear_wheel"};
  memset(car, 0, sizeof *car);
  if (o == NULL || o->type != MSGPACK_OBJECT_MAP)
    return;
  car->wheelbase = sn_double_or(o, "wheelbase", NAN);
  car->track_front = sn_double_or(o, "track_front", NAN);
  car->track_rear = sn_double_or(o, "track_rear", NAN);
  car->front_wheel_radius = sn_double_or(o, "front_wheel_radius", NAN);
  car->rear_wheel_radius = sn_double_or(o, "rear_wheel_radius", NAN);
  char *type = sn_strdup_obj(sn_get(o, "type"));
  char *steers = sn_strdup_obj(sn_get(o, "positive_steers"));
  car->type = type == NULL ? -1 : strcmp(type, "traction") == 0 ? 0 : strcmp(type, "propulsion") == 0 ? 1
                                : strcmp(type, "4x4") == 0        ? 2 : -1;
  car->sign = steers != NULL && strcmp(steers, "left") == 0 ? -1.0 : 1.0;
  char *engine = sn_strdup_obj(sn_get(o, "engine_type")); /* absent (an older server): combustion */
  car->engine = engine == NULL                           ? 0
                : strcmp(engine, "electric") == 0           ? 1
                : strcmp(engine, "parallel hybrid") == 0    ? 2
                : strcmp(engine, "power-split hybrid") == 0 ? 3
                                                            : 0;
  free(type);
  free(steers);
  free(engine);
  bool ok = car->type >= 0 && car->wheelbase > 0 && car->front_wheel_radius > 0 && car->rear_wheel_radius > 0;
  for (int i = 0; i < 6; i++) {
    car->motors[i] = sn_strdup_obj(sn_get(o, motors[i]));
    ok = ok && car->motors[i] != NULL;
  }
  car->present = ok;
}

static int call(sn_conn *c, sn_req *r, uint64_t id, int timeout_ms, sn_reply *out) {
  if (sn_conn_send(c, r, id) != 0) {
    sn_req_free(r);
    memset(out, 0, sizeof *out);
    const char *refused = sn_conn_handshake_problem(c);
    out->code = refused != NULL ? SN_TIMEOUT : SN_CONNECTION_LOST;
    snprintf(out->message, sizeof out->message, "%s %s%s%s", refused != NULL ? "no reply from" : "cannot send to",
             sn_conn_endpoint(c), refused != NULL ? ": " : "", refused != NULL ? refused : "");
    return -1;
  }
  sn_req_free(r);
  if (sn_conn_wait(c, id, timeout_ms, out) != 0 || !out->ok)
    return -1;
  return 0;
}

static char *only_robot(sn_conn *c) {
  sn_req r;
  uint64_t id = sn_conn_next_id(c);
  sn_req_begin(&r, id, "get_info", 0);
  sn_reply rep;
  if (call(c, &r, id, g_timeout_ms, &rep) != 0)
    fatal("wb_robot_init", rep.code, rep.message);
  const msgpack_object *robots = sn_get(rep.result, "robots");
  uint32_t n = robots && robots->type == MSGPACK_OBJECT_ARRAY ? robots->via.array.size : 0;
  if (n != 1) {
    char names[400] = "";
    for (uint32_t i = 0; i < n; i++) {
      const msgpack_object *nm = sn_get(&robots->via.array.ptr[i], "name");
      if (nm && nm->type == MSGPACK_OBJECT_STR)
        snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", i ? ", " : "",
                 sn_shown_n(nm->via.str.ptr, nm->via.str.size));
    }
    char msg[600];
    snprintf(msg, sizeof msg, "the controller URL names no robot and the world at %s has %u (%s): add '/ROBOT' to the URL",
             sn_conn_endpoint(c), n, names);
    sn_reply_free(&rep);
    fatal("wb_robot_init", SN_BAD_URL, msg);
  }
  char *name = sn_strdup_obj(sn_get(&robots->via.array.ptr[0], "name"));
  sn_reply_free(&rep);
  return name;
}

int wb_robot_init(void) {
  /* As libController: stdout and stderr line-buffered, so a controller's lines reach `sensorium run`'s
     pipe (or a log file) as they are printed, not when 4 KiB have gathered or the process ends; what
     was printed before goes out now. */
  fflush(stdout);
  fflush(stderr);
  setvbuf(stdout, NULL, _IOLBF, 4096);
  setvbuf(stderr, NULL, _IOLBF, 4096);
  if (g_robot != NULL)
    return 1;
  g_timeout_ms = timeout_from_env();
  const char *env = getenv("SENSORIUM_CONTROLLER_URL");
  if (env == NULL || *env == '\0')
    env = getenv("WEBOTS_CONTROLLER_URL");
  sn_url url;
  char err[512];
  if (sn_parse_url(env, &url, err, sizeof err) != 0)
    fatal("wb_robot_init", SN_BAD_URL, err);
  sn_conn *c = sn_conn_open(url.endpoint, err, sizeof err);
  if (c == NULL)
    fatal("wb_robot_init", SN_BAD_URL, err);
  /* a URL without a robot: WEBOTS_ROBOT_NAME's (Webots sets it for the controllers it starts; extern
     controllers before R2022b chose their robot with it), taken as it is; else the world's only robot */
  const char *named = getenv("WEBOTS_ROBOT_NAME");
  char *name = url.robot ? strdup(url.robot) : (named != NULL && *named != '\0') ? strdup(named) : only_robot(c);
  sn_url_free(&url);
  sn_req r;
  uint64_t id = sn_conn_next_id(c);
  sn_req_begin(&r, id, "attach", 1);
  sn_req_key(&r, "robot");
  sn_req_str(&r, name ? name : "");
  sn_reply rep;
  if (call(c, &r, id, g_timeout_ms, &rep) != 0) {
    char msg[700];
    snprintf(msg, sizeof msg, "attaching to robot '%s' at %s: %s", sn_shown(name ? name : ""), sn_conn_endpoint(c),
             rep.message);
    fatal("wb_robot_init", rep.code, msg);
  }
  sn_robot *rb = calloc(1, sizeof *rb);
  const msgpack_object *res = rep.result;
  rb->conn = c;
  rb->name = sn_strdup_obj(sn_get(res, "robot"));
  if (rb->name == NULL)
    rb->name = strdup(name ? name : "");
  free(name);
  rb->session = sn_strdup_obj(sn_get(res, "session"));
  rb->model = sn_strdup_obj(sn_get(res, "model"));
  rb->custom_data = sn_strdup_obj(sn_get(res, "custom_data"));
  if (rb->model == NULL)
    rb->model = strdup("");
  if (rb->custom_data == NULL)
    rb->custom_data = strdup("");
  parse_car(&rb->car, sn_get(res, "ackermann_drive"));
  rb->basic_time_step = (int)sn_int_or(res, "basic_time_step", 0);
  rb->time_ms = sn_int_or(res, "time_ms", 0);
  rb->synchronization = sn_bool_or(res, "synchronization", true);
  rb->supervisor = sn_bool_or(res, "supervisor", false);
  rb->wwi_fresh = true;
  int heartbeat_ms = (int)sn_int_or(res, "heartbeat_ms", 1000);
  size_t plen = strlen(rb->name) + 3;
  rb->prefix = malloc(plen);
  if (rb->prefix != NULL)
    snprintf(rb->prefix, plen, "/%s/", rb->name);
  const msgpack_object *devs = sn_get(res, "devices");
  int n = devs && devs->type == MSGPACK_OBJECT_ARRAY ? (int)devs->via.array.size : 0;
  if (n > 65535)
    n = 65535; /* a WbDeviceTag is an unsigned short */
  rb->devices = calloc(n > 0 ? (size_t)n : 1, sizeof(sn_device));
  rb->n_devices = n;
  bool bad = rb->session == NULL || rb->prefix == NULL || rb->basic_time_step <= 0 || rb->devices == NULL;
  for (int i = 0; !bad && i < n; i++)
    bad = describe(&rb->devices[i], i, &devs->via.array.ptr[i]) != 0;
  sn_reply_free(&rep);
  if (bad) {
    free_robot(rb);
    fatal("wb_robot_init", SN_BAD_REPLY, "the attach reply lacks session, basic_time_step or device descriptions");
  }
  g_robot = rb;
  g_cleaned = 0;
  if (sn_conn_start_heartbeat(c, rb->session, heartbeat_ms) != 0)
    fatal("wb_robot_init", SN_INTERNAL, "cannot start the heartbeat thread");
  if (!g_atexit) {
    atexit(wb_robot_cleanup);
    g_atexit = true;
  }
  return 1;
}

void wb_robot_cleanup(void) {
  sn_robot *rb = g_robot;
  if (rb == NULL)
    return;
  sn_movie_finish(rb); /* (while its calls still reach the server) */
  g_robot = NULL;
  g_cleaned = rb->terminated ? 1 : 2;
  sn_conn_stop_heartbeat(rb->conn);
  if (rb->pending != 0) {
    sn_conn_discard(rb->conn, rb->pending);
    rb->pending = 0;
  }
  sn_req r;
  uint64_t id = sn_conn_next_id(rb->conn);
  sn_req_begin(&r, id, "detach", 1);
  sn_req_key(&r, "session");
  sn_req_str(&r, rb->session);
  sn_reply rep;
  call(rb->conn, &r, id, 500, &rep); /* best effort */
  sn_reply_free(&rep);
  free_robot(rb);
}

/* ------------------------------------------------------------------ stepping */

static float le_float(const unsigned char *p) {
  uint32_t u = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
  float f;
  memcpy(&f, &u, sizeof f);
  return f;
}

/* the n doubles of reading[key] into out (NaN for a non-number), when present with n elements */
static void read_vector(const msgpack_object *reading, const char *key, double *out, uint32_t n) {
  const msgpack_object *v = sn_get(reading, key);
  if (v == NULL || v->type != MSGPACK_OBJECT_ARRAY || v->via.array.size != n)
    return;
  for (uint32_t j = 0; j < n; j++)
    if (!sn_as_double(&v->via.array.ptr[j], &out[j]))
      out[j] = NAN;
}

static void apply_values(sn_robot *rb, const msgpack_object *values) {
  if (values == NULL || values->type != MSGPACK_OBJECT_MAP)
    return;
  for (uint32_t i = 0; i < values->via.map.size; i++) {
    const msgpack_object *k = &values->via.map.ptr[i].key, *v = &values->via.map.ptr[i].val;
    if (k->type != MSGPACK_OBJECT_STR || v->type != MSGPACK_OBJECT_MAP)
      continue;
    sn_device *dev = NULL;
    for (int j = 0; j < rb->n_devices && dev == NULL; j++)
      if (strlen(rb->devices[j].name) == k->via.str.size && memcmp(rb->devices[j].name, k->via.str.ptr, k->via.str.size) == 0)
        dev = &rb->devices[j];
    if (dev == NULL)
      continue;
    double x;
    if (sn_as_double(sn_get(v, "value"), &x)) {
      dev->value = x;
      if (dev->kind == SN_LED && isfinite(x))
        dev->led_value = (int)x;
    }
    if (dev->kind == SN_GPS) {
      read_vector(v, "values", dev->gps_values, 3);
      read_vector(v, "speed_vector", dev->gps_speed_vector, 3);
      if (!sn_as_double(sn_get(v, "speed"), &dev->gps_speed))
        dev->gps_speed = NAN;
    } else {
      read_vector(v, "values", dev->values, 3);
      read_vector(v, "quaternion", dev->quaternion, 4);
      read_vector(v, "roll_pitch_yaw", dev->roll_pitch_yaw, 3);
    }
    sn_imaging_apply(dev, v);
    if (dev->kind == SN_RECEIVER)
      sn_radio_receive(dev, sn_get(v, "packets"));
    if (dev->kind == SN_RADAR)
      sn_radar_apply(dev, sn_get(v, "targets"));
    if (dev->kind == SN_SPEAKER)
      sn_speaker_apply(dev, v);
    if (dev->kind == SN_VACUUM) /* its pump, as measured (a simulation reset may change it) */
      dev->pump_on = sn_bool_or(v, "is_on", dev->pump_on);
    if (dev->kind != SN_LIDAR)
      continue;
    size_t n = (size_t)dev->width * (size_t)dev->layers;
    const msgpack_object *img = sn_get(v, "range_image");
    if (img != NULL && img->type == MSGPACK_OBJECT_BIN && img->via.bin.size == 4 * n) {
      const unsigned char *p = (const unsigned char *)img->via.bin.ptr;
      for (size_t j = 0; j < n; j++)
        dev->range_image[j] = le_float(p + 4 * j);
    } else if (img != NULL)
      fprintf(stderr, "Warning: lidar '%s': range image of %u bytes, expected %zu: ignored\n", sn_shown(dev->name),
              img->type == MSGPACK_OBJECT_BIN ? img->via.bin.size : 0u, 4 * n);
    const msgpack_object *pc = sn_get(v, "point_cloud");
    if (pc != NULL && pc->type == MSGPACK_OBJECT_BIN && pc->via.bin.size == 20 * n) {
      const unsigned char *p = (const unsigned char *)pc->via.bin.ptr;
      for (size_t j = 0; j < n; j++, p += 20) {
        WbLidarPoint *q = &dev->point_cloud[j];
        q->x = le_float(p);
        q->y = le_float(p + 4);
        q->z = le_float(p + 8);
        uint32_t u = (uint32_t)p[12] | (uint32_t)p[13] << 8 | (uint32_t)p[14] << 16 | (uint32_t)p[15] << 24;
        memcpy(&q->layer_id, &u, sizeof u);
        q->time = le_float(p + 16);
      }
    } else if (pc != NULL)
      fprintf(stderr, "Warning: lidar '%s': point cloud of %u bytes, expected %zu: ignored\n", sn_shown(dev->name),
              pc->type == MSGPACK_OBJECT_BIN ? pc->via.bin.size : 0u, 20 * n);
  }
}

int wb_robot_step_begin(int duration) {
  sn_robot *rb = sn_robot_get("wb_robot_step_begin");
  if (rb->pending != 0) {
    fprintf(stderr, "Error: wb_robot_step_begin(): a step is already pending: call wb_robot_step_end() first\n");
    return -1;
  }
  if (rb->terminated) {
    /* libController's end of a controller: once a step has answered -1 because the simulation ended
       for it (the server quit, stopped or went away, simulation_quit), the next step ends the process
       with status 0 (the atexit cleanup detaches), so a loop that ignores -1 does not spin forever */
    if (rb->quit_returned)
      exit(EXIT_SUCCESS);
    rb->quit_returned = true;
    return -1;
  }
  if (duration < 0) {
    fprintf(stderr, "Error: wb_robot_step(): step duration must be >= 0 ms, got %d\n", duration);
    return -1;
  }
  if (duration % rb->basic_time_step && !rb->warned_duration) {
    /* Webots warns once and wakes the controller at the first basic step that ends after it */
    rb->warned_duration = true;
    fprintf(stderr, "Warning: the step duration %d ms of robot '%s' is not a multiple of the basic time step (%d ms); "
            "the server rounds it up.\n", duration, sn_shown(rb->name), rb->basic_time_step);
  }
  sn_motion_step_all(duration); /* the playing motions set their motors' positions (motion.c) */
  rb->wwi_fresh = true;         /* what is left of the robot-window batch being read is dropped */
  int motors = 0, emitters = 0;
  for (int i = 0; i < rb->n_devices; i++) {
    motors += rb->devices[i].kind == SN_MOTOR && (rb->devices[i].cmd_position || rb->devices[i].cmd_velocity ||
                                                  rb->devices[i].cmd_acceleration || rb->devices[i].cmd_available);
    if (rb->devices[i].kind == SN_EMITTER)
      emitters += sn_radio_pace(&rb->devices[i], duration) > 0; /* what the baud rate lets leave now */
  }
  char service[512];
  snprintf(service, sizeof service, "%srobot/step", rb->prefix);
  sn_req r;
  uint64_t id = sn_conn_next_id(rb->conn);
  int displays = sn_display_pending(rb);
  sn_req_begin(&r, id, service, 1 + (motors > 0) + (emitters > 0) + (displays > 0));
  sn_req_key(&r, "duration");
  msgpack_pack_int(&r.pk, duration);
  if (displays)
    sn_display_pack(rb, &r);
  if (emitters) {
    sn_req_key(&r, "emitters");
    msgpack_pack_map(&r.pk, (size_t)emitters);
    for (int i = 0; i < rb->n_devices; i++)
      if (rb->devices[i].kind == SN_EMITTER && rb->devices[i].sending > 0)
        sn_radio_pack(&rb->devices[i], &r);
  }
  if (motors) {
    sn_req_key(&r, "motors");
    msgpack_pack_map(&r.pk, (size_t)motors);
    for (int i = 0; i < rb->n_devices; i++) {
      sn_device *d = &rb->devices[i];
      if (d->kind != SN_MOTOR || !(d->cmd_position || d->cmd_velocity || d->cmd_acceleration || d->cmd_available))
        continue;
      sn_req_str(&r, d->name);
      msgpack_pack_map(&r.pk, (size_t)d->cmd_position + (size_t)d->cmd_velocity + (size_t)d->cmd_acceleration +
                                  (size_t)d->cmd_available);
      if (d->cmd_position) {
        sn_req_key(&r, "position");
        msgpack_pack_double(&r.pk, d->target_position);
      }
      if (d->cmd_velocity) {
        sn_req_key(&r, "velocity");
        msgpack_pack_double(&r.pk, d->velocity);
      }
      if (d->cmd_acceleration) {
        sn_req_key(&r, "acceleration");
        msgpack_pack_double(&r.pk, d->acceleration);
      }
      if (d->cmd_available) {
        sn_req_key(&r, "available_force");
        msgpack_pack_double(&r.pk, d->available_force);
      }
      d->cmd_position = d->cmd_velocity = d->cmd_acceleration = d->cmd_available = false;
    }
  }
  int rc = sn_conn_send_retried(rb->conn, &r, id);
  sn_req_free(&r);
  if (rc != 0) {
    fprintf(stderr, "sensorium: cannot send the step request to %s; ending the controller's steps\n",
            sn_conn_endpoint(rb->conn));
    sn_steps_ended(rb);
    rb->quit_returned = true;
    return -1;
  }
  rb->pending = id;
  return 0;
}

static int step_end(sn_robot *rb);

void sn_steps_ended(sn_robot *rb) {
  rb->terminated = true;
  sn_movie_after_step(rb); /* (a movie recording ends with the world) */
}

int wb_robot_step_end(void) {
  sn_robot *rb = sn_robot_get("wb_robot_step_end");
  int status = step_end(rb);
  if (status == -1 && rb->terminated)
    rb->quit_returned = true;
  return status;
}

static int step_end(sn_robot *rb) {
  if (rb->pending == 0) {
    if (!rb->terminated)
      fprintf(stderr, "Error: wb_robot_step_end(): no step pending: call wb_robot_step_begin() first\n");
    return -1;
  }
  uint64_t id = rb->pending;
  rb->pending = 0;
  sn_reply rep;
  int rc = sn_conn_wait(rb->conn, id, -1, &rep);
  if (rc != 0 && rep.code == SN_CONNECTION_LOST) {
    fprintf(stderr, "sensorium: CONNECTION_LOST: %s; ending the controller's steps\n", rep.message);
    sn_steps_ended(rb);
    return -1;
  }
  if (rc != 0 || !rep.ok) {
    const bool ended = rep.code == SN_SHUTTING_DOWN;
    if (!ended)
      fprintf(stderr, "Error: wb_robot_step(): %s: %s\n", sn_error_name(rep.code), rep.message);
    sn_reply_free(&rep);
    if (ended)
      sn_steps_ended(rb);
    return -1;
  }
  int status = (int)sn_int_or(rep.result, "status", 0);
  rb->time_ms = sn_int_or(rep.result, "time_ms", rb->time_ms);
  apply_values(rb, sn_get(rep.result, "values"));
  /* a Supervisor set the robot's customData field: Webots sends it with the step's answer too */
  char *data = sn_strdup_obj(sn_get(rep.result, "custom_data"));
  if (data != NULL) {
    free(rb->custom_data);
    rb->custom_data = data;
  }
  sn_wwi_received(rb, sn_get(rep.result, "robot_window"));
  sn_reply_free(&rep);
  if (status == -1)
    rb->terminated = true;
  sn_movie_after_step(rb);
  return status;
}

int wb_robot_step(int duration) {
  if (wb_robot_step_begin(duration) == -1)
    return -1;
  return wb_robot_step_end();
}

/* ------------------------------------------------------------------ robot getters */

double wb_robot_get_time(void) { return (double)sn_robot_get("wb_robot_get_time")->time_ms / 1000.0; }

double wb_robot_get_basic_time_step(void) { return (double)sn_robot_get("wb_robot_get_basic_time_step")->basic_time_step; }

const char *wb_robot_get_name(void) { return sn_robot_get("wb_robot_get_name")->name; }

const char *wb_robot_get_model(void) { return sn_robot_get("wb_robot_get_model")->model; }

bool wb_robot_get_synchronization(void) { return sn_robot_get("wb_robot_get_synchronization")->synchronization; }

bool wb_robot_get_supervisor(void) { return sn_robot_get("wb_robot_get_supervisor")->supervisor; }

const char *wb_robot_get_custom_data(void) { return sn_robot_get("wb_robot_get_custom_data")->custom_data; }

static void arg_str(sn_req *r, const void *arg) { sn_req_str(r, (const char *)arg); }

void wb_robot_set_custom_data(const char *data) {
  sn_robot *rb = sn_robot_get("wb_robot_set_custom_data");
  if (data == NULL) {
    fprintf(stderr, "Error: wb_robot_set_custom_data() called with a NULL 'data' argument\n");
    return;
  }
  if (!rb->terminated) {
    sn_reply rep;
    if (sn_device_call(rb, NULL, "robot/set_custom_data", arg_str, data, "wb_robot_set_custom_data", &rep) != 0)
      return;
    sn_reply_free(&rep);
  }
  char *copy = strdup(data);
  if (copy == NULL)
    return;
  free(rb->custom_data);
  rb->custom_data = copy;
}

WbRobotMode wb_robot_get_mode(void) {
  sn_robot_get("wb_robot_get_mode");
  return WB_MODE_SIMULATION;
}

void wb_robot_set_mode(WbRobotMode mode, const char *arg) {
  (void)arg;
  sn_robot_get("wb_robot_set_mode");
  if (mode != WB_MODE_SIMULATION)
    fprintf(stderr, "Error: wb_robot_set_mode(): Sensorium robots are simulated only (mode %d refused)\n", (int)mode);
}

int wb_robot_get_number_of_devices(void) { return sn_robot_get("wb_robot_get_number_of_devices")->n_devices; }

WbDeviceTag wb_robot_get_device(const char *name) {
  sn_robot *rb = sn_robot_get("wb_robot_get_device");
  if (name == NULL || name[0] == '\0') {
    fprintf(stderr, "Error: wb_robot_get_device() called with a NULL or empty name.\n");
    return 0;
  }
  for (int i = 0; i < rb->n_devices; i++)
    if (strcmp(rb->devices[i].name, name) == 0)
      return rb->devices[i].tag;
  /* Webots warns too: a misspelt name would otherwise only show as a later "invalid device tag 0" */
  fprintf(stderr, "Warning: wb_robot_get_device(): robot \"%s\" has no device \"%s\".\n", sn_shown(rb->name), sn_shown(name));
  return 0;
}

WbDeviceTag wb_robot_get_device_by_index(int index) {
  sn_robot *rb = sn_robot_get("wb_robot_get_device_by_index");
  if (index >= 0 && index < rb->n_devices)
    return rb->devices[index].tag;
  fprintf(stderr, "Error: wb_robot_get_device_by_index(): index %d is outside [0, %d].\n", index, rb->n_devices - 1);
  return 0;
}

/* ------------------------------------------------------------------ device helpers */

/* the node types whose devices a kind's functions take (wb_motor_* takes both motors) */
static bool kind_accepts(sn_kind kind, int node) {
  switch (kind) {
    case SN_LIGHT: return node == WB_NODE_LIGHT_SENSOR;
    case SN_DISTANCE: return node == WB_NODE_DISTANCE_SENSOR;
    case SN_LIDAR: return node == WB_NODE_LIDAR;
    case SN_MOTOR: return node == WB_NODE_ROTATIONAL_MOTOR || node == WB_NODE_LINEAR_MOTOR;
    case SN_POSITION: return node == WB_NODE_POSITION_SENSOR;
    case SN_LED: return node == WB_NODE_LED;
    case SN_GPS: return node == WB_NODE_GPS;
    case SN_RANGE_FINDER: return node == WB_NODE_RANGE_FINDER;
    case SN_CAMERA: return node == WB_NODE_CAMERA;
    case SN_IMU: return node == WB_NODE_INERTIAL_UNIT;
    case SN_COMPASS: return node == WB_NODE_COMPASS;
    case SN_ACCELEROMETER: return node == WB_NODE_ACCELEROMETER;
    case SN_GYRO: return node == WB_NODE_GYRO;
    case SN_ALTIMETER: return node == WB_NODE_ALTIMETER;
    case SN_TOUCH: return node == WB_NODE_TOUCH_SENSOR;
    case SN_EMITTER: return node == WB_NODE_EMITTER;
    case SN_RECEIVER: return node == WB_NODE_RECEIVER;
    case SN_RADAR: return node == WB_NODE_RADAR;
    case SN_VACUUM: return node == WB_NODE_VACUUM_GRIPPER;
    case SN_SPEAKER: return node == WB_NODE_SPEAKER;
    case SN_CONNECTOR: return node == WB_NODE_CONNECTOR;
    case SN_BRAKE: return node == WB_NODE_BRAKE;
    default: return false;
  }
}

bool sn_unsimulated(WbDeviceTag tag, int node_type, const char *func) {
  sn_robot *rb = sn_robot_get(func);
  if (tag < 1 || tag > rb->n_devices) {
    fprintf(stderr, "Error: %s(): invalid device tag %u\n", func, (unsigned)tag);
    return false;
  }
  sn_device *d = &rb->devices[tag - 1];
  if (d->node_type != node_type && !(node_type == WB_NODE_ROTATIONAL_MOTOR && d->node_type == WB_NODE_LINEAR_MOTOR)) {
    fprintf(stderr, "Error: %s(): device tag %u is '%s', a %s\n", func, (unsigned)tag, sn_shown(d->name), d->type_name);
    return false;
  }
  if (!d->warned_unsimulated) {
    d->warned_unsimulated = true;
    if (d->simulated) /* the server measures it; this library does not read those readings yet */
      fprintf(stderr, "Warning: %s(): the C client does not read %s '%s' yet (its services and topics do): its functions "
              "answer Webots' \"no value\" (NaN, NULL, 0).\n", func, d->type_name, sn_shown(d->name));
    else
      fprintf(stderr, "Warning: %s(): Sensorium does not simulate %s '%s': its functions answer Webots' \"no value\" "
              "(NaN, NULL, 0).\n", func, d->type_name, sn_shown(d->name));
  }
  return false;
}

const double *sn_no_values(void) {
  static double nan_values[16];
  for (int i = 0; i < 16; i++)
    nan_values[i] = NAN;
  return nan_values;
}

sn_device *sn_device_get(WbDeviceTag tag, sn_kind kind, const char *func) {
  sn_robot *rb = sn_robot_get(func);
  if (tag >= 1 && tag <= rb->n_devices) {
    sn_device *d = &rb->devices[tag - 1];
    if (kind == SN_OTHER || d->kind == kind)
      return d;
    if (!d->simulated && kind_accepts(kind, d->node_type)) {
      sn_unsimulated(tag, d->node_type, func);
      return NULL;
    }
    fprintf(stderr, "Error: %s(): device tag %u is '%s', a %s\n", func, (unsigned)tag, sn_shown(d->name), d->type_name);
    return NULL;
  }
  fprintf(stderr, "Error: %s(): invalid device tag %u\n", func, (unsigned)tag);
  return NULL;
}

void sn_arg_int(sn_req *r, const void *arg) { msgpack_pack_int(&r->pk, *(const int *)arg); }

void sn_arg_bool(sn_req *r, const void *arg) {
  if (*(const bool *)arg)
    msgpack_pack_true(&r->pk);
  else
    msgpack_pack_false(&r->pk);
}

void sn_arg_double(sn_req *r, const void *arg) { msgpack_pack_double(&r->pk, *(const double *)arg); }

int sn_robot_call(sn_robot *rb, const char *item, uint32_t nargs, sn_arg_fn add_args, const void *arg,
                  const char *func, sn_reply *out) {
  char service[1024];
  snprintf(service, sizeof service, "%s%s", rb->prefix, item);
  sn_req r;
  uint64_t id = sn_conn_next_id(rb->conn);
  sn_req_begin(&r, id, service, nargs);
  if (add_args)
    add_args(&r, arg);
  if (call(rb->conn, &r, id, g_timeout_ms, out) != 0) {
    fprintf(stderr, "Error: %s(): %s: %s\n", func, sn_error_name(out->code), out->message);
    sn_reply_free(out);
    return -1;
  }
  const msgpack_object *success = sn_get(out->result, "success");
  if (success != NULL && success->type == MSGPACK_OBJECT_BOOLEAN && !success->via.boolean) {
    fprintf(stderr, "Error: %s(): refused by the server\n", func);
    sn_reply_free(out);
    return -1;
  }
  return 0;
}

typedef struct {
  sn_arg_fn add_value;
  const void *arg;
} value_arg;

static void add_value_arg(sn_req *r, const void *p) {
  const value_arg *v = p;
  sn_req_key(r, "value");
  v->add_value(r, v->arg);
}

int sn_device_call(sn_robot *rb, const sn_device *dev, const char *item, sn_arg_fn add_value, const void *arg,
                   const char *func, sn_reply *out) {
  char path[1024];
  snprintf(path, sizeof path, "%s%s%s", dev ? dev->name : "", dev ? "/" : "", item);
  value_arg v = {add_value, arg};
  return sn_robot_call(rb, path, add_value ? 1 : 0, add_value ? add_value_arg : NULL, &v, func, out);
}

bool sn_device_set(sn_device *dev, const char *item, sn_arg_fn add_value, const void *arg, const char *func) {
  sn_robot *rb = sn_robot_get(func);
  if (rb->terminated)
    return true;
  sn_reply rep;
  if (sn_device_call(rb, dev, item, add_value, arg, func, &rep) != 0)
    return false;
  sn_reply_free(&rep);
  return true;
}

void sn_device_enable(sn_device *dev, int period, const char *func) {
  if (period < 0) {
    fprintf(stderr, "Error: %s(): negative sampling period %d\n", func, period);
    return;
  }
  if (!sn_device_set(dev, "enable", sn_arg_int, &period, func))
    return;
  dev->sampling_period = period;
  dev->warned = false;
}

void sn_warn_disabled(sn_device *dev, const char *func, const char *enabler, const char *what) {
  if (!dev->warned) {
    dev->warned = true;
    fprintf(stderr, "Error: %s() called for %s! Please use: %s().\n", func, what ? what : "a disabled device", enabler);
  }
}
