// Sensorium C++ controller layer: a supervisor node (a robot or a solid of the world).
#ifndef WEBOTS_NODE_HPP
#define WEBOTS_NODE_HPP

#include <map>
#include <string>

#include <webots/Field.hpp>
#include <webots/contact_point.h>
#include <webots/supervisor.h>

namespace webots {

typedef WbContactPoint ContactPoint;

class Node {
public:
  explicit Node(WbNodeRef ref) : ref_(ref) {}
  ~Node() {
    for (std::map<WbFieldRef, Field *>::iterator it = fields_.begin(); it != fields_.end(); ++it)
      delete it->second;
  }
  Field *getField(const std::string &name) {
    WbFieldRef ref = wb_supervisor_node_get_field(ref_, name.c_str());
    if (ref == 0)
      return 0;
    Field *&f = fields_[ref];
    if (f == 0)
      f = new Field(ref);
    return f;
  }
  const double *getPosition() const { return wb_supervisor_node_get_position(ref_); }
  const double *getOrientation() const { return wb_supervisor_node_get_orientation(ref_); }
  // no physics contacts here: none (see supervisor.h)
  ContactPoint *getContactPoints(bool includeDescendants, int *size) const {
    return wb_supervisor_node_get_contact_points(ref_, includeDescendants, size);
  }
  void enableContactPointsTracking(int samplingPeriod, bool includeDescendants = false) const {
    wb_supervisor_node_enable_contact_points_tracking(ref_, samplingPeriod, includeDescendants);
  }
  void disableContactPointsTracking() const { wb_supervisor_node_disable_contact_points_tracking(ref_); }
  int getNumberOfContactPoints(bool includeDescendants = false) const {
    return wb_supervisor_node_get_number_of_contact_points(ref_, includeDescendants);
  }
  const double *getContactPoint(int index) const { return wb_supervisor_node_get_contact_point(ref_, index); }

private:
  WbNodeRef ref_;
  std::map<WbFieldRef, Field *> fields_;
  Node(const Node &);
  Node &operator=(const Node &);
};

}  // namespace webots

#endif
