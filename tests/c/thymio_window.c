/* The calls of Webots' thymio2_demo, our own text (tests/test_sweep18.py runs Webots' file instead when
 * WEBOTS_HOME has it): every 10 ms the circle LED of the current second lit, the top and bottom RGB LEDs
 * from three sines of the time, the seven horizontal and two ground infra-red readings scaled (÷ 43.08,
 * ÷ 10) and sent to the robot window, the ground LEDs from their sensors; the wheels at rest (no key). */
#include <math.h>
#include <stdio.h>

#include <webots/distance_sensor.h>
#include <webots/keyboard.h>
#include <webots/led.h>
#include <webots/motor.h>
#include <webots/plugins/robot_window/robot_wwi.h>
#include <webots/robot.h>

#define STEP 10

static int colour_at(double t) {
  int rgb = 0;
  for (int i = 0; i < 3; ++i)
    rgb = (rgb << 8) + (int)((0.5 * sin(2.0 * M_PI / 4.0 * t + i * M_PI / 3.0) + 0.5) * 255);
  return rgb;
}

int main(void) {
  char name[32], text[128];
  WbDeviceTag circle[8], sensors[9], ground_leds[2];
  wb_robot_init();
  for (int i = 0; i < 8; ++i) {
    snprintf(name, sizeof name, "leds.circle.led%d", i);
    circle[i] = wb_robot_get_device(name);
  }
  for (int i = 0; i < 9; ++i) {
    if (i < 7)
      snprintf(name, sizeof name, "prox.horizontal.%d", i);
    else
      snprintf(name, sizeof name, "prox.ground.%d", i - 7);
    sensors[i] = wb_robot_get_device(name);
    wb_distance_sensor_enable(sensors[i], STEP);
  }
  for (int i = 0; i < 2; ++i) {
    snprintf(name, sizeof name, "leds.prox.v.led%d", i);
    ground_leds[i] = wb_robot_get_device(name);
  }
  const WbDeviceTag top = wb_robot_get_device("leds.top"), left = wb_robot_get_device("leds.bottom.left"),
                    right = wb_robot_get_device("leds.bottom.right");
  const WbDeviceTag wheels[2] = {wb_robot_get_device("motor.left"), wb_robot_get_device("motor.right")};
  wb_led_set(wb_robot_get_device("leds.temperature.red"), 32);
  wb_led_set(wb_robot_get_device("leds.temperature.blue"), 32);
  for (int i = 0; i < 2; ++i) {
    wb_motor_set_position(wheels[i], INFINITY);
    wb_motor_set_velocity(wheels[i], 0.0);
  }
  wb_keyboard_enable(STEP);
  while (wb_robot_step(STEP) != -1) {
    const double t = wb_robot_get_time();
    for (int i = 0; i < 8; ++i)
      wb_led_set(circle[i], i == (int)t % 8 ? 32 : 0);
    wb_led_set(top, colour_at(t));
    wb_led_set(left, colour_at(t + 1.332));
    wb_led_set(right, colour_at(t + 2.664));
    int n = 0;
    for (int i = 0; i < 9; ++i)
      n += snprintf(text + n, sizeof text - n, i ? " %d" : "%d",
                    (int)(wb_distance_sensor_get_value(sensors[i]) / (i < 7 ? 43.08 : 10)));
    wb_robot_wwi_send_text(text);
    for (int i = 0; i < 2; ++i)
      wb_led_set(ground_leds[i], wb_distance_sensor_get_value(sensors[7 + i]) * 32 / 1000);
    while (wb_keyboard_get_key() != -1) {
    }
    for (int i = 0; i < 2; ++i)
      wb_motor_set_velocity(wheels[i], 0.0);
  }
  wb_robot_cleanup();
  return 0;
}
