// Sensorium C++ controller layer: PositionSensor (defined with Motor, which it refers to).
#ifndef WEBOTS_POSITION_SENSOR_HPP
#define WEBOTS_POSITION_SENSOR_HPP

#include <webots/Motor.hpp>

#endif
