// Sensorium C++ controller layer: Keyboard (a headless server never has a key: getKey() is -1).
#ifndef WEBOTS_KEYBOARD_HPP
#define WEBOTS_KEYBOARD_HPP

#include <webots/keyboard.h>

namespace webots {

class Keyboard {
public:
  enum {
    END = WB_KEYBOARD_END, HOME = WB_KEYBOARD_HOME, LEFT = WB_KEYBOARD_LEFT, UP = WB_KEYBOARD_UP,
    RIGHT = WB_KEYBOARD_RIGHT, DOWN = WB_KEYBOARD_DOWN, PAGEUP = WB_KEYBOARD_PAGEUP, PAGEDOWN = WB_KEYBOARD_PAGEDOWN,
    NUMPAD_HOME = WB_KEYBOARD_NUMPAD_HOME, NUMPAD_LEFT = WB_KEYBOARD_NUMPAD_LEFT, NUMPAD_UP = WB_KEYBOARD_NUMPAD_UP,
    NUMPAD_RIGHT = WB_KEYBOARD_NUMPAD_RIGHT, NUMPAD_DOWN = WB_KEYBOARD_NUMPAD_DOWN,
    NUMPAD_END = WB_KEYBOARD_NUMPAD_END, KEY = WB_KEYBOARD_KEY, SHIFT = WB_KEYBOARD_SHIFT,
    CONTROL = WB_KEYBOARD_CONTROL, ALT = WB_KEYBOARD_ALT
  };
  void enable(int samplingPeriod) { wb_keyboard_enable(samplingPeriod); }
  void disable() { wb_keyboard_disable(); }
  int getSamplingPeriod() const { return wb_keyboard_get_sampling_period(); }
  int getKey() const { return wb_keyboard_get_key(); }
};

}  // namespace webots

#endif
