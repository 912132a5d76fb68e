// Sensorium C++ controller layer: a supervisor field ("translation" or "rotation" of a node).
#ifndef WEBOTS_FIELD_HPP
#define WEBOTS_FIELD_HPP

#include <string>

#include <webots/supervisor.h>

namespace webots {

class Field {
public:
  enum Type {
    NO_FIELD = WB_NO_FIELD, SF_BOOL = WB_SF_BOOL, SF_INT32 = WB_SF_INT32, SF_FLOAT = WB_SF_FLOAT,
    SF_VEC2F = WB_SF_VEC2F, SF_VEC3F = WB_SF_VEC3F, SF_ROTATION = WB_SF_ROTATION, SF_COLOR = WB_SF_COLOR,
    SF_STRING = WB_SF_STRING, SF_NODE = WB_SF_NODE
  };
  explicit Field(WbFieldRef ref) : ref_(ref) {}
  Type getType() const { return static_cast<Type>(wb_supervisor_field_get_type(ref_)); }
  std::string getName() const { return wb_supervisor_field_get_name(ref_); }
  const double *getSFVec3f() const { return wb_supervisor_field_get_sf_vec3f(ref_); }
  void setSFVec3f(const double values[3]) { wb_supervisor_field_set_sf_vec3f(ref_, values); }
  const double *getSFRotation() const { return wb_supervisor_field_get_sf_rotation(ref_); }
  void setSFRotation(const double values[4]) { wb_supervisor_field_set_sf_rotation(ref_, values); }

private:
  WbFieldRef ref_;
};

}  // namespace webots

#endif
