/* Sensorium C controller library: internals shared by the source files (not installed).
 *
 * conn.c    - the only ZeroMQ code: controller URLs, the DEALER socket, requests matched by id,
 *             the heartbeat thread;
 * wire.c    - msgpack helpers (building requests, reading reply maps);
 * robot.c   - the session: attach, step (motor commands out, readings in), cleanup;
 * devices.c - light and distance sensors, generic device functions (and every sensor's enable,
 *             sampling period and reading: sn_sensor_*); lidar.c; motor.c; gps.c;
 * kinematic.c - InertialUnit, Compass, Accelerometer, Gyro, Altimeter, TouchSensor;
 * radio.c   - Emitter and Receiver (packet queues, baud-rate pacing);
 * radar.c   - Radar (the targets of the latest measurement);
 * vacuum_gripper.c - VacuumGripper (the pump, the presence); speaker.c - Speaker (sounds, speech);
 * connector.c - Connector (presence, lock state) and Brake (its joint's type and neighbours);
 * camera.c  - range finders and cameras;
 * display.c - the Display (drawing buffered, sent with the next step request);
 * unsimulated.c - the devices Sensorium lists without simulating ("no value").
 */
#ifndef SENSORIUM_INTERNAL_H
#define SENSORIUM_INTERNAL_H

#include <msgpack.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <webots/lidar_point.h>
#include <webots/radar_target.h>
#include <webots/types.h>

/* ------------------------------------------------------------------ error codes (PROTOCOL.md 3.2) */
enum {
  SN_BAD_REQUEST = 1,
  SN_UNKNOWN_SERVICE = 2,
  SN_UNKNOWN_ROBOT = 3,
  SN_UNKNOWN_DEVICE = 4,
  SN_INVALID_ARGUMENT = 5,
  SN_NOT_ATTACHED = 6,
  SN_ROBOT_TAKEN = 7,
  SN_TOO_LARGE = 8,
  SN_SHUTTING_DOWN = 9,
  SN_WRONG_STATE = 10,
  SN_INTERNAL = 99,
  /* client side, as the Python client's */
  SN_TIMEOUT = 1000,
  SN_CONNECTION_LOST = 1001,
  SN_BAD_REPLY = 1002,
  SN_BAD_URL = 1003
};
const char *sn_error_name(int code);

/* ------------------------------------------------------------------ utils.c */
/* s as it may show inside one error line: control characters as \n, \t, \r or \xNN (the Python
 * side's repr escapes), other bytes (UTF-8 included) as they are, cut with "..." past SN_SHOWN_MAX
 * bytes; NULL as "(null)". The text lives in one of SN_SHOWN_SLOTS buffers of the calling thread, reused
 * in turn: up to that many may be shown in one fprintf. */
#define SN_SHOWN_MAX 4096
#define SN_SHOWN_SLOTS 4
const char *sn_shown(const char *s);
/* sn_shown of the n bytes at s, which need no NUL (a msgpack string of a reply); a NUL byte among them
 * shows as \x00. */
const char *sn_shown_n(const char *s, size_t n);

/* ------------------------------------------------------------------ wire.c */
typedef struct {
  msgpack_sbuffer buf;
  msgpack_packer pk;
} sn_req;

/* Start {"id": id, "service": service, "args": {<nargs entries>}}; then add nargs key/values. */
void sn_req_begin(sn_req *r, uint64_t id, const char *service, uint32_t nargs);
void sn_req_key(sn_req *r, const char *key);
void sn_req_str(sn_req *r, const char *s);
void sn_req_free(sn_req *r);

const msgpack_object *sn_get(const msgpack_object *map, const char *key); /* NULL if absent */
bool sn_as_double(const msgpack_object *o, double *out);
bool sn_as_int64(const msgpack_object *o, int64_t *out);
double sn_double_or(const msgpack_object *map, const char *key, double fallback);
int64_t sn_int_or(const msgpack_object *map, const char *key, int64_t fallback);
bool sn_bool_or(const msgpack_object *map, const char *key, bool fallback);
char *sn_strdup_obj(const msgpack_object *o); /* malloc'ed NUL-terminated copy of a str, NULL otherwise */

/* ------------------------------------------------------------------ conn.c */
typedef struct {
  char *endpoint; /* ZeroMQ address of the RPC socket */
  char *robot;    /* NULL: the world's only robot */
} sn_url;

