/* Sensorium C controller library: the Supervisor functions Sensorium does not serve (see
 * webots/supervisor.h). Each does nothing, prints one error line the first time it is called
 * (sn_supervisor_unsupported, after Webots' check that the robot is a supervisor) and answers Webots'
 * "no value". Declared from Webots' documented signatures so that a Webots controller compiles. */
#include <math.h>
#include <stddef.h>

#include <webots/supervisor.h>

#include "internal.h"

void wb_supervisor_world_load(const char *filename) {
  (void)filename;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_world_load", &warned);
}

bool wb_supervisor_world_save(const char *filename) {
  (void)filename;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_world_save", &warned);
  return false;
}

void wb_supervisor_world_reload(void) {
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_world_reload", &warned);
}

void wb_supervisor_simulation_reset_physics(void) {
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_simulation_reset_physics", &warned);
}

void wb_supervisor_set_label(int id, const char *text, double x, double y, double size, int color, double transparency, const char *font) {
  (void)id;
  (void)text;
  (void)x;
  (void)y;
  (void)size;
  (void)color;
  (void)transparency;
  (void)font;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_set_label", &warned);
}

void wb_supervisor_export_image(const char *filename, int quality) {
  (void)filename;
  (void)quality;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_export_image", &warned);
}

void wb_supervisor_movie_start_recording(const char *filename, int width, int height, int codec, int quality, int acceleration, bool caption) {
  (void)filename;
  (void)width;
  (void)height;
  (void)codec;
  (void)quality;
  (void)acceleration;
  (void)caption;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_movie_start_recording", &warned);
}

void wb_supervisor_movie_stop_recording(void) {
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_movie_stop_recording", &warned);
}

bool wb_supervisor_movie_is_ready(void) {
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_movie_is_ready", &warned);
  return true;
}

bool wb_supervisor_movie_failed(void) {
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_movie_failed", &warned);
  return true;
}

bool wb_supervisor_animation_start_recording(const char *filename) {
  (void)filename;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_animation_start_recording", &warned);
  return false;
}

bool wb_supervisor_animation_stop_recording(void) {
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_animation_stop_recording", &warned);
  return false;
}

WbNodeRef wb_supervisor_node_get_root(void) {
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_root", &warned);
  return NULL;
}

WbNodeRef wb_supervisor_node_get_from_id(int id) {
  (void)id;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_from_id", &warned);
  return NULL;
}

WbNodeRef wb_supervisor_node_get_from_device(WbDeviceTag tag) {
  (void)tag;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_from_device", &warned);
  return NULL;
}

WbNodeRef wb_supervisor_node_get_from_proto_def(WbNodeRef node, const char *def) {
  (void)node;
  (void)def;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_from_proto_def", &warned);
  return NULL;
}

WbNodeRef wb_supervisor_node_get_parent_node(WbNodeRef node) {
  (void)node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_parent_node", &warned);
  return NULL;
}

WbNodeRef wb_supervisor_node_get_selected(void) {
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_selected", &warned);
  return NULL;
}

WbNodeType wb_supervisor_node_get_type(WbNodeRef node) {
  (void)node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_type", &warned);
  return WB_NODE_NO_NODE;
}

WbFieldRef wb_supervisor_node_get_field_by_index(WbNodeRef node, int index) {
  (void)node;
  (void)index;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_field_by_index", &warned);
  return NULL;
}

int wb_supervisor_node_get_number_of_fields(WbNodeRef node) {
  (void)node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_number_of_fields", &warned);
  return -1;
}

WbFieldRef wb_supervisor_node_get_base_node_field(WbNodeRef node, const char *field_name) {
  (void)node;
  (void)field_name;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_base_node_field", &warned);
  return NULL;
}

WbFieldRef wb_supervisor_node_get_base_node_field_by_index(WbNodeRef node, int index) {
  (void)node;
  (void)index;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_base_node_field_by_index", &warned);
  return NULL;
}

int wb_supervisor_node_get_number_of_base_node_fields(WbNodeRef node) {
  (void)node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_number_of_base_node_fields", &warned);
  return -1;
}

void wb_supervisor_node_remove(WbNodeRef node) {
  (void)node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_remove", &warned);
}

void wb_supervisor_node_save_state(WbNodeRef node, const char *state_name) {
  (void)node;
  (void)state_name;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_save_state", &warned);
}

void wb_supervisor_node_load_state(WbNodeRef node, const char *state_name) {
  (void)node;
  (void)state_name;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_load_state", &warned);
}

void wb_supervisor_node_set_joint_position(WbNodeRef node, double position, int index) {
  (void)node;
  (void)position;
  (void)index;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_set_joint_position", &warned);
}

