/* Sensorium C controller library: the Supervisor subset the server offers. Only the controller of
 * a robot with "supervisor: true" in the world file may call these (others print Webots' error and
 * get NULL / nothing). Nodes are the world's robots and solids, found by name; the only fields are
 * "translation" (SFVec3f) and "rotation" (SFRotation). Each call is one round trip, answered at
 * once. Returned arrays stay valid until the same function is called again for that node/field. */
#ifndef WB_SUPERVISOR_H
#define WB_SUPERVISOR_H

#include "contact_point.h"
#include "robot.h"
#include "types.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
  WB_SUPERVISOR_SIMULATION_MODE_PAUSE = 0,
  WB_SUPERVISOR_SIMULATION_MODE_REAL_TIME,
  WB_SUPERVISOR_SIMULATION_MODE_FAST
} WbSimulationMode;

typedef enum {
  WB_NO_FIELD = 0,
  WB_SF_BOOL,
  WB_SF_INT32,
  WB_SF_FLOAT,
  WB_SF_VEC2F,
  WB_SF_VEC3F,
  WB_SF_ROTATION,
  WB_SF_COLOR,
  WB_SF_STRING,
  WB_SF_NODE
} WbFieldType;

WbNodeRef wb_supervisor_node_get_from_def(const char *def);
WbNodeRef wb_supervisor_node_get_self(void);
const double *wb_supervisor_node_get_position(WbNodeRef node);    /* 3 values, world frame */
const double *wb_supervisor_node_get_orientation(WbNodeRef node); /* 3x3 rotation matrix, row-major */

WbFieldRef wb_supervisor_node_get_field(WbNodeRef node, const char *field_name);
WbFieldType wb_supervisor_field_get_type(WbFieldRef field);
const char *wb_supervisor_field_get_name(WbFieldRef field);
const double *wb_supervisor_field_get_sf_vec3f(WbFieldRef field);
void wb_supervisor_field_set_sf_vec3f(WbFieldRef field, const double values[3]);
const double *wb_supervisor_field_get_sf_rotation(WbFieldRef field);
void wb_supervisor_field_set_sf_rotation(WbFieldRef field, const double values[4]);

/* Contact points: Sensorium has no physics contacts, so there are none (0, NULL, a NaN vector; the
 * tracking functions do nothing). Webots' "no value" for a node touching nothing. */
const double *wb_supervisor_node_get_contact_point(WbNodeRef node, int index);
WbNodeRef wb_supervisor_node_get_contact_point_node(WbNodeRef node, int index);
int wb_supervisor_node_get_number_of_contact_points(WbNodeRef node, bool include_descendants);
WbContactPoint *wb_supervisor_node_get_contact_points(WbNodeRef node, bool include_descendants, int *size);
void wb_supervisor_node_enable_contact_points_tracking(WbNodeRef node, int sampling_period, bool include_descendants);
void wb_supervisor_node_disable_contact_points_tracking(WbNodeRef node);
/* Webots' older names (R2023a), kept as Webots keeps them */
void wb_supervisor_node_enable_contact_point_tracking(WbNodeRef node, int sampling_period, bool include_descendants);
void wb_supervisor_node_disable_contact_point_tracking(WbNodeRef node, bool include_descendants);

void wb_supervisor_simulation_reset(void);
void wb_supervisor_simulation_set_mode(WbSimulationMode mode);
WbSimulationMode wb_supervisor_simulation_get_mode(void);

#ifdef __cplusplus
}
#endif

#endif /* WB_SUPERVISOR_H */
