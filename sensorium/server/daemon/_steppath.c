/* The lockstep's step path in C (optional; sensorium/server/daemon/steppath.py loads it, or uses its
 * pure-Python twin with the same behaviour).
 *
 * One job: move request messages between the server's ROUTER socket and Python in batches, so that
 * Python runs once per world step instead of once per request. A Gate reads messages from the
 * socket (the GIL released while it waits), recognises the plainest step request of an attached
 * controller ({"id": <uint>, "service": "/<robot>/robot/step", "args": {} or {"duration": <int>}},
 * one frame after the routing id, from the socket the robot is attached to) and keeps reading
 * until every controller the world waits for has asked for its step (the lockstep barrier), until
 * any other message arrives (handed to Python as raw frames, in arrival order), or until the
 * deadline. It also drops the rest of a message with too many frames, a bounded number of frames
 * per call, and sends replies.
 *
 * It decides nothing: the lockstep, the sessions and every reply stay in Python (services.Core);
 * a recognised step is handed over already parsed, to the same handler Core.handle would call.
 *
 * libzmq: the functions are not linked but handed over as addresses (Gate.bind) from the libzmq
 * that pyzmq itself loaded, so the socket and the functions always come from the same library
 * (pyzmq wheels bundle their own libzmq). <zmq.h> is used for the types when present; the fallback
 * below is libzmq's stable ABI (so version 5, libzmq >= 4.1: zmq_msg_t is 64 bytes). */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <errno.h>
#include <stdint.h>
#include <string.h>
#include <time.h>

#if defined(__has_include)
#if __has_include(<zmq.h>)
#include <zmq.h>
#define HAVE_ZMQ_H 1
#endif
#endif
#ifndef HAVE_ZMQ_H
typedef struct zmq_msg_t {
  unsigned char _[64];
} __attribute__((aligned(sizeof(void *)))) zmq_msg_t;
#define ZMQ_DONTWAIT 1
#define ZMQ_SNDMORE 2
#define ZMQ_RCVTIMEO 27
#endif

/* ------------------------------------------------------------------ libzmq, by address */

typedef struct {
  int (*msg_init)(zmq_msg_t *);
  int (*msg_init_size)(zmq_msg_t *, size_t);
  int (*msg_close)(zmq_msg_t *);
  void *(*msg_data)(zmq_msg_t *);
  size_t (*msg_size)(const zmq_msg_t *);
  int (*msg_more)(const zmq_msg_t *);
  int (*msg_recv)(zmq_msg_t *, void *, int);
  int (*msg_send)(zmq_msg_t *, void *, int);
  int (*setsockopt)(void *, int, const void *, size_t);
  int (*errno_)(void);
} zmq_api;

static zmq_api Z;
static int Z_bound = 0;

#define MAX_FRAMES_CAP 64 /* frames kept per message (the transport's MAX_FRAMES is 16) */

/* ------------------------------------------------------------------ msgpack: the plain step request */

typedef struct {
  const unsigned char *p, *end;
} reader;

/* A msgpack integer >= 0 (any integer encoding); 0 if the next item is something else. */
static int read_uint(reader *r, uint64_t *out) {
  if (r->p >= r->end)
    return 0;
  unsigned char t = *r->p++;
  size_t n = 0;
  int is_signed = 0;
  if (t <= 0x7f) {
    *out = t;
    return 1;
  }
  switch (t) {
  case 0xcc: n = 1; break;
  case 0xcd: n = 2; break;
  case 0xce: n = 4; break;
  case 0xcf: n = 8; break;
  case 0xd0: n = 1; is_signed = 1; break;
  case 0xd1: n = 2; is_signed = 1; break;
  case 0xd2: n = 4; is_signed = 1; break;
  case 0xd3: n = 8; is_signed = 1; break;
  default: return 0;
  }
  if ((size_t)(r->end - r->p) < n)
    return 0;
  uint64_t v = 0;
  for (size_t i = 0; i < n; i++)
    v = v << 8 | r->p[i];
  r->p += n;
  if (is_signed && (r->p[-(ptrdiff_t)n] & 0x80))
    return 0; /* negative */
  *out = v;
  return 1;
}

/* A msgpack str; 0 if the next item is something else. */
static int read_str(reader *r, const unsigned char **s, size_t *len) {
  if (r->p >= r->end)
    return 0;
  unsigned char t = *r->p++;
  size_t n, hdr = 0;
  if ((t & 0xe0) == 0xa0)
    n = t & 0x1f;
  else if (t == 0xd9)
    hdr = 1;
  else if (t == 0xda)
    hdr = 2;
  else if (t == 0xdb)
    hdr = 4;
  else
    return 0;
  if (hdr) {
    if ((size_t)(r->end - r->p) < hdr)
      return 0;
    n = 0;
    for (size_t i = 0; i < hdr; i++)
      n = n << 8 | r->p[i];
    r->p += hdr;
  }
  if ((size_t)(r->end - r->p) < n)
    return 0;
  *s = r->p;
  *len = n;
  r->p += n;
  return 1;
}