WbProtoRef wb_supervisor_node_get_proto(WbNodeRef node) {
  (void)node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_proto", &warned);
  return NULL;
}

const char *wb_supervisor_node_get_def(WbNodeRef node) {
  (void)node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_def", &warned);
  return "";
}

const char *wb_supervisor_node_get_type_name(WbNodeRef node) {
  (void)node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_type_name", &warned);
  return "";
}

const char *wb_supervisor_node_get_base_type_name(WbNodeRef node) {
  (void)node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_base_type_name", &warned);
  return "";
}

bool wb_supervisor_node_is_proto(WbNodeRef node) {
  (void)node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_is_proto", &warned);
  return false;
}

const double *wb_supervisor_node_get_center_of_mass(WbNodeRef node) {
  (void)node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_center_of_mass", &warned);
  return sn_no_values();
}

const double *wb_supervisor_node_get_pose(WbNodeRef node, WbNodeRef from_node) {
  (void)node;
  (void)from_node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_pose", &warned);
  return sn_no_values();
}

bool wb_supervisor_node_get_static_balance(WbNodeRef node) {
  (void)node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_static_balance", &warned);
  return false;
}

const double *wb_supervisor_node_get_velocity(WbNodeRef node) {
  (void)node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_get_velocity", &warned);
  return sn_no_values();
}

void wb_supervisor_node_set_velocity(WbNodeRef node, const double velocity[6]) {
  (void)node;
  (void)velocity;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_set_velocity", &warned);
}

void wb_supervisor_node_reset_physics(WbNodeRef node) {
  (void)node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_reset_physics", &warned);
}

void wb_supervisor_node_restart_controller(WbNodeRef node) {
  (void)node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_restart_controller", &warned);
}

const char *wb_supervisor_node_export_string(WbNodeRef node) {
  (void)node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_export_string", &warned);
  return "";
}

void wb_supervisor_node_move_viewpoint(WbNodeRef node) {
  (void)node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_move_viewpoint", &warned);
}

void wb_supervisor_node_set_visibility(WbNodeRef node, WbNodeRef from, bool visible) {
  (void)node;
  (void)from;
  (void)visible;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_set_visibility", &warned);
}

void wb_supervisor_node_add_force(WbNodeRef node, const double force[3], bool relative) {
  (void)node;
  (void)force;
  (void)relative;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_add_force", &warned);
}

void wb_supervisor_node_add_force_with_offset(WbNodeRef node, const double force[3], const double offset[3], bool relative) {
  (void)node;
  (void)force;
  (void)offset;
  (void)relative;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_add_force_with_offset", &warned);
}

void wb_supervisor_node_add_torque(WbNodeRef node, const double torque[3], bool relative) {
  (void)node;
  (void)torque;
  (void)relative;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_add_torque", &warned);
}

WbFieldRef wb_supervisor_field_get_actual_field(WbFieldRef field) {
  (void)field;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_get_actual_field", &warned);
  return NULL;
}

void wb_supervisor_field_enable_sf_tracking(WbFieldRef field, int sampling_period) {
  (void)field;
  (void)sampling_period;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_enable_sf_tracking", &warned);
}

void wb_supervisor_field_disable_sf_tracking(WbFieldRef field) {
  (void)field;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_disable_sf_tracking", &warned);
}

void wb_supervisor_node_enable_pose_tracking(WbNodeRef node, int sampling_period, WbNodeRef from_node) {
  (void)node;
  (void)sampling_period;
  (void)from_node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_enable_pose_tracking", &warned);
}

void wb_supervisor_node_disable_pose_tracking(WbNodeRef node, WbNodeRef from_node) {
  (void)node;
  (void)from_node;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_node_disable_pose_tracking", &warned);
}

bool wb_supervisor_field_get_sf_bool(WbFieldRef field) {
  (void)field;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_get_sf_bool", &warned);
  return false;
}

int wb_supervisor_field_get_sf_int32(WbFieldRef field) {
  (void)field;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_get_sf_int32", &warned);
  return 0;
}

double wb_supervisor_field_get_sf_float(WbFieldRef field) {
  (void)field;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_get_sf_float", &warned);
  return NAN;
}

const double *wb_supervisor_field_get_sf_vec2f(WbFieldRef field) {
  (void)field;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_get_sf_vec2f", &warned);
  return sn_no_values();
}

const double *wb_supervisor_field_get_sf_color(WbFieldRef field) {
  (void)field;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_get_sf_color", &warned);
  return sn_no_values();
}

const char *wb_supervisor_field_get_sf_string(WbFieldRef field) {
  (void)field;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_get_sf_string", &warned);
  return "";
}