/* Parse a controller URL (NULL/empty: default endpoint, only robot). 0 on success, else writes a
 * one-line reason to err. */
int sn_parse_url(const char *url, sn_url *out, char *err, size_t errlen);
void sn_url_free(sn_url *u);

/* A decoded reply: the whole message is kept so that str/bin objects stay valid. */
typedef struct {
  msgpack_unpacked unpacked;
  char *data;
  size_t size;
  bool ok;
  const msgpack_object *result; /* the result map when ok */
  int code;                     /* error code when !ok */
  char message[512];            /* error message when !ok */
} sn_reply;
void sn_reply_free(sn_reply *r);

typedef struct sn_conn sn_conn;
sn_conn *sn_conn_open(const char *endpoint, char *err, size_t errlen);
void sn_conn_close(sn_conn *c);
/* Send a built request (consumes nothing: the caller frees r). Returns its id, 0 on failure. */
uint64_t sn_conn_next_id(sn_conn *c);
int sn_conn_send(sn_conn *c, sn_req *r, uint64_t id);
/* Why the server refuses this client's security handshake (a missing or wrong CURVE key), or NULL. */
const char *sn_conn_handshake_problem(sn_conn *c);
/* Like sn_conn_send, for a step request: re-sent with the same id every second while
   sn_conn_wait waits for it (a reply lost with a dropped connection is answered again). */
int sn_conn_send_retried(sn_conn *c, sn_req *r, uint64_t id);
/* Wait for the reply of id: timeout_ms < 0 waits forever (but gives up with SN_CONNECTION_LOST when
 * the heartbeat finds the server gone). Returns 0 and fills out (ok or error reply), or -1 with a
 * client-side error in out->code/out->message. */
int sn_conn_wait(sn_conn *c, uint64_t id, int timeout_ms, sn_reply *out);
void sn_conn_discard(sn_conn *c, uint64_t id);
/* The next reply, whatever its id (for raw replays such as the conformance vectors). */
int sn_conn_wait_any(sn_conn *c, int timeout_ms, sn_reply *out);
int sn_conn_start_heartbeat(sn_conn *c, const char *session, int interval_ms);
void sn_conn_stop_heartbeat(sn_conn *c);
const char *sn_conn_endpoint(const sn_conn *c);

/* ------------------------------------------------------------------ robot.c */
typedef enum {
  SN_LIGHT, SN_DISTANCE, SN_LIDAR, SN_MOTOR, SN_POSITION, SN_LED, SN_GPS, SN_IMU, SN_COMPASS, SN_ACCELEROMETER,
  SN_GYRO, SN_ALTIMETER, SN_TOUCH, SN_EMITTER, SN_RECEIVER, SN_RANGE_FINDER, SN_CAMERA, SN_RADAR, SN_VACUUM, SN_SPEAKER,
  SN_CONNECTOR, SN_BRAKE, SN_OTHER
} sn_kind;

struct sn_imaging; /* camera.c: a range finder's or camera's images and constants */
struct sn_sound;   /* speaker.c: a sound this controller played on a speaker */

/* A packet in an emitter's queue (channel and range when sent) or a receiver's (signal strength,
 * emitter direction); data follows the struct. */
typedef struct sn_packet {
  struct sn_packet *next;
  int size;
  int channel;
  double range;
  double signal;
  double direction[3];
  unsigned char data[];
} sn_packet;