static int key_is(const unsigned char *s, size_t n, const char *want) {
  return strlen(want) == n && memcmp(s, want, n) == 0;
}

/* {"id": uint, "service": str, "args": {} | {"duration": 1..max_duration | nil}}, keys in any order,
 * each once, nothing after the map. duration_out: -1 for none/nil. Returns 1 when the body is
 * exactly that; the service is returned for the caller to match. */
static int parse_step(const unsigned char *body, size_t size, uint64_t max_duration, uint64_t *rid,
                      const unsigned char **service, size_t *service_len, int64_t *duration_out) {
  reader r = {body, body + size};
  if (size < 1 || *r.p++ != 0x83)
    return 0;
  int seen = 0;
  *duration_out = -1;
  for (int i = 0; i < 3; i++) {
    const unsigned char *k;
    size_t kn;
    if (!read_str(&r, &k, &kn))
      return 0;
    if (key_is(k, kn, "id") && !(seen & 1)) {
      seen |= 1;
      if (!read_uint(&r, rid))
        return 0;
    } else if (key_is(k, kn, "service") && !(seen & 2)) {
      seen |= 2;
      if (!read_str(&r, service, service_len))
        return 0;
    } else if (key_is(k, kn, "args") && !(seen & 4)) {
      seen |= 4;
      if (r.p >= r.end)
        return 0;
      unsigned char m = *r.p++;
      if (m == 0x81) {
        if (!read_str(&r, &k, &kn) || !key_is(k, kn, "duration"))
          return 0;
        if (r.p < r.end && *r.p == 0xc0) {
          r.p++; /* nil: one basic step, like no duration */
        } else {
          uint64_t d;
          if (!read_uint(&r, &d) || d == 0 || d > max_duration)
            return 0; /* 0 (Webots' step(0)) and out-of-range values: Python's path */
          *duration_out = (int64_t)d;
        }
      } else if (m != 0x80) {
        return 0;
      }
    } else {
      return 0;
    }
  }
  return r.p == r.end;
}

/* ------------------------------------------------------------------ the Gate */

typedef struct {
  char *identity;
  size_t identity_len;
  char *service;
  size_t service_len;
  Py_ssize_t slot;
} entry;

typedef struct {
  PyObject_HEAD void *sock;
  PyObject *owner; /* the pyzmq socket: kept alive while the Gate uses its handle */
  int max_frames;
  Py_ssize_t max_request;
  uint64_t max_duration;
  long discard_budget;
  int rcvtimeo; /* the value last set on the socket (-2: unknown) */
  int discarding;
  entry *entries;
  Py_ssize_t n_entries;
  unsigned char *waiting; /* per entry index: the world waits for this one's step */
  unsigned char *counted;
  unsigned long long messages, fast_steps, frames_dropped;
} Gate;

static void clear_entries(Gate *g) {
  for (Py_ssize_t i = 0; i < g->n_entries; i++) {
    PyMem_Free(g->entries[i].identity);
    PyMem_Free(g->entries[i].service);
  }
  PyMem_Free(g->entries);
  PyMem_Free(g->waiting);
  PyMem_Free(g->counted);
  g->entries = NULL;
  g->waiting = g->counted = NULL;
  g->n_entries = 0;
}

static void Gate_dealloc(Gate *g) {
  clear_entries(g);
  Py_XDECREF(g->owner);
  Py_TYPE(g)->tp_free((PyObject *)g);
}

static int Gate_init(Gate *g, PyObject *args, PyObject *kw) {
  static char *names[] = {"socket", "handle", "max_frames", "max_request", "max_duration", "discard_budget", NULL};
  PyObject *owner;
  unsigned long long handle, max_duration;
  int max_frames;
  Py_ssize_t max_request;
  long discard_budget;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "OKinKl", names, &owner, &handle, &max_frames, &max_request,
                                   &max_duration, &discard_budget))
    return -1;
  if (!Z_bound) {
    PyErr_SetString(PyExc_RuntimeError, "_steppath.bind() was not called");
    return -1;
  }
  if (max_frames < 2 || max_frames > MAX_FRAMES_CAP || discard_budget < 1 || handle == 0) {
    PyErr_SetString(PyExc_ValueError, "bad Gate limits");
    return -1;
  }
  Py_INCREF(owner);
  Py_XSETREF(g->owner, owner);
  g->sock = (void *)(uintptr_t)handle;
  g->max_frames = max_frames;
  g->max_request = max_request;
  g->max_duration = max_duration;
  g->discard_budget = discard_budget;
  g->rcvtimeo = -2;
  g->discarding = 0;
  return 0;
}

