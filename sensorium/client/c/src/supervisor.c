/* Sensorium C controller library: the Supervisor subset (PROTOCOL.md, supervisor services). A
 * WbNodeRef / WbFieldRef points to a small record kept until wb_robot_cleanup(); one record per
 * node id and per (node, field), so the arrays they hold stay valid between calls. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/supervisor.h>

#include "internal.h"

struct WbNodeStructPrivate {
  int64_t id;
  double position[3];
  double orientation[9];
  struct WbNodeStructPrivate *next;
};

struct WbFieldStructPrivate {
  int64_t node;
  WbFieldType type;
  const char *name; /* "translation" or "rotation" */
  double value[4];
  struct WbFieldStructPrivate *next;
};

void sn_supervisor_free(sn_robot *rb) {
  for (struct WbNodeStructPrivate *n = rb->nodes, *next; n != NULL; n = next) {
    next = n->next;
    free(n);
  }
  for (struct WbFieldStructPrivate *f = rb->fields, *next; f != NULL; f = next) {
    next = f->next;
    free(f);
  }
  rb->nodes = rb->fields = NULL;
}

static sn_robot *supervisor(const char *func) {
  sn_robot *rb = sn_robot_get(func);
  if (!rb->supervisor) {
    fprintf(stderr,
            "Error: ignoring illegal call to %s() in a 'Robot' controller.\n"
            "Error: this function can only be used in a 'Supervisor' controller (set 'supervisor: true' on robot "
            "'%s' in the world file).\n",
            func, rb->name);
    return NULL;
  }
  return rb;
}

void sn_supervisor_unsupported(const char *func, bool *warned) {
  if (supervisor(func) == NULL || *warned)
    return;
  *warned = true;
  fprintf(stderr,
          "Error: %s(): not served by Sensorium (its Supervisor finds robots and solids by DEF, reads and sets their "
          "translation and rotation, reads poses, resets and sets the run mode): ignored, Webots' \"no value\" "
          "returned.\n",
          func);
}

static WbNodeRef node_ref(sn_robot *rb, int64_t id) {
  if (id <= 0)
    return NULL;
  for (struct WbNodeStructPrivate *n = rb->nodes; n != NULL; n = n->next)
    if (n->id == id)
      return n;
  struct WbNodeStructPrivate *n = calloc(1, sizeof *n);
  if (n == NULL)
    return NULL;
  n->id = id;
  n->next = rb->nodes;
  rb->nodes = n;
  return n;
}

static void args_name(sn_req *r, const void *arg) {
  sn_req_key(r, "name");
  sn_req_str(r, (const char *)arg);
}

static WbNodeRef node_from_reply(sn_robot *rb, sn_reply *rep) {
  WbNodeRef n = node_ref(rb, sn_int_or(rep->result, "node", 0));
  sn_reply_free(rep);
  return n;
}

WbNodeRef wb_supervisor_node_get_from_def(const char *def) {
  const char *func = "wb_supervisor_node_get_from_def";
  sn_robot *rb = supervisor(func);
  if (rb == NULL)
    return NULL;
  if (def == NULL || *def == '\0') {
    fprintf(stderr, "Error: %s() called with a NULL or empty 'def' argument.\n", func);
    return NULL;
  }
  sn_reply rep;
  if (sn_robot_call(rb, "robot/get_from_def", 1, args_name, def, func, &rep) != 0)
    return NULL;
  return node_from_reply(rb, &rep);
}

WbNodeRef wb_supervisor_node_get_self(void) {
  const char *func = "wb_supervisor_node_get_self";
  sn_robot *rb = supervisor(func);
  sn_reply rep;
  if (rb == NULL || sn_robot_call(rb, "robot/get_self", 0, NULL, NULL, func, &rep) != 0)
    return NULL;
  return node_from_reply(rb, &rep);
}

static void args_node(sn_req *r, const void *arg) {
  sn_req_key(r, "node");
  msgpack_pack_int64(&r->pk, *(const int64_t *)arg);
}

static bool copy_numbers(const msgpack_object *list, double *out, uint32_t n) {
  if (list == NULL || list->type != MSGPACK_OBJECT_ARRAY || list->via.array.size != n)
    return false;
  for (uint32_t i = 0; i < n; i++)
    if (!sn_as_double(&list->via.array.ptr[i], &out[i]))
      return false;
  return true;
}

static const double *node_pose(WbNodeRef node, bool position, const char *func) {
  sn_robot *rb = supervisor(func);
  if (rb == NULL || node == NULL)
    return NULL;
  sn_reply rep;
  if (sn_robot_call(rb, "robot/get_node_pose", 1, args_node, &node->id, func, &rep) != 0)
    return NULL;
  bool ok = position ? copy_numbers(sn_get(rep.result, "position"), node->position, 3)
                     : copy_numbers(sn_get(rep.result, "orientation"), node->orientation, 9);
  sn_reply_free(&rep);
  if (!ok)
    fprintf(stderr, "Error: %s(): malformed reply\n", func);
  return ok ? (position ? node->position : node->orientation) : NULL;
}