WbNodeRef wb_supervisor_field_get_sf_node(WbFieldRef field) {
  (void)field;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_get_sf_node", &warned);
  return NULL;
}

bool wb_supervisor_field_get_mf_bool(WbFieldRef field, int index) {
  (void)field;
  (void)index;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_get_mf_bool", &warned);
  return false;
}

int wb_supervisor_field_get_mf_int32(WbFieldRef field, int index) {
  (void)field;
  (void)index;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_get_mf_int32", &warned);
  return 0;
}

double wb_supervisor_field_get_mf_float(WbFieldRef field, int index) {
  (void)field;
  (void)index;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_get_mf_float", &warned);
  return NAN;
}

const double *wb_supervisor_field_get_mf_vec2f(WbFieldRef field, int index) {
  (void)field;
  (void)index;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_get_mf_vec2f", &warned);
  return sn_no_values();
}

const double *wb_supervisor_field_get_mf_vec3f(WbFieldRef field, int index) {
  (void)field;
  (void)index;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_get_mf_vec3f", &warned);
  return sn_no_values();
}

const double *wb_supervisor_field_get_mf_color(WbFieldRef field, int index) {
  (void)field;
  (void)index;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_get_mf_color", &warned);
  return sn_no_values();
}

const double *wb_supervisor_field_get_mf_rotation(WbFieldRef field, int index) {
  (void)field;
  (void)index;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_get_mf_rotation", &warned);
  return sn_no_values();
}

const char *wb_supervisor_field_get_mf_string(WbFieldRef field, int index) {
  (void)field;
  (void)index;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_get_mf_string", &warned);
  return "";
}

WbNodeRef wb_supervisor_field_get_mf_node(WbFieldRef field, int index) {
  (void)field;
  (void)index;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_get_mf_node", &warned);
  return NULL;
}

void wb_supervisor_field_set_sf_bool(WbFieldRef field, bool value) {
  (void)field;
  (void)value;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_set_sf_bool", &warned);
}

void wb_supervisor_field_set_sf_int32(WbFieldRef field, int value) {
  (void)field;
  (void)value;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_set_sf_int32", &warned);
}

void wb_supervisor_field_set_sf_float(WbFieldRef field, double value) {
  (void)field;
  (void)value;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_set_sf_float", &warned);
}

void wb_supervisor_field_set_sf_vec2f(WbFieldRef field, const double values[2]) {
  (void)field;
  (void)values;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_set_sf_vec2f", &warned);
}

void wb_supervisor_field_set_sf_color(WbFieldRef field, const double values[3]) {
  (void)field;
  (void)values;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_set_sf_color", &warned);
}

void wb_supervisor_field_set_sf_string(WbFieldRef field, const char *value) {
  (void)field;
  (void)value;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_set_sf_string", &warned);
}

void wb_supervisor_field_set_mf_bool(WbFieldRef field, int index, bool value) {
  (void)field;
  (void)index;
  (void)value;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_set_mf_bool", &warned);
}

void wb_supervisor_field_set_mf_int32(WbFieldRef field, int index, int value) {
  (void)field;
  (void)index;
  (void)value;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_set_mf_int32", &warned);
}

void wb_supervisor_field_set_mf_float(WbFieldRef field, int index, double value) {
  (void)field;
  (void)index;
  (void)value;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_set_mf_float", &warned);
}

void wb_supervisor_field_set_mf_vec2f(WbFieldRef field, int index, const double values[2]) {
  (void)field;
  (void)index;
  (void)values;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_set_mf_vec2f", &warned);
}

void wb_supervisor_field_set_mf_vec3f(WbFieldRef field, int index, const double values[3]) {
  (void)field;
  (void)index;
  (void)values;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_set_mf_vec3f", &warned);
}

void wb_supervisor_field_set_mf_rotation(WbFieldRef field, int index, const double values[4]) {
  (void)field;
  (void)index;
  (void)values;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_set_mf_rotation", &warned);
}

void wb_supervisor_field_set_mf_color(WbFieldRef field, int index, const double values[3]) {
  (void)field;
  (void)index;
  (void)values;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_set_mf_color", &warned);
}

void wb_supervisor_field_set_mf_string(WbFieldRef field, int index, const char *value) {
  (void)field;
  (void)index;
  (void)value;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_set_mf_string", &warned);
}

void wb_supervisor_field_insert_mf_bool(WbFieldRef field, int index, bool value) {
  (void)field;
  (void)index;
  (void)value;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_insert_mf_bool", &warned);
}

void wb_supervisor_field_insert_mf_int32(WbFieldRef field, int index, int value) {
  (void)field;
  (void)index;
  (void)value;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_insert_mf_int32", &warned);
}

