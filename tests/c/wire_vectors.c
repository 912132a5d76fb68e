/* Replays request vectors with the C library's own codec and transport (src/conn.c, src/wire.c):
 * wire_vectors ENDPOINT reads one hex-encoded request per stdin line, sends it on one DEALER
 * connection, waits for one reply and prints
 *   "id=<n|nil> ok=<0|1> code=<n|-> keys=<k1,k2,...> K=V ..."
 * (keys of the result map, then its scalar entries: ints, %.17g floats, true/false, strings). */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zmq.h>

#include "../../sensorium/client/c/src/internal.h"

static int hexval(int c) {
  return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
}

static void print_scalar(const msgpack_object *k, const msgpack_object *v) {
  switch (v->type) {
    case MSGPACK_OBJECT_POSITIVE_INTEGER: printf(" %.*s=%" PRIu64, (int)k->via.str.size, k->via.str.ptr, v->via.u64); break;
    case MSGPACK_OBJECT_NEGATIVE_INTEGER: printf(" %.*s=%" PRId64, (int)k->via.str.size, k->via.str.ptr, v->via.i64); break;
    case MSGPACK_OBJECT_FLOAT32:
    case MSGPACK_OBJECT_FLOAT64: printf(" %.*s=%.17g", (int)k->via.str.size, k->via.str.ptr, v->via.f64); break;
    case MSGPACK_OBJECT_BOOLEAN:
      printf(" %.*s=%s", (int)k->via.str.size, k->via.str.ptr, v->via.boolean ? "true" : "false");
      break;
    case MSGPACK_OBJECT_STR:
      printf(" %.*s=%.*s", (int)k->via.str.size, k->via.str.ptr, (int)v->via.str.size, v->via.str.ptr);
      break;
    default: break;
  }
}

int main(int argc, char **argv) {
  if (argc != 2)
    return 2;
  char err[256];
  sn_conn *c = sn_conn_open(argv[1], err, sizeof err);
  if (c == NULL) {
    fprintf(stderr, "%s\n", err);
    return 1;
  }
  static char line[4 << 20];
  while (fgets(line, sizeof line, stdin) != NULL) {
    size_t n = strcspn(line, "\r\n");
    sn_req r;
    msgpack_sbuffer_init(&r.buf);
    for (size_t i = 0; i + 1 < n; i += 2) {
      char b = (char)(hexval(line[i]) * 16 + hexval(line[i + 1]));
      msgpack_sbuffer_write(&r.buf, &b, 1);
    }
    uint64_t id = sn_conn_next_id(c);
    sn_conn_send(c, &r, id);
    sn_req_free(&r);
    /* the reply carries the vector's own id (or nil): take whatever comes first */
    sn_conn_discard(c, id);
    sn_reply rep;
    int rc = sn_conn_wait_any(c, 20000, &rep);
    if (rc != 0) {
      printf("error %s %s\n", sn_error_name(rep.code), rep.message);
      fflush(stdout);
      continue;
    }
    int64_t rid;
    if (sn_as_int64(sn_get(&rep.unpacked.data, "id"), &rid))
      printf("id=%" PRId64, rid);
    else
      printf("id=nil");
    printf(" ok=%d", rep.ok ? 1 : 0);
    if (!rep.ok)
      printf(" code=%d", rep.code);
    else
      printf(" code=-");
    printf(" keys=");
    const msgpack_object *res = rep.result;
    if (res != NULL && res->type == MSGPACK_OBJECT_MAP) {
      for (uint32_t i = 0; i < res->via.map.size; i++) {
        const msgpack_object *k = &res->via.map.ptr[i].key;
        if (k->type == MSGPACK_OBJECT_STR)
          printf("%s%.*s", i ? "," : "", (int)k->via.str.size, k->via.str.ptr);
      }
      for (uint32_t i = 0; i < res->via.map.size; i++)
        if (res->via.map.ptr[i].key.type == MSGPACK_OBJECT_STR)
          print_scalar(&res->via.map.ptr[i].key, &res->via.map.ptr[i].val);
    }
    printf("\n");
    fflush(stdout);
    sn_reply_free(&rep);
  }
  sn_conn_close(c);
  return 0;
}
