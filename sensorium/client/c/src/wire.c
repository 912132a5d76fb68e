/* Sensorium C controller library: msgpack helpers (requests out, reply maps in). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

static void pack_cstr(msgpack_packer *pk, const char *s) {
  size_t n = strlen(s);
  msgpack_pack_str(pk, n);
  msgpack_pack_str_body(pk, s, n);
}

void sn_req_begin(sn_req *r, uint64_t id, const char *service, uint32_t nargs) {
  msgpack_sbuffer_init(&r->buf);
  msgpack_packer_init(&r->pk, &r->buf, msgpack_sbuffer_write);
  msgpack_pack_map(&r->pk, 3);
  pack_cstr(&r->pk, "id");
  msgpack_pack_uint64(&r->pk, id);
  pack_cstr(&r->pk, "service");
  pack_cstr(&r->pk, service);
  pack_cstr(&r->pk, "args");
  msgpack_pack_map(&r->pk, nargs);
}

void sn_req_key(sn_req *r, const char *key) { pack_cstr(&r->pk, key); }

void sn_req_str(sn_req *r, const char *s) { pack_cstr(&r->pk, s); }

void sn_req_free(sn_req *r) { msgpack_sbuffer_destroy(&r->buf); }

const msgpack_object *sn_get(const msgpack_object *map, const char *key) {
  if (map == NULL || map->type != MSGPACK_OBJECT_MAP)
    return NULL;
  size_t n = strlen(key);
  for (uint32_t i = 0; i < map->via.map.size; i++) {
    const msgpack_object_kv *kv = &map->via.map.ptr[i];
    if (kv->key.type == MSGPACK_OBJECT_STR && kv->key.via.str.size == n && memcmp(kv->key.via.str.ptr, key, n) == 0)
      return &kv->val;
  }
  return NULL;
}

bool sn_as_double(const msgpack_object *o, double *out) {
  if (o == NULL)
    return false;
  switch (o->type) {
    case MSGPACK_OBJECT_FLOAT32:
    case MSGPACK_OBJECT_FLOAT64:
      *out = o->via.f64;
      return true;
    case MSGPACK_OBJECT_POSITIVE_INTEGER:
      *out = (double)o->via.u64;
      return true;
    case MSGPACK_OBJECT_NEGATIVE_INTEGER:
      *out = (double)o->via.i64;
      return true;
    case MSGPACK_OBJECT_NIL:
      *out = NAN;
      return true;
    default:
      return false;
  }
}

bool sn_as_int64(const msgpack_object *o, int64_t *out) {
  if (o == NULL)
    return false;
  switch (o->type) {
    case MSGPACK_OBJECT_POSITIVE_INTEGER:
      *out = (int64_t)o->via.u64;
      return true;
    case MSGPACK_OBJECT_NEGATIVE_INTEGER:
      *out = o->via.i64;
      return true;
    case MSGPACK_OBJECT_FLOAT32:
    case MSGPACK_OBJECT_FLOAT64:
      if (!isfinite(o->via.f64))
        return false;
      *out = (int64_t)o->via.f64;
      return true;
    case MSGPACK_OBJECT_BOOLEAN:
      *out = o->via.boolean ? 1 : 0;
      return true;
    default:
      return false;
  }
}

double sn_double_or(const msgpack_object *map, const char *key, double fallback) {
  double v;
  return sn_as_double(sn_get(map, key), &v) ? v : fallback;
}

int64_t sn_int_or(const msgpack_object *map, const char *key, int64_t fallback) {
  int64_t v;
  return sn_as_int64(sn_get(map, key), &v) ? v : fallback;
}

bool sn_bool_or(const msgpack_object *map, const char *key, bool fallback) {
  const msgpack_object *o = sn_get(map, key);
  if (o == NULL)
    return fallback;
  if (o->type == MSGPACK_OBJECT_BOOLEAN)
    return o->via.boolean;
  int64_t v;
  return sn_as_int64(o, &v) ? v != 0 : fallback;
}

char *sn_strdup_obj(const msgpack_object *o) {
  if (o == NULL || o->type != MSGPACK_OBJECT_STR)
    return NULL;
  char *s = malloc(o->via.str.size + 1);
  if (s == NULL)
    return NULL;
  memcpy(s, o->via.str.ptr, o->via.str.size);
  s[o->via.str.size] = '\0';
  return s;
}

const char *sn_error_name(int code) {
  switch (code) {
    case SN_BAD_REQUEST: return "BAD_REQUEST";
    case SN_UNKNOWN_SERVICE: return "UNKNOWN_SERVICE";
    case SN_UNKNOWN_ROBOT: return "UNKNOWN_ROBOT";
    case SN_UNKNOWN_DEVICE: return "UNKNOWN_DEVICE";
    case SN_INVALID_ARGUMENT: return "INVALID_ARGUMENT";
    case SN_NOT_ATTACHED: return "NOT_ATTACHED";
    case SN_ROBOT_TAKEN: return "ROBOT_TAKEN";
    case SN_TOO_LARGE: return "TOO_LARGE";
    case SN_SHUTTING_DOWN: return "SHUTTING_DOWN";
    case SN_WRONG_STATE: return "WRONG_STATE";
    case SN_INTERNAL: return "INTERNAL";
    case SN_TIMEOUT: return "TIMEOUT";
    case SN_CONNECTION_LOST: return "CONNECTION_LOST";
    case SN_BAD_REPLY: return "BAD_REPLY";
    case SN_BAD_URL: return "BAD_URL";
    default: return "ERROR";
  }
}