void wb_supervisor_field_insert_mf_float(WbFieldRef field, int index, double value) {
  (void)field;
  (void)index;
  (void)value;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_insert_mf_float", &warned);
}

void wb_supervisor_field_insert_mf_vec2f(WbFieldRef field, int index, const double values[2]) {
  (void)field;
  (void)index;
  (void)values;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_insert_mf_vec2f", &warned);
}

void wb_supervisor_field_insert_mf_vec3f(WbFieldRef field, int index, const double values[3]) {
  (void)field;
  (void)index;
  (void)values;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_insert_mf_vec3f", &warned);
}

void wb_supervisor_field_insert_mf_rotation(WbFieldRef field, int index, const double values[4]) {
  (void)field;
  (void)index;
  (void)values;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_insert_mf_rotation", &warned);
}

void wb_supervisor_field_insert_mf_color(WbFieldRef field, int index, const double values[3]) {
  (void)field;
  (void)index;
  (void)values;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_insert_mf_color", &warned);
}

void wb_supervisor_field_insert_mf_string(WbFieldRef field, int index, const char *value) {
  (void)field;
  (void)index;
  (void)value;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_insert_mf_string", &warned);
}

void wb_supervisor_field_remove_mf(WbFieldRef field, int index) {
  (void)field;
  (void)index;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_remove_mf", &warned);
}

void wb_supervisor_field_import_mf_node_from_string(WbFieldRef field, int position, const char *node_string) {
  (void)field;
  (void)position;
  (void)node_string;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_import_mf_node_from_string", &warned);
}

void wb_supervisor_field_remove_sf(WbFieldRef field) {
  (void)field;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_remove_sf", &warned);
}

void wb_supervisor_field_import_sf_node_from_string(WbFieldRef field, const char *node_string) {
  (void)field;
  (void)node_string;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_import_sf_node_from_string", &warned);
}

const char *wb_supervisor_proto_get_type_name(WbProtoRef proto) {
  (void)proto;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_proto_get_type_name", &warned);
  return "";
}

bool wb_supervisor_proto_is_derived(WbProtoRef proto) {
  (void)proto;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_proto_is_derived", &warned);
  return false;
}

WbProtoRef wb_supervisor_proto_get_parent(WbProtoRef proto) {
  (void)proto;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_proto_get_parent", &warned);
  return NULL;
}

WbFieldRef wb_supervisor_proto_get_field(WbProtoRef proto, const char *field_name) {
  (void)proto;
  (void)field_name;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_proto_get_field", &warned);
  return NULL;
}

WbFieldRef wb_supervisor_proto_get_field_by_index(WbProtoRef proto, int index) {
  (void)proto;
  (void)index;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_proto_get_field_by_index", &warned);
  return NULL;
}

int wb_supervisor_proto_get_number_of_fields(WbProtoRef proto) {
  (void)proto;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_proto_get_number_of_fields", &warned);
  return -1;
}

bool wb_supervisor_virtual_reality_headset_is_used(void) {
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_virtual_reality_headset_is_used", &warned);
  return false;
}

const double *wb_supervisor_virtual_reality_headset_get_position(void) {
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_virtual_reality_headset_get_position", &warned);
  return sn_no_values();
}

const double *wb_supervisor_virtual_reality_headset_get_orientation(void) {
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_virtual_reality_headset_get_orientation", &warned);
  return sn_no_values();
}

int wb_supervisor_movie_get_status(void) {
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_movie_get_status", &warned);
  return WB_SUPERVISOR_MOVIE_SIMULATION_ERROR;
}

void wb_supervisor_simulation_revert(void) {
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_simulation_revert", &warned);
}

void wb_supervisor_load_world(const char *filename) {
  (void)filename;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_load_world", &warned);
}

bool wb_supervisor_save_world(const char *filename) {
  (void)filename;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_save_world", &warned);
  return false;
}

void wb_supervisor_field_remove_mf_node(WbFieldRef field, int position) {
  (void)field;
  (void)position;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_field_remove_mf_node", &warned);
}

void wb_supervisor_simulation_physics_reset(void) {
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_simulation_physics_reset", &warned);
}

void wb_supervisor_start_movie(const char *file, int width, int height, int codec, int quality, int acceleration, bool caption) {
  (void)file;
  (void)width;
  (void)height;
  (void)codec;
  (void)quality;
  (void)acceleration;
  (void)caption;
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_start_movie", &warned);
}

void wb_supervisor_stop_movie(void) {
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_stop_movie", &warned);
}

int wb_supervisor_get_movie_status(void) {
  static bool warned;
  sn_supervisor_unsupported("wb_supervisor_get_movie_status", &warned);
  return WB_SUPERVISOR_MOVIE_SIMULATION_ERROR;
}
