/* Sensorium C controller library: Webots' motion files (utils/motion.h), the rules and lines of the
 * Python client's sensorium/client/wb_motion.py. Playback is client side, as in libController: each
 * wb_robot_step_begin() first has every playing motion set its motors' target positions for its
 * current time (linear between the two poses around it; '*' leaves a motor alone), then moves its
 * time on by the step's duration; the positions travel with that step's request.
 *
 * A file: "#WEBOTS_MOTION,V1.0,<motor>,..." then one line per pose "[[mm:]ss:]mmm,<name>,<value|*>,..."
 * with strictly increasing times; an empty line ends the poses; empty fields are skipped. Bounds: a
 * line holds at most MAX_LINE characters, a file at most MAX_VALUES values (poses x motors), a time
 * is at most MAX_TIME_MS. A damaged file prints one line naming the file and line; no motion (NULL). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/motor.h>
#include <webots/nodes.h>
#include <webots/utils/motion.h>

#include "internal.h"

#define MAX_LINE 4094            /* characters, the end of line not counted (Webots reads 4095) */
#define MAX_VALUES 1000000L      /* poses x motors */
#define MAX_TIME_MS 1000000000LL /* a pose's time: a motion's clock never overflows an int */
#define NEW "wbu_motion_new"

struct WbMotionStructPrivate {
  char *filename;
  int n_motors, n_poses;
  char **motors;       /* the header's motor names */
  WbDeviceTag *tags;   /* each column's motor, 0 if the robot has none of that name */
  int *times;          /* ms, n_poses */
  double *values;      /* n_poses x n_motors, NaN for '*' */
  long long elapsed;   /* ms */
  bool playing, reverse, loop;
  struct WbMotionStructPrivate *next;
};

/* newest first, as libController's list: when two motions set one motor, the older one sets it
   last and wins */
static WbMotionRef g_motions = NULL;

/* ------------------------------------------------------------------ parsing */

typedef struct {
  FILE *f;
  const char *filename;
  int number;            /* of the line in buf */
  char buf[MAX_LINE + 1];
  char *tokens[MAX_LINE / 2 + 2];
  int n_tokens;
} reader;

/* The next line into r->buf (without its end of line): 1, 0 at the end of the file, -1 after
 * printing why it cannot be read (too long, a NUL character, a read error: a folder opened). */
static int read_line(reader *r) {
  int c, n = 0;
  bool nul = false;
  while ((c = getc(r->f)) != EOF && c != '\n') {
    if (n == MAX_LINE) {
      fprintf(stderr, "Error: " NEW "(): file '%s', line %d: longer than %d characters.\n", sn_shown(r->filename),
              r->number + 1, MAX_LINE);
      return -1;
    }
    nul = nul || c == '\0';
    r->buf[n++] = (char)c;
  }
  if (c == EOF && ferror(r->f)) { /* a folder, a read error: what the Python client says for its OSError */
    fprintf(stderr, "Error: " NEW "(): could not open '%s' file.\n", sn_shown(r->filename));
    return -1;
  }
  if (c == EOF && n == 0)
    return 0;
  r->buf[n] = '\0';
  r->number++;
  if (nul) {
    fprintf(stderr, "Error: " NEW "(): file '%s', line %d: holds a NUL character.\n", sn_shown(r->filename), r->number);
    return -1;
  }
  return 1;
}

/* r->buf split at ',' and '\r', empty fields skipped (Webots' tokenizer) */
static void split(reader *r) {
  r->n_tokens = 0;
  char *p = r->buf;
  while (*p) {
    while (*p == ',' || *p == '\r')
      *p++ = '\0';
    if (!*p)
      break;
    r->tokens[r->n_tokens++] = p;
    while (*p && *p != ',' && *p != '\r')
      p++;
  }
}

/* "[[mm:]ss:]mmm" in ms (each part's digits saturated: too big anyway); -1 if it is not that */
static long long parse_time(const char *s) {
  long long part[3] = {0, 0, 0};
  int k = 0;
  bool digit = false;
  for (; *s; s++) {
    if (*s >= '0' && *s <= '9') {
      part[k] = part[k] * 10 + (*s - '0');
      if (part[k] > 1000000000000LL)
        part[k] = 1000000000000LL;
      digit = true;
    } else if (*s == ':' && digit && k < 2) {
      k++;
      digit = false;
    } else
      return -1;
  }
  if (!digit)
    return -1;
  long long v[3] = {0, 0, 0};
  for (int i = 0; i <= k; i++)
    v[2 - k + i] = part[i];
  return v[0] * 60000 + v[1] * 1000 + v[2];
}

