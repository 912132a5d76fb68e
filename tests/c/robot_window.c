/* A Webots-style C controller sending its robot window a benchmark's messages (tests/test_c_client.py):
 * with $SENSORIUM_ROBOT_WINDOW_LOG=1 each is one stderr line; stdout stays the controller's. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/plugins/robot_window/robot_wwi.h>
#include <webots/robot.h>

int main(void) {
  wb_robot_init();
  wb_robot_step((int)wb_robot_get_basic_time_step());
  wb_robot_wwi_send_text("time:1.500");
  wb_robot_wwi_send_text("record:0.87\nsecond line");
  char *big = malloc(70001);
  memset(big, 'x', 70000);
  big[70000] = '\0';
  wb_robot_wwi_send_text(big);
  free(big);
  wb_robot_wwi_send("bytes", 3); /* a size short of the text: its first 3 bytes */
  printf("scored %s\n", wb_robot_wwi_receive_text() == NULL ? "nothing received" : "?");
  wb_robot_cleanup();
  return 0;
}
