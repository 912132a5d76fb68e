/* Sensorium C controller library: the robot (Webots' wb_robot_* functions).
 *
 * wb_robot_init() attaches this process to its robot; the controller URL comes from
 * SENSORIUM_CONTROLLER_URL, else WEBOTS_CONTROLLER_URL (forms: "NAME", "tcp://HOST[:PORT][/NAME]",
 * "ipc://PATH/NAME"; default tcp://127.0.0.1:5560; a URL without a robot takes WEBOTS_ROBOT_NAME's
 * robot, else the world's only robot). A URL that cannot be
 * parsed, a robot that does not exist or a server that does not answer within
 * SENSORIUM_CONTROLLER_TIMEOUT seconds (default 10) print one line and exit the process with
 * status 1. */
#ifndef WB_ROBOT_H
#define WB_ROBOT_H

#include "device.h"
#include "nodes.h"
#include "types.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum { WB_MODE_SIMULATION = 0, WB_MODE_CROSS_COMPILATION, WB_MODE_REMOTE_CONTROL } WbRobotMode;

int wb_robot_init(void);
void wb_robot_cleanup(void);

/* Advance the simulation by duration ms (a multiple of the basic time step); motor commands set
 * since the previous step travel with it and sensor readings come back with it. Returns 0 (for an
 * asynchronous robot: the ms it was late), or -1 once the server quits or is gone. */
int wb_robot_step(int duration);
int wb_robot_step_begin(int duration);
int wb_robot_step_end(void);

double wb_robot_get_time(void);                 /* seconds of simulated time */
double wb_robot_get_basic_time_step(void);      /* ms */
const char *wb_robot_get_name(void);
const char *wb_robot_get_model(void);
bool wb_robot_get_synchronization(void);
bool wb_robot_get_supervisor(void);
const char *wb_robot_get_custom_data(void);
void wb_robot_set_custom_data(const char *data);
WbRobotMode wb_robot_get_mode(void);
void wb_robot_set_mode(WbRobotMode mode, const char *arg);

int wb_robot_get_number_of_devices(void);
WbDeviceTag wb_robot_get_device(const char *name);       /* 0 if the robot has no such device */
WbDeviceTag wb_robot_get_device_by_index(int index);     /* 0 if index is out of range */

/* Webots' semantics: the simulation runs (steps of the basic time step) until an event of
 * event_type (WB_EVENT_* flags) happens or timeout ms pass. Headless, no keyboard, mouse or
 * joystick event ever happens: it steps timeout ms and returns WB_EVENT_NO_EVENT (WB_EVENT_QUIT
 * when the simulation ends). */
WbUserInputEvent wb_robot_wait_for_user_input_event(WbUserInputEvent event_type, int timeout);

/* The robot's battery (Robot.battery): its energy (J) every sampling period, NaN before the first value, -1
 * without a battery (README "Battery and Charger"). */
void wb_robot_battery_sensor_enable(int sampling_period);
void wb_robot_battery_sensor_disable(void);
int wb_robot_battery_sensor_get_sampling_period(void);
double wb_robot_battery_sensor_get_value(void);

/* What a controller of a Sensorium server does not have: a Webots project ("" paths), a robot
 * window to pin. The URDF is the server's export (the library owns the string until the next call). */
const char *wb_robot_get_project_path(void);
const char *wb_robot_get_world_path(void);
const char *wb_robot_get_urdf(const char *prefix);
void wb_robot_pin_to_static_environment(bool pin);

/* Webots' multi-thread helpers: a task runs in its own (detached) thread; mutexes are pthread ones. */
typedef void *WbMutexRef;
void wb_robot_task_new(void (*task)(void *), void *param);
WbMutexRef wb_robot_mutex_new(void);
void wb_robot_mutex_lock(WbMutexRef mutex);
void wb_robot_mutex_unlock(WbMutexRef mutex);
void wb_robot_mutex_delete(WbMutexRef mutex);

/* Deprecated in Webots: the controller's name ("<extern>": Sensorium starts no controller) and the
 * robot's custom data under its old names. */
const char *wb_robot_get_controller_name(void);
const char *wb_robot_get_data(void);
void wb_robot_set_data(const char *data);

#ifdef __cplusplus
}
#endif

#endif /* WB_ROBOT_H */
