// Sensorium C++ controller layer: Supervisor (a Robot whose world entry has "supervisor: true").
#ifndef WEBOTS_SUPERVISOR_HPP
#define WEBOTS_SUPERVISOR_HPP

#include <map>
#include <string>

#include <webots/Node.hpp>
#include <webots/Robot.hpp>
#include <webots/supervisor.h>

namespace webots {

class Supervisor : public Robot {
public:
  enum SimulationMode {
    SIMULATION_MODE_PAUSE = WB_SUPERVISOR_SIMULATION_MODE_PAUSE,
    SIMULATION_MODE_REAL_TIME = WB_SUPERVISOR_SIMULATION_MODE_REAL_TIME,
    SIMULATION_MODE_FAST = WB_SUPERVISOR_SIMULATION_MODE_FAST
  };
  Supervisor() {}
  virtual ~Supervisor() {
    for (std::map<WbNodeRef, Node *>::iterator it = nodes_.begin(); it != nodes_.end(); ++it)
      delete it->second;
  }
  Node *getFromDef(const std::string &name) { return node(wb_supervisor_node_get_from_def(name.c_str())); }
  Node *getSelf() { return node(wb_supervisor_node_get_self()); }
  void simulationReset() { wb_supervisor_simulation_reset(); }
  void simulationSetMode(SimulationMode mode) { wb_supervisor_simulation_set_mode(static_cast<WbSimulationMode>(mode)); }
  SimulationMode simulationGetMode() const { return static_cast<SimulationMode>(wb_supervisor_simulation_get_mode()); }

private:
  Node *node(WbNodeRef ref) {
    if (ref == 0)
      return 0;
    Node *&n = nodes_[ref];
    if (n == 0)
      n = new Node(ref);
    return n;
  }
  std::map<WbNodeRef, Node *> nodes_;
};

}  // namespace webots

#endif