/* set_peers([(identity: bytes, service: bytes, slot: int), ...]): the attached controllers whose
 * plain step requests the Gate recognises (slot: the caller's number for it, handed back). */
static PyObject *Gate_set_peers(Gate *g, PyObject *arg) {
  PyObject *seq = PySequence_Fast(arg, "set_peers takes a sequence of (identity, service, slot)");
  if (seq == NULL)
    return NULL;
  Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
  entry *entries = PyMem_Calloc(n ? (size_t)n : 1, sizeof *entries);
  unsigned char *waiting = PyMem_Calloc(n ? (size_t)n : 1, 1), *counted = PyMem_Calloc(n ? (size_t)n : 1, 1);
  if (entries == NULL || waiting == NULL || counted == NULL) {
    PyMem_Free(entries);
    PyMem_Free(waiting);
    PyMem_Free(counted);
    Py_DECREF(seq);
    return PyErr_NoMemory();
  }
  Py_ssize_t filled = 0;
  for (Py_ssize_t i = 0; i < n; i++) {
    char *ident, *service;
    Py_ssize_t il, sl, slot;
    if (!PyArg_ParseTuple(PySequence_Fast_GET_ITEM(seq, i), "y#y#n", &ident, &il, &service, &sl, &slot))
      goto fail;
    entry *e = &entries[i];
    e->identity = PyMem_Malloc(il ? (size_t)il : 1);
    e->service = PyMem_Malloc(sl ? (size_t)sl : 1);
    filled = i + 1;
    if (e->identity == NULL || e->service == NULL) {
      PyErr_NoMemory();
      goto fail;
    }
    memcpy(e->identity, ident, (size_t)il);
    memcpy(e->service, service, (size_t)sl);
    e->identity_len = (size_t)il;
    e->service_len = (size_t)sl;
    e->slot = slot;
  }
  Py_DECREF(seq);
  clear_entries(g);
  g->entries = entries;
  g->waiting = waiting;
  g->counted = counted;
  g->n_entries = n;
  Py_RETURN_NONE;
fail:
  for (Py_ssize_t i = 0; i < filled; i++) {
    PyMem_Free(entries[i].identity);
    PyMem_Free(entries[i].service);
  }
  PyMem_Free(entries);
  PyMem_Free(waiting);
  PyMem_Free(counted);
  Py_DECREF(seq);
  return NULL;
}

