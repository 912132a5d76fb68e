/* A tracked robot's Track motors and their sensors from C (tests/test_wbt_tracks.py): their node and
 * joint types, the motor's limits, then both belts at 0.2 m/s for 1 s and the sensors' travel. */
#include <math.h>
#include <stdio.h>

#include <webots/device.h>
#include <webots/motor.h>
#include <webots/position_sensor.h>
#include <webots/robot.h>

int main(void) {
  wb_robot_init();
  WbDeviceTag left = wb_robot_get_device("left motor"), right = wb_robot_get_device("right motor");
  WbDeviceTag sensor = wb_robot_get_device("left sensor");
  printf("node %d %d %d\n", wb_device_get_node_type(left) == WB_NODE_LINEAR_MOTOR,
         wb_device_get_node_type(right) == WB_NODE_LINEAR_MOTOR, wb_device_get_node_type(sensor) == WB_NODE_POSITION_SENSOR);
  printf("type %d %d %d\n", wb_motor_get_type(left) == WB_LINEAR, wb_motor_get_type(right) == WB_LINEAR,
         wb_position_sensor_get_type(sensor) == WB_LINEAR);
  printf("motor %d limits %g %g %g\n", wb_position_sensor_get_motor(sensor) == left, wb_motor_get_max_velocity(left),
         wb_motor_get_min_position(left), wb_motor_get_max_position(left));
  wb_position_sensor_enable(sensor, 10);
  wb_motor_set_position(left, INFINITY);
  wb_motor_set_position(right, INFINITY);
  wb_motor_set_velocity(left, 0.2);
  wb_motor_set_velocity(right, 0.2);
  for (int k = 0; k < 100; k++)
    wb_robot_step(10);
  printf("travel %.12f\n", wb_position_sensor_get_value(sensor));
  wb_robot_cleanup();
  return 0;
}