/* a whole finite number: [ \t]*[+-]?(digits[.digits*] | .digits)([eE][+-]?digits)?[ \t]* */
static bool parse_number(const char *s, double *out) {
  const char *p = s;
  while (*p == ' ' || *p == '\t')
    p++;
  if (*p == '+' || *p == '-')
    p++;
  int digits = 0;
  while (*p >= '0' && *p <= '9')
    p++, digits++;
  if (*p == '.') {
    p++;
    while (*p >= '0' && *p <= '9')
      p++, digits++;
  }
  if (digits == 0)
    return false;
  if (*p == 'e' || *p == 'E') {
    p++;
    if (*p == '+' || *p == '-')
      p++;
    if (!(*p >= '0' && *p <= '9'))
      return false;
    while (*p >= '0' && *p <= '9')
      p++;
  }
  while (*p == ' ' || *p == '\t')
    p++;
  if (*p)
    return false;
  *out = strtod(s, NULL);
  return isfinite(*out);
}

static void motion_free(WbMotionRef m) {
  if (m == NULL)
    return;
  for (int i = 0; i < m->n_motors; i++)
    free(m->motors[i]);
  free(m->motors);
  free(m->tags);
  free(m->times);
  free(m->values);
  free(m->filename);
  free(m);
}

static char *copy(const char *s) {
  size_t n = strlen(s) + 1;
  char *c = malloc(n);
  if (c != NULL)
    memcpy(c, s, n);
  return c;
}

#define FAIL(...)                                                                                   \
  do {                                                                                              \
    fprintf(stderr, "Error: " NEW "(): file '%s', line %d: ", sn_shown(r->filename), r->number);           \
    fprintf(stderr, __VA_ARGS__);                                                                   \
    fprintf(stderr, ".\n");                                                                         \
    return false;                                                                                   \
  } while (0)

static bool out_of_memory(const reader *r) {
  fprintf(stderr, "Error: " NEW "(): file '%s': out of memory.\n", sn_shown(r->filename));
  return false;
}

/* the file's motors, times and values into m; false after printing why not */
static bool parse(reader *r, WbMotionRef m) {
  int got = read_line(r);
  if (got < 0)
    return false;
  if (got == 0) {
    fprintf(stderr, "Error: " NEW "(): file '%s' is empty.\n", sn_shown(r->filename));
    return false;
  }
  split(r);
  if (r->n_tokens == 0 || strcmp(r->tokens[0], "#WEBOTS_MOTION") != 0)
    FAIL("expected the header '#WEBOTS_MOTION,V1.0,<motor names>' but found '%s'", r->n_tokens ? r->tokens[0] : "");
  if (r->n_tokens < 2 || strcmp(r->tokens[1], "V1.0") != 0)
    FAIL("unsupported version '%s' (Sensorium reads V1.0)", r->n_tokens > 1 ? r->tokens[1] : "");
  if (r->n_tokens < 3)
    FAIL("no motor names after the version");
  m->n_motors = r->n_tokens - 2;
  m->motors = calloc((size_t)m->n_motors, sizeof *m->motors);
  if (m->motors == NULL)
    return out_of_memory(r);
  for (int i = 0; i < m->n_motors; i++)
    if ((m->motors[i] = copy(r->tokens[2 + i])) == NULL)
      return out_of_memory(r);
  int n = m->n_motors, capacity = 0;
  while ((got = read_line(r)) > 0) {
    split(r);
    if (r->n_tokens == 0) { /* an empty line ends the poses (Webots) */
      int empty = r->number;
      while ((got = read_line(r)) > 0) {
        split(r);
        if (r->n_tokens > 0) {
          fprintf(stderr, "Warning: " NEW "(): file '%s', line %d: ignored with every line after the empty line %d "
                  "(an empty line ends the poses, as in Webots).\n", sn_shown(r->filename), r->number, empty);
          break;
        }
      }
      if (got < 0)
        return false;
      break;
    }
    const char *first = r->tokens[0];
    long long t = parse_time(first);
    if (t < 0)
      FAIL("expected a time ([[mm:]ss:]mmm) but found '%s'", first);
    if (t > MAX_TIME_MS)
      FAIL("time '%s' is beyond %lld ms", first, MAX_TIME_MS);
    if (m->n_poses > 0 && t <= m->times[m->n_poses - 1])
      FAIL("time '%s' is not after the previous pose's (%d ms)", first, m->times[m->n_poses - 1]);
    if (r->n_tokens < 2)
      FAIL("pose name expected");
    if (r->n_tokens < 2 + n)
      FAIL("%d values for %d motors", r->n_tokens - 2, n);
    if (r->n_tokens > 2 + n)
      FAIL("unexpected extra data '%s' after %d values", r->tokens[2 + n], n);
    if ((long)(m->n_poses + 1) * n > MAX_VALUES)
      FAIL("more than %ld values (poses x motors)", MAX_VALUES);
    if (m->n_poses == capacity) {
      capacity = capacity ? 2 * capacity : 16;
      int *times = realloc(m->times, (size_t)capacity * sizeof *times);
      if (times == NULL)
        return out_of_memory(r);
      m->times = times;
      double *values = realloc(m->values, (size_t)capacity * (size_t)n * sizeof *values);
      if (values == NULL)
        return out_of_memory(r);
      m->values = values;
    }
    double *row = m->values + (size_t)m->n_poses * (size_t)n;
    for (int j = 0; j < n; j++) {
      const char *token = r->tokens[2 + j];
      if (strcmp(token, "*") == 0)
        row[j] = NAN;
      else if (!parse_number(token, &row[j]))
        FAIL("expected a number or '*' but found '%s'", token);
    }
    m->times[m->n_poses++] = (int)t;
  }
  if (got < 0)
    return false;
  if (m->n_poses == 0) {
    fprintf(stderr, "Error: " NEW "(): file '%s' has no pose.\n", sn_shown(r->filename));
    return false;
  }
  return true;
}

