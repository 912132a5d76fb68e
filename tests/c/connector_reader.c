/* A Connector and Brakes from C (tests/worlds/connector.yaml): the sequence of
 * tests/controllers/connector_reader.py. */
#include <stdio.h>
#include <string.h>

#include <webots/brake.h>
#include <webots/connector.h>
#include <webots/device.h>
#include <webots/motor.h>
#include <webots/position_sensor.h>
#include <webots/robot.h>

static void name(WbDeviceTag tag) {
  if (tag == 0) {
    printf(" none");
    return;
  }
  char buf[64];
  snprintf(buf, sizeof buf, "%s", wb_device_get_name(tag));
  for (char *p = buf; *p; p++)
    if (*p == ' ')
      *p = '_';
  printf(" %s", buf);
}

static void brake(const char *label, WbDeviceTag b) {
  printf("%s %d", label, (int)wb_brake_get_type(b));
  name(wb_brake_get_motor(b));
  name(wb_brake_get_position_sensor(b));
  printf("\n");
}

int main(void) {
  wb_robot_init();
  WbDeviceTag dock = wb_robot_get_device("dock"), side = wb_robot_get_device("side");
  WbDeviceTag socket = wb_robot_get_device("socket");
  wb_connector_enable_presence(dock, 32);
  wb_connector_enable_presence(side, 32);
  wb_connector_enable_presence(socket, 32);
  printf("before %d %d %d\n", wb_connector_get_presence(dock), wb_connector_get_presence_sampling_period(dock),
         (int)wb_connector_is_locked(dock));
  wb_robot_step(16);
  printf("at16 %d %d %d\n", wb_connector_get_presence(dock), wb_connector_get_presence(side),
         wb_connector_get_presence(socket));
  wb_robot_step(16);
  printf("at32 %d %d %d\n", wb_connector_get_presence(dock), wb_connector_get_presence(side),
         wb_connector_get_presence(socket));
  wb_connector_lock(dock);
  wb_connector_lock(socket);
  printf("locked %d %d\n", (int)wb_connector_is_locked(dock), (int)wb_connector_is_locked(socket));
  wb_robot_step(16);
  wb_connector_unlock(dock);
  printf("unlocked %d\n", (int)wb_connector_is_locked(dock));
  wb_connector_disable_presence(dock);
  wb_robot_step(32);
  printf("kept %d %d\n", wb_connector_get_presence(dock), wb_connector_get_presence_sampling_period(dock));
  WbDeviceTag arm = wb_robot_get_device("arm brake");
  brake("arm", arm);
  brake("slide", wb_robot_get_device("slide brake"));
  brake("loose", wb_robot_get_device("loose brake"));
  printf("back");
  name(wb_motor_get_brake(wb_robot_get_device("arm")));
  name(wb_position_sensor_get_brake(wb_robot_get_device("arm sensor")));
  name(wb_motor_get_brake(wb_robot_get_device("slide")));
  printf("\n");
  wb_brake_set_damping_constant(arm, 2.0);
  wb_brake_set_damping_constant(arm, 3.0);
  wb_robot_step(16);
  wb_robot_cleanup();
  return 0;
}
