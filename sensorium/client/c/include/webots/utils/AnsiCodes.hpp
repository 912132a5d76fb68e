// Sensorium C++ controller layer: the terminal escape sequences of utils/ansi_codes.h (ANSI_RESET,
// ANSI_RED_FOREGROUND, ...), included from C++ as Webots' AnsiCodes.hpp does.
#ifndef WEBOTS_ANSICODES_HPP
#define WEBOTS_ANSICODES_HPP

#include <webots/utils/ansi_codes.h>

#endif  // WEBOTS_ANSICODES_HPP
