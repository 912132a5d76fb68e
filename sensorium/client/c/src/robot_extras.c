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

/* Robot-window texts. What a controller sends goes to the server's wwi_send at once (libController
 * sends it so too, with an immediate request), which publishes it on /<robot>/robot_window; with
 * $SENSORIUM_ROBOT_WINDOW_LOG set to 1 (sensorium run --robot-window-log) it is also printed on stderr
 * as one line "robot window: TEXT" (line breaks shown as \n, at most ROBOT_WINDOW_CHARS bytes shown:
 * the Python client's line). stdout is left to the controller. What the window side sends
 * (window_send) comes with the step replies. */
#define ROBOT_WINDOW_CHARS 4096
#define WWI_MAX_BYTES (1 << 20) /* a longer text would not fit one request: not sent, one line */

static void log_text(const char *data, int n) {
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

/* The length of the valid UTF-8 sequence at s (at most n bytes), 0 if none starts there. */
static int utf8_length(const unsigned char *s, size_t n) {
  int len = s[0] < 0x80 ? 1 : (s[0] & 0xE0) == 0xC0 ? 2 : (s[0] & 0xF0) == 0xE0 ? 3 : (s[0] & 0xF8) == 0xF0 ? 4 : 0;
  if (len == 0 || (size_t)len > n)
    return 0;
  for (int i = 1; i < len; i++)
    if ((s[i] & 0xC0) != 0x80)
      return 0;
  unsigned cp = len == 1 ? s[0] : len == 2 ? s[0] & 0x1Fu : len == 3 ? s[0] & 0x0Fu : s[0] & 0x07u;
  for (int i = 1; i < len; i++)
    cp = (cp << 6) | (s[i] & 0x3Fu);
  static const unsigned least[5] = {0, 0, 0x80, 0x800, 0x10000};
  if (cp < least[len] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
    return 0; /* overlong, beyond Unicode, a surrogate */
  return len;
}

typedef struct {
  const char *text;
  size_t size;
} text_arg;

static void add_text(sn_req *r, const void *arg) {
  const text_arg *t = arg;
  sn_req_key(r, "text");
  msgpack_pack_str(&r->pk, t->size);
  msgpack_pack_str_body(&r->pk, t->text, t->size);
}

void wb_robot_wwi_send(const char *data, int size) {
  sn_robot *rb = sn_robot_get("wb_robot_wwi_send");
  if (data == NULL || size <= 0)
    return;
  int n = 0;
  while (n < size && data[n] != '\0') /* text: up to its NUL (wb_robot_wwi_send_text counts it) */
    n++;
  const char *on = getenv("SENSORIUM_ROBOT_WINDOW_LOG");
  if (on != NULL && strcmp(on, "1") == 0)
    log_text(data, n);
  if (n > WWI_MAX_BYTES) {
    fprintf(stderr, "Error: wb_robot_wwi_send(): a text of %d bytes is longer than %d: not sent\n", n, WWI_MAX_BYTES);
    return;
  }
  if (rb->terminated)
    return;
  /* bytes that are not UTF-8 become U+FFFD, as the server takes only text */
  char *text = malloc(3 * (size_t)n + 1);
  if (text == NULL)
    return;
  size_t out = 0;
  for (size_t i = 0; i < (size_t)n;) {
    int len = utf8_length((const unsigned char *)data + i, (size_t)n - i);
    if (len == 0) {
      memcpy(text + out, "\xEF\xBF\xBD", 3);
      out += 3;
      i++;
    } else {
      memcpy(text + out, data + i, (size_t)len);
      out += (size_t)len;
      i += (size_t)len;
    }
  }
  text_arg arg = {text, out};
  sn_reply rep;
  if (sn_robot_call(rb, "robot/wwi_send", 1, add_text, &arg, "wb_robot_wwi_send", &rep) == 0)
    sn_reply_free(&rep);
  free(text);
}

void sn_wwi_received(sn_robot *rb, const msgpack_object *texts) {
  if (texts == NULL || texts->type != MSGPACK_OBJECT_ARRAY)
    return;
  for (uint32_t i = 0; i < texts->via.array.size; i++) {
    const msgpack_object *t = &texts->via.array.ptr[i];
    if (t->type != MSGPACK_OBJECT_STR)
      continue;
    size_t need = rb->wwi_inbox_size + t->via.str.size + 1;
    if (need > rb->wwi_inbox_cap) {
      size_t cap = rb->wwi_inbox_cap ? rb->wwi_inbox_cap : 256;
      while (cap < need)
        cap *= 2;
      char *grown = realloc(rb->wwi_inbox, cap);
      if (grown == NULL)
        return;
      rb->wwi_inbox = grown;
      rb->wwi_inbox_cap = cap;
    }
    memcpy(rb->wwi_inbox + rb->wwi_inbox_size, t->via.str.ptr, t->via.str.size);
    rb->wwi_inbox_size += t->via.str.size;
    rb->wwi_inbox[rb->wwi_inbox_size++] = '\0';
  }
}

/* libController's rule: every text received since the last call, each followed by its NUL, in one
 * buffer the library owns (valid until the next call); NULL and size 0 when none came. */
const char *wb_robot_wwi_receive(int *size) {
  sn_robot *rb = sn_robot_get("wb_robot_wwi_receive");
  if (rb->wwi_inbox_size == 0) {
    if (size != NULL)
      *size = 0;
    return NULL;
  }
  free(rb->wwi_batch); /* the inbox becomes the batch */
  rb->wwi_batch = rb->wwi_inbox;
  rb->wwi_batch_size = rb->wwi_inbox_size;
  rb->wwi_inbox = NULL;
  rb->wwi_inbox_size = rb->wwi_inbox_cap = 0;
  rb->wwi_batch_read = rb->wwi_batch_size; /* taken whole: not for wb_robot_wwi_receive_text */
  if (size != NULL)
    *size = (int)rb->wwi_batch_size;
  return rb->wwi_batch;
}

/* libController's rule: the first call after a step takes the texts received (wb_robot_wwi_receive)
 * and returns them one per call, in order, then NULL; what is left of them when the next step begins
 * is dropped. */
const char *wb_robot_wwi_receive_text(void) {
  sn_robot *rb = sn_robot_get("wb_robot_wwi_receive_text");
  if (rb->wwi_fresh) {
    rb->wwi_fresh = false;
    if (wb_robot_wwi_receive(NULL) == NULL)
      rb->wwi_batch_size = 0;
    rb->wwi_batch_read = 0;
  }
  if (rb->wwi_batch_read >= rb->wwi_batch_size)
    return NULL;
  const char *text = rb->wwi_batch + rb->wwi_batch_read;
  rb->wwi_batch_read += strlen(text) + 1;
  return text;
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