typedef struct {
  WbDeviceTag tag;
  char *name;
  char *type_name;
  char *model;      /* the world's "model" field, "" when absent */
  int node_type;    /* Webots' WB_NODE_* value of type_name (WB_NODE_NO_NODE if unknown) */
  bool simulated;   /* false: listed only, every function answers "no value" (sn_unsimulated) */
  bool warned_unsimulated;
  sn_kind kind;
  int sampling_period;
  bool warned; /* "disabled device" message printed since the last enable */
  /* light / distance */
  double value;
  double *lookup_table;
  int lookup_rows;
  double min_value, max_value, aperture;
  int sensor_type;
  /* lidar */
  int width, layers;
  double fov, vertical_fov, min_range, max_range, frequency, min_frequency, max_frequency;
  bool point_cloud_enabled;
  float *range_image;         /* layers * width, zeros before the first measurement */
  WbLidarPoint *point_cloud;  /* layers * width */
  /* position sensor: its wheel motor's name; LED: value, colours, gradual */
  char *motor_name;
  int led_value, led_colors;
  bool led_gradual;
  /* GPS: position, speed, speed vector; WbGpsCoordinateSystem */
  double gps_values[3], gps_speed, gps_speed_vector[3];
  int coordinate_system;
  /* range finder, camera (camera.c) */
  struct sn_imaging *imaging;
  /* Compass, Accelerometer, Gyro, force-3d TouchSensor: values; InertialUnit: quaternion (x, y, z, w),
     roll/pitch/yaw, noise */
  double values[3], quaternion[4], roll_pitch_yaw[3], noise;
  /* Emitter / Receiver: channel and range as this controller set them, the world's constants, the
     packet queue (bytes used; an emitter's byte budget of libController's baud-rate rule) */
  int channel, buffer_size, n_allowed, sending;
  int *allowed;
  double range, emitter_max_range, byte_rate, bytes_to_send;
  sn_packet *queue, *queue_tail;
  int queue_length;
  long queue_bytes;
  /* motor */
  double max_velocity, min_position, max_position, target_position, velocity, acceleration;
  bool joint;                        /* no drive's motor: its joint moves kinematically (maxForce known) */
  double max_force, available_force; /* a joint motor's maxTorque/maxForce and setAvailableTorque/Force */
  double initial_position;           /* where a simulation reset puts a joint (0 for a wheel) */
  double multiplier;                 /* scales the position and velocity commands it takes (1: a wheel) */
  char **coupled;                    /* the other motors of its coupled group ("group::part" names) */
  int n_coupled;
  bool cmd_position, cmd_velocity;   /* to send with the next step */
  bool cmd_acceleration, cmd_available;
  bool warned_physics;             /* a physics-only motor function was called (one warning) */
  int force_feedback_period, torque_feedback_period;
  /* Radar (radar.c): the latest targets (NULL before the first value, and when there are none);
     its range and fields of view are min_range, max_range, fov and vertical_fov above */
  WbRadarTarget *radar_targets;
  int radar_count;
  /* Connector (connector.c): passive or not, the lock state the server answered; Brake: its joint's
     type (WB_ROTATIONAL/WB_LINEAR), the motor (motor_name above) and position sensor on its joint */
  bool connector_passive, is_locked;
  int joint_type;
  char *position_sensor_name;
  bool warned_damping;
  /* Display (display.c): the world's size; the drawing commands packed since the last step (an
     array's items, draw_n of them), the image ids given out, whether a camera is attached */
  int display_width, display_height;
  msgpack_sbuffer *draw_buf;
  msgpack_packer draw_pk;
  int draw_n, draw_items, image_ids;
  bool camera_attached;
  /* VacuumGripper (vacuum_gripper.c): the pump as this controller last set it (the world's isOn at
     start); its presence is value above (1 or 0). Speaker (speaker.c): the sounds played here, the text
     being spoken (NULL: none), libController's engine and language */
  bool pump_on;
  struct sn_sound *sounds;
  char *speech;
  char engine[10], language[6];
} sn_device;

/* A car-like robot's drive from the attach reply ("ackermann_drive"): what the vehicle library
 * (vehicle.c) works from, as Webots' reads a Car's customData. */
typedef struct {
  bool present;
  double wheelbase, track_front, track_rear, front_wheel_radius, rear_wheel_radius;
  int type;    /* WBU_CAR_TRACTION, WBU_CAR_PROPULSION or WBU_CAR_FOUR_BY_FOUR */
  double sign; /* 1: a positive steering motor position steers right (Webots' Driver), -1: left */
  int engine;  /* WBU_CAR_COMBUSTION_ENGINE, ...: a Webots Car's engineType */
  char *motors[6]; /* right_steer, left_steer, right_front_wheel, left_front_wheel, right_rear_wheel, left_rear_wheel */
} sn_car;