const double *wb_supervisor_node_get_position(WbNodeRef node) {
  return node_pose(node, true, "wb_supervisor_node_get_position");
}

const double *wb_supervisor_node_get_orientation(WbNodeRef node) {
  return node_pose(node, false, "wb_supervisor_node_get_orientation");
}

WbFieldRef wb_supervisor_node_get_field(WbNodeRef node, const char *field_name) {
  const char *func = "wb_supervisor_node_get_field";
  sn_robot *rb = supervisor(func);
  if (rb == NULL || node == NULL)
    return NULL;
  WbFieldType type = WB_NO_FIELD;
  const char *name = NULL;
  if (field_name != NULL && strcmp(field_name, "translation") == 0)
    type = WB_SF_VEC3F, name = "translation";
  else if (field_name != NULL && strcmp(field_name, "rotation") == 0)
    type = WB_SF_ROTATION, name = "rotation";
  if (name == NULL) {
    fprintf(stderr, "Error: %s(): field '%s' is not supported by Sensorium (only 'translation' and 'rotation').\n",
            func, field_name ? field_name : "(null)");
    return NULL;
  }
  for (struct WbFieldStructPrivate *f = rb->fields; f != NULL; f = f->next)
    if (f->node == node->id && f->type == type)
      return f;
  struct WbFieldStructPrivate *f = calloc(1, sizeof *f);
  if (f == NULL)
    return NULL;
  f->node = node->id;
  f->type = type;
  f->name = name;
  f->next = rb->fields;
  rb->fields = f;
  return f;
}

WbFieldType wb_supervisor_field_get_type(WbFieldRef field) { return field ? field->type : WB_NO_FIELD; }

const char *wb_supervisor_field_get_name(WbFieldRef field) { return field ? field->name : ""; }

const char *wb_supervisor_field_get_type_name(WbFieldRef field) {
  if (field == NULL)
    return "";
  return field->type == WB_SF_VEC3F ? "SFVec3f" : "SFRotation";
}

int wb_supervisor_field_get_count(WbFieldRef field) {
  (void)field;
  return -1; /* Webots' count of a single (SF) field; Sensorium has no MF field */
}

int wb_supervisor_node_get_id(WbNodeRef node) {
  return node != NULL ? (int)node->id : -1;
}

void wb_supervisor_simulation_quit(int status) {
  const char *func = "wb_supervisor_simulation_quit";
  sn_robot *rb = supervisor(func);
  if (rb == NULL)
    return;
  /* The server serves other controllers and runs until it is stopped; for this controller the
     simulation ends as in Webots: its next steps return -1. */
  fprintf(stderr, "Warning: %s(%d): the server runs on until it is stopped; robot '%s' "
          "steps no more (wb_robot_step() returns -1).\n", func, status, rb->name);
  rb->terminated = true;
}

typedef struct {
  const struct WbFieldStructPrivate *field;
  const double *values;
  int n;
} field_args;

static void args_field(sn_req *r, const void *arg) {
  const field_args *a = arg;
  sn_req_key(r, "node");
  msgpack_pack_int64(&r->pk, a->field->node);
  sn_req_key(r, "field");
  sn_req_str(r, a->field->name);
  if (a->values != NULL) {
    sn_req_key(r, "value");
    msgpack_pack_array(&r->pk, (size_t)a->n);
    for (int i = 0; i < a->n; i++)
      msgpack_pack_double(&r->pk, a->values[i]);
  }
}

static const double *field_get(WbFieldRef field, WbFieldType type, const char *func) {
  sn_robot *rb = supervisor(func);
  if (rb == NULL || field == NULL)
    return NULL;
  if (field->type != type) {
    fprintf(stderr, "Error: %s() called with a field of the wrong type (%s).\n", func, field->name);
    return NULL;
  }
  field_args a = {field, NULL, 0};
  sn_reply rep;
  if (sn_robot_call(rb, "robot/get_field", 2, args_field, &a, func, &rep) != 0)
    return NULL;
  bool ok = copy_numbers(sn_get(rep.result, "value"), field->value, type == WB_SF_VEC3F ? 3 : 4);
  sn_reply_free(&rep);
  if (!ok)
    fprintf(stderr, "Error: %s(): malformed reply\n", func);
  return ok ? field->value : NULL;
}

static void field_set(WbFieldRef field, WbFieldType type, const double *values, const char *func) {
  sn_robot *rb = supervisor(func);
  if (rb == NULL || field == NULL)
    return;
  if (field->type != type) {
    fprintf(stderr, "Error: %s() called with a field of the wrong type (%s).\n", func, field->name);
    return;
  }
  if (values == NULL) {
    fprintf(stderr, "Error: %s() called with a NULL 'values' argument.\n", func);
    return;
  }
  field_args a = {field, values, type == WB_SF_VEC3F ? 3 : 4};
  sn_reply rep;
  if (sn_robot_call(rb, "robot/set_field", 3, args_field, &a, func, &rep) == 0)
    sn_reply_free(&rep);
}