static double mono_ms(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

static void set_rcvtimeo(Gate *g, int ms) {
  if (g->rcvtimeo != ms && Z.setsockopt(g->sock, ZMQ_RCVTIMEO, &ms, sizeof ms) == 0)
    g->rcvtimeo = ms;
}

/* Receive one frame: 1, 0 (nothing: EAGAIN or timeout), -1 (EINTR: a signal), -2 (other error). */
static int recv_frame(Gate *g, zmq_msg_t *m, int wait_ms) {
  int rc;
  if (wait_ms == 0) {
    rc = Z.msg_recv(m, g->sock, ZMQ_DONTWAIT);
  } else {
    set_rcvtimeo(g, wait_ms);
    Py_BEGIN_ALLOW_THREADS rc = Z.msg_recv(m, g->sock, 0);
    Py_END_ALLOW_THREADS
  }
  if (rc >= 0)
    return 1;
  int e = Z.errno_();
  return e == EAGAIN ? 0 : e == EINTR ? -1 : -2;
}

static PyObject *frame_bytes(zmq_msg_t *m) {
  return PyBytes_FromStringAndSize((const char *)Z.msg_data(m), (Py_ssize_t)Z.msg_size(m));
}

static PyObject *zmq_failure(void) {
  int e = Z.errno_();
  return PyErr_Format(PyExc_OSError, "the step path's socket failed (errno %d: %s)", e, strerror(e));
}

/* Drop frames of the over-long message, at most discard_budget; sets discarding = 0 at its end. */
static int drop_rest(Gate *g) {
  zmq_msg_t m;
  Z.msg_init(&m);
  for (long i = 0; i < g->discard_budget; i++) {
    if (Z.msg_recv(&m, g->sock, ZMQ_DONTWAIT) < 0)
      break; /* the rest has not arrived yet (it always has: libzmq delivers messages whole) */
    g->frames_dropped++;
    if (!Z.msg_more(&m)) {
      g->discarding = 0;
      break;
    }
  }
  Z.msg_close(&m);
  return g->discarding;
}

/* discard() -> True when the over-long message is gone (call while .discarding). */
static int closed(Gate *g) {
  if (g->sock != NULL)
    return 0;
  PyErr_SetString(PyExc_RuntimeError, "the step path's gate is closed (its socket was closed)");
  return 1;
}

static PyObject *Gate_discard(Gate *g, PyObject *Py_UNUSED(arg)) {
  if (closed(g))
    return NULL;
  if (g->discarding)
    drop_rest(g);
  return PyBool_FromLong(!g->discarding);
}

/* receive(wait_ms, waiting, limit) -> list | None
 *
 * waiting: the slots the world waits for (a step from each completes the barrier). The first
 * message is awaited for up to wait_ms (0: only what is queued); while the barrier is incomplete,
 * more until the same deadline (wait_ms 0: only what is queued). Items, in arrival order: (slot,
 * identity, rid, duration or None) for a recognised step, a list of frames (bytes) for any other
 * message, the identity alone (bytes) for a message of more than max_frames frames (.discarding is
 * then set and discard() drops the rest). The batch ends at the first message after which the
 * world might step: any but a recognised step, the step completing the barrier, every message
 * when nobody is waited for. None: nothing arrived. */
static PyObject *Gate_receive(Gate *g, PyObject *args) {
  int wait_ms, limit;
  PyObject *waiting_arg;
  if (!PyArg_ParseTuple(args, "iOi", &wait_ms, &waiting_arg, &limit) || closed(g))
    return NULL;
  if (g->discarding) {
    PyErr_SetString(PyExc_RuntimeError, "receive() while an over-long message is being dropped: discard() first");
    return NULL;
  }
  PyObject *wseq = PySequence_Fast(waiting_arg, "waiting must be a sequence of slots");
  if (wseq == NULL)
    return NULL;
  Py_ssize_t n_waiting = 0;
  if (g->n_entries) {
    memset(g->waiting, 0, (size_t)g->n_entries);
    memset(g->counted, 0, (size_t)g->n_entries);
  }
  for (Py_ssize_t i = 0; i < PySequence_Fast_GET_SIZE(wseq); i++) {
    Py_ssize_t slot = PyLong_AsSsize_t(PySequence_Fast_GET_ITEM(wseq, i));
    if (slot == -1 && PyErr_Occurred()) {
      Py_DECREF(wseq);
      return NULL;
    }
    for (Py_ssize_t k = 0; k < g->n_entries; k++)
      if (g->entries[k].slot == slot && !g->waiting[k]) {
        g->waiting[k] = 1;
        n_waiting++;
      }
  }
  Py_DECREF(wseq);

  PyObject *items = PyList_New(0);
  if (items == NULL)
    return NULL;
  double deadline = wait_ms > 0 ? mono_ms() + wait_ms : 0.0;
  Py_ssize_t counted = 0;
  zmq_msg_t frames[MAX_FRAMES_CAP];
  int wait_next = wait_ms;
  while (PyList_GET_SIZE(items) < limit) {
    int nf = 0;
    Z.msg_init(&frames[0]);
    int rc = recv_frame(g, &frames[0], wait_next);
    if (rc <= 0) {
      Z.msg_close(&frames[0]);
      if (rc == -2) {
        Py_DECREF(items);
        return zmq_failure();
      }
      if (rc == -1 && PyErr_CheckSignals() < 0) {
        Py_DECREF(items);
        return NULL;
      }
      break; /* nothing more now, or the deadline: the caller looks again */
    }
    nf = 1;
    g->messages++;
    int too_many = 0;
    while (Z.msg_more(&frames[nf - 1])) {
      if (nf >= g->max_frames) {
        too_many = 1;
        break;
      }
      Z.msg_init(&frames[nf]);
      if (Z.msg_recv(&frames[nf], g->sock, ZMQ_DONTWAIT) < 0) {
        Z.msg_close(&frames[nf]); /* cannot happen: libzmq delivers messages whole */
        break;
      }
      nf++;
    }
    PyObject *item = NULL;
    int ends_batch = 1;
    if (too_many) {
      g->discarding = 1;
      item = frame_bytes(&frames[0]);
    } else if (nf == 2 && (Py_ssize_t)Z.msg_size(&frames[1]) <= g->max_request) {
      uint64_t rid;
      int64_t duration;
      const unsigned char *service;
      size_t service_len;
      const char *ident = (const char *)Z.msg_data(&frames[0]);
      size_t ident_len = Z.msg_size(&frames[0]);
      if (parse_step((const unsigned char *)Z.msg_data(&frames[1]), Z.msg_size(&frames[1]), g->max_duration, &rid,
                     &service, &service_len, &duration)) {
        for (Py_ssize_t k = 0; k < g->n_entries; k++) {
          entry *e = &g->entries[k];
          if (e->identity_len == ident_len && e->service_len == service_len &&
              memcmp(e->identity, ident, ident_len) == 0 && memcmp(e->service, service, service_len) == 0) {
            PyObject *d = duration < 0 ? Py_NewRef(Py_None) : PyLong_FromLongLong(duration);
            item = d ? Py_BuildValue("(nNKN)", e->slot, frame_bytes(&frames[0]), (unsigned long long)rid, d) : NULL;
            ends_batch = 0;
            g->fast_steps++;
            if (g->waiting[k] && !g->counted[k]) {
              g->counted[k] = 1;
              counted++;
            }
            break;
          }
        }
      }
    }
    if (item == NULL && !PyErr_Occurred()) {
      item = PyList_New(nf);
      for (int i = 0; item != NULL && i < nf; i++) {
        PyObject *b = frame_bytes(&frames[i]);
        if (b == NULL) {
          Py_CLEAR(item);
          break;
        }
        PyList_SET_ITEM(item, i, b);
      }
    }
    for (int i = 0; i < nf; i++)
      Z.msg_close(&frames[i]);
    if (item == NULL || PyList_Append(items, item) < 0) {
      Py_XDECREF(item);
      Py_DECREF(items);
      return NULL;
    }
    Py_DECREF(item);
    /* the batch ends where the world might step: after any other message, after the step that
       completes the barrier, after every message when the world waits for nobody */
    if (ends_batch || n_waiting == 0 || counted >= n_waiting)
      break;
    if (wait_ms > 0) { /* the barrier is incomplete: wait for the rest until the deadline */
      double left = deadline - mono_ms();
      if (left <= 0)
        break;
      wait_next = (int)left + 1;
    } else {
      wait_next = 0;
    }
  }
  if (PyList_GET_SIZE(items) == 0) {
    Py_DECREF(items);
    Py_RETURN_NONE;
  }
  return items;
}

/* send([[frame, ..., body], ...]): each reply as one message (frames copied); a reply libzmq
 * refuses (peer gone) is dropped, as the ROUTER does. */
static PyObject *Gate_send(Gate *g, PyObject *arg) {
  if (closed(g))
    return NULL;
  PyObject *replies = PySequence_Fast(arg, "send takes a sequence of frame lists");
  if (replies == NULL)
    return NULL;
  for (Py_ssize_t i = 0; i < PySequence_Fast_GET_SIZE(replies); i++) {
    PyObject *frames = PySequence_Fast(PySequence_Fast_GET_ITEM(replies, i), "a reply is a sequence of bytes");
    if (frames == NULL) {
      Py_DECREF(replies);
      return NULL;
    }
    Py_ssize_t n = PySequence_Fast_GET_SIZE(frames);
    for (Py_ssize_t k = 0; k < n; k++) {
      Py_buffer view;
      if (PyObject_GetBuffer(PySequence_Fast_GET_ITEM(frames, k), &view, PyBUF_SIMPLE) < 0) {
        Py_DECREF(frames);
        Py_DECREF(replies);
        return NULL;
      }
      zmq_msg_t m;
      int rc = Z.msg_init_size(&m, (size_t)view.len);
      if (rc == 0) {
        memcpy(Z.msg_data(&m), view.buf, (size_t)view.len);
        rc = Z.msg_send(&m, g->sock, k + 1 < n ? ZMQ_SNDMORE : 0);
        if (rc < 0)
          Z.msg_close(&m);
      }
      PyBuffer_Release(&view);
      if (rc < 0)
        break; /* the rest of this reply goes nowhere either */
    }
    Py_DECREF(frames);
  }
  Py_DECREF(replies);
  Py_RETURN_NONE;
}

/* msgpack's integer, in the smallest encoding (as msgpack-python packs it: unsigned formats for
 * values >= 0, signed ones below). Returns the bytes written (at most 9); -1 with an exception set
 * for a value outside [-2**63, 2**64). */
static int pack_int(unsigned char *p, PyObject *v) {
  int overflow = 0;
  long long s = PyLong_AsLongLongAndOverflow(v, &overflow);
  if (s == -1 && PyErr_Occurred())
    return -1;
  if (overflow < 0) {
    PyErr_SetString(PyExc_OverflowError, "a step reply's integer is below -2**63");
    return -1;
  }
  if (overflow > 0 || s >= 0) {
    unsigned long long u = overflow > 0 ? PyLong_AsUnsignedLongLong(v) : (unsigned long long)s;
    if (u == (unsigned long long)-1 && PyErr_Occurred())
      return -1;
    if (u < 0x80) {
      p[0] = (unsigned char)u;
      return 1;
    }
    int n = u <= 0xff ? 1 : u <= 0xffff ? 2 : u <= 0xffffffffULL ? 4 : 8;
    p[0] = n == 1 ? 0xcc : n == 2 ? 0xcd : n == 4 ? 0xce : 0xcf;
    for (int i = 0; i < n; i++)
      p[1 + i] = (unsigned char)(u >> (8 * (n - 1 - i)));
    return 1 + n;
  }
  if (s >= -32) {
    p[0] = (unsigned char)(s & 0xff);
    return 1;
  }
  int n = s >= -128 ? 1 : s >= -32768 ? 2 : s >= -2147483648LL ? 4 : 8;
  p[0] = n == 1 ? 0xd0 : n == 2 ? 0xd1 : n == 4 ? 0xd2 : 0xd3;
  unsigned long long u = (unsigned long long)s;
  for (int i = 0; i < n; i++)
    p[1 + i] = (unsigned char)(u >> (8 * (n - 1 - i)));
  return 1 + n;
}

/* Send one frame (copied); 0, or -1 when libzmq refuses it (peer gone: the rest of the reply too). */
static int send_frame(Gate *g, const void *data, size_t len, int more) {
  zmq_msg_t m;
  if (Z.msg_init_size(&m, len) != 0)
    return -1;
  memcpy(Z.msg_data(&m), data, len);
  if (Z.msg_send(&m, g->sock, more ? ZMQ_SNDMORE : 0) < 0) {
    Z.msg_close(&m);
    return -1;
  }
  return 0;
}

/* send_steps(replies, pieces): send() for a world step's replies, where a reply is either a list of
 * frames (sent as is) or a tuple (envelope frames, rid, status, time_ms): the common step reply
 * without new values, whose body the Core defines as pieces = (head, status key, time key, tail):
 * head + rid + status key + status + time key + time_ms + tail, the integers msgpack-packed. So
 * Python hands over four numbers per controller instead of packing each reply. All replies are
 * checked before the first is sent (a bad one raises and sends nothing). */
#define STEP_PIECES_MAX 256
static PyObject *Gate_send_steps(Gate *g, PyObject *args) {
  PyObject *replies_arg, *pieces_arg;
  if (!PyArg_ParseTuple(args, "OO", &replies_arg, &pieces_arg) || closed(g))
    return NULL;
  const char *piece[4];
  Py_ssize_t piece_len[4], total = 0;
  if (!PyArg_ParseTuple(pieces_arg, "y#y#y#y#", &piece[0], &piece_len[0], &piece[1], &piece_len[1], &piece[2],
                        &piece_len[2], &piece[3], &piece_len[3]))
    return NULL;
  for (int i = 0; i < 4; i++)
    total += piece_len[i];
  if (total > STEP_PIECES_MAX) {
    PyErr_SetString(PyExc_ValueError, "send_steps: the step reply's pieces are too long");
    return NULL;
  }
  PyObject *replies = PySequence_Fast(replies_arg, "send_steps takes a sequence of replies");
  if (replies == NULL)
    return NULL;
  Py_ssize_t n = PySequence_Fast_GET_SIZE(replies);
  for (Py_ssize_t i = 0; i < n; i++) { /* checked first: nothing is sent for a bad batch */
    PyObject *r = PySequence_Fast_GET_ITEM(replies, i);
    if (PyTuple_Check(r)) {
      if (PyTuple_GET_SIZE(r) != 4 || !PyList_Check(PyTuple_GET_ITEM(r, 0)))
        goto bad;
      for (int k = 1; k < 4; k++) /* ints, not bools (msgpack packs those as true/false) */
        if (!PyLong_CheckExact(PyTuple_GET_ITEM(r, k)))
          goto bad;
      PyObject *env = PyTuple_GET_ITEM(r, 0);
      for (Py_ssize_t k = 0; k < PyList_GET_SIZE(env); k++)
        if (!PyBytes_Check(PyList_GET_ITEM(env, k)))
          goto bad;
      unsigned char scratch[9];
      for (int k = 1; k < 4; k++)
        if (pack_int(scratch, PyTuple_GET_ITEM(r, k)) < 0)
          goto fail;
    } else if (PyList_Check(r)) {
      if (PyList_GET_SIZE(r) < 1)
        goto bad;
      for (Py_ssize_t k = 0; k < PyList_GET_SIZE(r); k++)
        if (!PyObject_CheckBuffer(PyList_GET_ITEM(r, k)))
          goto bad;
    } else {
      goto bad;
    }
  }
  unsigned char body[STEP_PIECES_MAX + 27]; /* the pieces and three integers of at most 9 bytes */
  for (Py_ssize_t i = 0; i < n; i++) {
    PyObject *r = PySequence_Fast_GET_ITEM(replies, i);
    if (PyList_Check(r)) {
      Py_ssize_t nf = PyList_GET_SIZE(r);
      for (Py_ssize_t k = 0; k < nf; k++) {
        Py_buffer view;
        if (PyObject_GetBuffer(PyList_GET_ITEM(r, k), &view, PyBUF_SIMPLE) < 0) {
          Py_DECREF(replies);
          return NULL;
        }
        int rc = send_frame(g, view.buf, (size_t)view.len, k + 1 < nf);
        PyBuffer_Release(&view);
        if (rc < 0)
          break;
      }
      continue;
    }
    size_t len = 0;
    int w;
    memcpy(body, piece[0], (size_t)piece_len[0]);
    len += (size_t)piece_len[0];
    if ((w = pack_int(body + len, PyTuple_GET_ITEM(r, 1))) < 0)
      goto fail;
    len += (size_t)w;
    memcpy(body + len, piece[1], (size_t)piece_len[1]);
    len += (size_t)piece_len[1];
    if ((w = pack_int(body + len, PyTuple_GET_ITEM(r, 2))) < 0)
      goto fail;
    len += (size_t)w;
    memcpy(body + len, piece[2], (size_t)piece_len[2]);
    len += (size_t)piece_len[2];
    if ((w = pack_int(body + len, PyTuple_GET_ITEM(r, 3))) < 0)
      goto fail;
    len += (size_t)w;
    memcpy(body + len, piece[3], (size_t)piece_len[3]);
    len += (size_t)piece_len[3];
    PyObject *env = PyTuple_GET_ITEM(r, 0);
    int rc = 0;
    for (Py_ssize_t k = 0; rc == 0 && k < PyList_GET_SIZE(env); k++) {
      PyObject *f = PyList_GET_ITEM(env, k);
      rc = send_frame(g, PyBytes_AS_STRING(f), (size_t)PyBytes_GET_SIZE(f), 1);
    }
    if (rc == 0)
      send_frame(g, body, len, 0);
  }
  Py_DECREF(replies);
  Py_RETURN_NONE;
bad:
  PyErr_SetString(PyExc_TypeError, "send_steps: a reply is a list of frames or (envelope: list of bytes, rid, status, "
                                   "time_ms)");
fail:
  Py_DECREF(replies);
  return NULL;
}

/* exchange(replies, pieces, wait_ms, waiting, limit) -> list | None: send_steps(replies, pieces)
 * (skipped when there are none), then receive(wait_ms, waiting, limit), in one call: after the
 * world step's replies this thread goes straight to waiting for the next requests. (Any work it
 * did between sending and waiting took a core from the replies' way to the controllers: libzmq's
 * I/O thread and the controllers' own threads; measured ~1 µs of round trip per µs of it.) */
static PyObject *Gate_exchange(Gate *g, PyObject *args) {
  if (PyTuple_GET_SIZE(args) != 5) {
    PyErr_SetString(PyExc_TypeError, "exchange(replies, pieces, wait_ms, waiting, limit)");
    return NULL;
  }
  PyObject *replies = PyTuple_GET_ITEM(args, 0);
  Py_ssize_t n = PyObject_Length(replies);
  if (n < 0)
    return NULL;
  if (n > 0) {
    PyObject *send_args = PyTuple_GetSlice(args, 0, 2);
    if (send_args == NULL)
      return NULL;
    PyObject *r = Gate_send_steps(g, send_args);
    Py_DECREF(send_args);
    if (r == NULL)
      return NULL;
    Py_DECREF(r);
  }
  PyObject *recv_args = PyTuple_GetSlice(args, 2, 5);
  if (recv_args == NULL)
    return NULL;
  PyObject *r = Gate_receive(g, recv_args);
  Py_DECREF(recv_args);
  return r;
}

/* close(): forget the socket (before it is closed: libzmq frees it, so no call may follow). */
static PyObject *Gate_close(Gate *g, PyObject *Py_UNUSED(arg)) {
  g->sock = NULL;
  g->discarding = 0;
  Py_CLEAR(g->owner);
  Py_RETURN_NONE;
}

static PyObject *Gate_get_discarding(Gate *g, void *Py_UNUSED(c)) { return PyBool_FromLong(g->discarding); }

static PyObject *Gate_get_counts(Gate *g, void *Py_UNUSED(c)) {
  return Py_BuildValue("{sKsKsK}", "messages", g->messages, "fast_steps", g->fast_steps, "frames_dropped",
                       g->frames_dropped);
}

static PyMethodDef Gate_methods[] = {
    {"set_peers", (PyCFunction)Gate_set_peers, METH_O, "set_peers([(identity, service, slot), ...])"},
    {"receive", (PyCFunction)Gate_receive, METH_VARARGS, "receive(wait_ms, waiting_slots, limit) -> list | None"},
    {"discard", (PyCFunction)Gate_discard, METH_NOARGS, "drop frames of an over-long message; True when done"},
    {"send", (PyCFunction)Gate_send, METH_O, "send(replies): each a list of frames"},
    {"send_steps", (PyCFunction)Gate_send_steps, METH_VARARGS,
     "send_steps(replies, pieces): lists of frames, or (envelope, rid, status, time_ms) step replies"},
    {"exchange", (PyCFunction)Gate_exchange, METH_VARARGS,
     "exchange(replies, pieces, wait_ms, waiting, limit): send_steps, then receive, in one call"},
    {"close", (PyCFunction)Gate_close, METH_NOARGS, "forget the socket (call before closing it)"},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef Gate_getset[] = {
    {"discarding", (getter)Gate_get_discarding, NULL, "dropping the rest of an over-long message", NULL},
    {"counts", (getter)Gate_get_counts, NULL, "messages received, steps recognised, frames dropped", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyTypeObject GateType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "sensorium.server.daemon._steppath.Gate",
    .tp_basicsize = sizeof(Gate),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "The ROUTER socket's step path: batches of requests in, replies out.",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Gate_init,
    .tp_dealloc = (destructor)Gate_dealloc,
    .tp_methods = Gate_methods,
    .tp_getset = Gate_getset,
};

/* bind((zmq_msg_init, zmq_msg_init_size, zmq_msg_close, zmq_msg_data, zmq_msg_size, zmq_msg_more,
 *       zmq_msg_recv, zmq_msg_send, zmq_setsockopt, zmq_errno)) — addresses of pyzmq's libzmq. */
static PyObject *bind(PyObject *Py_UNUSED(m), PyObject *arg) {
  unsigned long long a[10];
  if (!PyArg_ParseTuple(arg, "KKKKKKKKKK", &a[0], &a[1], &a[2], &a[3], &a[4], &a[5], &a[6], &a[7], &a[8], &a[9]))
    return NULL;
  for (int i = 0; i < 10; i++)
    if (a[i] == 0) {
      PyErr_SetString(PyExc_ValueError, "a libzmq function address is 0");
      return NULL;
    }
  Z.msg_init = (int (*)(zmq_msg_t *))(uintptr_t)a[0];
  Z.msg_init_size = (int (*)(zmq_msg_t *, size_t))(uintptr_t)a[1];
  Z.msg_close = (int (*)(zmq_msg_t *))(uintptr_t)a[2];
  Z.msg_data = (void *(*)(zmq_msg_t *))(uintptr_t)a[3];
  Z.msg_size = (size_t(*)(const zmq_msg_t *))(uintptr_t)a[4];
  Z.msg_more = (int (*)(const zmq_msg_t *))(uintptr_t)a[5];
  Z.msg_recv = (int (*)(zmq_msg_t *, void *, int))(uintptr_t)a[6];
  Z.msg_send = (int (*)(zmq_msg_t *, void *, int))(uintptr_t)a[7];
  Z.setsockopt = (int (*)(void *, int, const void *, size_t))(uintptr_t)a[8];
  Z.errno_ = (int (*)(void))(uintptr_t)a[9];
  Z_bound = 1;
  Py_RETURN_NONE;
}

static PyMethodDef module_methods[] = {
    {"bind", bind, METH_O, "bind(addresses): the libzmq functions to use (pyzmq's own library)"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT,
    .m_name = "_steppath",
    .m_doc = "The lockstep's step path in C.",
    .m_size = -1,
    .m_methods = module_methods,
};

PyMODINIT_FUNC PyInit__steppath(void) {
  if (PyType_Ready(&GateType) < 0)
    return NULL;
  PyObject *m = PyModule_Create(&module);
  if (m == NULL)
    return NULL;
  Py_INCREF(&GateType);
  if (PyModule_AddObject(m, "Gate", (PyObject *)&GateType) < 0) {
    Py_DECREF(&GateType);
    Py_DECREF(m);
    return NULL;
  }
  PyModule_AddIntConstant(m, "MSG_SIZE", (long)sizeof(zmq_msg_t));
  return m;
}
