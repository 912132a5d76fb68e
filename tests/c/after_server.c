/* The newer devices once the server is gone, from C: the sequence of tests/controllers/after_server.py
 * (tests/test_bad_input.py). Argument: the WAV. */
#include <stdio.h>

#include <webots/brake.h>
#include <webots/connector.h>
#include <webots/device.h>
#include <webots/motor.h>
#include <webots/robot.h>
#include <webots/speaker.h>
#include <webots/vacuum_gripper.h>

int main(int argc, char **argv) {
  if (argc < 2)
    return 2;
  const char *wav = argv[1];
  wb_robot_init();
  WbDeviceTag dock = wb_robot_get_device("dock"), gripper = wb_robot_get_device("gripper"),
              speaker = wb_robot_get_device("speaker"), brake = wb_robot_get_device("arm brake"),
              coupled = wb_robot_get_device("grip::b");
  wb_robot_step(16);
  printf("ready\n");
  fflush(stdout);
  char line[16];
  if (fgets(line, sizeof line, stdin) == NULL)
    return 3;
  wb_connector_lock(dock);
  wb_vacuum_gripper_turn_on(gripper);
  wb_speaker_speak(speaker, "hi", 1.0);
  wb_speaker_play_sound(speaker, speaker, wav, 1.0, 1.0, 0.0, false);
  printf("refused 4\n"); /* the lines on stderr, one per call, are counted by the test */
  printf("copies %d %d %d %d\n", (int)wb_connector_is_locked(dock), (int)wb_vacuum_gripper_is_on(gripper),
         (int)wb_speaker_is_speaking(speaker), (int)wb_speaker_is_sound_playing(speaker, wav));
  printf("brake %s %d %g\n", wb_device_get_name(wb_brake_get_motor(brake)), (int)wb_brake_get_type(brake),
         wb_motor_get_multiplier(coupled));
  printf("step %d\n", wb_robot_step(16));
  wb_connector_lock(dock);
  wb_vacuum_gripper_turn_on(gripper);
  wb_speaker_speak(speaker, "hi", 1.0);
  wb_speaker_play_sound(speaker, speaker, wav, 1.0, 1.0, 0.0, false);
  printf("after %d %d %d %d\n", (int)wb_connector_is_locked(dock), (int)wb_vacuum_gripper_is_on(gripper),
         (int)wb_speaker_is_speaking(speaker), (int)wb_speaker_is_sound_playing(speaker, wav));
  fflush(stdout);
  wb_robot_cleanup();
  return 0;
}
