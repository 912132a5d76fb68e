// Sensorium C++ controller layer: Motion over utils/motion.h: a .motion file played on the robot's
// motors, one pose interpolation per step; a file that cannot be read or is damaged prints one line
// and gives a motion whose isValid() is false.
#ifndef WEBOTS_MOTION_HPP
#define WEBOTS_MOTION_HPP

#include <string>

#include <webots/utils/motion.h>

namespace webots {

class Motion {
public:
  explicit Motion(const std::string &fileName) : motionRef_(wbu_motion_new(fileName.c_str())) {}
  virtual ~Motion() { wbu_motion_delete(motionRef_); }
  bool isValid() const { return motionRef_ != NULL; }
  virtual void play() { wbu_motion_play(motionRef_); }
  virtual void stop() { wbu_motion_stop(motionRef_); }
  int getDuration() const { return wbu_motion_get_duration(motionRef_); }
  int getTime() const { return wbu_motion_get_time(motionRef_); }
  virtual void setTime(int time) { wbu_motion_set_time(motionRef_, time); }
  virtual void setReverse(bool reverse) { wbu_motion_set_reverse(motionRef_, reverse); }
  virtual void setLoop(bool loop) { wbu_motion_set_loop(motionRef_, loop); }
  bool isOver() const { return wbu_motion_is_over(motionRef_); }

protected:
  WbMotionRef getMotionRef() const { return motionRef_; }

private:
  Motion(const Motion &);
  Motion &operator=(const Motion &);
  WbMotionRef motionRef_;
};

}  // namespace webots

#endif  // WEBOTS_MOTION_HPP