const double *wb_supervisor_field_get_sf_vec3f(WbFieldRef field) {
  return field_get(field, WB_SF_VEC3F, "wb_supervisor_field_get_sf_vec3f");
}

void wb_supervisor_field_set_sf_vec3f(WbFieldRef field, const double values[3]) {
  field_set(field, WB_SF_VEC3F, values, "wb_supervisor_field_set_sf_vec3f");
}

const double *wb_supervisor_field_get_sf_rotation(WbFieldRef field) {
  return field_get(field, WB_SF_ROTATION, "wb_supervisor_field_get_sf_rotation");
}

void wb_supervisor_field_set_sf_rotation(WbFieldRef field, const double values[4]) {
  field_set(field, WB_SF_ROTATION, values, "wb_supervisor_field_set_sf_rotation");
}

void wb_supervisor_simulation_reset(void) {
  const char *func = "wb_supervisor_simulation_reset";
  sn_robot *rb = supervisor(func);
  sn_reply rep;
  if (rb == NULL || sn_robot_call(rb, "robot/simulation_reset", 0, NULL, NULL, func, &rep) != 0)
    return;
  sn_reply_free(&rep);
  for (int i = 0; i < rb->n_devices; i++) { /* the server reset the motors' commands and the LEDs */
    sn_device *d = &rb->devices[i];
    if (d->kind == SN_MOTOR) {
      d->target_position = 0.0;
      d->velocity = d->max_velocity;
      d->cmd_position = d->cmd_velocity = false;
    } else if (d->kind == SN_LED)
      d->led_value = 0;
  }
}

static void args_mode(sn_req *r, const void *arg) {
  sn_req_key(r, "mode");
  msgpack_pack_int(&r->pk, *(const int *)arg);
}

void wb_supervisor_simulation_set_mode(WbSimulationMode mode) {
  const char *func = "wb_supervisor_simulation_set_mode";
  sn_robot *rb = supervisor(func);
  if (rb == NULL)
    return;
  int m = (int)mode;
  if (m < 0 || m > 2) {
    fprintf(stderr, "Error: %s() called with an invalid mode %d.\n", func, m);
    return;
  }
  sn_reply rep;
  if (sn_robot_call(rb, "robot/simulation_set_mode", 1, args_mode, &m, func, &rep) == 0)
    sn_reply_free(&rep);
}

WbSimulationMode wb_supervisor_simulation_get_mode(void) {
  const char *func = "wb_supervisor_simulation_get_mode";
  sn_robot *rb = supervisor(func);
  sn_reply rep;
  if (rb == NULL || sn_robot_call(rb, "robot/simulation_get_mode", 0, NULL, NULL, func, &rep) != 0)
    return WB_SUPERVISOR_SIMULATION_MODE_FAST;
  int64_t v = sn_int_or(rep.result, "value", 2);
  sn_reply_free(&rep);
  return (WbSimulationMode)v;
}

/* ------------------------------------------------------------------ contact points */
/* No physics here: a node never touches anything, so every query answers "none". The supervisor check
 * still applies, as for every wb_supervisor_* function. */
const double *wb_supervisor_node_get_contact_point(WbNodeRef node, int index) {
  (void)node;
  (void)index;
  supervisor("wb_supervisor_node_get_contact_point");
  return sn_no_values();
}

WbNodeRef wb_supervisor_node_get_contact_point_node(WbNodeRef node, int index) {
  (void)node;
  (void)index;
  supervisor("wb_supervisor_node_get_contact_point_node");
  return NULL;
}

int wb_supervisor_node_get_number_of_contact_points(WbNodeRef node, bool include_descendants) {
  (void)node;
  (void)include_descendants;
  supervisor("wb_supervisor_node_get_number_of_contact_points");
  return 0;
}

WbContactPoint *wb_supervisor_node_get_contact_points(WbNodeRef node, bool include_descendants, int *size) {
  (void)node;
  (void)include_descendants;
  if (size != NULL)
    *size = 0;
  supervisor("wb_supervisor_node_get_contact_points");
  return NULL;
}

void wb_supervisor_node_enable_contact_points_tracking(WbNodeRef node, int sampling_period, bool include_descendants) {
  (void)node;
  (void)sampling_period;
  (void)include_descendants;
  supervisor("wb_supervisor_node_enable_contact_points_tracking");
}

void wb_supervisor_node_disable_contact_points_tracking(WbNodeRef node) {
  (void)node;
  supervisor("wb_supervisor_node_disable_contact_points_tracking");
}

void wb_supervisor_node_enable_contact_point_tracking(WbNodeRef node, int sampling_period, bool include_descendants) {
  (void)node;
  (void)sampling_period;
  (void)include_descendants;
  supervisor("wb_supervisor_node_enable_contact_point_tracking");
}

void wb_supervisor_node_disable_contact_point_tracking(WbNodeRef node, bool include_descendants) {
  (void)node;
  (void)include_descendants;
  supervisor("wb_supervisor_node_disable_contact_point_tracking");
}