typedef struct {
  sn_conn *conn;
  char *name;
  char *session;
  char *model;
  char *custom_data;
  char *prefix; /* "/<robot>/" */
  int basic_time_step;
  int64_t time_ms;
  bool synchronization;
  bool supervisor;
  bool terminated;
  bool quit_returned; /* a step answered -1 for the termination: the next one ends the process */
  bool warned_duration;
  int keyboard_period;
  void *nodes, *fields, *protos; /* supervisor handles handed out (supervisor.c) */
  uint64_t pending; /* id of the pending step, 0 if none */
  int n_devices;
  sn_device *devices;
  sn_car car;
  /* robot-window texts that came with step replies, each followed by its NUL (libController's
     reception buffer), and the batch wb_robot_wwi_receive took from it (robot_extras.c) */
  char *wwi_inbox, *wwi_batch;
  size_t wwi_inbox_size, wwi_inbox_cap, wwi_batch_size, wwi_batch_read;
  bool wwi_fresh; /* a step began since wb_robot_wwi_receive_text took a batch */
} sn_robot;

/* The texts of a step reply's "robot_window" list, appended to the robot's window inbox. */
void sn_wwi_received(sn_robot *rb, const msgpack_object *texts);

/* The playing motions set their motors' target positions for their current time, then move it on
 * by millis (motion.c; wb_robot_step_begin calls it before building the step request). */
void sn_motion_step_all(int millis);
/* The process's robot; exits with a message if wb_robot_init() was not called. */
sn_robot *sn_robot_get(const char *func);
/* The device of tag if it is of kind (SN_OTHER: any), else prints Webots' error and returns NULL. */
sn_device *sn_device_get(WbDeviceTag tag, sn_kind kind, const char *func);
/* A synchronous call to "/<robot>/<device>/<item>" (device NULL: "/<robot>/<item>") with one
 * argument "value" built by add_value (NULL: no args). Returns 0 on an ok reply (out filled; free
 * it), else prints "Error: func(): ..." and returns -1. */
typedef void (*sn_arg_fn)(sn_req *r, const void *arg);
int sn_device_call(sn_robot *rb, const sn_device *dev, const char *item, sn_arg_fn add_value,
                   const void *arg, const char *func, sn_reply *out);
/* The general form: service "/<robot>/<item>"; add_args packs nargs key/value pairs. */
int sn_robot_call(sn_robot *rb, const char *item, uint32_t nargs, sn_arg_fn add_args, const void *arg,
                  const char *func, sn_reply *out);
void sn_supervisor_free(sn_robot *rb);
/* A Supervisor's movie (movie.c): its frames taken after each step reply; stopped and its file
 * completed when the controller ends. */
void sn_movie_after_step(sn_robot *rb);
void sn_movie_finish(sn_robot *rb);
/* The end of the controller's steps without a step's answer (the server quit, stopped or went away; this
 * Supervisor's own quit): terminated, and sn_movie_after_step as after a step answering -1 (robot.c). */
void sn_steps_ended(sn_robot *rb);
void sn_arg_int(sn_req *r, const void *arg);
void sn_arg_bool(sn_req *r, const void *arg);
void sn_arg_double(sn_req *r, const void *arg);
/* A setting the server keeps: "/<robot>/<device>/<item>" with one argument. true once the server
 * took it, or at once when the controller's steps have ended (its local copy is all there is then);
 * false after the error message of a refused call (the caller keeps its local copy unchanged). */
bool sn_device_set(sn_device *dev, const char *item, sn_arg_fn add_value, const void *arg, const char *func);
/* enable/disable a sensor (period 0 disables): RPC, then the local state. */
void sn_device_enable(sn_device *dev, int period, const char *func);
/* devices.c: what every sensor's wb_<kind>_enable/disable/get_sampling_period does on the device of tag
 * (Webots' error and no effect when tag is not of kind); sn_sensor_reading: the device for a getter of
 * its readings, with Webots' once-per-disable message when it is read while disabled. */
void sn_sensor_enable(WbDeviceTag tag, sn_kind kind, int period, const char *func);
int sn_sensor_period(WbDeviceTag tag, sn_kind kind, const char *func);
sn_device *sn_sensor_reading(WbDeviceTag tag, sn_kind kind, const char *func, const char *enabler);
/* A device Sensorium lists but does not simulate: checks that tag is a device of node_type (else
 * Webots' error), prints one warning line per device, returns false. true if tag is simulated. */
