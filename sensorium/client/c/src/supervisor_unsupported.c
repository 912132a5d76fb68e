/* Sensorium C controller library: the Supervisor functions Sensorium does not serve (see
 * webots/supervisor.h). Each does nothing, prints one error line the first time it is called
 * (SN_UNSUPPORTED: sn_supervisor_unsupported with the function's own name, after Webots' check that the robot is a supervisor) and answers Webots'
 * "no value". Declared from Webots' documented signatures so that a Webots controller compiles. */
#include <math.h>
#include <stddef.h>

#include <webots/supervisor.h>

#include "internal.h"

/* every function here ignores its arguments (it answers Webots' "no value") */
#pragma GCC diagnostic ignored "-Wunused-parameter"

bool wb_supervisor_animation_start_recording(const char *filename) {
  SN_UNSUPPORTED();
  return false;
}

bool wb_supervisor_animation_stop_recording(void) {
  SN_UNSUPPORTED();
  return false;
}

WbNodeRef wb_supervisor_node_get_selected(void) {
  SN_UNSUPPORTED();
  return NULL;
}

void wb_supervisor_node_add_force(WbNodeRef node, const double force[3], bool relative) {
  SN_UNSUPPORTED();
}

void wb_supervisor_node_add_force_with_offset(WbNodeRef node, const double force[3], const double offset[3], bool relative) {
  SN_UNSUPPORTED();
}

void wb_supervisor_node_add_torque(WbNodeRef node, const double torque[3], bool relative) {
  SN_UNSUPPORTED();
}

bool wb_supervisor_virtual_reality_headset_is_used(void) {
  SN_UNSUPPORTED();
  return false;
}

const double *wb_supervisor_virtual_reality_headset_get_position(void) {
  SN_UNSUPPORTED();
  return sn_no_values();
}

const double *wb_supervisor_virtual_reality_headset_get_orientation(void) {
  SN_UNSUPPORTED();
  return sn_no_values();
}

void wb_supervisor_field_remove_mf_node(WbFieldRef field, int position) {
  SN_UNSUPPORTED();
}
