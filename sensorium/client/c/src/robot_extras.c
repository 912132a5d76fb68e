/* Sensorium C controller library: what Webots' robot API offers beyond the simulation (paths, URDF,
 * threads and mutexes, deprecated names). */
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/device.h>
#include <webots/plugins/robot_window/default.h>
#include <webots/plugins/robot_window/robot_wwi.h>
#include <webots/robot.h>

#include "internal.h"

const char *wb_robot_get_project_path(void) {
  sn_robot_get("wb_robot_get_project_path");
  return ""; /* no Webots project: the controller runs beside a Sensorium server */
}

const char *wb_robot_get_world_path(void) {
  sn_robot_get("wb_robot_get_world_path");
  return "";
}

static void add_prefix(sn_req *r, const void *arg) {
  sn_req_key(r, "prefix");
  sn_req_str(r, (const char *)arg);
}

/* The server's get_urdf. As libController, the library owns the string: it stays valid until the
 * next call (which frees it); "" when the call failed. */
const char *wb_robot_get_urdf(const char *prefix) {
  static char *urdf;
  sn_robot *rb = sn_robot_get("wb_robot_get_urdf");
  free(urdf);
  urdf = NULL;
  sn_reply rep;
  if (sn_robot_call(rb, "robot/get_urdf", 1, add_prefix, prefix != NULL ? prefix : "", "wb_robot_get_urdf", &rep) != 0)
    return "";
  urdf = sn_strdup_obj(sn_get(rep.result, "value"));
  sn_reply_free(&rep);
  return urdf != NULL ? urdf : "";
}

void wb_robot_pin_to_static_environment(bool pin) {
  (void)pin;
  sn_robot_get("wb_robot_pin_to_static_environment");
}

/* No robot window here: none sends messages; what a controller sends it goes nowhere, or with
 * $SENSORIUM_ROBOT_WINDOW_LOG set to 1 (sensorium run --robot-window-log) is printed on stderr as one
 * line "robot window: TEXT" (line breaks shown as \n, at most ROBOT_WINDOW_CHARS bytes shown: the
 * Python client's line). stdout is left to the controller. */
#define ROBOT_WINDOW_CHARS 4096

void wb_robot_wwi_send(const char *data, int size) {
  sn_robot_get("wb_robot_wwi_send");
  const char *on = getenv("SENSORIUM_ROBOT_WINDOW_LOG");
  if (on == NULL || strcmp(on, "1") != 0 || data == NULL || size <= 0)
    return;
  int n = 0;
  while (n < size && data[n] != '\0') /* text: up to its NUL (wb_robot_wwi_send_text counts it) */
    n++;
  int shown = n < ROBOT_WINDOW_CHARS ? n : ROBOT_WINDOW_CHARS;
  flockfile(stderr);
  fputs("robot window: ", stderr);
  for (int i = 0; i < shown; i++) {
    char c = data[i];
    if (c == '\n')
      fputs("\\n", stderr);
    else if (c == '\r')
      fputs("\\r", stderr);
    else if (c == '\\')
      fputs("\\\\", stderr);
    else
      fputc(c, stderr);
  }
  if (n > shown)
    fprintf(stderr, " ... (%d more characters not shown)", n - shown);
  fputc('\n', stderr);
  funlockfile(stderr);
  fflush(stderr);
}

const char *wb_robot_wwi_receive(int *size) {
  sn_robot_get("wb_robot_wwi_receive");
  if (size != NULL)
    *size = 0;
  return NULL;
}

const char *wb_robot_wwi_receive_text(void) {
  sn_robot_get("wb_robot_wwi_receive_text");
  return NULL;
}

/* Webots' default robot window: nothing to configure or update without a window */
void wbu_default_robot_window_configure(void) {
  sn_robot_get("wbu_default_robot_window_configure");
}

void wbu_default_robot_window_update(void) {
  sn_robot_get("wbu_default_robot_window_update");
}

void wbu_default_robot_window_set_images_max_size(int max_width, int max_height) {
  (void)max_width;
  (void)max_height;
  sn_robot_get("wbu_default_robot_window_set_images_max_size");
}

const char *wb_robot_get_controller_name(void) {
  sn_robot_get("wb_robot_get_controller_name");
  return "<extern>";
}

const char *wb_robot_get_data(void) { return wb_robot_get_custom_data(); }

void wb_robot_set_data(const char *data) { wb_robot_set_custom_data(data); }

WbNodeType wb_device_get_type(WbDeviceTag tag) { return wb_device_get_node_type(tag); }

/* ------------------------------------------------------------------ tasks and mutexes */

typedef struct {
  void (*task)(void *);
  void *param;
} task_start;

static void *run_task(void *arg) {
  task_start start = *(task_start *)arg;
  free(arg);
  start.task(start.param);
  return NULL;
}

void wb_robot_task_new(void (*task)(void *), void *param) {
  task_start *start = malloc(sizeof *start);
  pthread_t thread;
  if (start == NULL || task == NULL) {
    free(start);
    fprintf(stderr, "Error: wb_robot_task_new(): %s\n", task == NULL ? "NULL task" : "out of memory");
    return;
  }
  start->task = task;
  start->param = param;
  if (pthread_create(&thread, NULL, run_task, start) != 0) {
    free(start);
    fprintf(stderr, "Error: wb_robot_task_new(): cannot start a thread\n");
    return;
  }
  pthread_detach(thread);
}

WbMutexRef wb_robot_mutex_new(void) {
  pthread_mutex_t *m = malloc(sizeof *m);
  if (m != NULL && pthread_mutex_init(m, NULL) != 0) {
    free(m);
    m = NULL;
  }
  return m;
}

void wb_robot_mutex_lock(WbMutexRef mutex) {
  if (mutex != NULL)
    pthread_mutex_lock((pthread_mutex_t *)mutex);
}

void wb_robot_mutex_unlock(WbMutexRef mutex) {
  if (mutex != NULL)
    pthread_mutex_unlock((pthread_mutex_t *)mutex);
}

void wb_robot_mutex_delete(WbMutexRef mutex) {
  if (mutex != NULL) {
    pthread_mutex_destroy((pthread_mutex_t *)mutex);
    free(mutex);
  }
}
