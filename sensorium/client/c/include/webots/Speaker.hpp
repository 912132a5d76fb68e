// Sensorium C++ controller layer: Speaker (Webots' C++ names over the wb_speaker_* functions).
#ifndef WEBOTS_SPEAKER_HPP
#define WEBOTS_SPEAKER_HPP

#include <string>

#include <webots/Device.hpp>
#include <webots/speaker.h>

namespace webots {

class Speaker : public Device {
public:
  explicit Speaker(WbDeviceTag tag) : Device(tag) {}
  explicit Speaker(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  static void playSound(Speaker *left, Speaker *right, const std::string &sound, double volume, double pitch,
                        double balance, bool loop) {
    wb_speaker_play_sound(left ? left->getTag() : 0, right ? right->getTag() : 0, sound.c_str(), volume, pitch,
                          balance, loop);
  }
  void stop(const std::string &sound) { wb_speaker_stop(tag_, sound.c_str()); }
  bool isSoundPlaying(const std::string &sound) const { return wb_speaker_is_sound_playing(tag_, sound.c_str()); }
  bool setEngine(const std::string &engine) { return wb_speaker_set_engine(tag_, engine.c_str()); }
  bool setLanguage(const std::string &language) { return wb_speaker_set_language(tag_, language.c_str()); }
  std::string getEngine() const { return std::string(wb_speaker_get_engine(tag_)); }
  std::string getLanguage() const { return std::string(wb_speaker_get_language(tag_)); }
  void speak(const std::string &text, double volume) { wb_speaker_speak(tag_, text.c_str(), volume); }
  bool isSpeaking() const { return wb_speaker_is_speaking(tag_); }
};

}  // namespace webots

#endif