/* ------------------------------------------------------------------ playback */

static int duration_of(WbMotionRef m) { return m->times[m->n_poses - 1]; }

/* the column's motor position at the current time; NaN where the poses around it leave it alone
   (the same operations in the same order as the Python client's: the same bits) */
static double position_of(WbMotionRef m, int column) {
  int n = m->n_motors, last = m->n_poses - 1;
  long long e = m->elapsed;
  if (e <= m->times[0])
    return m->values[column];
  if (e >= m->times[last])
    return m->values[(size_t)last * (size_t)n + (size_t)column];
  int a = 0;
  while (!(m->times[a] <= e && e <= m->times[a + 1]))
    a++;
  double pa = m->values[(size_t)a * (size_t)n + (size_t)column];
  double pb = m->values[(size_t)(a + 1) * (size_t)n + (size_t)column];
  return pa + (double)(e - m->times[a]) * (pb - pa) / (double)(m->times[a + 1] - m->times[a]);
}

static void advance(WbMotionRef m, int millis) {
  int d = duration_of(m);
  if (m->reverse) {
    if (m->elapsed <= 0) {
      if (m->loop)
        m->elapsed = d;
      else {
        m->elapsed = 0;
        m->playing = false;
      }
    } else
      m->elapsed -= millis;
  } else if (m->elapsed >= d) {
    if (m->loop)
      m->elapsed = 0;
    else {
      m->elapsed = d;
      m->playing = false;
    }
  } else
    m->elapsed += millis;
}

void sn_motion_step_all(int millis) {
  if (millis <= 0)
    return;
  for (WbMotionRef m = g_motions; m != NULL; m = m->next) {
    if (!m->playing)
      continue;
    for (int j = 0; j < m->n_motors; j++) {
      if (m->tags[j] == 0)
        continue;
      double p = position_of(m, j);
      if (!isnan(p))
        wb_motor_set_position(m->tags[j], p);
    }
    advance(m, millis);
  }
}

/* ------------------------------------------------------------------ Webots' functions */

