/* Sensorium C controller library: the Supervisor (PROTOCOL.md, supervisor services). A WbNodeRef /
 * WbFieldRef points to a small record kept until wb_robot_cleanup(); one record per node id and per
 * (node, field name), so the arrays and strings they hold stay valid between calls (until the next
 * call on the same node or field, as in Webots). Nodes are the root (id 0), robots, top-level solids
 * and top-level lights, and the nodes inside robots and solids (Solids, devices, Poses, Groups, joints);
 * a reply whose type is "" is Webots' NULL. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/nodes.h>
#include <webots/supervisor.h>

#include "internal.h"

struct WbNodeStructPrivate {
  int64_t id;
  WbNodeType type;
  char type_name[64]; /* "Group", "Robot", "Solid", a light's, or a top-level node's not simulated ("WorldInfo") */
  char *def_name;     /* "" without one */
  char *proto;        /* a PROTO instance's PROTO name (wb_supervisor_node_get_type_name), "" for a base node */
  int64_t parent;     /* 0 for a top-level node, the holding node's id for a nested one, -1 for the root */
  double position[3];
  double orientation[9];
  double velocity[6];
  double center_of_mass[3];
  double pose[16];
  WbContactPoint *contact_points[2]; /* its contact points without, with its descendants: the library's */
  int n_contact_points[2];
  int64_t contact_time[2]; /* the simulated time (ms) they were asked at */
  bool contact_known[2];
  bool contact_descendants; /* include_descendants of its last get_number_of_contact_points */
  struct WbNodeStructPrivate *next;
};

struct WbFieldStructPrivate {
  int64_t node;
  WbFieldType type;
  char *name;
  int level; /* -1 the node's field (a PROTO instance's: its PROTO's), 0 its base node's, k its k-th PROTO's */
  double value[4]; /* an SF vector's or an MFColor item's last value */
  char *string; /* an SFString's last value */
  struct WbFieldStructPrivate *next;
};

/* Webots' WbProtoRef: the k-th PROTO (level) of a PROTO instance's chain, 1 its own PROTO */
struct WbProtoInfoStructPrivate {
  int64_t node;
  int level;
  char *type_name;
  bool derived;
  int n_fields;
  char **fields; /* its interface fields' names, in declaration order */
  struct WbProtoInfoStructPrivate *next;
};

static void proto_free(struct WbProtoInfoStructPrivate *p) {
  for (int i = 0; i < p->n_fields; i++)
    free(p->fields[i]);
  free(p->fields);
  free(p->type_name);
  free(p);
}

void sn_supervisor_free(sn_robot *rb) {
  for (struct WbNodeStructPrivate *n = rb->nodes, *next; n != NULL; n = next) {
    next = n->next;
    free(n->def_name);
    free(n->proto);
    free(n->contact_points[0]);
    free(n->contact_points[1]);
    free(n);
  }
  for (struct WbFieldStructPrivate *f = rb->fields, *next; f != NULL; f = next) {
    next = f->next;
    free(f->name);
    free(f->string);
    free(f);
  }
  for (struct WbProtoInfoStructPrivate *p = rb->protos, *next; p != NULL; p = next) {
    next = p->next;
    proto_free(p);
  }
  rb->nodes = rb->fields = rb->protos = NULL;
}

sn_robot *sn_supervisor(const char *func) {
  sn_robot *rb = sn_robot_get(func);
  if (!rb->supervisor) {
    fprintf(stderr,
            "Error: ignoring illegal call to %s() in a 'Robot' controller.\n"
            "Error: this function can only be used in a 'Supervisor' controller (set 'supervisor: true' on robot "
            "'%s' in the world file).\n",
            func, sn_shown(rb->name));
    return NULL;
  }
  return rb;
}

/* the supervisor's robot when node is a node; Webots' line for a NULL one */
static sn_robot *supervisor_node(WbNodeRef node, const char *func) {
  sn_robot *rb = sn_supervisor(func);
  if (rb != NULL && node == NULL) {
    fprintf(stderr, "Error: %s() called with a NULL or invalid 'node' argument.\n", func);
    return NULL;
  }
  return rb;
}

void sn_supervisor_unsupported(const char *func, bool *warned) {
  if (sn_supervisor(func) == NULL || *warned)
    return;
  *warned = true;
  fprintf(stderr,
          "Error: %s(): not served by Sensorium (its Supervisor walks the root's children, reads nodes' identity, "
          "poses, velocities and fields (translation, rotation, name, lights' fields, ...), sets poses and lights, "
          "resets and sets the run mode): ignored, Webots' \"no value\" returned.\n",
          func);
}

static WbNodeRef node_ref(sn_robot *rb, int64_t id) {
  if (id < 0)
    return NULL;
  for (struct WbNodeStructPrivate *n = rb->nodes; n != NULL; n = n->next)
    if (n->id == id)
      return n;
  struct WbNodeStructPrivate *n = calloc(1, sizeof *n);
  if (n == NULL)
    return NULL;
  n->id = id;
  n->parent = -1;
  n->next = rb->nodes;
  rb->nodes = n;
  return n;
}

static const struct {
  const char *name;
  WbNodeType type;
} NODE_TYPES[] = {{"Group", WB_NODE_GROUP},
                  {"Robot", WB_NODE_ROBOT},
                  {"Solid", WB_NODE_SOLID},
                  {"PointLight", WB_NODE_POINT_LIGHT},
                  {"SpotLight", WB_NODE_SPOT_LIGHT},
                  {"DirectionalLight", WB_NODE_DIRECTIONAL_LIGHT},
                  /* top-level nodes Sensorium lists but does not simulate; any other type name: NO_NODE */
                  {"WorldInfo", WB_NODE_WORLD_INFO},
                  {"Viewpoint", WB_NODE_VIEWPOINT},
                  {"Background", WB_NODE_BACKGROUND},
                  {"Fog", WB_NODE_FOG},
                  {"Transform", WB_NODE_TRANSFORM},
                  {"Pose", WB_NODE_POSE},
                  {"Shape", WB_NODE_SHAPE},
                  /* a shape's nodes */
                  {"Appearance", WB_NODE_APPEARANCE},
                  {"PBRAppearance", WB_NODE_PBR_APPEARANCE},
                  {"Material", WB_NODE_MATERIAL},
                  {"ImageTexture", WB_NODE_IMAGE_TEXTURE},
                  {"Box", WB_NODE_BOX},
                  {"Sphere", WB_NODE_SPHERE},
                  {"Cylinder", WB_NODE_CYLINDER},
                  {"Capsule", WB_NODE_CAPSULE},
                  {"Cone", WB_NODE_CONE},
                  {"Plane", WB_NODE_PLANE},
                  {"Mesh", WB_NODE_MESH},
                  {"IndexedFaceSet", WB_NODE_INDEXED_FACE_SET},
                  {"ElevationGrid", WB_NODE_ELEVATION_GRID},
                  /* nodes inside a robot that are no devices (a device's type: sn_node_type_of) */
                  {"HingeJoint", WB_NODE_HINGE_JOINT},
                  {"Hinge2Joint", WB_NODE_HINGE_2_JOINT},
                  {"SliderJoint", WB_NODE_SLIDER_JOINT},
                  {"BallJoint", WB_NODE_BALL_JOINT},
                  {"Slot", WB_NODE_SLOT}};

static bool str_is(const msgpack_object *o, const char *s) {
  return o != NULL && o->type == MSGPACK_OBJECT_STR && o->via.str.size == strlen(s) &&
         memcmp(o->via.str.ptr, s, o->via.str.size) == 0;
}

/* A node reply (PROTOCOL.md): the node's record, its identity refreshed; NULL for type "". A type
   name outside NODE_TYPES (a top-level node not simulated) keeps its name, its type is NO_NODE. */
static WbNodeRef node_from_reply(sn_robot *rb, sn_reply *rep) {
  const msgpack_object *type = sn_get(rep->result, "type");
  WbNodeRef n = NULL;
  if (type != NULL && type->type == MSGPACK_OBJECT_STR && type->via.str.size > 0 &&
      (n = node_ref(rb, sn_int_or(rep->result, "node", -1))) != NULL) {
    n->type = WB_NODE_NO_NODE;
    snprintf(n->type_name, sizeof n->type_name, "%.*s", (int)type->via.str.size, type->via.str.ptr);
    for (size_t i = 0; i < sizeof NODE_TYPES / sizeof NODE_TYPES[0]; i++)
      if (str_is(type, NODE_TYPES[i].name))
        n->type = NODE_TYPES[i].type;
    if (n->type == WB_NODE_NO_NODE)
      n->type = sn_node_type_of(n->type_name); /* a device inside a robot (Camera, RotationalMotor, ...) */
    char *def = sn_strdup_obj(sn_get(rep->result, "def_name"));
    if (def != NULL && n->def_name != NULL && strcmp(def, n->def_name) == 0)
      free(def); /* unchanged: the string a caller holds stays valid (the readers ask again each time) */
    else {
      free(n->def_name);
      n->def_name = def;
    }
    const msgpack_object *proto_obj = sn_get(rep->result, "proto");
    char *proto = proto_obj != NULL && proto_obj->type == MSGPACK_OBJECT_STR ? sn_strdup_obj(proto_obj) : NULL;
    if (proto != NULL && n->proto != NULL && strcmp(proto, n->proto) == 0)
      free(proto); /* unchanged, as the DEF */
    else {
      free(n->proto);
      n->proto = proto;
    }
    n->parent = sn_int_or(rep->result, "parent", -1);
  }
  sn_reply_free(rep);
  return n;
}

static void args_name(sn_req *r, const void *arg) {
  sn_req_key(r, "name");
  sn_req_str(r, (const char *)arg);
}

