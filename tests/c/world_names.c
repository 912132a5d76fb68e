/* World names in the C library's lines (tests/worlds/control_names.yaml; tests/test_c_client.py): the
 * robot's and its LED's names hold line breaks; each call below prints one line naming one of them,
 * escaped, so each line stays one line. Prints "done" on stdout at the end. */
#include <stdio.h>

#include <webots/distance_sensor.h>
#include <webots/led.h>
#include <webots/robot.h>

int main(void) {
  wb_robot_init();
  WbDeviceTag led = wb_robot_get_device_by_index(0);
  wb_led_set(led, 5);                     /* out of range: the LED's name */
  wb_distance_sensor_get_value(led);      /* another kind of device: the LED's name */
  wb_robot_get_device("none");            /* no such device: the robot's name */
  wb_robot_step(20);                      /* not a multiple of the basic time step: the robot's name */
  printf("done\n");
  wb_robot_cleanup();
  return 0;
}
