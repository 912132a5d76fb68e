/* A VacuumGripper and a Speaker from C: the sequence of tests/controllers/vacuum_speaker.py, its
 * files given as arguments (the WAV, the unreadable file, the missing file). */
#include <stdio.h>

#include <webots/robot.h>
#include <webots/speaker.h>
#include <webots/vacuum_gripper.h>

int main(int argc, char **argv) {
  if (argc < 4)
    return 2;
  const char *wav = argv[1], *bad = argv[2], *missing = argv[3];
  wb_robot_init();
  WbDeviceTag gripper = wb_robot_get_device("gripper"), speaker = wb_robot_get_device("speaker");
  printf("on %d\n", (int)wb_vacuum_gripper_is_on(gripper));
  wb_vacuum_gripper_enable_presence(gripper, 16);
  wb_robot_step(16);
  printf("presence off %d\n", (int)wb_vacuum_gripper_get_presence(gripper));
  wb_vacuum_gripper_turn_on(gripper);
  printf("on %d\n", (int)wb_vacuum_gripper_is_on(gripper));
  wb_robot_step(16);
  printf("presence on %d %d\n", (int)wb_vacuum_gripper_get_presence(gripper),
         wb_vacuum_gripper_get_presence_sampling_period(gripper));
  wb_vacuum_gripper_turn_off(gripper);
  wb_robot_step(16);
  printf("presence off %d %d\n", (int)wb_vacuum_gripper_get_presence(gripper), (int)wb_vacuum_gripper_is_on(gripper));

  wb_speaker_play_sound(speaker, speaker, wav, 1.0, 1.0, 0.0, false);
  int n = 0;
  while (wb_speaker_is_sound_playing(speaker, wav)) {
    wb_robot_step(16);
    n++;
  }
  printf("played %d\n", n);
  wb_speaker_play_sound(speaker, speaker, wav, 0.5, 1.0, 0.0, true);
  for (int k = 0; k < 50; k++)
    wb_robot_step(16);
  printf("looping %d %d\n", (int)wb_speaker_is_sound_playing(speaker, wav), (int)wb_speaker_is_sound_playing(speaker, ""));
  wb_speaker_stop(speaker, wav);
  wb_robot_step(16);
  printf("stopped %d %d\n", (int)wb_speaker_is_sound_playing(speaker, wav), (int)wb_speaker_is_sound_playing(speaker, ""));
  wb_speaker_play_sound(speaker, speaker, missing, 1.0, 1.0, 0.0, false);
  wb_speaker_play_sound(speaker, speaker, bad, 1.0, 1.0, 0.0, false);
  printf("bad files %d %d\n", (int)wb_speaker_is_sound_playing(speaker, missing),
         (int)wb_speaker_is_sound_playing(speaker, bad));
  printf("engine %s", wb_speaker_get_engine(speaker));
  printf(" %d", (int)wb_speaker_set_engine(speaker, "microsoft"));
  printf(" %d\n", (int)wb_speaker_set_engine(speaker, "pico"));
  printf("language %s", wb_speaker_get_language(speaker));
  printf(" %d", (int)wb_speaker_set_language(speaker, "fr-FR"));
  printf(" %d", (int)wb_speaker_set_language(speaker, "pt-BR"));
  printf(" %d", (int)wb_speaker_set_language(speaker, "french"));
  printf(" %s\n", wb_speaker_get_language(speaker));
  wb_speaker_speak(speaker, "one two three", 1.0);
  n = 0;
  while (wb_speaker_is_speaking(speaker)) {
    wb_robot_step(16);
    n++;
  }
  printf("spoke %d\n", n);
  wb_robot_cleanup();
  return 0;
}