WbMotionRef wbu_motion_new(const char *filename) {
  if (filename == NULL || filename[0] == '\0') {
    fprintf(stderr, "Error: " NEW "() called with NULL or empty 'filename' argument.\n");
    return NULL;
  }
  sn_robot *rb = sn_robot_get(NEW);
  FILE *f = fopen(filename, "rb");
  if (f == NULL) {
    fprintf(stderr, "Error: " NEW "(): could not open '%s' file.\n", sn_shown(filename));
    return NULL;
  }
  reader *r = calloc(1, sizeof *r);
  WbMotionRef m = calloc(1, sizeof *m);
  if (r == NULL || m == NULL) {
    fprintf(stderr, "Error: " NEW "(): file '%s': out of memory.\n", sn_shown(filename));
    free(r);
    free(m);
    fclose(f);
    return NULL;
  }
  r->f = f;
  r->filename = filename;
  bool ok = parse(r, m);
  fclose(f);
  free(r);
  if (ok && ((m->filename = copy(filename)) == NULL || (m->tags = calloc((size_t)m->n_motors, sizeof *m->tags)) == NULL)) {
    fprintf(stderr, "Error: " NEW "(): file '%s': out of memory.\n", sn_shown(filename));
    ok = false;
  }
  if (!ok) {
    motion_free(m);
    return NULL;
  }
  for (int j = 0; j < m->n_motors; j++) {
    const sn_device *d = NULL;
    for (int i = 0; i < rb->n_devices && d == NULL; i++)
      if (strcmp(rb->devices[i].name, m->motors[j]) == 0)
        d = &rb->devices[i];
    if (d == NULL)
      fprintf(stderr, "Warning: " NEW "(): ignoring motor '%s' of file '%s': robot '%s' has no such device.\n",
              sn_shown(m->motors[j]), sn_shown(filename), sn_shown(rb->name));
    else if (d->node_type != WB_NODE_ROTATIONAL_MOTOR && d->node_type != WB_NODE_LINEAR_MOTOR)
      fprintf(stderr, "Warning: " NEW "(): ignoring '%s' of file '%s': it is a %s, not a motor.\n",
              sn_shown(m->motors[j]), sn_shown(filename), d->type_name);
    else
      m->tags[j] = d->tag;
  }
  m->next = g_motions;
  g_motions = m;
  return m;
}

static bool listed(WbMotionRef motion) {
  for (WbMotionRef m = g_motions; m != NULL; m = m->next)
    if (m == motion)
      return true;
  return false;
}

void wbu_motion_delete(WbMotionRef motion) {
  if (motion == NULL)
    return;
  WbMotionRef *p = &g_motions;
  while (*p != NULL && *p != motion)
    p = &(*p)->next;
  if (*p == NULL) {
    fprintf(stderr, "Error: wbu_motion_delete(): attempt to delete an invalid 'motion'.\n");
    return;
  }
  *p = motion->next;
  motion_free(motion);
}

/* motion if it is a live motion; else NULL, after Webots' line for NULL */
static WbMotionRef valid(WbMotionRef motion, const char *func, const char *what) {
  if (motion == NULL) {
    fprintf(stderr, "Error: %s() called with NULL %s.\n", func, what);
    return NULL;
  }
  if (!listed(motion)) {
    fprintf(stderr, "Error: %s(): not a motion (deleted?).\n", func);
    return NULL;
  }
  return motion;
}

void wbu_motion_play(WbMotionRef motion) {
  WbMotionRef m = valid(motion, "wbu_motion_play", "'motion' argument");
  if (m == NULL)
    return;
  m->playing = true;
  if (m->reverse && m->elapsed <= 0)
    m->elapsed = duration_of(m);
  else if (!m->reverse && m->elapsed >= duration_of(m))
    m->elapsed = 0;
}

void wbu_motion_stop(WbMotionRef motion) {
  WbMotionRef m = valid(motion, "wbu_motion_stop", "argument");
  if (m != NULL)
    m->playing = false;
}

void wbu_motion_set_loop(WbMotionRef motion, bool loop) {
  WbMotionRef m = valid(motion, "wbu_motion_set_loop", "argument");
  if (m != NULL)
    m->loop = loop;
}

void wbu_motion_set_reverse(WbMotionRef motion, bool reverse) {
  WbMotionRef m = valid(motion, "wbu_motion_set_reverse", "argument");
  if (m != NULL)
    m->reverse = reverse;
}

bool wbu_motion_is_over(WbMotionRef motion) {
  WbMotionRef m = valid(motion, "wbu_motion_is_over", "argument");
  if (m == NULL)
    return false;
  if (m->loop)
    return false;
  return m->reverse ? m->elapsed <= 0 : m->elapsed >= duration_of(m);
}

int wbu_motion_get_duration(WbMotionRef motion) {
  WbMotionRef m = valid(motion, "wbu_motion_get_duration", "argument");
  return m == NULL ? -1 : duration_of(m);
}

int wbu_motion_get_time(WbMotionRef motion) {
  WbMotionRef m = valid(motion, "wbu_motion_get_time", "argument");
  if (m == NULL)
    return -1;
  return m->elapsed > INT32_MAX ? INT32_MAX : m->elapsed < INT32_MIN ? INT32_MIN : (int)m->elapsed;
}

void wbu_motion_set_time(WbMotionRef motion, int time) {
  WbMotionRef m = valid(motion, "wbu_motion_set_time", "argument");
  if (m == NULL)
    return;
  m->elapsed = time < 0 ? 0 : time > duration_of(m) ? duration_of(m) : time;
}
