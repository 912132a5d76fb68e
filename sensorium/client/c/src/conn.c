/* Sensorium C controller library: the only ZeroMQ code. Controller URLs, one DEALER socket with
 * requests matched to replies by id, and a heartbeat thread (its own socket) that pings the
 * session every heartbeat_ms and notices when the server is gone: no answer for 5 heartbeats and
 * no live ZeroMQ connection either (a server computing a long step answers no ping, but its ZeroMQ
 * I/O thread answers the ZMTP heartbeats this socket sends, so its connection stays up). */
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <errno.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <zmq.h>

#include "internal.h"

#define DEFAULT_ENDPOINT "tcp://127.0.0.1:5560"
#define DEFAULT_PORT 5560
#define MAX_REPLY (64u << 20) /* a reply larger than this is refused (bounded memory); the server's MAX_REPLY */

static int64_t now_ms(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (int64_t)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

/* ------------------------------------------------------------------ URLs */

static char *dup_range(const char *s, size_t n) {
  char *out = malloc(n + 1);
  if (out != NULL) {
    memcpy(out, s, n);
    out[n] = '\0';
  }
  return out;
}

static int hexval(int c) {
  if (c >= '0' && c <= '9')
    return c - '0';
  c = tolower(c);
  return (c >= 'a' && c <= 'f') ? c - 'a' + 10 : -1;
}

/* The robot part of a URL: '/' stripped at both ends, percent-decoded; NULL robot when empty. */
static int robot_part(const char *url, const char *part, size_t n, char **robot, char *err, size_t errlen) {
  while (n > 0 && *part == '/') {
    part++;
    n--;
  }
  while (n > 0 && part[n - 1] == '/')
    n--;
  *robot = NULL;
  if (n == 0)
    return 0;
  if (memchr(part, '/', n) != NULL) {
    char name[512];
    snprintf(name, sizeof name, "%.*s", (int)n, part);
    snprintf(err, errlen, "controller URL '%s': robot name '%s' contains '/'; percent-encode it (%%2F)", sn_shown(url),
             sn_shown(name));
    return -1;
  }
  char *out = malloc(n + 1);
  if (out == NULL)
    return -1;
  size_t j = 0;
  for (size_t i = 0; i < n; i++) {
    if (part[i] == '%' && i + 2 < n && hexval(part[i + 1]) >= 0 && hexval(part[i + 2]) >= 0) {
      out[j++] = (char)(hexval(part[i + 1]) * 16 + hexval(part[i + 2]));
      i += 2;
    } else
      out[j++] = part[i];
  }
  out[j] = '\0';
  *robot = out;
  return 0;
}

static bool is_socket_file(const char *path) {
  struct stat st;
  return stat(path, &st) == 0 && S_ISSOCK(st.st_mode);
}

int sn_parse_url(const char *url_in, sn_url *out, char *err, size_t errlen) {
  out->endpoint = NULL;
  out->robot = NULL;
  const char *s = url_in ? url_in : "";
  while (isspace((unsigned char)*s))
    s++;
  size_t n = strlen(s);
  while (n > 0 && isspace((unsigned char)s[n - 1]))
    n--;
  char *url = dup_range(s, n);
  if (url == NULL)
    return -1;
  int rc = 0;
  const char *sep = strstr(url, "://");
  if (n == 0) {
    out->endpoint = strdup(DEFAULT_ENDPOINT);
  } else if (sep == NULL) {
    out->endpoint = strdup(DEFAULT_ENDPOINT);
    rc = robot_part(url, url, n, &out->robot, err, errlen);
  } else {
    size_t slen = (size_t)(sep - url);
    char scheme[16] = {0};
    if (slen >= sizeof scheme) {
      snprintf(err, errlen, "controller URL '%s': unsupported scheme (use tcp://, ipc:// or a robot name)",
               sn_shown(url));
      free(url);
      return -1;
    }
    for (size_t i = 0; i < slen; i++)
      scheme[i] = (char)tolower((unsigned char)url[i]);
    const char *rest = sep + 3;
    if (strcmp(scheme, "tcp") == 0) {
      const char *slash = strchr(rest, '/');
      size_t hlen = slash ? (size_t)(slash - rest) : strlen(rest);
      const char *path = slash ? slash : "";
      const char *host = rest, *port = NULL;
      size_t host_len = hlen, port_len = 0;
      if (hlen > 0 && rest[0] == '[') { /* IPv6 literal: [::1]:5560 */
        const char *close = memchr(rest, ']', hlen);
        if (close == NULL) {
          snprintf(err, errlen, "controller URL '%s': unterminated IPv6 address", sn_shown(url));
          rc = -1;
        } else {
          host_len = (size_t)(close - rest) + 1;
          port = close + 1;
          port_len = hlen - host_len;
          if (port_len > 0 && *port == ':') {
            port++;
            port_len--;
          }
        }
      } else {
        const char *colon = memchr(rest, ':', hlen);
        if (colon != NULL) {
          host_len = (size_t)(colon - rest);
          port = colon + 1;
          port_len = hlen - host_len - 1;
        }
      }
      if (rc == 0 && host_len == 0) {
        snprintf(err, errlen, "controller URL '%s': no host", sn_shown(url));
        rc = -1;
      }
      long portnum = DEFAULT_PORT;
      if (rc == 0 && port_len > 0) {
        bool digits = port_len <= 5;
        for (size_t i = 0; digits && i < port_len; i++)
          digits = isdigit((unsigned char)port[i]) != 0;
        portnum = digits ? strtol(port, NULL, 10) : -1;
        if (!digits || portnum <= 0 || portnum >= 65536) {
          char shown[64];
          snprintf(shown, sizeof shown, "%.*s", (int)port_len, port);
          snprintf(err, errlen, "controller URL '%s': bad port '%s'", sn_shown(url), sn_shown(shown));
          rc = -1;
        }
      }
      if (rc == 0) {
        size_t cap = host_len + 32;
        out->endpoint = malloc(cap);
        if (out->endpoint != NULL)
          snprintf(out->endpoint, cap, "tcp://%.*s:%ld", (int)host_len, host, portnum);
        rc = robot_part(url, path, strlen(path), &out->robot, err, errlen);
      }
    } else if (strcmp(scheme, "ipc") == 0 || strcmp(scheme, "inproc") == 0) {
      size_t rlen = strlen(rest);
      if (rlen == 0) {
        snprintf(err, errlen, "controller URL '%s': no path", sn_shown(url));
        rc = -1;
      } else if (rest[rlen - 1] == '/') {
        while (rlen > 0 && rest[rlen - 1] == '/')
          rlen--;
        size_t cap = slen + 3 + rlen + 1;
        out->endpoint = malloc(cap);
        if (out->endpoint != NULL)
          snprintf(out->endpoint, cap, "%s://%.*s", scheme, (int)rlen, rest);
      } else if (strcmp(scheme, "ipc") == 0 && is_socket_file(rest)) {
        out->endpoint = strdup(url);
      } else {
        const char *last = strrchr(rest, '/');
        if (last == NULL || last == rest) {
          out->endpoint = strdup(url);
        } else {
          size_t cap = slen + 3 + (size_t)(last - rest) + 1;
          out->endpoint = malloc(cap);
          if (out->endpoint != NULL)
            snprintf(out->endpoint, cap, "%s://%.*s", scheme, (int)(last - rest), rest);
          rc = robot_part(url, last + 1, strlen(last + 1), &out->robot, err, errlen);
        }
      }
    } else {
      snprintf(err, errlen, "controller URL '%s': unsupported scheme '%s' (use tcp://, ipc:// or a robot name)",
               sn_shown(url), sn_shown(scheme));
      rc = -1;
    }
  }
  free(url);
  if (rc != 0 || out->endpoint == NULL) {
    if (rc == 0)
      snprintf(err, errlen, "out of memory");
    sn_url_free(out);
    return -1;
  }
  return 0;
}

void sn_url_free(sn_url *u) {
  free(u->endpoint);
  free(u->robot);
  u->endpoint = NULL;
  u->robot = NULL;
}

/* ------------------------------------------------------------------ replies */

void sn_reply_free(sn_reply *r) {
  if (r->data != NULL) {
    msgpack_unpacked_destroy(&r->unpacked);
    free(r->data);
  }
  r->data = NULL;
  r->result = NULL;
}

static void client_error(sn_reply *out, int code, const char *fmt, const char *a, const char *b) {
  memset(out, 0, sizeof *out);
  out->ok = false;
  out->code = code;
  snprintf(out->message, sizeof out->message, fmt, a, b);
}

/* Decode one received message into out (which takes ownership of data). id_out: the reply's id, 0
 * for nil. Returns 0, or -1 for an undecodable reply (out filled with BAD_REPLY). */
static int decode_reply(char *data, size_t size, sn_reply *out, uint64_t *id_out) {
  memset(out, 0, sizeof *out);
  msgpack_unpacked_init(&out->unpacked);
  out->data = data;
  out->size = size;
  size_t off = 0;
  if (msgpack_unpack_next(&out->unpacked, data, size, &off) != MSGPACK_UNPACK_SUCCESS ||
      out->unpacked.data.type != MSGPACK_OBJECT_MAP) {
    sn_reply_free(out);
    client_error(out, SN_BAD_REPLY, "undecodable reply (not a msgpack map)%s%s", "", "");
    return -1;
  }
  const msgpack_object *root = &out->unpacked.data;
  int64_t id = 0;
  *id_out = sn_as_int64(sn_get(root, "id"), &id) && id > 0 ? (uint64_t)id : 0;
  const msgpack_object *ok = sn_get(root, "ok");
  out->ok = ok != NULL && ok->type == MSGPACK_OBJECT_BOOLEAN && ok->via.boolean;
  if (out->ok) {
    out->result = sn_get(root, "result");
  } else {
    const msgpack_object *e = sn_get(root, "error");
    out->code = (int)sn_int_or(e, "code", SN_INTERNAL);
    const msgpack_object *m = sn_get(e, "message");
    if (m != NULL && m->type == MSGPACK_OBJECT_STR)
      snprintf(out->message, sizeof out->message, "%s", sn_shown_n(m->via.str.ptr, m->via.str.size));
    else if (e == NULL)
      out->code = SN_BAD_REPLY, snprintf(out->message, sizeof out->message, "error reply without an error map");
  }
  return 0;
}

/* ------------------------------------------------------------------ connection */

typedef struct {
  uint64_t id;
  char *data;
  size_t size;
} stashed;

struct sn_conn {
  void *ctx;
  void *sock;
  char *endpoint;
  char *shown_endpoint; /* endpoint as its lines show it (sn_shown): the URL may hold a line break */
  uint64_t next_id;
  uint64_t *outstanding;
  size_t n_out, cap_out;
  stashed *stash;
  size_t n_stash, cap_stash;
  /* heartbeat */
  pthread_t hb_thread;
  bool hb_running;
  atomic_bool hb_stop;
  atomic_llong hb_last_reply;
  atomic_bool hb_dropped;
  char hb_session[256];
  char hb_problem[256];
  pthread_mutex_t hb_lock;
  int hb_interval_ms;
  int64_t hb_lost_after_ms;
  atomic_bool hb_connected;   /* a connection passed its handshake and has not closed since */
  atomic_llong hb_down_since; /* when it closed (or the heartbeat started) */
  int64_t hb_zmtp_timeout_ms; /* ZMTP heartbeats: no traffic this long closes the connection */
  int64_t hb_down_grace_ms;   /* a connection down this long counts as none (a reconnection: ~0.1 s) */
  /* the step request in flight, re-sent (same id) while unanswered: its reply may have been lost
     with a dropped connection (PROTOCOL.md, "Connections that drop") */
  char *retry_data;
  size_t retry_size;
  uint64_t retry_id;
  int64_t retry_sent_ms;
  int64_t retry_wait_ms; /* RETRY_MS, doubled at each re-send up to RETRY_MAX_MS (a long step) */
  /* handshake events (tcp only), so that a server that refuses this client's security handshake is
     said as such rather than as "is the server running?"; dropped after the first reply */
  void *monitor;
  int handshake_failed; /* the last failed handshake's event, 0: none */
  bool has_key;
};

#define RETRY_MS 1000
#define RETRY_MAX_MS 8000
#define PING_BACKLOG 16 /* unanswered pings at most (a long step): the server's queue stays short */

/* CURVE (PROTOCOL.md, README "Security and limits"): with SENSORIUM_CURVE_SERVERKEY set (the
   server's public key, 64 hex or 40 Z85 characters) the socket encrypts and authenticates the
   server, with a fresh key pair of its own. Returns 0, or -1 with a message for a malformed key. */
static int curve_client(void *sock, char *err, size_t errlen) {
  const char *text = getenv("SENSORIUM_CURVE_SERVERKEY");
  if (text == NULL || *text == '\0')
    return 0;
  char z85[41];
  size_t n = strlen(text);
  if (n == 64) {
    uint8_t raw[32];
    for (size_t i = 0; i < 32; i++) {
      unsigned v;
      if (!isxdigit((unsigned char)text[2 * i]) || !isxdigit((unsigned char)text[2 * i + 1]) ||
          sscanf(text + 2 * i, "%2x", &v) != 1)
        goto bad;
      raw[i] = (uint8_t)v;
    }
    if (zmq_z85_encode(z85, raw, sizeof raw) == NULL)
      goto bad;
  } else if (n == 40) {
    uint8_t raw[32];
    memcpy(z85, text, 41);
    if (zmq_z85_decode(raw, z85) == NULL)
      goto bad;
  } else {
    goto bad;
  }
  char pub[41], sec[41];
  if (zmq_curve_keypair(pub, sec) != 0) {
    snprintf(err, errlen, "SENSORIUM_CURVE_SERVERKEY is set but this libzmq has no CURVE: %s", zmq_strerror(zmq_errno()));
    return -1;
  }
  if (zmq_setsockopt(sock, ZMQ_CURVE_SERVERKEY, z85, 40) != 0 || zmq_setsockopt(sock, ZMQ_CURVE_PUBLICKEY, pub, 40) != 0 ||
      zmq_setsockopt(sock, ZMQ_CURVE_SECRETKEY, sec, 40) != 0) {
    snprintf(err, errlen, "cannot set the CURVE keys: %s", zmq_strerror(zmq_errno()));
    return -1;
  }
  return 0;
bad:
  snprintf(err, errlen, "SENSORIUM_CURVE_SERVERKEY: a CURVE key is 40 Z85 or 64 hex characters (got %zu characters)", n);
  return -1;
}

/* libzmq sends monitor events from its I/O thread with a blocking send: an unbounded receiving pipe
   (RCVHWM 0, set before connecting) keeps a handshake failing at every reconnection from stalling
   the context; the events are a few bytes each and read at the next wait. */
static void start_monitor(sn_conn *c) {
  char addr[64];
  snprintf(addr, sizeof addr, "inproc://sensorium-handshake-%p", (void *)c);
  if (zmq_socket_monitor(c->sock, addr, ZMQ_EVENT_HANDSHAKE_SUCCEEDED | ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL |
                                            ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL | ZMQ_EVENT_HANDSHAKE_FAILED_AUTH) != 0)
    return; /* no monitor: a refused handshake is then a plain timeout */
  void *mon = zmq_socket(c->ctx, ZMQ_PAIR);
  int zero = 0;
  if (mon == NULL)
    return;
  zmq_setsockopt(mon, ZMQ_RCVHWM, &zero, sizeof zero);
  zmq_setsockopt(mon, ZMQ_LINGER, &zero, sizeof zero);
  if (zmq_connect(mon, addr) != 0) {
    zmq_close(mon);
    zmq_socket_monitor(c->sock, NULL, 0);
    return;
  }
  c->monitor = mon;
}

static void stop_monitor(sn_conn *c) {
  if (c->monitor == NULL)
    return;
  zmq_socket_monitor(c->sock, NULL, 0);
  zmq_close(c->monitor);
  c->monitor = NULL;
}

/* Reads the handshake events received so far (never blocks). */
static void watch_handshakes(sn_conn *c) {
  while (c->monitor != NULL) {
    zmq_pollitem_t item = {c->monitor, 0, ZMQ_POLLIN, 0};
    if (zmq_poll(&item, 1, 0) <= 0)
      return;
    int event = 0;
    zmq_msg_t msg;
    zmq_msg_init(&msg);
    if (zmq_msg_recv(&msg, c->monitor, ZMQ_DONTWAIT) < 0) {
      zmq_msg_close(&msg);
      return;
    }
    if (zmq_msg_size(&msg) >= 2) {
      const unsigned char *d = zmq_msg_data(&msg);
      event = d[0] | (d[1] << 8); /* a 16-bit event number, little-endian, then a 32-bit value */
    }
    while (zmq_msg_more(&msg)) { /* the second frame: the endpoint */
      zmq_msg_close(&msg);
      zmq_msg_init(&msg);
      if (zmq_msg_recv(&msg, c->monitor, ZMQ_DONTWAIT) < 0)
        break;
    }
    zmq_msg_close(&msg);
    if (event == ZMQ_EVENT_HANDSHAKE_SUCCEEDED) {
      c->handshake_failed = 0;
      stop_monitor(c);
      return;
    }
    if (event != 0)
      c->handshake_failed = event;
  }
}

const char *sn_conn_handshake_problem(sn_conn *c) {
  watch_handshakes(c);
  if (c->handshake_failed == 0)
    return NULL;
  if (!c->has_key)
    return "the server refused the connection's handshake: it uses CURVE encryption and this client has no key; "
           "set SENSORIUM_CURVE_SERVERKEY to the key `sensorium serve --curve-keys` prints";
  if (c->handshake_failed == ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL)
    return "the handshake failed: this client uses CURVE (SENSORIUM_CURVE_SERVERKEY) but the server does not "
           "(started without --curve-keys?)";
  return "the server did not accept the CURVE handshake: SENSORIUM_CURVE_SERVERKEY is wrong for this server";
}

sn_conn *sn_conn_open(const char *endpoint, char *err, size_t errlen) {
  sn_conn *c = calloc(1, sizeof *c);
  if (c == NULL)
    return NULL;
  c->ctx = zmq_ctx_new();
  c->sock = c->ctx ? zmq_socket(c->ctx, ZMQ_DEALER) : NULL;
  c->endpoint = strdup(endpoint);
  c->shown_endpoint = strdup(sn_shown(endpoint));
  c->next_id = 1;
  pthread_mutex_init(&c->hb_lock, NULL);
  if (c->sock == NULL || c->endpoint == NULL || c->shown_endpoint == NULL) {
    snprintf(err, errlen, "cannot create a ZeroMQ socket: %s", zmq_strerror(zmq_errno()));
    sn_conn_close(c);
    return NULL;
  }
  int zero = 0;
  int64_t maxmsg = MAX_REPLY;
  zmq_setsockopt(c->sock, ZMQ_LINGER, &zero, sizeof zero);
  zmq_setsockopt(c->sock, ZMQ_MAXMSGSIZE, &maxmsg, sizeof maxmsg);
  /* a random routing id of our own, so that after a reconnection the server sees the same peer
     (a first byte of 0 is reserved by libzmq) */
  unsigned char rid[16];
  rid[0] = 'S';
  FILE *urandom = fopen("/dev/urandom", "rb");
  if (urandom == NULL || fread(rid + 1, 1, sizeof rid - 1, urandom) != sizeof rid - 1) {
    uint64_t x = (uint64_t)now_ms() ^ ((uint64_t)(uintptr_t)c << 16);
    for (size_t i = 1; i < sizeof rid; i++) {
      x = x * 6364136223846793005ULL + 1442695040888963407ULL;
      rid[i] = (unsigned char)(x >> 56);
    }
  }
  if (urandom != NULL)
    fclose(urandom);
  zmq_setsockopt(c->sock, ZMQ_ROUTING_ID, rid, sizeof rid);
  if (curve_client(c->sock, err, errlen) != 0) {
    sn_conn_close(c);
    return NULL;
  }
  const char *key = getenv("SENSORIUM_CURVE_SERVERKEY");
  c->has_key = key != NULL && *key != '\0';
  if (strncmp(endpoint, "tcp://", 6) == 0)
    start_monitor(c);
  if (zmq_connect(c->sock, endpoint) != 0) {
    snprintf(err, errlen, "cannot connect to %s: %s", c->shown_endpoint, zmq_strerror(zmq_errno()));
    sn_conn_close(c);
    return NULL;
  }
  return c;
}

const char *sn_conn_endpoint(const sn_conn *c) { return c->shown_endpoint; }

void sn_conn_close(sn_conn *c) {
  if (c == NULL)
    return;
  sn_conn_stop_heartbeat(c);
  stop_monitor(c);
  if (c->sock != NULL)
    zmq_close(c->sock);
  if (c->ctx != NULL)
    zmq_ctx_term(c->ctx);
  free(c->retry_data);
  for (size_t i = 0; i < c->n_stash; i++)
    free(c->stash[i].data);
  free(c->stash);
  free(c->outstanding);
  free(c->endpoint);
  free(c->shown_endpoint);
  pthread_mutex_destroy(&c->hb_lock);
  free(c);
}

uint64_t sn_conn_next_id(sn_conn *c) { return c->next_id++; }

static bool is_outstanding(const sn_conn *c, uint64_t id, size_t *where) {
  for (size_t i = 0; i < c->n_out; i++)
    if (c->outstanding[i] == id) {
      if (where)
        *where = i;
      return true;
    }
  return false;
}

static void forget(sn_conn *c, uint64_t id) {
  size_t i;
  if (c->retry_id == id && id != 0) {
    free(c->retry_data);
    c->retry_data = NULL;
    c->retry_id = 0;
  }
  if (is_outstanding(c, id, &i))
    c->outstanding[i] = c->outstanding[--c->n_out];
  for (size_t k = 0; k < c->n_stash; k++)
    if (c->stash[k].id == id) {
      free(c->stash[k].data);
      c->stash[k] = c->stash[--c->n_stash];
      break;
    }
}

int sn_conn_send(sn_conn *c, sn_req *r, uint64_t id) {
  if (c->n_out == c->cap_out) {
    size_t cap = c->cap_out ? 2 * c->cap_out : 8;
    uint64_t *p = realloc(c->outstanding, cap * sizeof *p);
    if (p == NULL)
      return -1;
    c->outstanding = p;
    c->cap_out = cap;
  }
  /* never blocks: a DEALER queues while (re)connecting; it refuses (EAGAIN) only once ZeroMQ closed
     its connection for good (see sn_conn_wait) or 1000 requests are queued */
  if (zmq_send(c->sock, r->buf.data, r->buf.size, ZMQ_DONTWAIT) < 0)
    return -1;
  c->outstanding[c->n_out++] = id;
  return 0;
}

int sn_conn_send_retried(sn_conn *c, sn_req *r, uint64_t id) {
  if (sn_conn_send(c, r, id) != 0)
    return -1;
  free(c->retry_data);
  c->retry_data = malloc(r->buf.size ? r->buf.size : 1);
  c->retry_id = c->retry_data != NULL ? id : 0;
  if (c->retry_data != NULL) {
    memcpy(c->retry_data, r->buf.data, r->buf.size);
    c->retry_size = r->buf.size;
    c->retry_sent_ms = now_ms();
    c->retry_wait_ms = RETRY_MS;
  }
  return 0;
}

void sn_conn_discard(sn_conn *c, uint64_t id) { forget(c, id); }

static char *heartbeat_problem(sn_conn *c, char *buf, size_t len) {
  if (!c->hb_running)
    return NULL;
  if (atomic_load(&c->hb_dropped)) {
    pthread_mutex_lock(&c->hb_lock);
    snprintf(buf, len, "%s", c->hb_problem);
    pthread_mutex_unlock(&c->hb_lock);
    return buf;
  }
  int64_t now = now_ms();
  int64_t silent = now - (int64_t)atomic_load(&c->hb_last_reply);
  if (silent <= c->hb_lost_after_ms || atomic_load(&c->hb_connected))
    return NULL; /* answering, or busy (a long step): its connection lives */
  int64_t down = now - (int64_t)atomic_load(&c->hb_down_since);
  if (down <= c->hb_down_grace_ms)
    return NULL;
  snprintf(buf, len, "no answer from %s for %.1f s and no connection to it for %.1f s (server gone?)", c->shown_endpoint,
           (double)silent / 1000.0, (double)down / 1000.0);
  return buf;
}

int sn_conn_wait(sn_conn *c, uint64_t id, int timeout_ms, sn_reply *out) {
  memset(out, 0, sizeof *out);
  for (size_t k = 0; k < c->n_stash; k++)
    if (c->stash[k].id == id) {
      stashed s = c->stash[k];
      c->stash[k] = c->stash[--c->n_stash];
      forget(c, id);
      uint64_t got;
      return decode_reply(s.data, s.size, out, &got);
    }
  if (!is_outstanding(c, id, NULL)) {
    client_error(out, SN_WRONG_STATE, "request %s is not outstanding%s", "", "");
    return -1;
  }
  int64_t deadline = timeout_ms < 0 ? -1 : now_ms() + timeout_ms;
  for (;;) {
    int slice = 250;
    if (deadline >= 0) {
      int64_t left = deadline - now_ms();
      if (left <= 0) {
        forget(c, id);
        const char *refused = sn_conn_handshake_problem(c);
        if (refused != NULL) {
          client_error(out, SN_TIMEOUT, "no reply from %s: %s", c->shown_endpoint, refused);
          return -1;
        }
        char t[32];
        snprintf(t, sizeof t, "%g", timeout_ms / 1000.0);
        client_error(out, SN_TIMEOUT, "no reply from %s within %s s (is `sensorium serve` running there?)",
                     c->shown_endpoint, t);
        return -1;
      }
      if (left < slice)
        slice = (int)left + 1;
    }
    zmq_pollitem_t item = {c->sock, 0, ZMQ_POLLIN, 0};
    int n = zmq_poll(&item, 1, slice);
    if (n < 0) {
      if (zmq_errno() == EINTR)
        continue;
      forget(c, id);
      client_error(out, SN_CONNECTION_LOST, "polling %s: %s", c->shown_endpoint, zmq_strerror(zmq_errno()));
      return -1;
    }
    if (n == 0) {
      if (c->retry_id == id && now_ms() - c->retry_sent_ms >= c->retry_wait_ms) {
        if (zmq_send(c->sock, c->retry_data, c->retry_size, ZMQ_DONTWAIT) < 0 && zmq_errno() == EAGAIN) {
          /* the socket has no connection left to queue on: ZeroMQ closed it for good, which it does
             (without reconnecting) when a message breaks the protocol, e.g. a reply larger than
             MAX_REPLY (ZMQ_MAXMSGSIZE); a dropped network connection would still queue */
          forget(c, id);
          const char *refused = sn_conn_handshake_problem(c);
          if (refused != NULL) { /* libzmq gave up reconnecting after the handshake failed */
            client_error(out, SN_TIMEOUT, "no reply from %s: %s", c->shown_endpoint, refused);
            return -1;
          }
          char limit[32];
          snprintf(limit, sizeof limit, "%u MiB", MAX_REPLY >> 20);
          client_error(out, SN_CONNECTION_LOST,
                       "ZeroMQ closed the connection to %s for good while a reply was due: a reply larger than "
                       "this client's limit of %s (or not ZeroMQ) ends it; the Sensorium server sends no larger one",
                       c->shown_endpoint, limit);
          return -1;
        }
        c->retry_sent_ms = now_ms();
        c->retry_wait_ms = 2 * c->retry_wait_ms < RETRY_MAX_MS ? 2 * c->retry_wait_ms : RETRY_MAX_MS;
      }
      if (c->monitor != NULL)
        watch_handshakes(c);
      char why[300];
      if (heartbeat_problem(c, why, sizeof why) != NULL) {
        forget(c, id);
        client_error(out, SN_CONNECTION_LOST, "%s%s", why, "");
        return -1;
      }
      continue;
    }
    while (true) { /* every reply already received; stop at ours */
      zmq_msg_t msg;
      zmq_msg_init(&msg);
      if (zmq_msg_recv(&msg, c->sock, ZMQ_DONTWAIT) < 0) {
        zmq_msg_close(&msg);
        break;
      }
      size_t size = zmq_msg_size(&msg);
      char *data = malloc(size ? size : 1);
      if (data == NULL) {
        zmq_msg_close(&msg);
        forget(c, id);
        client_error(out, SN_BAD_REPLY, "out of memory for a reply%s%s", "", "");
        return -1;
      }
      memcpy(data, zmq_msg_data(&msg), size);
      zmq_msg_close(&msg);
      uint64_t got = 0;
      sn_reply tmp;
      if (decode_reply(data, size, &tmp, &got) != 0) {
        forget(c, id);
        *out = tmp;
        return -1;
      }
      if (got == id) {
        forget(c, id);
        stop_monitor(c); /* the handshake succeeded */
        *out = tmp;
        return 0;
      }
      if (got == 0 && !tmp.ok) { /* the server could not read one of our requests */
        forget(c, id);
        *out = tmp;
        return 0;
      }
      if (is_outstanding(c, got, NULL)) { /* someone else's reply (a pending step): keep its bytes */
        msgpack_unpacked_destroy(&tmp.unpacked); /* data stays ours */
        if (c->n_stash == c->cap_stash) {
          size_t cap = c->cap_stash ? 2 * c->cap_stash : 4;
          stashed *p = realloc(c->stash, cap * sizeof *p);
          if (p == NULL) {
            free(data);
            continue;
          }
          c->stash = p;
          c->cap_stash = cap;
        }
        c->stash[c->n_stash++] = (stashed){got, data, size};
        continue;
      }
      sn_reply_free(&tmp); /* a reply to a request we gave up on */
    }
  }
}

int sn_conn_wait_any(sn_conn *c, int timeout_ms, sn_reply *out) {
  zmq_pollitem_t item = {c->sock, 0, ZMQ_POLLIN, 0};
  if (zmq_poll(&item, 1, timeout_ms) <= 0) {
    client_error(out, SN_TIMEOUT, "no reply from %s%s", c->shown_endpoint, "");
    return -1;
  }
  zmq_msg_t msg;
  zmq_msg_init(&msg);
  if (zmq_msg_recv(&msg, c->sock, 0) < 0) {
    zmq_msg_close(&msg);
    client_error(out, SN_CONNECTION_LOST, "receiving from %s%s", c->shown_endpoint, "");
    return -1;
  }
  size_t size = zmq_msg_size(&msg);
  char *data = malloc(size ? size : 1);
  if (data == NULL) {
    zmq_msg_close(&msg);
    client_error(out, SN_BAD_REPLY, "out of memory for a reply%s%s", "", "");
    return -1;
  }
  memcpy(data, zmq_msg_data(&msg), size);
  zmq_msg_close(&msg);
  uint64_t got;
  return decode_reply(data, size, out, &got);
}

/* ------------------------------------------------------------------ heartbeat */

/* The heartbeat connection's events (never blocks): up after a handshake, down when it closes. */
static void watch_connection(sn_conn *c, void *mon, int *unanswered) {
  for (;;) {
    zmq_msg_t msg;
    zmq_msg_init(&msg);
    if (zmq_msg_recv(&msg, mon, ZMQ_DONTWAIT) < 0) {
      zmq_msg_close(&msg);
      return;
    }
    int event = 0;
    if (zmq_msg_size(&msg) >= 2) {
      const unsigned char *d = zmq_msg_data(&msg);
      event = d[0] | (d[1] << 8);
    }
    while (zmq_msg_more(&msg)) { /* the second frame: the endpoint */
      zmq_msg_close(&msg);
      zmq_msg_init(&msg);
      if (zmq_msg_recv(&msg, mon, ZMQ_DONTWAIT) < 0)
        break;
    }
    zmq_msg_close(&msg);
    if (event == ZMQ_EVENT_HANDSHAKE_SUCCEEDED) {
      atomic_store(&c->hb_connected, true);
      *unanswered = 0; /* a new connection: pings sent before may be lost */
    } else if (event == ZMQ_EVENT_DISCONNECTED && atomic_load(&c->hb_connected)) {
      atomic_store(&c->hb_connected, false);
      atomic_store(&c->hb_down_since, (long long)now_ms());
    }
  }
}

static void *heartbeat_main(void *arg) {
  sn_conn *c = arg;
  void *sock = zmq_socket(c->ctx, ZMQ_DEALER);
  if (sock == NULL)
    return NULL;
  int zero = 0;
  int ivl = c->hb_interval_ms, timeout = (int)c->hb_zmtp_timeout_ms;
  zmq_setsockopt(sock, ZMQ_LINGER, &zero, sizeof zero);
  zmq_setsockopt(sock, ZMQ_HEARTBEAT_IVL, &ivl, sizeof ivl);
  zmq_setsockopt(sock, ZMQ_HEARTBEAT_TIMEOUT, &timeout, sizeof timeout);
  /* the connection's ups and downs, on an unbounded pipe (see start_monitor); without a monitor the
     connection counts as down: unanswered pings then mean gone, as before */
  static atomic_uint monitors; /* a fresh address each time: a closed monitor's may linger */
  char addr[80];
  snprintf(addr, sizeof addr, "inproc://sensorium-heartbeat-%p-%u", (void *)c, atomic_fetch_add(&monitors, 1u));
  void *mon = NULL;
  if (zmq_socket_monitor(sock, addr, ZMQ_EVENT_HANDSHAKE_SUCCEEDED | ZMQ_EVENT_DISCONNECTED) == 0) {
    mon = zmq_socket(c->ctx, ZMQ_PAIR);
    if (mon != NULL) {
      zmq_setsockopt(mon, ZMQ_RCVHWM, &zero, sizeof zero);
      zmq_setsockopt(mon, ZMQ_LINGER, &zero, sizeof zero);
      if (zmq_connect(mon, addr) != 0) {
        zmq_close(mon);
        mon = NULL;
      }
    }
    if (mon == NULL)
      zmq_socket_monitor(sock, NULL, 0);
  }
  char curve_err[160];
  if (curve_client(sock, curve_err, sizeof curve_err) != 0 || zmq_connect(sock, c->endpoint) != 0) {
    if (mon != NULL) {
      zmq_socket_monitor(sock, NULL, 0);
      zmq_close(mon);
    }
    zmq_close(sock);
    return NULL;
  }
  uint64_t ids = 1;
  int unanswered = 0; /* pings sent since the last reply (or connection) */
  int64_t next_ping = now_ms();
  while (!atomic_load(&c->hb_stop)) {
    int64_t now = now_ms();
    if (now >= next_ping) {
      if (unanswered < PING_BACKLOG) { /* a server computing a long step reads none: a few wait for it */
        sn_req r;
        sn_req_begin(&r, ids++, "ping", 1);
        sn_req_key(&r, "session");
        sn_req_str(&r, c->hb_session);
        zmq_send(sock, r.buf.data, r.buf.size, ZMQ_DONTWAIT);
        sn_req_free(&r);
        unanswered++;
      }
      next_ping = now + c->hb_interval_ms;
    }
    int64_t wait = next_ping - now_ms();
    if (wait > 50)
      wait = 50;
    if (wait < 1)
      wait = 1;
    zmq_pollitem_t items[2] = {{sock, 0, ZMQ_POLLIN, 0}, {mon, 0, ZMQ_POLLIN, 0}};
    if (zmq_poll(items, mon != NULL ? 2 : 1, (long)wait) > 0 && (items[1].revents & ZMQ_POLLIN))
      watch_connection(c, mon, &unanswered);
    if (items[0].revents & ZMQ_POLLIN) {
      zmq_msg_t msg;
      zmq_msg_init(&msg);
      while (zmq_msg_recv(&msg, sock, ZMQ_DONTWAIT) >= 0) {
        size_t size = zmq_msg_size(&msg);
        char *data = malloc(size ? size : 1);
        if (data != NULL) {
          memcpy(data, zmq_msg_data(&msg), size);
          sn_reply rep;
          uint64_t got;
          if (decode_reply(data, size, &rep, &got) == 0) {
            atomic_store(&c->hb_last_reply, (long long)now_ms());
            unanswered = 0;
            if (!rep.ok) {
              pthread_mutex_lock(&c->hb_lock);
              snprintf(c->hb_problem, sizeof c->hb_problem, "the server dropped session '%s' (%s: %s)", c->hb_session,
                       sn_error_name(rep.code), rep.message);
              pthread_mutex_unlock(&c->hb_lock);
              atomic_store(&c->hb_dropped, true);
            }
            sn_reply_free(&rep);
          }
        }
        zmq_msg_close(&msg);
        zmq_msg_init(&msg);
      }
      zmq_msg_close(&msg);
    }
  }
  if (mon != NULL) {
    zmq_socket_monitor(sock, NULL, 0);
    zmq_close(mon);
  }
  zmq_close(sock);
  return NULL;
}

int sn_conn_start_heartbeat(sn_conn *c, const char *session, int interval_ms) {
  sn_conn_stop_heartbeat(c);
  snprintf(c->hb_session, sizeof c->hb_session, "%s", session);
  c->hb_interval_ms = interval_ms > 0 ? interval_ms : 1000;
  c->hb_lost_after_ms = 5 * (int64_t)c->hb_interval_ms;
  if (c->hb_lost_after_ms < 2000)
    c->hb_lost_after_ms = 2000;
  c->hb_zmtp_timeout_ms = 3 * (int64_t)c->hb_interval_ms;
  if (c->hb_zmtp_timeout_ms < 1000)
    c->hb_zmtp_timeout_ms = 1000;
  if (c->hb_zmtp_timeout_ms > 0x7fffffff)
    c->hb_zmtp_timeout_ms = 0x7fffffff;
  c->hb_down_grace_ms = 2 * (int64_t)c->hb_interval_ms;
  if (c->hb_down_grace_ms < 500)
    c->hb_down_grace_ms = 500;
  atomic_store(&c->hb_connected, false);
  atomic_store(&c->hb_down_since, (long long)now_ms());
  atomic_store(&c->hb_stop, false);
  atomic_store(&c->hb_dropped, false);
  atomic_store(&c->hb_last_reply, (long long)now_ms());
  if (pthread_create(&c->hb_thread, NULL, heartbeat_main, c) != 0)
    return -1;
  c->hb_running = true;
  return 0;
}

void sn_conn_stop_heartbeat(sn_conn *c) {
  if (!c->hb_running)
    return;
  atomic_store(&c->hb_stop, true);
  pthread_join(c->hb_thread, NULL);
  c->hb_running = false;
}
