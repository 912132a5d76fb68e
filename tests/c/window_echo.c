/* A Webots-style C controller talking with its robot window (tests/test_c_client.py): the texts queued
 * before it started come with its first step (read whole with wb_robot_wwi_receive); then each text is
 * answered with "echo:TEXT" until "stop"; last, bytes that are not UTF-8. */
#include <stdio.h>
#include <string.h>

#include <webots/plugins/robot_window/robot_wwi.h>
#include <webots/robot.h>

int main(void) {
  wb_robot_init();
  int step = (int)wb_robot_get_basic_time_step();
  wb_robot_step(step);
  int size = -1;
  const char *all = wb_robot_wwi_receive(&size);
  printf("raw %d", size);
  for (int at = 0; all != NULL && at < size; at += (int)strlen(all + at) + 1)
    printf(" %s", all + at);
  printf("\nthen %s\n", wb_robot_wwi_receive_text() == NULL ? "NULL" : "?"); /* taken whole */
  fflush(stdout);
  wb_robot_wwi_send_text("ready");
  int done = 0;
  while (!done && wb_robot_step(step) != -1) {
    const char *text;
    while ((text = wb_robot_wwi_receive_text()) != NULL) {
      char answer[256];
      snprintf(answer, sizeof answer, "echo:%s", text);
      wb_robot_wwi_send_text(answer);
      printf("received %s\n", text);
      done = done || strcmp(text, "stop") == 0;
    }
  }
  wb_robot_wwi_send("bad\xff\xc3!", 6); /* an invalid byte, a cut sequence: each U+FFFD */
  wb_robot_cleanup();
  return 0;
}
