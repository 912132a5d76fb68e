// Sensorium C++ controller layer: Supervisor (a Robot whose world entry has "supervisor: true"): Webots'
// methods, over supervisor.h (what Sensorium serves, and Webots' "no value" for the rest).
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
  // deprecated since Webots 8.4.0 (movieIsReady and movieFailed instead)
  enum { MOVIE_READY = 0, MOVIE_RECORDING, MOVIE_SAVING, MOVIE_WRITE_ERROR, MOVIE_ENCODING_ERROR, MOVIE_SIMULATION_ERROR };
  Supervisor() { instance() = this; }
  static Supervisor *getSupervisorInstance() { return instance(); }
  virtual ~Supervisor() {  // the nodes, fields and protos handed out
    for (std::map<WbNodeRef, Node *>::iterator it = internal::nodes().begin(); it != internal::nodes().end(); ++it)
      delete it->second;
    internal::nodes().clear();
    for (std::map<WbFieldRef, Field *>::iterator it = internal::fields().begin(); it != internal::fields().end(); ++it)
      delete it->second;
    internal::fields().clear();
    for (std::map<WbProtoRef, Proto *>::iterator it = internal::protos().begin(); it != internal::protos().end(); ++it)
      delete it->second;
    internal::protos().clear();
    if (instance() == this)
      instance() = 0;
  }
  // served by Sensorium
  Node *getFromDef(const std::string &name) const { return Node::findNode(wb_supervisor_node_get_from_def(name.c_str())); }
  Node *getSelf() const { return Node::findNode(wb_supervisor_node_get_self()); }
  void simulationReset() { wb_supervisor_simulation_reset(); }
  void simulationSetMode(SimulationMode mode) { wb_supervisor_simulation_set_mode(static_cast<WbSimulationMode>(mode)); }
  SimulationMode simulationGetMode() const { return static_cast<SimulationMode>(wb_supervisor_simulation_get_mode()); }
  void simulationQuit(int status) { wb_supervisor_simulation_quit(status); }  // every controller's steps end; the server exits with status
  // Webots' others: one error line per function, "no value" (see supervisor.h)
  Node *getRoot() const { return Node::findNode(wb_supervisor_node_get_root()); }
  Node *getFromId(int id) const { return Node::findNode(wb_supervisor_node_get_from_id(id)); }
  Node *getFromDevice(const Device *device) const {
    return Node::findNode(wb_supervisor_node_get_from_device(device ? device->getTag() : 0));
  }
  Node *getFromDeviceTag(int tag) const {
    return Node::findNode(wb_supervisor_node_get_from_device(static_cast<WbDeviceTag>(tag)));
  }
  Node *getSelected() const { return Node::findNode(wb_supervisor_node_get_selected()); }
  void setLabel(int id, const std::string &label, double xpos, double ypos, double size, int color,
                double transparency = 0, const std::string &font = "Arial") {
    wb_supervisor_set_label(id, label.c_str(), xpos, ypos, size, color, transparency, font.c_str());
  }
  void simulationResetPhysics() { wb_supervisor_simulation_reset_physics(); }
  void worldLoad(const std::string &file) { wb_supervisor_world_load(file.c_str()); }
  bool worldSave() { return wb_supervisor_world_save(NULL); }
  bool worldSave(const std::string &file) { return wb_supervisor_world_save(file.c_str()); }
  void worldReload() { wb_supervisor_world_reload(); }
  void exportImage(const std::string &file, int quality) const { wb_supervisor_export_image(file.c_str(), quality); }
  void movieStartRecording(const std::string &file, int width, int height, int codec, int quality, int acceleration,
                           bool caption) const {
    wb_supervisor_movie_start_recording(file.c_str(), width, height, codec, quality, acceleration, caption);
  }
  void movieStopRecording() { wb_supervisor_movie_stop_recording(); }
  bool movieIsReady() const { return wb_supervisor_movie_is_ready(); }
  bool movieFailed() const { return wb_supervisor_movie_failed(); }
  bool animationStartRecording(const std::string &file) { return wb_supervisor_animation_start_recording(file.c_str()); }
  bool animationStopRecording() { return wb_supervisor_animation_stop_recording(); }
  bool virtualRealityHeadsetIsUsed() const { return wb_supervisor_virtual_reality_headset_is_used(); }
  const double *virtualRealityHeadsetGetPosition() const { return wb_supervisor_virtual_reality_headset_get_position(); }
  const double *virtualRealityHeadsetGetOrientation() const {
    return wb_supervisor_virtual_reality_headset_get_orientation();
  }
  // Webots' deprecated names (the C library's deprecated functions)
  void simulationRevert() { wb_supervisor_world_reload(); }
  void loadWorld(const std::string &file) { wb_supervisor_world_load(file.c_str()); }
  bool saveWorld() { return wb_supervisor_world_save(NULL); }
  bool saveWorld(const std::string &file) { return wb_supervisor_world_save(file.c_str()); }
  void simulationPhysicsReset() { wb_supervisor_simulation_reset_physics(); }
  void startMovie(const std::string &file, int width, int height, int codec, int quality, int acceleration, bool caption) {
    wb_supervisor_movie_start_recording(file.c_str(), width, height, codec, quality, acceleration, caption);
  }
  void stopMovie() { wb_supervisor_movie_stop_recording(); }
  int getMovieStatus() { return wb_supervisor_movie_get_status(); }
  int movieGetStatus() const { return wb_supervisor_movie_get_status(); }

private:
  static Supervisor *&instance() {
    static Supervisor *created = 0;
    return created;
  }
};

}  // namespace webots

#endif
