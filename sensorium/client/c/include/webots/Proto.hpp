// Sensorium C++ controller layer: a PROTO of a supervisor node (Node::getProto). Sensorium's
// Supervisor does not serve PROTO queries: no Proto is ever handed out and its methods answer
// Webots' "no value" with one error line per function (see supervisor.h).
#ifndef WEBOTS_PROTO_HPP
#define WEBOTS_PROTO_HPP

#include <map>
#include <string>

#include <webots/Field.hpp>
#include <webots/supervisor.h>

namespace webots {

class Proto;

namespace internal {
inline std::map<WbProtoRef, Proto *> &protos() {
  static std::map<WbProtoRef, Proto *> table;
  return table;
}
}  // namespace internal

class Proto {
public:
  explicit Proto(WbProtoRef ref) : ref_(ref) {}
  static Proto *findProto(WbProtoRef ref) {
    if (ref == 0)
      return 0;
    Proto *&p = internal::protos()[ref];
    if (p == 0)
      p = new Proto(ref);
    return p;
  }
  std::string getTypeName() const { return wb_supervisor_proto_get_type_name(ref_); }
  bool isDerived() const { return wb_supervisor_proto_is_derived(ref_); }
  Proto *getParent() const { return findProto(wb_supervisor_proto_get_parent(ref_)); }
  Field *getField(const std::string &fieldName) const {
    return Field::findField(wb_supervisor_proto_get_field(ref_, fieldName.c_str()));
  }
  Field *getFieldByIndex(int index) const { return Field::findField(wb_supervisor_proto_get_field_by_index(ref_, index)); }
  int getNumberOfFields() const { return wb_supervisor_proto_get_number_of_fields(ref_); }

private:
  WbProtoRef ref_;
  Proto(const Proto &);
  Proto &operator=(const Proto &);
};

}  // namespace webots

#endif  // WEBOTS_PROTO_HPP