bool sn_unsimulated(WbDeviceTag tag, int node_type, const char *func);
/* supervisor.c: the calling robot if it is a Supervisor, else Webots' two error lines for func and NULL. */
sn_robot *sn_supervisor(const char *func);
/* supervisor.c: a Supervisor function Sensorium does not serve: Webots' error in a Robot controller,
   else one line the first time (*warned) it is called. */
void sn_supervisor_unsupported(const char *func, bool *warned);
/* In a Supervisor function Sensorium does not serve: its one error line, the first time only. */
#define SN_UNSUPPORTED()                         \
  do {                                           \
    static bool warned_;                         \
    sn_supervisor_unsupported(__func__, &warned_); \
  } while (0)
/* Webots' "no value" for a vector getter: NaN values (16 of them), never NULL. */
const double *sn_no_values(void);
/* Webots' node type of a device type name ("DistanceSensor"), WB_NODE_NO_NODE if unknown. */
int sn_node_type_of(const char *type_name);
void sn_warn_disabled(sn_device *dev, const char *func, const char *enabler, const char *what);
/* radio.c: the packets of a step reply into a receiver's queue; an emitter's packets into a step request
   (sn_radio_pace counts those its baud rate lets leave with a step of duration ms, sn_radio_pack writes
   them as "name": [{"data", "channel", "range"}, ...] and drops them from the queue) */
void sn_radio_receive(sn_device *dev, const msgpack_object *packets);
/* radar.c: a step reply's targets (distance, power, speed, azimuth of each in turn) into the radar */
void sn_radar_apply(sn_device *dev, const msgpack_object *targets);
/* speaker.c: a step reply's speaker state (the sounds still playing, whether it speaks); its cleanup */
void sn_speaker_apply(sn_device *dev, const msgpack_object *reading);
void sn_speaker_free(sn_device *dev);
/* connector.c: the tag of the Brake on the joint of the motor (of_motor) or position sensor named name, 0 if none */
WbDeviceTag sn_brake_of(const char *name, bool of_motor, const char *func);
int sn_radio_pace(sn_device *dev, int duration);
void sn_radio_pack(sn_device *dev, sn_req *r);
void sn_radio_free(sn_device *dev);

/* ------------------------------------------------------------------ display.c */
/* A Display's commands into a step request ("displays": {name: [commands]}), and its cleanup. */
int sn_display_pending(const sn_robot *rb);
void sn_display_pack(sn_robot *rb, sn_req *r);
void sn_display_free(sn_device *d);

/* ------------------------------------------------------------------ camera.c */
/* An 8-bit PNG of data (height rows of channels*width bytes: RGB or RGBA); 0 or -1. */
int sn_write_png(const char *filename, const unsigned char *data, int width, int height, int channels);
/* The CRC-32 of PNG chunks (and zlib's), continued from crc (0 to start). */
uint32_t sn_crc32(uint32_t crc, const unsigned char *p, size_t n);
/* ------------------------------------------------------------------ png_read.c */
/* A PNG file as 8-bit RGBA rows (*rgba malloc'ed, the caller frees it), at most max_pixels; 0, or -1
 * with the reason in why ("is not a PNG file", ...). */
int sn_read_png(const char *filename, long max_pixels, int *width, int *height, unsigned char **rgba, char *why,
                size_t why_len);
/* ------------------------------------------------------------------ jpeg_io.c */
/* A JPEG file as 8-bit RGBA rows, opaque (*rgba malloc'ed, the caller frees it), at most max_pixels;
 * 0, or -1 with libjpeg's reason in why. */
int sn_read_jpeg(const char *filename, long max_pixels, int *width, int *height, unsigned char **rgba, char *why,
                 size_t why_len);
/* rgb (height rows of 3*width bytes) as a JPEG file of that quality (1..100), no chroma subsampling;
 * 0, or -1 with the reason in why. */
int sn_write_jpeg(const char *filename, const unsigned char *rgb, int width, int height, int quality, char *why,
                  size_t why_len);
/* A range finder's or camera's state from its attach description (0, or -1 on a bad one); its
 * readings from a step reply; freed at cleanup. No-ops for other devices. */
int sn_imaging_describe(sn_device *d, const msgpack_object *desc);
void sn_imaging_apply(sn_device *d, const msgpack_object *reading);
void sn_imaging_free(sn_device *d);

#endif /* SENSORIUM_INTERNAL_H */
