/*
 * Sensorium's own text of the calls Webots' e-puck_position_supervisor.c (projects/languages/matlab) makes
 * (sweep 34): every 320 ms it sends the E_PUCK's translation as three doubles and shows each string it
 * received (null-terminated by the sender) as label 0; it also prints every 20th label with the time, and
 * the position it sent each 1.6 s, for the test to compare.
 */

#include <stdio.h>
#include <webots/emitter.h>
#include <webots/receiver.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

#define TIME_STEP 320

int main(void) {
  wb_robot_init();
  WbDeviceTag emitter = wb_robot_get_device("emitter");
  WbDeviceTag receiver = wb_robot_get_device("receiver");
  wb_receiver_enable(receiver, TIME_STEP);
  WbNodeRef epuck = wb_supervisor_node_get_from_def("E_PUCK");
  WbFieldRef trans = wb_supervisor_node_get_field(epuck, "translation");
  int labels = 0, steps = 0;
  while (wb_robot_step(TIME_STEP) != -1) {
    const double *pos = wb_supervisor_field_get_sf_vec3f(trans);
    wb_emitter_send(emitter, pos, 3 * sizeof(double));
    if (++steps % 5 == 0)
      printf("sent %.0f %.17g %.17g %.17g\n", wb_robot_get_time() * 1000, pos[0], pos[1], pos[2]);
    while (wb_receiver_get_queue_length(receiver) > 0) {
      const char *string = wb_receiver_get_data(receiver);
      wb_supervisor_set_label(0, string, 0.01, 0.01, 0.1, 0x000000, 0.0, "Arial");
      if (++labels % 20 == 0)
        printf("label %d %s\n", labels, string);
      wb_receiver_next_packet(receiver);
    }
    fflush(stdout);
  }
  wb_robot_cleanup();
  return 0;
}