WbNodeRef wb_supervisor_node_get_from_def(const char *def) {
  const char *func = "wb_supervisor_node_get_from_def";
  sn_robot *rb = sn_supervisor(func);
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

static WbNodeRef node_without_args(const char *item, const char *func) {
  sn_robot *rb = sn_supervisor(func);
  sn_reply rep;
  if (rb == NULL || sn_robot_call(rb, item, 0, NULL, NULL, func, &rep) != 0)
    return NULL;
  return node_from_reply(rb, &rep);
}

static void args_device(sn_req *r, const void *arg) {
  sn_req_key(r, "device");
  sn_req_str(r, (const char *)arg);
}

/* the node of one of this robot's devices (its parent, pose and fields as any node inside the robot) */
WbNodeRef wb_supervisor_node_get_from_device(WbDeviceTag tag) {
  const char *func = "wb_supervisor_node_get_from_device";
  sn_robot *rb = sn_supervisor(func);
  if (rb == NULL)
    return NULL;
  sn_device *d = sn_device_get(tag, SN_OTHER, func);
  sn_reply rep;
  if (d == NULL || sn_robot_call(rb, "robot/get_from_device", 1, args_device, d->name, func, &rep) != 0)
    return NULL;
  return node_from_reply(rb, &rep);
}

WbNodeRef wb_supervisor_node_get_self(void) {
  return node_without_args("robot/get_self", "wb_supervisor_node_get_self");
}

WbNodeRef wb_supervisor_node_get_root(void) {
  return node_without_args("robot/get_root", "wb_supervisor_node_get_root");
}

static void args_id(sn_req *r, const void *arg) {
  sn_req_key(r, "id");
  msgpack_pack_int64(&r->pk, *(const int64_t *)arg);
}

static WbNodeRef node_from_id(int64_t id, const char *func) {
  sn_robot *rb = sn_supervisor(func);
  if (rb == NULL)
    return NULL;
  if (id < 0) {
    fprintf(stderr, "Error: %s() called with a negative 'id' argument.\n", func);
    return NULL;
  }
  sn_reply rep;
  if (sn_robot_call(rb, "robot/get_from_id", 1, args_id, &id, func, &rep) != 0)
    return NULL;
  return node_from_reply(rb, &rep);
}

WbNodeRef wb_supervisor_node_get_from_id(int id) {
  return node_from_id(id, "wb_supervisor_node_get_from_id");
}

/* The node with its identity (type, DEF, parent) asked again of the server, for the functions that
   read it: a node the server no longer has (removed by wb_supervisor_node_remove, here or by another
   supervisor) gets Webots' line and NULL, as libController answers for a reference it dropped; its
   record forgets the type it had. */
static WbNodeRef live_node(WbNodeRef node, const char *func) {
  sn_robot *rb = supervisor_node(node, func);
  sn_reply rep;
  if (rb == NULL || sn_robot_call(rb, "robot/get_from_id", 1, args_id, &node->id, func, &rep) != 0)
    return NULL;
  if (node_from_reply(rb, &rep) == NULL) {
    node->type = WB_NODE_NO_NODE;
    node->type_name[0] = '\0';
    fprintf(stderr, "Error: %s() called with a NULL or invalid 'node' argument.\n", func);
    return NULL;
  }
  return node;
}

WbNodeRef wb_supervisor_node_get_parent_node(WbNodeRef node) {
  const char *func = "wb_supervisor_node_get_parent_node";
  if (live_node(node, func) == NULL || node->parent < 0)
    return NULL; /* the root has no parent */
  return node_from_id(node->parent, func);
}

int wb_supervisor_node_get_id(WbNodeRef node) {
  return live_node(node, "wb_supervisor_node_get_id") != NULL ? (int)node->id : -1;
}

WbNodeType wb_supervisor_node_get_type(WbNodeRef node) {
  return live_node(node, "wb_supervisor_node_get_type") != NULL ? node->type : WB_NODE_NO_NODE;
}

/* a PROTO instance's PROTO name ("MiniPuck"), else the node's type ("Solid") */
const char *wb_supervisor_node_get_type_name(WbNodeRef node) {
  if (live_node(node, "wb_supervisor_node_get_type_name") == NULL)
    return "";
  return node->proto != NULL && *node->proto != '\0' ? node->proto : node->type_name;
}

/* the base node type (Robot, Solid, PointLight, Background, ...), a PROTO instance's too */
const char *wb_supervisor_node_get_base_type_name(WbNodeRef node) {
  return live_node(node, "wb_supervisor_node_get_base_type_name") != NULL ? node->type_name : "";
}

bool wb_supervisor_node_is_proto(WbNodeRef node) {
  return live_node(node, "wb_supervisor_node_is_proto") != NULL && node->proto != NULL && *node->proto != '\0';
}

const char *wb_supervisor_node_get_def(WbNodeRef node) {
  if (live_node(node, "wb_supervisor_node_get_def") == NULL)
    return "";
  return node->def_name != NULL ? node->def_name : "";
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

/* Webots never answers NULL here: a NULL, removed or refused node (or a Robot controller) gets its
   line and NaNs */
static const double *node_pose(WbNodeRef node, bool position, const char *func) {
  sn_robot *rb = supervisor_node(node, func);
  sn_reply rep;
  if (rb == NULL || sn_robot_call(rb, "robot/get_node_pose", 1, args_node, &node->id, func, &rep) != 0)
    return sn_no_values();
  bool ok = position ? copy_numbers(sn_get(rep.result, "position"), node->position, 3)
                     : copy_numbers(sn_get(rep.result, "orientation"), node->orientation, 9);
  sn_reply_free(&rep);
  if (!ok)
    fprintf(stderr, "Error: %s(): malformed reply\n", func);
  return ok ? (position ? node->position : node->orientation) : sn_no_values();
}

const double *wb_supervisor_node_get_position(WbNodeRef node) {
  return node_pose(node, true, "wb_supervisor_node_get_position");
}

const double *wb_supervisor_node_get_orientation(WbNodeRef node) {
  return node_pose(node, false, "wb_supervisor_node_get_orientation");
}

/* node's 4x4 row-major world transform into m: 1 when it has one, 0 when it has none (the root, a
   light: NaN position), -1 after the error line (a NULL, removed or refused node) */
static int world_pose(WbNodeRef node, const char *func, double m[16]) {
  sn_robot *rb = supervisor_node(node, func);
  sn_reply rep;
  if (rb == NULL || sn_robot_call(rb, "robot/get_node_pose", 1, args_node, &node->id, func, &rep) != 0)
    return -1;
  double t[3], r[9];
  bool ok = copy_numbers(sn_get(rep.result, "position"), t, 3) && copy_numbers(sn_get(rep.result, "orientation"), r, 9);
  sn_reply_free(&rep);
  if (!ok) {
    fprintf(stderr, "Error: %s(): malformed reply\n", func);
    return -1;
  }
  for (int i = 0; i < 3; i++) {
    if (isnan(t[i]))
      return 0;
    for (int j = 0; j < 3; j++)
      m[4 * i + j] = r[3 * i + j];
    m[4 * i + 3] = t[i];
  }
  m[12] = m[13] = m[14] = 0.0;
  m[15] = 1.0;
  return 1;
}

/* Webots' 4x4 row-major transform of node in from_node's frame: the world's for NULL and, as Webots'
   server answers a "from" node that is no Pose, for the root or a light; NaN for a node with no pose
   (as its position), Webots' line and NaN for a NULL, invalid or removed node */
const double *wb_supervisor_node_get_pose(WbNodeRef node, WbNodeRef from_node) {
  const char *func = "wb_supervisor_node_get_pose";
  double base[16], m[16];
  int has_base = 0;
  if (from_node != NULL && (has_base = world_pose(from_node, func, base)) < 0)
    return sn_no_values();
  if (world_pose(node, func, m) != 1)
    return sn_no_values();
  if (has_base != 1) {
    memcpy(node->pose, m, sizeof m);
    return node->pose;
  }
  /* inverse(base) . m: the rotation Rb^T R, the translation Rb^T (t - tb) */
  for (int i = 0; i < 3; i++) {
    for (int j = 0; j < 3; j++) {
      double v = 0.0;
      for (int k = 0; k < 3; k++)
        v += base[4 * k + i] * m[4 * k + j];
      node->pose[4 * i + j] = v;
    }
    double v = 0.0;
    for (int k = 0; k < 3; k++)
      v += base[4 * k + i] * (m[4 * k + 3] - base[4 * k + 3]);
    node->pose[4 * i + 3] = v;
  }
  node->pose[12] = node->pose[13] = node->pose[14] = 0.0;
  node->pose[15] = 1.0;
  return node->pose;
}

/* Webots streams a tracked pose every sampling period; wb_supervisor_node_get_pose asks the server
   at each call here, so tracking changes nothing: accepted after Webots' checks */
void wb_supervisor_node_enable_pose_tracking(WbNodeRef node, int sampling_period, WbNodeRef from_node) {
  const char *func = "wb_supervisor_node_enable_pose_tracking";
  (void)from_node;
  if (sampling_period < 0) {
    fprintf(stderr, "Error: %s() called with negative sampling period.\n", func);
    return;
  }
  supervisor_node(node, func);
}

void wb_supervisor_node_disable_pose_tracking(WbNodeRef node, WbNodeRef from_node) {
  (void)from_node;
  supervisor_node(node, "wb_supervisor_node_disable_pose_tracking");
}

/* linear (m/s) then angular (rad/s) velocity in world axes: a driven robot's last step, zeros for
   anything else; Webots' NaNs for a NULL node */
const double *wb_supervisor_node_get_velocity(WbNodeRef node) {
  const char *func = "wb_supervisor_node_get_velocity";
  sn_robot *rb = supervisor_node(node, func);
  sn_reply rep;
  if (rb == NULL || sn_robot_call(rb, "robot/get_node_velocity", 1, args_node, &node->id, func, &rep) != 0)
    return sn_no_values();
  bool ok = copy_numbers(sn_get(rep.result, "value"), node->velocity, 6);
  sn_reply_free(&rep);
  if (!ok)
    fprintf(stderr, "Error: %s(): malformed reply\n", func);
  return ok ? node->velocity : sn_no_values();
}

/* the centre of mass in world coordinates of a robot, solid or device with the Solids inside it that
   have a Physics node, where they are now; 0 0 0 without Physics, NaNs for a node that is no Solid */
const double *wb_supervisor_node_get_center_of_mass(WbNodeRef node) {
  const char *func = "wb_supervisor_node_get_center_of_mass";
  sn_robot *rb = supervisor_node(node, func);
  sn_reply rep;
  if (rb == NULL || sn_robot_call(rb, "robot/get_node_center_of_mass", 1, args_node, &node->id, func, &rep) != 0)
    return sn_no_values();
  bool ok = copy_numbers(sn_get(rep.result, "value"), node->center_of_mass, 3);
  sn_reply_free(&rep);
  if (!ok)
    fprintf(stderr, "Error: %s(): malformed reply\n", func);
  return ok ? node->center_of_mass : sn_no_values();
}

/* whether a top-level solid's or robot's centre of mass, seen from above, is over the support polygon of
   where its bounding shapes touch the ground now; false without physics or touching nothing, and after
   the server's line for a node that is no top-level Solid (Webots) */
bool wb_supervisor_node_get_static_balance(WbNodeRef node) {
  const char *func = "wb_supervisor_node_get_static_balance";
  sn_robot *rb = supervisor_node(node, func);
  sn_reply rep;
  if (rb == NULL || sn_robot_call(rb, "robot/get_node_static_balance", 1, args_node, &node->id, func, &rep) != 0)
    return false;
  const msgpack_object *value = sn_get(rep.result, "value");
  bool ok = value != NULL && value->type == MSGPACK_OBJECT_BOOLEAN;
  bool balanced = ok && value->via.boolean;
  sn_reply_free(&rep);
  if (!ok)
    fprintf(stderr, "Error: %s(): malformed reply\n", func);
  return balanced;
}

/* Webots' node.remove() for a top-level solid or light: no sensor sees it from the next step and its
   id answers NULL from then on (never reused); the root and robots are refused with the server's one
   line (a departure from Webots, which removes robots too). The node's record stays until cleanup. */
void wb_supervisor_node_remove(WbNodeRef node) {
  const char *func = "wb_supervisor_node_remove";
  sn_robot *rb = supervisor_node(node, func);
  sn_reply rep;
  if (rb == NULL || sn_robot_call(rb, "robot/remove_node", 1, args_node, &node->id, func, &rep) != 0)
    return;
  sn_reply_free(&rep);
}

/* Webots' exportString: a node as .wbt text, as its world file or node string wrote it with the fields
   the server keeps as they are now. As libController, the library owns the string: it stays valid until
   the next call (which frees it); "" after the server's line (a node a PROTO's body made, a YAML world's
   node: no such text here). */
const char *wb_supervisor_node_export_string(WbNodeRef node) {
  static char *text;
  const char *func = "wb_supervisor_node_export_string";
  free(text);
  text = NULL;
  sn_robot *rb = supervisor_node(node, func);
  sn_reply rep;
  if (rb == NULL || sn_robot_call(rb, "robot/node_export_string", 1, args_node, &node->id, func, &rep) != 0)
    return "";
  text = sn_strdup_obj(sn_get(rep.result, "value"));
  sn_reply_free(&rep);
  return text != NULL ? text : "";
}

/* Webots' restartController and worldReload, served under `sensorium run` (which starts the
   controllers); under `sensorium serve` the server refuses them and one error line is printed. */
void wb_supervisor_node_restart_controller(WbNodeRef node) {
  const char *func = "wb_supervisor_node_restart_controller";
  sn_robot *rb = supervisor_node(node, func);
  sn_reply rep;
  if (rb == NULL || sn_robot_call(rb, "robot/restart_controller", 1, args_node, &node->id, func, &rep) != 0)
    return;
  sn_reply_free(&rep);
}

typedef struct {
  int64_t node, from;
  bool visible;
} visibility_args;

static void args_visibility(sn_req *r, const void *arg) {
  const visibility_args *a = arg;
  sn_req_key(r, "node");
  msgpack_pack_int64(&r->pk, a->node);
  sn_req_key(r, "from_node");
  msgpack_pack_int64(&r->pk, a->from);
  sn_req_key(r, "visible");
  sn_arg_bool(r, &a->visible);
}

/* Webots' setVisibility: `node` (and what is inside it) hidden from, or shown again to, one Camera, Lidar or
   RangeFinder (`from`, its node) or the Viewpoint; the other devices keep seeing it */
void wb_supervisor_node_set_visibility(WbNodeRef node, WbNodeRef from, bool visible) {
  const char *func = "wb_supervisor_node_set_visibility";
  if (live_node(node, func) == NULL)
    return;
  sn_robot *rb = sn_supervisor(func);
  sn_reply rep;
  if (from == NULL || sn_robot_call(rb, "robot/get_from_id", 1, args_id, &from->id, func, &rep) != 0 ||
      node_from_reply(rb, &rep) == NULL) {
    fprintf(stderr, "Error: %s() called with a NULL or invalid 'from' argument.\n", func);
    return;
  }
  const char *t = from->type_name;
  if (strcmp(t, "Camera") != 0 && strcmp(t, "Lidar") != 0 && strcmp(t, "RangeFinder") != 0 && strcmp(t, "Viewpoint") != 0) {
    fprintf(stderr, "Error: %s() called with a 'from' argument which is not the viewpoint or a camera, lidar or "
                    "range-finder device.\n", func);
    return;
  }
  visibility_args a = {node->id, from->id, visible};
  if (sn_robot_call(rb, "robot/set_visibility", 3, args_visibility, &a, func, &rep) == 0)
    sn_reply_free(&rep);
}

void wb_supervisor_world_reload(void) {
  const char *func = "wb_supervisor_world_reload";
  sn_robot *rb = sn_supervisor(func);
  sn_reply rep;
  if (rb == NULL || sn_robot_call(rb, "robot/world_reload", 0, NULL, NULL, func, &rep) != 0)
    return;
  sn_reply_free(&rep);
}

/* Webots' deprecated simulation_revert is its worldReload (the C++ simulationRevert() calls that too) */
void wb_supervisor_simulation_revert(void) {
  if (sn_supervisor("wb_supervisor_simulation_revert") != NULL)
    wb_supervisor_world_reload();
}

static void args_filename(sn_req *r, const void *arg) {
  sn_req_key(r, "filename");
  sn_req_str(r, (const char *)arg);
}

/* Webots' worldLoad, served under `sensorium run`: the simulation ends (every step -1) and run loads
   filename (relative to the controller's folder, as in Webots) and starts its controllers; a name that
   gives no world is one line of run's and the run ends (exit 1). */
void wb_supervisor_world_load(const char *filename) {
  const char *func = "wb_supervisor_world_load";
  sn_robot *rb = sn_supervisor(func);
  if (rb == NULL)
    return;
  if (filename == NULL || filename[0] == '\0') {
    fprintf(stderr, "Error: %s() called with NULL or empty 'filename' argument.\n", func);
    return;
  }
  sn_reply rep;
  if (sn_robot_call(rb, "robot/world_load", 1, args_filename, filename, func, &rep) != 0)
    return;
  sn_reply_free(&rep);
}

void wb_supervisor_load_world(const char *filename) {
  wb_supervisor_world_load(filename);
}

/* Webots' worldSave: the world as it is now written to filename (a .wbt file, relative to the
   controller's folder) through a temporary file beside it renamed onto it. Without a filename Webots
   overwrites the world file it loaded: here one line and false (a headless server never overwrites its
   world file). */
static bool ends_with(const char *s, const char *suffix);

bool wb_supervisor_world_save(const char *filename) {
  const char *func = "wb_supervisor_world_save";
  sn_robot *rb = sn_supervisor(func);
  if (rb == NULL)
    return false;
  if (filename == NULL || filename[0] == '\0') {
    fprintf(stderr, "Error: %s(): the world file is not overwritten here: name the file to write (a departure from "
                    "Webots, which overwrites the world file it loaded).\n", func);
    return false;
  }
  if (!ends_with(filename, ".wbt")) {
    fprintf(stderr, "Error: the target file given to %s() should have the '.wbt' extension.\n", func);
    return false;
  }
  sn_reply rep;
  if (sn_robot_call(rb, "robot/world_save", 0, NULL, NULL, func, &rep) != 0)
    return false;
  const msgpack_object *text = sn_get(rep.result, "value");
  size_t n = strlen(filename) + 8;
  char *tmp = malloc(n);
  bool ok = text != NULL && text->type == MSGPACK_OBJECT_STR && tmp != NULL;
  if (ok) {
    snprintf(tmp, n, "%s.tmp", filename);
    FILE *out = fopen(tmp, "wb");
    ok = out != NULL && fwrite(text->via.str.ptr, 1, text->via.str.size, out) == text->via.str.size;
    if (out != NULL && fclose(out) != 0)
      ok = false;
    if (ok && rename(tmp, filename) != 0)
      ok = false;
    if (!ok) {
      fprintf(stderr, "Error: %s(): cannot write '%s': %s.\n", func, sn_shown(filename), strerror(errno));
      remove(tmp);
    }
  }
  free(tmp);
  sn_reply_free(&rep);
  return ok;
}

bool wb_supervisor_save_world(const char *filename) {
  return wb_supervisor_world_save(filename);
}

typedef struct {
  int64_t node;
  double position;
  int64_t index;
} joint_args;

static void args_joint(sn_req *r, const void *arg) {
  const joint_args *a = arg;
  sn_req_key(r, "node");
  msgpack_pack_int64(&r->pk, a->node);
  sn_req_key(r, "position");
  msgpack_pack_double(&r->pk, a->position);
  sn_req_key(r, "index");
  msgpack_pack_int64(&r->pk, a->index);
}

/* Webots' setJointPosition: the joint's axis index at position at once (what rides on it with it), the
   axis's motor targeting it; Webots' checks of the index and node type first (libController's lines),
   then the server's (a joint without a motor on that axis does not move here: its one line). */
void wb_supervisor_node_set_joint_position(WbNodeRef node, double position, int index) {
  const char *func = "wb_supervisor_node_set_joint_position";
  sn_robot *rb = supervisor_node(node, func);
  if (rb == NULL)
    return;
  if (index < 1) {
    fprintf(stderr, "Error: %s() called with an invalid 'index'. Only values greater than or equal to 1 are supported.\n",
            func);
    return;
  }
  int axes = node->type == WB_NODE_HINGE_JOINT || node->type == WB_NODE_SLIDER_JOINT ? 1
             : node->type == WB_NODE_HINGE_2_JOINT                                  ? 2
             : node->type == WB_NODE_BALL_JOINT                                     ? 3
                                                                                    : 0;
  static const char *const only[] = {"", "SliderJoint and HingeJoint only support index 1",
                                     "Hinge2Joint only supports index 1 or 2", "BallJoint only supports index 1, 2, or 3"};
  if (axes == 0) {
    fprintf(stderr, "Error: %s() called with a 'node' argument which is not a joint node.\n", func);
    return;
  }
  if (index > axes) {
    fprintf(stderr, "Error: %s() called with an invalid 'index'. %s.\n", func, only[axes]);
    return;
  }
  if (!isfinite(position)) {
    fprintf(stderr, "Error: %s() called with a 'position' that is not a finite number: %g.\n", func, position);
    return;
  }
  joint_args a = {node->id, position, index};
  sn_reply rep;
  if (sn_robot_call(rb, "robot/set_joint_position", 3, args_joint, &a, func, &rep) == 0)
    sn_reply_free(&rep);
}

#define MAX_STATE_NAME 1024 /* the longest state name the server keeps */

typedef struct {
  int64_t node;
  const char *state;
} state_args;

static void args_state(sn_req *r, const void *arg) {
  const state_args *a = arg;
  sn_req_key(r, "node");
  msgpack_pack_int64(&r->pk, a->node);
  sn_req_key(r, "state");
  sn_req_str(r, a->state);
}

static void node_state(WbNodeRef node, const char *state_name, const char *item, const char *func) {
  sn_robot *rb = supervisor_node(node, func);
  if (rb == NULL)
    return;
  if (state_name == NULL) {
    fprintf(stderr, "Error: %s() called with a NULL 'state_name' argument.\n", func);
    return;
  }
  size_t n = strlen(state_name);
  if (n > MAX_STATE_NAME) {
    fprintf(stderr, "Error: %s() called with a 'state_name' of %zu bytes: at most %d here.\n", func, n, MAX_STATE_NAME);
    return;
  }
  state_args a = {node->id, state_name};
  sn_reply rep;
  if (sn_robot_call(rb, item, 2, args_state, &a, func, &rep) == 0)
    sn_reply_free(&rep);
}

/* Webots' saveState: the node's state (a robot's pose and joints' positions, a top-level solid's pose,
   a nested node's joints) kept under state_name; at most 64 names per node (the server's line beyond). */
void wb_supervisor_node_save_state(WbNodeRef node, const char *state_name) {
  node_state(node, state_name, "robot/save_node_state", "wb_supervisor_node_save_state");
}

/* Webots' loadState: the state saved under state_name put back ("__init__": as the world loaded); an
   unknown name is refused with the server's one line, nothing changed. */
void wb_supervisor_node_load_state(WbNodeRef node, const char *state_name) {
  node_state(node, state_name, "robot/load_node_state", "wb_supervisor_node_load_state");
}

/* Webots' resetPhysics: the velocities of the node and the Solids under it zeroed. A top-level solid
   falling falls again from rest from where it is; a robot keeps its motors' commands. The root's (node
   0, simulationResetPhysics): every falling solid's. */
static void reset_physics(sn_robot *rb, int64_t node, const char *func) {
  sn_reply rep;
  if (rb != NULL && sn_robot_call(rb, "robot/reset_physics", 1, args_node, &node, func, &rep) == 0)
    sn_reply_free(&rep);
}

void wb_supervisor_node_reset_physics(WbNodeRef node) {
  const char *func = "wb_supervisor_node_reset_physics";
  sn_robot *rb = supervisor_node(node, func);
  if (rb != NULL)
    reset_physics(rb, node->id, func);
}

/* Webots' Solid and the nodes derived from it (its node chart): Robot, Charger, Track and the devices
   that are Solids; not Pose, Group, Shape, joints, motors, position sensors, brakes, Propeller, Skin, ... */
static bool is_solid(WbNodeType type) {
  switch (type) {
    case WB_NODE_SOLID: case WB_NODE_ROBOT: case WB_NODE_CHARGER: case WB_NODE_TRACK:
    case WB_NODE_ACCELEROMETER: case WB_NODE_ALTIMETER: case WB_NODE_CAMERA: case WB_NODE_COMPASS:
    case WB_NODE_CONNECTOR: case WB_NODE_DISPLAY: case WB_NODE_DISTANCE_SENSOR: case WB_NODE_EMITTER:
    case WB_NODE_GPS: case WB_NODE_GYRO: case WB_NODE_INERTIAL_UNIT: case WB_NODE_LED: case WB_NODE_LIDAR:
    case WB_NODE_LIGHT_SENSOR: case WB_NODE_PEN: case WB_NODE_RADAR: case WB_NODE_RANGE_FINDER:
    case WB_NODE_RECEIVER: case WB_NODE_SPEAKER: case WB_NODE_TOUCH_SENSOR: case WB_NODE_VACUUM_GRIPPER:
    case WB_NODE_MICROPHONE: case WB_NODE_RADIO:
      return true;
    default:
      return false;
  }
}

/* Webots' setVelocity (linear then angular, world axes), after Webots' checks (NULL, NaN, infinite).
   Zero is served: it is resetPhysics here (the one velocity of its own a node can have is a top-level
   solid's fall, which starts again from rest; a robot keeps its motors' commands). Any other velocity has
   nothing to act on without a physics engine: one warning, ignored. */
void wb_supervisor_node_set_velocity(WbNodeRef node, const double velocity[6]) {
  static const char *func = "wb_supervisor_node_set_velocity";
  static bool warned;
  sn_robot *rb = supervisor_node(node, func);
  if (rb == NULL)
    return;
  if (velocity == NULL) {
    fprintf(stderr, "Error: %s() called with NULL argument.\n", func);
    return;
  }
  bool zero = true;
  for (int i = 0; i < 6; i++) {
    if (!isfinite(velocity[i])) {
      fprintf(stderr, "Error: %s() called with a NaN or infinite value.\n", func);
      return;
    }
    zero = zero && velocity[i] == 0.0;
  }
  /* a node that is no Solid (the root, whose resetPhysics would stop all, a Pose, a joint, ...): Webots
     warns and sets nothing, whatever the velocity; no request */
  if (node->id == 0 || (node->type != WB_NODE_NO_NODE && !is_solid(node->type))) {
    fprintf(stderr, "Warning: %s() can exclusively be used with a Solid.\n", func);
    return;
  }
  if (zero) {
    reset_physics(rb, node->id, func);
    return;
  }
  if (warned)
    return;
  warned = true;
  fprintf(stderr, "Warning: %s(): a velocity other than zero is ignored: Sensorium has no physics engine (robots move "
                  "by their wheels' commands, solids only fall straight down from rest).\n", func);
}

/* Webots' moveViewpoint: the Viewpoint backed off along its view direction until the node's bounding sphere
   fills the view (its orientation kept); at once here, where Webots animates it over about a second */
void wb_supervisor_node_move_viewpoint(WbNodeRef node) {
  const char *func = "wb_supervisor_node_move_viewpoint";
  sn_robot *rb = supervisor_node(node, func);
  sn_reply rep;
  int64_t id = rb != NULL ? node->id : 0;
  if (rb != NULL && sn_robot_call(rb, "robot/move_viewpoint", 1, args_node, &id, func, &rep) == 0)
    sn_reply_free(&rep);
}

void wb_supervisor_simulation_reset_physics(void) {
  const char *func = "wb_supervisor_simulation_reset_physics";
  reset_physics(sn_supervisor(func), 0, func);
}

void wb_supervisor_simulation_physics_reset(void) {
  const char *func = "wb_supervisor_simulation_physics_reset";
  reset_physics(sn_supervisor(func), 0, func);
}

/* ------------------------------------------------------------------ fields */
static const struct {
  const char *name;
  WbFieldType type;
} FIELD_TYPES[] = {{"SFBool", WB_SF_BOOL},     {"SFInt32", WB_SF_INT32},   {"SFFloat", WB_SF_FLOAT},
                   {"SFVec2f", WB_SF_VEC2F},     {"SFVec3f", WB_SF_VEC3F},   {"SFRotation", WB_SF_ROTATION},
                   {"SFColor", WB_SF_COLOR},     {"SFString", WB_SF_STRING}, {"SFNode", WB_SF_NODE},
                   {"MFBool", WB_MF_BOOL},       {"MFInt32", WB_MF_INT32},   {"MFFloat", WB_MF_FLOAT},
                   {"MFVec2f", WB_MF_VEC2F},     {"MFVec3f", WB_MF_VEC3F},   {"MFRotation", WB_MF_ROTATION},
                   {"MFColor", WB_MF_COLOR},     {"MFString", WB_MF_STRING}, {"MFNode", WB_MF_NODE}};

/* the longest string a set or an MFString item sends (the server's bound) */
#define SN_MAX_MF_STRING 4096

typedef struct {
  int64_t node;
  const char *name;
  int kind; /* 0: no value, 1: bool, 2: double, 3: numbers, 4: an int32, 5: a string */
  bool flag;
  double number;
  const double *values;
  int n;
  bool has_level; /* a PROTO level (FieldArgs.level) is sent */
  int level;
  int integer;
  const char *string;
} field_args;

static void args_field(sn_req *r, const void *arg) {
  const field_args *a = arg;
  sn_req_key(r, "node");
  msgpack_pack_int64(&r->pk, a->node);
  sn_req_key(r, "field");
  sn_req_str(r, a->name);
  if (a->has_level) {
    sn_req_key(r, "level");
    msgpack_pack_int(&r->pk, a->level);
  }
  if (a->kind == 0)
    return;
  sn_req_key(r, "value");
  if (a->kind == 1)
    sn_arg_bool(r, &a->flag);
  else if (a->kind == 2)
    msgpack_pack_double(&r->pk, a->number);
  else if (a->kind == 4)
    msgpack_pack_int(&r->pk, a->integer);
  else if (a->kind == 5)
    sn_req_str(r, a->string);
  else {
    msgpack_pack_array(&r->pk, (size_t)a->n);
    for (int i = 0; i < a->n; i++)
      msgpack_pack_double(&r->pk, a->values[i]);
  }
}

/* The field `field_name` of the node (level -1), of its base node (0) or of the k-th PROTO of its chain (k) */
static WbFieldRef field_at(WbNodeRef node, const char *field_name, int level, const char *func) {
  sn_robot *rb = supervisor_node(node, func);
  if (rb == NULL)
    return NULL;
  if (field_name == NULL || *field_name == '\0' || strlen(field_name) > 256) {
    fprintf(stderr, "Error: %s() called with a NULL, empty or invalid 'field_name' argument.\n", func);
    return NULL;
  }
  for (struct WbFieldStructPrivate *f = rb->fields; f != NULL; f = f->next)
    if (f->node == node->id && f->level == level && strcmp(f->name, field_name) == 0)
      return f;
  field_args a = {node->id, field_name, 0, false, 0.0, NULL, 0, level >= 0, level, 0, NULL};
  sn_reply rep;
  if (sn_robot_call(rb, "robot/get_field", 2 + (level >= 0), args_field, &a, func, &rep) != 0)
    return NULL;
  const msgpack_object *type = sn_get(rep.result, "type");
  WbFieldType t = WB_NO_FIELD;
  for (size_t i = 0; i < sizeof FIELD_TYPES / sizeof FIELD_TYPES[0]; i++)
    if (str_is(type, FIELD_TYPES[i].name))
      t = FIELD_TYPES[i].type;
  const msgpack_object *absent = sn_get(rep.result, "absent");   /* Webots' node has none either */
  const bool silent = absent != NULL && absent->type == MSGPACK_OBJECT_BOOLEAN && absent->via.boolean;
  sn_reply_free(&rep);
  if (t == WB_NO_FIELD && silent)
    return NULL;
  if (t == WB_NO_FIELD) {
    fprintf(stderr, "Error: %s(): node %d (%s) has no field '%s' in Sensorium (README \"Supervisor\" lists the fields "
                    "of each node kind).\n", func, (int)node->id, node->type_name, sn_shown(field_name));
    return NULL;
  }
  struct WbFieldStructPrivate *f = calloc(1, sizeof *f);
  char *name = malloc(strlen(field_name) + 1);
  if (f == NULL || name == NULL) {
    free(f);
    free(name);
    return NULL;
  }
  strcpy(name, field_name);
  f->node = node->id;
  f->type = t;
  f->name = name;
  f->level = level;
  f->next = rb->fields;
  rb->fields = f;
  return f;
}

/* a PROTO instance's: its PROTO's interface field, as Webots */
WbFieldRef wb_supervisor_node_get_field(WbNodeRef node, const char *field_name) {
  return field_at(node, field_name, -1, "wb_supervisor_node_get_field");
}

/* the base node's field (a PROTO instance's Robot, Solid, ...): read-only on a PROTO instance, as in Webots */
WbFieldRef wb_supervisor_node_get_base_node_field(WbNodeRef node, const char *field_name) {
  return field_at(node, field_name, 0, "wb_supervisor_node_get_base_node_field");
}

typedef struct {
  int64_t node;
  int level;
} proto_args;

static void args_proto(sn_req *r, const void *arg) {
  const proto_args *a = arg;
  sn_req_key(r, "node");
  msgpack_pack_int64(&r->pk, a->node);
  sn_req_key(r, "level");
  msgpack_pack_int(&r->pk, a->level);
}

/* PROTO `level` of the node's chain (kept until wb_robot_cleanup: a PROTO instance's interface never changes
   here); NULL when there is none (a base node, a level past the chain) */
static WbProtoRef proto_at(sn_robot *rb, int64_t node, int level, const char *func) {
  for (struct WbProtoInfoStructPrivate *p = rb->protos; p != NULL; p = p->next)
    if (p->node == node && p->level == level)
      return p;
  proto_args a = {node, level};
  sn_reply rep;
  if (sn_robot_call(rb, "robot/get_proto", 2, args_proto, &a, func, &rep) != 0)
    return NULL;
  const msgpack_object *name = sn_get(rep.result, "type_name");
  const msgpack_object *derived = sn_get(rep.result, "derived");
  const msgpack_object *fields = sn_get(rep.result, "fields");
  struct WbProtoInfoStructPrivate *p = NULL;
  if (name != NULL && name->type == MSGPACK_OBJECT_STR && name->via.str.size > 0)
    p = calloc(1, sizeof *p);
  if (p != NULL) {
    p->node = node;
    p->level = level;
    p->type_name = sn_strdup_obj(name);
    p->derived = derived != NULL && derived->type == MSGPACK_OBJECT_BOOLEAN && derived->via.boolean;
    uint32_t n = fields != NULL && fields->type == MSGPACK_OBJECT_ARRAY ? fields->via.array.size : 0;
    p->fields = n ? calloc(n, sizeof *p->fields) : NULL;
    for (uint32_t i = 0; p->fields != NULL && i < n; i++) {
      p->fields[i] = sn_strdup_obj(&fields->via.array.ptr[i]);
      if (p->fields[i] == NULL)
        break;
      p->n_fields = (int)i + 1;
    }
    if (p->type_name == NULL || (n && p->n_fields != (int)n)) {
      proto_free(p);
      p = NULL;
    } else {
      p->next = rb->protos;
      rb->protos = p;
    }
  }
  sn_reply_free(&rep);
  return p;
}

/* the node's PROTO; NULL for a base node (or a PROTO Sensorium builds in: RectangleArena, ...) */
WbProtoRef wb_supervisor_node_get_proto(WbNodeRef node) {
  const char *func = "wb_supervisor_node_get_proto";
  sn_robot *rb = supervisor_node(node, func);
  return rb == NULL ? NULL : proto_at(rb, node->id, 1, func);
}

/* the supervisor robot for a call on `proto`, or NULL after Webots' line */
static sn_robot *proto_robot(WbProtoRef proto, const char *func) {
  sn_robot *rb = sn_supervisor(func);
  if (rb == NULL)
    return NULL;
  for (struct WbProtoInfoStructPrivate *p = rb->protos; proto != NULL && p != NULL; p = p->next)
    if (p == proto)
      return rb;
  fprintf(stderr, "Error: %s() called with a NULL or invalid 'proto' argument.\n", func);
  return NULL;
}

const char *wb_supervisor_proto_get_type_name(WbProtoRef proto) {
  return proto_robot(proto, "wb_supervisor_proto_get_type_name") ? proto->type_name : "";
}

bool wb_supervisor_proto_is_derived(WbProtoRef proto) {
  return proto_robot(proto, "wb_supervisor_proto_is_derived") ? proto->derived : false;
}

/* the PROTO this one is built on (its body is an instance of it); NULL when it is built on a base node */
WbProtoRef wb_supervisor_proto_get_parent(WbProtoRef proto) {
  const char *func = "wb_supervisor_proto_get_parent";
  sn_robot *rb = proto_robot(proto, func);
  if (rb == NULL || !proto->derived)
    return NULL;
  return proto_at(rb, proto->node, proto->level + 1, func);
}

int wb_supervisor_proto_get_number_of_fields(WbProtoRef proto) {
  return proto_robot(proto, "wb_supervisor_proto_get_number_of_fields") ? proto->n_fields : -1;
}

/* a parent PROTO's fields are read-only, as in Webots */
WbFieldRef wb_supervisor_proto_get_field(WbProtoRef proto, const char *field_name) {
  const char *func = "wb_supervisor_proto_get_field";
  sn_robot *rb = proto_robot(proto, func);
  return rb == NULL ? NULL : field_at(node_ref(rb, proto->node), field_name, proto->level, func);
}

static const char *field_name_at(WbProtoRef proto, int index, const char *func) {
  if (index < 0 || index >= proto->n_fields) {
    fprintf(stderr, "Error: %s() called with an invalid 'index' argument: %d (the %s has %d fields).\n", func, index,
            proto->level == 0 ? "node" : "PROTO", proto->n_fields);
    return NULL;
  }
  return proto->fields[index];
}

WbFieldRef wb_supervisor_proto_get_field_by_index(WbProtoRef proto, int index) {
  const char *func = "wb_supervisor_proto_get_field_by_index";
  sn_robot *rb = proto_robot(proto, func);
  const char *name = rb == NULL ? NULL : field_name_at(proto, index, func);
  return name == NULL ? NULL : field_at(node_ref(rb, proto->node), name, proto->level, func);
}

/* The field names getNumberOfFields counts (`base` false: a PROTO instance's interface, else its base node's)
   or getNumberOfBaseNodeFields does (`base` true): the server's get_proto at level 1, or at level 0 (the base
   node's fields served here, in Webots' declaration order), kept as a level-0 entry of the PROTO list */
static WbProtoRef node_fields(WbNodeRef node, bool base, const char *func) {
  sn_robot *rb = supervisor_node(node, func);
  if (rb == NULL)
    return NULL;
  WbProtoRef p = base ? NULL : proto_at(rb, node->id, 1, func);
  return p != NULL ? p : proto_at(rb, node->id, 0, func);
}

typedef struct {
  int64_t node;
  const char *name;
} proto_def_args;

static void args_proto_def(sn_req *r, const void *arg) {
  const proto_def_args *a = arg;
  sn_req_key(r, "node");
  msgpack_pack_int64(&r->pk, a->node);
  sn_req_key(r, "name");
  sn_req_str(r, a->name);
}

/* Webots' DEF lookup inside a PROTO instance's body: the node of the instance's own body (and of what its
   nested PROTO instances hold in their fields, not their own bodies) with that DEF, usable as any node; NULL
   when there is none. Webots' checks and lines first (a NULL or empty def, a NULL node, a node that is no
   PROTO instance); the server's line when the DEF names a node Sensorium serves no Supervisor node for. */
WbNodeRef wb_supervisor_node_get_from_proto_def(WbNodeRef node, const char *def) {
  const char *func = "wb_supervisor_node_get_from_proto_def";
  sn_robot *rb = sn_supervisor(func);
  if (rb == NULL)
    return NULL;
  if (def == NULL || *def == '\0') {
    fprintf(stderr, "Error: %s() called with NULL or empty 'def' argument.\n", func);
    return NULL;
  }
  if (live_node(node, func) == NULL)
    return NULL;
  if (node->proto == NULL || *node->proto == '\0') {
    fprintf(stderr, "Error: %s(): 'node' is not a PROTO node.\n", func);
    return NULL;
  }
  proto_def_args a = {node->id, def};
  sn_reply rep;
  if (sn_robot_call(rb, "robot/get_from_proto_def", 2, args_proto_def, &a, func, &rep) != 0)
    return NULL;
  const msgpack_object *note = sn_get(rep.result, "note");
  if (note != NULL && note->type == MSGPACK_OBJECT_STR && note->via.str.size > 0)
    fprintf(stderr, "Error: %s(): %s.\n", func, sn_shown_n(note->via.str.ptr, note->via.str.size));
  return node_from_reply(rb, &rep);
}

int wb_supervisor_node_get_number_of_fields(WbNodeRef node) {
  WbProtoRef p = node_fields(node, false, "wb_supervisor_node_get_number_of_fields");
  return p == NULL ? -1 : p->n_fields;
}

WbFieldRef wb_supervisor_node_get_field_by_index(WbNodeRef node, int index) {
  const char *func = "wb_supervisor_node_get_field_by_index";
  WbProtoRef p = node_fields(node, false, func);
  const char *name = p == NULL ? NULL : field_name_at(p, index, func);
  return name == NULL ? NULL : field_at(node, name, -1, func);
}

int wb_supervisor_node_get_number_of_base_node_fields(WbNodeRef node) {
  WbProtoRef p = node_fields(node, true, "wb_supervisor_node_get_number_of_base_node_fields");
  return p == NULL ? -1 : p->n_fields;
}

/* on a PROTO instance read-only, as wb_supervisor_node_get_base_node_field */
WbFieldRef wb_supervisor_node_get_base_node_field_by_index(WbNodeRef node, int index) {
  const char *func = "wb_supervisor_node_get_base_node_field_by_index";
  WbProtoRef p = node_fields(node, true, func);
  const char *name = p == NULL ? NULL : field_name_at(p, index, func);
  return name == NULL ? NULL : field_at(node, name, 0, func);
}

WbFieldType wb_supervisor_field_get_type(WbFieldRef field) { return field ? field->type : WB_NO_FIELD; }

const char *wb_supervisor_field_get_name(WbFieldRef field) { return field ? field->name : ""; }

const char *wb_supervisor_field_get_type_name(WbFieldRef field) {
  if (field != NULL)
    for (size_t i = 0; i < sizeof FIELD_TYPES / sizeof FIELD_TYPES[0]; i++)
      if (FIELD_TYPES[i].type == field->type)
        return FIELD_TYPES[i].name;
  return "";
}

/* The supervisor robot for a call on `field` of `type` (WB_NO_FIELD: any), or NULL after Webots'
   line for a NULL field or a wrong type. */
static sn_robot *field_robot(WbFieldRef field, WbFieldType type, const char *func) {
  sn_robot *rb = sn_supervisor(func);
  if (rb == NULL)
    return NULL;
  if (field == NULL) {
    fprintf(stderr, "Error: %s() called with NULL 'field' argument.\n", func);
    return NULL;
  }
  bool known = false; /* a ref of this library's (compared, never read before), as Webots checks it */
  for (struct WbFieldStructPrivate *f = rb->fields; f != NULL && !known; f = f->next)
    known = f == field;
  if (!known) {
    fprintf(stderr, "Error: %s() called with invalid 'field' argument.\n", func);
    return NULL;
  }
  if (type != WB_NO_FIELD && field->type != type) {
    fprintf(stderr, "Error: %s() called with wrong field type: %s.\n", func, wb_supervisor_field_get_type_name(field));
    return NULL;
  }
  return rb;
}

/* The field's value: 0 with rep filled (free it) and *value its "value" object, -1 after Webots' line
   for a NULL field or a wrong type (type WB_NO_FIELD: any). */
static int field_value(WbFieldRef field, WbFieldType type, const char *func, sn_reply *rep,
                       const msgpack_object **value) {
  sn_robot *rb = field_robot(field, type, func);
  if (rb == NULL)
    return -1;
  field_args a = {field->node, field->name, 0, false, 0.0, NULL, 0, field->level >= 0, field->level, 0, NULL};
  if (sn_robot_call(rb, "robot/get_field", 2 + (field->level >= 0), args_field, &a, func, rep) != 0)
    return -1;
  const msgpack_object *note = sn_get(rep->result, "note"); /* a value the server does not serve: its line */
  if (note != NULL && note->type == MSGPACK_OBJECT_STR && note->via.str.size > 0) {
    fprintf(stderr, "Error: %s(): %s.\n", func, sn_shown_n(note->via.str.ptr, note->via.str.size));
    sn_reply_free(rep);
    return -1;
  }
  *value = sn_get(rep->result, "value");
  return 0;
}

/* Webots' getActualField: the node's own field (getField: the scene tree's, the same ref) that `field` takes
   its value from through IS; a node's own field is its own; NULL when no interface field reaches it */
WbFieldRef wb_supervisor_field_get_actual_field(WbFieldRef field) {
  const char *func = "wb_supervisor_field_get_actual_field";
  sn_robot *rb = field_robot(field, WB_NO_FIELD, func);
  if (rb == NULL)
    return NULL;
  if (field->level < 0)
    return field;
  field_args a = {field->node, field->name, 0, false, 0.0, NULL, 0, true, field->level, 0, NULL};
  sn_reply rep;
  if (sn_robot_call(rb, "robot/get_actual_field", 3, args_field, &a, func, &rep) != 0)
    return NULL;
  char *name = sn_strdup_obj(sn_get(rep.result, "value"));
  sn_reply_free(&rep);
  WbFieldRef actual = name != NULL && *name != '\0' ? field_at(node_ref(rb, field->node), name, -1, func) : NULL;
  free(name);
  return actual;
}

int wb_supervisor_field_get_count(WbFieldRef field) {
  sn_reply rep;
  const msgpack_object *v;
  const char *func = "wb_supervisor_field_get_count";
  if (field_robot(field, WB_NO_FIELD, func) == NULL || !(field->type & WB_MF) ||
      field_value(field, WB_NO_FIELD, func, &rep, &v) != 0)
    return -1; /* Webots' line for a NULL field; its count of a single (SF) field */
  int n = v != NULL && v->type == MSGPACK_OBJECT_ARRAY ? (int)v->via.array.size : -1;
  sn_reply_free(&rep);
  return n;
}

bool wb_supervisor_field_get_sf_bool(WbFieldRef field) {
  sn_reply rep;
  const msgpack_object *v;
  if (field_value(field, WB_SF_BOOL, "wb_supervisor_field_get_sf_bool", &rep, &v) != 0)
    return false;
  bool out = v != NULL && v->type == MSGPACK_OBJECT_BOOLEAN && v->via.boolean;
  sn_reply_free(&rep);
  return out;
}

int wb_supervisor_field_get_sf_int32(WbFieldRef field) {
  sn_reply rep;
  const msgpack_object *v;
  int64_t out = 0;
  if (field_value(field, WB_SF_INT32, "wb_supervisor_field_get_sf_int32", &rep, &v) != 0)
    return 0;
  if (v == NULL || !sn_as_int64(v, &out))
    out = 0;
  sn_reply_free(&rep);
  return (int)out;
}

/* Webots streams a tracked field's value every sampling period so that its getters need no round trip;
   here every getter asks the server and answers the value of now, which is what tracking shows at each
   step: accepted after Webots' checks, nothing else to do */
void wb_supervisor_field_enable_sf_tracking(WbFieldRef field, int sampling_period) {
  const char *func = "wb_supervisor_field_enable_sf_tracking";
  if (field_robot(field, WB_NO_FIELD, func) != NULL && sampling_period < 0)
    fprintf(stderr, "Error: %s() called with negative sampling period.\n", func);
}

void wb_supervisor_field_disable_sf_tracking(WbFieldRef field) {
  field_robot(field, WB_NO_FIELD, "wb_supervisor_field_disable_sf_tracking");
}

double wb_supervisor_field_get_sf_float(WbFieldRef field) {
  sn_reply rep;
  const msgpack_object *v;
  double out = NAN;
  if (field_value(field, WB_SF_FLOAT, "wb_supervisor_field_get_sf_float", &rep, &v) != 0)
    return NAN;
  if (v == NULL || !sn_as_double(v, &out))
    out = NAN;
  sn_reply_free(&rep);
  return out;
}

const char *wb_supervisor_field_get_sf_string(WbFieldRef field) {
  sn_reply rep;
  const msgpack_object *v;
  if (field_value(field, WB_SF_STRING, "wb_supervisor_field_get_sf_string", &rep, &v) != 0)
    return "";
  char *copy = sn_strdup_obj(v);
  sn_reply_free(&rep);
  if (copy == NULL)
    return "";
  free(field->string);
  field->string = copy;
  return copy;
}

static const double *field_numbers(WbFieldRef field, WbFieldType type, const char *func) {
  sn_reply rep;
  const msgpack_object *v;
  if (field_value(field, type, func, &rep, &v) != 0)
    return NULL;
  bool ok = copy_numbers(v, field->value, type == WB_SF_ROTATION ? 4 : type == WB_SF_VEC2F ? 2 : 3);
  sn_reply_free(&rep);
  if (!ok)
    fprintf(stderr, "Error: %s(): malformed reply\n", func);
  return ok ? field->value : NULL;
}

const double *wb_supervisor_field_get_sf_vec2f(WbFieldRef field) {
  return field_numbers(field, WB_SF_VEC2F, "wb_supervisor_field_get_sf_vec2f");
}

const double *wb_supervisor_field_get_sf_vec3f(WbFieldRef field) {
  return field_numbers(field, WB_SF_VEC3F, "wb_supervisor_field_get_sf_vec3f");
}

const double *wb_supervisor_field_get_sf_rotation(WbFieldRef field) {
  return field_numbers(field, WB_SF_ROTATION, "wb_supervisor_field_get_sf_rotation");
}

const double *wb_supervisor_field_get_sf_color(WbFieldRef field) {
  return field_numbers(field, WB_SF_COLOR, "wb_supervisor_field_get_sf_color");
}

/* item index of an MF field's value v (negative counts from the end, as Webots); NULL after Webots' line */
static const msgpack_object *mf_item(const msgpack_object *v, int index, const char *func) {
  int count = v != NULL && v->type == MSGPACK_OBJECT_ARRAY ? (int)v->via.array.size : 0;
  if (index >= -count && index < count)
    return &v->via.array.ptr[index < 0 ? index + count : index];
  if (count == 0)
    fprintf(stderr, "Error: %s() called on an empty list.\n", func);
  else
    fprintf(stderr, "Error: %s() called with an out-of-bound index: %d (should be between %d and %d).\n", func,
            index, -count, count - 1);
  return NULL;
}

WbNodeRef wb_supervisor_field_get_mf_node(WbFieldRef field, int index) {
  const char *func = "wb_supervisor_field_get_mf_node";
  sn_reply rep;
  const msgpack_object *v;
  if (field_value(field, WB_MF_NODE, func, &rep, &v) != 0)
    return NULL;
  const msgpack_object *item = mf_item(v, index, func);
  int64_t id = -1;
  if (item != NULL && !sn_as_int64(item, &id))
    id = -1;
  sn_reply_free(&rep);
  return id < 0 ? NULL : node_from_id(id, func);
}

/* the node of an SFNode field (a joint's jointParameters); NULL for Webots' NULL (id 0 on the wire) */
WbNodeRef wb_supervisor_field_get_sf_node(WbFieldRef field) {
  const char *func = "wb_supervisor_field_get_sf_node";
  sn_reply rep;
  const msgpack_object *v;
  if (field_value(field, WB_SF_NODE, func, &rep, &v) != 0)
    return NULL;
  int64_t id = 0;
  if (v == NULL || !sn_as_int64(v, &id))
    id = 0;
  sn_reply_free(&rep);
  return id <= 0 ? NULL : node_from_id(id, func);
}

/* colour index of an MFColor field (a Background's skyColor); valid until the next call on the field */
const double *wb_supervisor_field_get_mf_color(WbFieldRef field, int index) {
  const char *func = "wb_supervisor_field_get_mf_color";
  sn_reply rep;
  const msgpack_object *v;
  if (field_value(field, WB_MF_COLOR, func, &rep, &v) != 0)
    return NULL;
  const msgpack_object *item = mf_item(v, index, func);
  bool ok = item != NULL && copy_numbers(item, field->value, 3);
  if (item != NULL && !ok)
    fprintf(stderr, "Error: %s(): malformed reply\n", func);
  sn_reply_free(&rep);
  return ok ? field->value : NULL;
}

/* item `index` of an MF field of `type` into *out (numbers: `width` of them into field->value; a string:
   into field->string); false after Webots' line */
static bool mf_get(WbFieldRef field, WbFieldType type, int index, int width, const char *func, double *number) {
  sn_reply rep;
  const msgpack_object *v;
  if (field_value(field, type, func, &rep, &v) != 0)
    return false;
  const msgpack_object *item = mf_item(v, index, func);
  bool ok = item != NULL;
  if (ok && type == WB_MF_STRING) {
    char *copy = sn_strdup_obj(item);
    ok = copy != NULL;
    if (ok) {
      free(field->string);
      field->string = copy;
    }
  } else if (ok && type == WB_MF_BOOL) {
    ok = item->type == MSGPACK_OBJECT_BOOLEAN;
    *number = ok && item->via.boolean ? 1.0 : 0.0;
  } else if (ok && width == 1)
    ok = sn_as_double(item, number);
  else if (ok)
    ok = copy_numbers(item, field->value, (uint32_t)width);
  if (item != NULL && !ok)
    fprintf(stderr, "Error: %s(): malformed reply\n", func);
  sn_reply_free(&rep);
  return ok;
}

bool wb_supervisor_field_get_mf_bool(WbFieldRef field, int index) {
  double v = 0.0;
  return mf_get(field, WB_MF_BOOL, index, 1, "wb_supervisor_field_get_mf_bool", &v) && v != 0.0;
}

int wb_supervisor_field_get_mf_int32(WbFieldRef field, int index) {
  double v = 0.0;
  return mf_get(field, WB_MF_INT32, index, 1, "wb_supervisor_field_get_mf_int32", &v) ? (int)v : 0;
}

double wb_supervisor_field_get_mf_float(WbFieldRef field, int index) {
  double v = NAN;
  return mf_get(field, WB_MF_FLOAT, index, 1, "wb_supervisor_field_get_mf_float", &v) ? v : NAN;
}

const double *wb_supervisor_field_get_mf_vec2f(WbFieldRef field, int index) {
  double unused;
  return mf_get(field, WB_MF_VEC2F, index, 2, "wb_supervisor_field_get_mf_vec2f", &unused) ? field->value : NULL;
}

const double *wb_supervisor_field_get_mf_vec3f(WbFieldRef field, int index) {
  double unused;
  return mf_get(field, WB_MF_VEC3F, index, 3, "wb_supervisor_field_get_mf_vec3f", &unused) ? field->value : NULL;
}

const double *wb_supervisor_field_get_mf_rotation(WbFieldRef field, int index) {
  double unused;
  return mf_get(field, WB_MF_ROTATION, index, 4, "wb_supervisor_field_get_mf_rotation", &unused) ? field->value : NULL;
}

const char *wb_supervisor_field_get_mf_string(WbFieldRef field, int index) {
  double unused;
  return mf_get(field, WB_MF_STRING, index, 1, "wb_supervisor_field_get_mf_string", &unused) ? field->string : "";
}

static void field_set(WbFieldRef field, WbFieldType type, field_args *a, const char *func) {
  sn_robot *rb = field_robot(field, type, func);
  if (rb == NULL)
    return;
  if (a->kind == 3 && a->values == NULL) {
    fprintf(stderr, "Error: %s() called with a NULL 'values' argument.\n", func);
    return;
  }
  if (a->kind == 5 && a->string == NULL) {
    fprintf(stderr, "Error: %s() called with a NULL 'value' argument.\n", func);
    return;
  }
  if (a->kind == 5 && strlen(a->string) > SN_MAX_MF_STRING) {
    fprintf(stderr, "Error: %s(): a string of %zu characters is longer than the %d a field takes here.\n", func,
            strlen(a->string), SN_MAX_MF_STRING);
    return;
  }
  bool finite = a->kind != 2 || isfinite(a->number);
  for (int i = 0; a->kind == 3 && i < a->n; i++)
    finite = finite && isfinite(a->values[i]);
  if (!finite) {
    fprintf(stderr, "Error: %s() called with a NaN or infinite value.\n", func);
    return;
  }
  a->node = field->node;
  a->name = field->name;
  a->has_level = field->level >= 0;
  a->level = field->level;
  sn_reply rep;
  if (sn_robot_call(rb, "robot/set_field", 3 + a->has_level, args_field, a, func, &rep) == 0)
    sn_reply_free(&rep);
}

void wb_supervisor_field_set_sf_bool(WbFieldRef field, bool value) {
  field_args a = {0, NULL, 1, value, 0.0, NULL, 0, false, 0, 0, NULL};
  field_set(field, WB_SF_BOOL, &a, "wb_supervisor_field_set_sf_bool");
}

void wb_supervisor_field_set_sf_float(WbFieldRef field, double value) {
  field_args a = {0, NULL, 2, false, value, NULL, 0, false, 0, 0, NULL};
  field_set(field, WB_SF_FLOAT, &a, "wb_supervisor_field_set_sf_float");
}

void wb_supervisor_field_set_sf_vec3f(WbFieldRef field, const double values[3]) {
  field_args a = {0, NULL, 3, false, 0.0, values, 3, false, 0, 0, NULL};
  field_set(field, WB_SF_VEC3F, &a, "wb_supervisor_field_set_sf_vec3f");
}

void wb_supervisor_field_set_sf_rotation(WbFieldRef field, const double values[4]) {
  field_args a = {0, NULL, 3, false, 0.0, values, 4, false, 0, 0, NULL};
  field_set(field, WB_SF_ROTATION, &a, "wb_supervisor_field_set_sf_rotation");
}

void wb_supervisor_field_set_sf_color(WbFieldRef field, const double values[3]) {
  field_args a = {0, NULL, 3, false, 0.0, values, 3, false, 0, 0, NULL};
  field_set(field, WB_SF_COLOR, &a, "wb_supervisor_field_set_sf_color");
}

/* read-only here (a robot's name, WorldInfo's randomSeed, a PROTO's fields, ...): the server's line */
void wb_supervisor_field_set_sf_int32(WbFieldRef field, int value) {
  field_args a = {.kind = 4, .integer = value};
  field_set(field, WB_SF_INT32, &a, "wb_supervisor_field_set_sf_int32");
}

void wb_supervisor_field_set_sf_vec2f(WbFieldRef field, const double values[2]) {
  field_args a = {.kind = 3, .values = values, .n = 2};
  field_set(field, WB_SF_VEC2F, &a, "wb_supervisor_field_set_sf_vec2f");
}

void wb_supervisor_field_set_sf_string(WbFieldRef field, const char *value) {
  field_args a = {.kind = 5, .string = value};
  field_set(field, WB_SF_STRING, &a, "wb_supervisor_field_set_sf_string");
}

/* an MF field's item set, inserted or removed (Webots' setMF*, insertMF*, removeMF): served on an imported
   line or point set's fields and on a shape's ImageTexture url; the server checks the index (negative from
   the end) and the value */
typedef struct {
  int64_t node;
  const char *name;
  bool has_level;
  int level;
  int index;
  const char *op;
  int kind; /* 0: no value (remove), 1: an int32, 2: a bool, 3: numbers, 4: a double, 5: a string */
  int number;
  const double *values;
  int n;
  bool flag;
  double real;
  const char *string;
} mf_args;


static void args_mf(sn_req *r, const void *arg) {
  const mf_args *a = arg;
  sn_req_key(r, "node");
  msgpack_pack_int64(&r->pk, a->node);
  sn_req_key(r, "field");
  sn_req_str(r, a->name);
  if (a->has_level) {
    sn_req_key(r, "level");
    msgpack_pack_int(&r->pk, a->level);
  }
  sn_req_key(r, "index");
  msgpack_pack_int(&r->pk, a->index);
  sn_req_key(r, "op");
  sn_req_str(r, a->op);
  if (a->kind == 0)
    return;
  sn_req_key(r, "value");
  if (a->kind == 1)
    msgpack_pack_int(&r->pk, a->number);
  else if (a->kind == 2)
    a->flag ? msgpack_pack_true(&r->pk) : msgpack_pack_false(&r->pk);
  else if (a->kind == 4)
    msgpack_pack_double(&r->pk, a->real);
  else if (a->kind == 5)
    sn_req_str(r, a->string);
  else {
    msgpack_pack_array(&r->pk, (size_t)a->n);
    for (int i = 0; i < a->n; i++)
      msgpack_pack_double(&r->pk, a->values[i]);
  }
}

static void mf_change(WbFieldRef field, WbFieldType type, mf_args *a, const char *func) {
  sn_robot *rb = field_robot(field, type, func);
  if (rb == NULL)
    return;
  if (type == WB_NO_FIELD && !(field->type & WB_MF)) {
    fprintf(stderr, "Error: %s() called with wrong field type: %s.\n", func, wb_supervisor_field_get_type_name(field));
    return;
  }
  if (a->kind == 3 && a->values == NULL) {
    fprintf(stderr, "Error: %s() called with a NULL 'values' argument.\n", func);
    return;
  }
  bool finite = a->kind != 4 || isfinite(a->real);
  for (int i = 0; a->kind == 3 && i < a->n; i++)
    finite = finite && isfinite(a->values[i]);
  if (!finite) {
    fprintf(stderr, "Error: %s() called with a NaN or infinite value.\n", func);
    return;
  }
  if (type == WB_MF_ROTATION && a->values[0] == 0.0 && a->values[1] == 0.0 && a->values[2] == 0.0) {
    fprintf(stderr, "Error: %s() called with invalid values for the [x y z] axis (a zero vector).\n", func);
    return;
  }
  if (a->kind == 5 && a->string == NULL) {
    fprintf(stderr, "Error: %s() called with a NULL 'value' argument.\n", func);
    return;
  }
  if (a->kind == 5 && strlen(a->string) > SN_MAX_MF_STRING) {
    fprintf(stderr, "Error: %s(): a string of %zu characters is longer than the %d a field item takes here.\n", func,
            strlen(a->string), SN_MAX_MF_STRING);
    return;
  }
  a->node = field->node;
  a->name = field->name;
  a->has_level = field->level >= 0;
  a->level = field->level;
  sn_reply rep;
  if (sn_robot_call(rb, "robot/set_field", 4 + a->has_level + (a->kind != 0), args_mf, a, func, &rep) == 0)
    sn_reply_free(&rep);
}

void wb_supervisor_field_set_mf_int32(WbFieldRef field, int index, int value) {
  mf_args a = {.index = index, .op = "set", .kind = 1, .number = value};
  mf_change(field, WB_MF_INT32, &a, "wb_supervisor_field_set_mf_int32");
}

void wb_supervisor_field_set_mf_vec3f(WbFieldRef field, int index, const double values[3]) {
  mf_args a = {.index = index, .op = "set", .kind = 3, .values = values, .n = 3};
  mf_change(field, WB_MF_VEC3F, &a, "wb_supervisor_field_set_mf_vec3f");
}

void wb_supervisor_field_set_mf_color(WbFieldRef field, int index, const double values[3]) {
  mf_args a = {.index = index, .op = "set", .kind = 3, .values = values, .n = 3};
  mf_change(field, WB_MF_COLOR, &a, "wb_supervisor_field_set_mf_color");
}

void wb_supervisor_field_insert_mf_int32(WbFieldRef field, int index, int value) {
  mf_args a = {.index = index, .op = "insert", .kind = 1, .number = value};
  mf_change(field, WB_MF_INT32, &a, "wb_supervisor_field_insert_mf_int32");
}

void wb_supervisor_field_insert_mf_vec3f(WbFieldRef field, int index, const double values[3]) {
  mf_args a = {.index = index, .op = "insert", .kind = 3, .values = values, .n = 3};
  mf_change(field, WB_MF_VEC3F, &a, "wb_supervisor_field_insert_mf_vec3f");
}

void wb_supervisor_field_insert_mf_color(WbFieldRef field, int index, const double values[3]) {
  mf_args a = {.index = index, .op = "insert", .kind = 3, .values = values, .n = 3};
  mf_change(field, WB_MF_COLOR, &a, "wb_supervisor_field_insert_mf_color");
}

void wb_supervisor_field_set_mf_bool(WbFieldRef field, int index, bool value) {
  mf_args a = {.index = index, .op = "set", .kind = 2, .flag = value};
  mf_change(field, WB_MF_BOOL, &a, "wb_supervisor_field_set_mf_bool");
}

void wb_supervisor_field_insert_mf_bool(WbFieldRef field, int index, bool value) {
  mf_args a = {.index = index, .op = "insert", .kind = 2, .flag = value};
  mf_change(field, WB_MF_BOOL, &a, "wb_supervisor_field_insert_mf_bool");
}

void wb_supervisor_field_set_mf_float(WbFieldRef field, int index, double value) {
  mf_args a = {.index = index, .op = "set", .kind = 4, .real = value};
  mf_change(field, WB_MF_FLOAT, &a, "wb_supervisor_field_set_mf_float");
}

void wb_supervisor_field_insert_mf_float(WbFieldRef field, int index, double value) {
  mf_args a = {.index = index, .op = "insert", .kind = 4, .real = value};
  mf_change(field, WB_MF_FLOAT, &a, "wb_supervisor_field_insert_mf_float");
}

void wb_supervisor_field_set_mf_vec2f(WbFieldRef field, int index, const double values[2]) {
  mf_args a = {.index = index, .op = "set", .kind = 3, .values = values, .n = 2};
  mf_change(field, WB_MF_VEC2F, &a, "wb_supervisor_field_set_mf_vec2f");
}

void wb_supervisor_field_insert_mf_vec2f(WbFieldRef field, int index, const double values[2]) {
  mf_args a = {.index = index, .op = "insert", .kind = 3, .values = values, .n = 2};
  mf_change(field, WB_MF_VEC2F, &a, "wb_supervisor_field_insert_mf_vec2f");
}

void wb_supervisor_field_set_mf_rotation(WbFieldRef field, int index, const double values[4]) {
  mf_args a = {.index = index, .op = "set", .kind = 3, .values = values, .n = 4};
  mf_change(field, WB_MF_ROTATION, &a, "wb_supervisor_field_set_mf_rotation");
}

void wb_supervisor_field_insert_mf_rotation(WbFieldRef field, int index, const double values[4]) {
  mf_args a = {.index = index, .op = "insert", .kind = 3, .values = values, .n = 4};
  mf_change(field, WB_MF_ROTATION, &a, "wb_supervisor_field_insert_mf_rotation");
}

void wb_supervisor_field_set_mf_string(WbFieldRef field, int index, const char *value) {
  mf_args a = {.index = index, .op = "set", .kind = 5, .string = value};
  mf_change(field, WB_MF_STRING, &a, "wb_supervisor_field_set_mf_string");
}

void wb_supervisor_field_insert_mf_string(WbFieldRef field, int index, const char *value) {
  mf_args a = {.index = index, .op = "insert", .kind = 5, .string = value};
  mf_change(field, WB_MF_STRING, &a, "wb_supervisor_field_insert_mf_string");
}

void wb_supervisor_field_remove_mf(WbFieldRef field, int index) {
  mf_args a = {.index = index, .op = "remove"};
  mf_change(field, WB_NO_FIELD, &a, "wb_supervisor_field_remove_mf");
}

typedef struct {
  int64_t node;
  const char *field;
  int position;
  const char *node_string;
} import_args;

static void args_import(sn_req *r, const void *arg) {
  const import_args *a = arg;
  sn_req_key(r, "node");
  msgpack_pack_int64(&r->pk, a->node);
  sn_req_key(r, "field");
  sn_req_str(r, a->field);
  sn_req_key(r, "position");
  msgpack_pack_int(&r->pk, a->position);
  sn_req_key(r, "node_string");
  sn_req_str(r, a->node_string);
}

/* Webots' import into the root's children: the string's solids and lights join the world from the
   next step at position (0 first, -1 last); a robot, another node kind or a string that does not read
   is refused with the server's one line (it names node string:LINE:COL), nothing changed. */
void wb_supervisor_field_import_mf_node_from_string(WbFieldRef field, int position, const char *node_string) {
  const char *func = "wb_supervisor_field_import_mf_node_from_string";
  sn_robot *rb = field_robot(field, WB_MF_NODE, func);
  if (rb == NULL)
    return;
  if (node_string == NULL || *node_string == '\0') {
    fprintf(stderr, "Error: %s() called with a NULL or empty 'node_string' argument.\n", func);
    return;
  }
  import_args a = {field->node, field->name, position, node_string};
  sn_reply rep;
  if (sn_robot_call(rb, "robot/import_node_from_string", 4, args_import, &a, func, &rep) == 0)
    sn_reply_free(&rep);
}

/* Webots' import into an SFNode field: served into the empty coord (a Coordinate) or color (a Color) of an
   imported line or point set; any other SFNode field, a full one or a string that does not read is refused
   with the server's one line, nothing changed. */
void wb_supervisor_field_import_sf_node_from_string(WbFieldRef field, const char *node_string) {
  const char *func = "wb_supervisor_field_import_sf_node_from_string";
  sn_robot *rb = field_robot(field, WB_SF_NODE, func);
  if (rb == NULL)
    return;
  if (node_string == NULL || *node_string == '\0') {
    fprintf(stderr, "Error: %s() called with a NULL or empty 'node_string' argument.\n", func);
    return;
  }
  import_args a = {field->node, field->name, 0, node_string};
  sn_reply rep;
  if (sn_robot_call(rb, "robot/import_node_from_string", 4, args_import, &a, func, &rep) == 0)
    sn_reply_free(&rep);
}

/* Webots' removeSF: served on the coord and color of an imported line or point set (the node there
   leaves, the field is empty and takes a node again); an empty field stays empty; any other SFNode field
   is read-only here (the server's one line, nothing changed). */
void wb_supervisor_field_remove_sf(WbFieldRef field) {
  const char *func = "wb_supervisor_field_remove_sf";
  sn_robot *rb = field_robot(field, WB_SF_NODE, func);
  if (rb == NULL)
    return;
  field_args a = {field->node, field->name, 0, false, 0.0, NULL, 0, field->level >= 0, field->level, 0, NULL};
  sn_reply rep;
  if (sn_robot_call(rb, "robot/field_remove_sf", 2 + (field->level >= 0), args_field, &a, func, &rep) == 0)
    sn_reply_free(&rep);
}

/* ------------------------------------------------------------------ the simulation */
static void args_status(sn_req *r, const void *arg) {
  sn_req_key(r, "status");
  msgpack_pack_int(&r->pk, *(const int *)arg);
}

void wb_supervisor_simulation_quit(int status) {
  const char *func = "wb_supervisor_simulation_quit";
  sn_robot *rb = sn_supervisor(func);
  if (rb == NULL)
    return;
  /* As Webots quits: the server stops, every controller's steps answer -1 (this one's next step at
     once) and `sensorium run`/`serve` exit with status. */
  sn_reply rep;
  if (sn_robot_call(rb, "robot/simulation_quit", 1, args_status, &status, func, &rep) == 0)
    sn_reply_free(&rep);
  sn_steps_ended(rb);
}

void wb_supervisor_simulation_reset(void) {
  const char *func = "wb_supervisor_simulation_reset";
  sn_robot *rb = sn_supervisor(func);
  sn_reply rep;
  if (rb == NULL || sn_robot_call(rb, "robot/simulation_reset", 0, NULL, NULL, func, &rep) != 0)
    return;
  sn_reply_free(&rep);
  for (int i = 0; i < rb->n_devices; i++) { /* the server reset the motors' commands and the LEDs */
    sn_device *d = &rb->devices[i];
    if (d->kind == SN_MOTOR) { /* a joint's: back to its initial position, its full torque/force */
      d->target_position = d->initial_position;
      d->velocity = d->max_velocity;
      d->available_force = d->max_force;
      d->cmd_position = d->cmd_velocity = d->cmd_acceleration = d->cmd_available = false;
    } else if (d->kind == SN_LED)
      d->led_value = 0;
  }
  /* the robot's customData is reset too; Webots resets at its next step and sends the value with that step's
     answer, so wb_robot_get_custom_data() keeps the old value until wb_robot_step() returns (the server sends it) */
}

static void args_mode(sn_req *r, const void *arg) {
  sn_req_key(r, "mode");
  msgpack_pack_int(&r->pk, *(const int *)arg);
}

void wb_supervisor_simulation_set_mode(WbSimulationMode mode) {
  const char *func = "wb_supervisor_simulation_set_mode";
  sn_robot *rb = sn_supervisor(func);
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
  sn_robot *rb = sn_supervisor(func);
  sn_reply rep;
  if (rb == NULL || sn_robot_call(rb, "robot/simulation_get_mode", 0, NULL, NULL, func, &rep) != 0)
    return WB_SUPERVISOR_SIMULATION_MODE_FAST;
  int64_t v = sn_int_or(rep.result, "value", 2);
  sn_reply_free(&rep);
  return (WbSimulationMode)v;
}

/* ------------------------------------------------------------------ contact points */
/* Where a top-level solid's or robot's bounding shapes (with include_descendants, those of the solids
 * inside it too) touch the ground now, each with the id of the Solid touching there (README
 * "Supervisor"): asked of the server at a node's first query in a step; as in Webots' libController, the
 * step's later queries answer that one's array, valid until the step ends (tracking changes nothing). */
typedef struct {
  int64_t node;
  bool descendants;
} contact_args;

static void args_contacts(sn_req *r, const void *arg) {
  const contact_args *a = arg;
  sn_req_key(r, "node");
  msgpack_pack_int64(&r->pk, a->node);
  sn_req_key(r, "include_descendants");
  sn_arg_bool(r, &a->descendants);
}

/* the node's contact points in its array for that flag (the library's until a query in a later step, or
   cleanup): how many, -1 after the server's line (a node that is no top-level Solid) or a malformed reply */
static int query_contacts(WbNodeRef node, bool descendants, const char *func) {
  sn_robot *rb = supervisor_node(node, func);
  if (rb == NULL)
    return -1;
  int d = descendants ? 1 : 0;
  if (node->contact_known[d] && node->contact_time[d] == rb->time_ms)
    return node->n_contact_points[d];
  sn_reply rep;
  contact_args a = {node->id, descendants};
  if (sn_robot_call(rb, "robot/get_node_contact_points", 2, args_contacts, &a, func, &rep) != 0)
    return -1;
  const msgpack_object *points = sn_get(rep.result, "points"), *ids = sn_get(rep.result, "nodes");
  int n = -1;
  if (points != NULL && ids != NULL && points->type == MSGPACK_OBJECT_ARRAY && ids->type == MSGPACK_OBJECT_ARRAY &&
      points->via.array.size == 3 * ids->via.array.size) {
    n = (int)ids->via.array.size;
    WbContactPoint *out = n > 0 ? calloc((size_t)n, sizeof *out) : NULL;
    bool ok = n == 0 || out != NULL;
    for (int i = 0; ok && i < n; i++) {
      int64_t id;
      ok = sn_as_int64(&ids->via.array.ptr[i], &id);
      out[i].node_id = (int)id;
      for (int k = 0; ok && k < 3; k++)
        ok = sn_as_double(&points->via.array.ptr[3 * i + k], &out[i].point[k]);
    }
    if (ok) {
      free(node->contact_points[d]);
      node->contact_points[d] = out;
      node->n_contact_points[d] = n;
      node->contact_time[d] = rb->time_ms;
      node->contact_known[d] = true;
    } else {
      free(out);
      n = -1;
    }
  }
  sn_reply_free(&rep);
  if (n < 0)
    fprintf(stderr, "Error: %s(): malformed reply\n", func);
  return n;
}

static void deprecated(const char *func, bool *warned) {
  if (*warned)
    return;
  *warned = true;
  fprintf(stderr, "Warning: %s() is deprecated, use wb_supervisor_node_get_contact_points() instead.\n", func);
}

WbContactPoint *wb_supervisor_node_get_contact_points(WbNodeRef node, bool include_descendants, int *size) {
  int n = query_contacts(node, include_descendants, "wb_supervisor_node_get_contact_points");
  if (size != NULL)
    *size = n > 0 ? n : 0;
  return n > 0 ? node->contact_points[include_descendants ? 1 : 0] : NULL;
}

/* Webots' deprecated functions: the count (-1 for a node that is no top-level Solid) sets the
   include_descendants the point and node functions then take */
int wb_supervisor_node_get_number_of_contact_points(WbNodeRef node, bool include_descendants) {
  static bool warned;
  deprecated("wb_supervisor_node_get_number_of_contact_points", &warned);
  if (node != NULL)
    node->contact_descendants = include_descendants;
  return query_contacts(node, include_descendants, "wb_supervisor_node_get_number_of_contact_points");
}

const double *wb_supervisor_node_get_contact_point(WbNodeRef node, int index) {
  static bool warned;
  const char *func = "wb_supervisor_node_get_contact_point";
  deprecated(func, &warned);
  bool d = node != NULL && node->contact_descendants;
  int n = query_contacts(node, d, func);
  return index >= 0 && index < n ? node->contact_points[d][index].point : sn_no_values();
}

WbNodeRef wb_supervisor_node_get_contact_point_node(WbNodeRef node, int index) {
  static bool warned;
  const char *func = "wb_supervisor_node_get_contact_point_node";
  deprecated(func, &warned);
  bool d = node != NULL && node->contact_descendants;
  int n = query_contacts(node, d, func);
  return index >= 0 && index < n ? node_from_id(node->contact_points[d][index].node_id, func) : NULL;
}

void wb_supervisor_node_enable_contact_points_tracking(WbNodeRef node, int sampling_period, bool include_descendants) {
  (void)node;
  (void)sampling_period;
  (void)include_descendants;
  sn_supervisor("wb_supervisor_node_enable_contact_points_tracking");
}

void wb_supervisor_node_disable_contact_points_tracking(WbNodeRef node) {
  (void)node;
  sn_supervisor("wb_supervisor_node_disable_contact_points_tracking");
}

void wb_supervisor_node_enable_contact_point_tracking(WbNodeRef node, int sampling_period, bool include_descendants) {
  (void)node;
  (void)sampling_period;
  (void)include_descendants;
  sn_supervisor("wb_supervisor_node_enable_contact_point_tracking");
}

void wb_supervisor_node_disable_contact_point_tracking(WbNodeRef node, bool include_descendants) {
  (void)node;
  (void)include_descendants;
  sn_supervisor("wb_supervisor_node_disable_contact_point_tracking");
}

/* ------------------------------------------------------------------ labels and pictures */
#define MAX_LABEL_ID 65534 /* Webots: 0..65534, 65535 is its movie caption's */
#define MAX_LABEL_TEXT 1024
#define MAX_LABEL_FONT 256

typedef struct {
  int id;
  const char *text;
  double x, y, size;
  int color;
  double transparency;
  const char *font;
} label_args;

static void args_label(sn_req *r, const void *arg) {
  const label_args *a = arg;
  sn_req_key(r, "id");
  msgpack_pack_int(&r->pk, a->id);
  sn_req_key(r, "text");
  sn_req_str(r, a->text);
  sn_req_key(r, "x");
  msgpack_pack_double(&r->pk, a->x);
  sn_req_key(r, "y");
  msgpack_pack_double(&r->pk, a->y);
  sn_req_key(r, "size");
  msgpack_pack_double(&r->pk, a->size);
  sn_req_key(r, "color");
  msgpack_pack_int(&r->pk, a->color);
  sn_req_key(r, "transparency");
  msgpack_pack_double(&r->pk, a->transparency);
  sn_req_key(r, "font");
  sn_req_str(r, a->font);
}

static bool unit_arg(const char *func, const char *name, double v) {
  if (!(v >= 0.0 && v <= 1.0)) { /* NaN refused too (Webots' checks let it by) */
    fprintf(stderr, "Error: %s() called with %s parameter outside of [0,1] range.\n", func, name);
    return false;
  }
  return true;
}

/* Webots' label over the 3D view: here over every wb_supervisor_export_image picture, kept by the
   server under id (README "Supervisor"). Webots' checks, then the id's and colour's ranges. */
void wb_supervisor_set_label(int id, const char *text, double x, double y, double size, int color, double transparency,
                             const char *font) {
  const char *func = "wb_supervisor_set_label";
  if (!unit_arg(func, "x", x) || !unit_arg(func, "y", y) || !unit_arg(func, "size", size) ||
      !unit_arg(func, "transparency", transparency))
    return;
  sn_robot *rb = sn_supervisor(func);
  if (rb == NULL)
    return;
  if (text == NULL) {
    fprintf(stderr, "Error: %s() called with NULL 'text' argument.\n", func);
    return;
  }
  if (font == NULL) {
    fprintf(stderr, "Error: %s() called with NULL 'font' argument.\n", func);
    return;
  }
  if (id < 0 || id > MAX_LABEL_ID) {
    fprintf(stderr, "Error: %s() called with an 'id' outside of [0,%d] (%d).\n", func, MAX_LABEL_ID, id);
    return;
  }
  if (color < 0 || color > 0xFFFFFF) {
    fprintf(stderr, "Error: %s() called with a 'color' that is no 0xRRGGBB value (%d).\n", func, color);
    return;
  }
  if (strlen(text) > MAX_LABEL_TEXT || strlen(font) > MAX_LABEL_FONT) {
    fprintf(stderr, "Error: %s() called with a 'text' over %d or a 'font' over %d characters.\n", func, MAX_LABEL_TEXT,
            MAX_LABEL_FONT);
    return;
  }
  label_args a = {id, text, x, y, size, color, transparency, font};
  sn_reply rep;
  if (sn_robot_call(rb, "robot/set_label", 8, args_label, &a, func, &rep) == 0)
    sn_reply_free(&rep);
}

static bool ends_with(const char *s, const char *suffix) {
  size_t n = strlen(s), k = strlen(suffix);
  if (n < k)
    return false;
  for (size_t i = 0; i < k; i++) {
    char c = s[n - k + i];
    if (c >= 'A' && c <= 'Z')
      c = (char)(c - 'A' + 'a');
    if (c != suffix[i])
      return false;
  }
  return true;
}

/* Webots' exportImage: the world seen from its Viewpoint (640 x 480 here) with the labels over it.
   The server sends the pixels; this library writes filename (.png, or .jpg/.jpeg at quality) through
   a temporary file beside it renamed onto it (Webots' way: never a half-written picture). */
void wb_supervisor_export_image(const char *filename, int quality) {
  const char *func = "wb_supervisor_export_image";
  sn_robot *rb = sn_supervisor(func);
  if (rb == NULL)
    return;
  if (filename == NULL || filename[0] == '\0') {
    fprintf(stderr, "Error: %s() called with NULL or empty 'filename' argument.\n", func);
    return;
  }
  if (quality < 1 || quality > 100) {
    fprintf(stderr, "Error: %s(): 'quality' argument (%d) must be between 1 and 100.\n", func, quality);
    return;
  }
  const bool png = ends_with(filename, ".png");
  const char *ext = png ? ".png" : ends_with(filename, ".jpg") ? ".jpg" : ends_with(filename, ".jpeg") ? ".jpeg" : NULL;
  if (ext == NULL) {
    fprintf(stderr, "Error: %s(): unsupported image format of '%s' (use .png, .jpg or .jpeg).\n", func, sn_shown(filename));
    return;
  }
  sn_reply rep;
  if (sn_robot_call(rb, "robot/export_image", 0, NULL, NULL, func, &rep) != 0)
    return;
  const msgpack_object *data = sn_get(rep.result, "data");
  int w = (int)sn_int_or(rep.result, "width", 0), h = (int)sn_int_or(rep.result, "height", 0);
  if (data == NULL || data->type != MSGPACK_OBJECT_BIN || w < 1 || h < 1 ||
      data->via.bin.size != 3 * (size_t)w * (size_t)h) {
    fprintf(stderr, "Error: %s(): the server sent no picture: '%s' is not written.\n", func, sn_shown(filename));
    sn_reply_free(&rep);
    return;
  }
  size_t n = strlen(filename) + 16;
  char *tmp = malloc(n);
  if (tmp == NULL) {
    sn_reply_free(&rep);
    return;
  }
  snprintf(tmp, n, "%s.tmp%s", filename, ext);
  const unsigned char *rgb = (const unsigned char *)data->via.bin.ptr;
  char why[256] = "";
  int rc = png ? sn_write_png(tmp, rgb, w, h, 3) : sn_write_jpeg(tmp, rgb, w, h, quality, why, sizeof why);
  sn_reply_free(&rep);
  if (rc == 0 && rename(tmp, filename) != 0)
    rc = -1;
  if (rc != 0) {
    fprintf(stderr, "Error: %s(): cannot write '%s'%s%s%s.\n", func, sn_shown(filename), why[0] ? " (" : "", why, why[0] ? ")" : "");
    remove(tmp);
  }
  free(tmp);
}
