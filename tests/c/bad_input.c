/* Bad input to the newer devices from C (tests/worlds/new_devices.yaml; tests/test_bad_input.py): the
 * lines of tests/controllers/bad_input.py both clients print, then C's own: tags of no device, of
 * another kind of device and of 0 for every Connector, Brake, VacuumGripper, Speaker and coupled
 * motor function, and NULL strings, each answered with one error line and Webots' return value.
 * Arguments: the WAV, a WAV whose header says 3e9 frames/s. */
#include <math.h>
#include <stdio.h>

#include <webots/brake.h>
#include <webots/connector.h>
#include <webots/motor.h>
#include <webots/robot.h>
#include <webots/speaker.h>
#include <webots/vacuum_gripper.h>

static WbDeviceTag speaker;

static int steps_playing(const char *sound) {
  int n = 0;
  while (wb_speaker_is_sound_playing(speaker, sound) && n < 1000) {
    wb_robot_step(16);
    n++;
  }
  return n;
}

int main(int argc, char **argv) {
  if (argc < 3)
    return 2;
  const char *wav = argv[1], *fast = argv[2];
  wb_robot_init();
  speaker = wb_robot_get_device("speaker");
  WbDeviceTag brake = wb_robot_get_device("arm brake"), dock = wb_robot_get_device("dock"),
              gripper = wb_robot_get_device("gripper"), ds = wb_robot_get_device("ds"),
              coupled = wb_robot_get_device("grip::b");
  const char *names[] = {"volume", "pitch", "balance"};
  for (int i = 0; i < 3; i++) {
    wb_speaker_play_sound(speaker, speaker, wav, i == 0 ? NAN : 1.0, i == 1 ? NAN : 1.0, i == 2 ? NAN : 0.0, false);
    printf("nan %s %d\n", names[i], (int)wb_speaker_is_sound_playing(speaker, wav));
  }
  wb_speaker_speak(speaker, "hello there", NAN);
  printf("nan speak %d\n", (int)wb_speaker_is_speaking(speaker));
  wb_brake_set_damping_constant(brake, NAN);
  const double pitches[] = {INFINITY, 1e308};
  for (int i = 0; i < 2; i++) {
    wb_speaker_play_sound(speaker, speaker, wav, 1.0, pitches[i], 0.0, false);
    int playing = wb_speaker_is_sound_playing(speaker, wav);
    printf("pitch %s %d %d\n", i == 0 ? "inf" : "1e+308", playing, steps_playing(wav));
  }
  wb_speaker_play_sound(speaker, speaker, "", 1.0, 1.0, 0.0, false);
  printf("empty sound %d\n", (int)wb_speaker_is_sound_playing(speaker, ""));
  wb_speaker_play_sound(speaker, speaker, fast, 1.0, 1.0, 0.0, false);
  printf("damaged rate %d\n", (int)wb_speaker_is_sound_playing(speaker, fast));
  wb_speaker_speak(speaker, "", 1.0);
  int speaking = wb_speaker_is_speaking(speaker);
  printf("empty speech %d %d\n", speaking, steps_playing(""));
  wb_connector_enable_presence(dock, 16);
  wb_robot_step(16);
  printf("presence %d\n", wb_connector_get_presence(dock));

  /* C's own: bad tags (0, none, another kind of device) and NULL strings */
  const WbDeviceTag bad[] = {0, 999, ds};
  for (int i = 0; i < 3; i++) {
    WbDeviceTag t = bad[i];
    wb_connector_enable_presence(t, 16);
    wb_connector_lock(t);
    wb_brake_set_damping_constant(t, 1.0);
    wb_vacuum_gripper_turn_on(t);
    wb_speaker_stop(t, NULL);
    wb_speaker_speak(t, "hi", 1.0);
    const char *engine = wb_speaker_get_engine(t), *language = wb_speaker_get_language(t);
    printf("tag %u: %d %d %d %d %u %u %d %d %d %d %d %d %d %s %s %g\n", (unsigned)t, wb_connector_get_presence(t),
           wb_connector_get_presence_sampling_period(t), (int)wb_connector_is_locked(t), (int)wb_brake_get_type(t),
           (unsigned)wb_brake_get_motor(t), (unsigned)wb_brake_get_position_sensor(t),
           (int)wb_vacuum_gripper_is_on(t), (int)wb_vacuum_gripper_get_presence(t),
           (int)wb_speaker_is_sound_playing(t, NULL), (int)wb_speaker_is_speaking(t),
           (int)wb_speaker_set_engine(t, "pico"), (int)wb_speaker_set_language(t, "en-US"),
           wb_vacuum_gripper_get_presence_sampling_period(t), engine ? engine : "NULL", language ? language : "NULL",
           wb_motor_get_multiplier(t));
  }
  wb_speaker_play_sound(ds, speaker, wav, 1.0, 1.0, 0.0, false);
  wb_speaker_play_sound(speaker, 999, wav, 1.0, 1.0, 0.0, false);
  wb_speaker_play_sound(speaker, speaker, NULL, 1.0, 1.0, 0.0, false);
  wb_speaker_speak(speaker, NULL, 1.0);
  wb_speaker_stop(speaker, NULL);
  printf("nulls %d %d %d %d\n", (int)wb_speaker_is_sound_playing(speaker, NULL), (int)wb_speaker_is_speaking(speaker),
         (int)wb_speaker_set_engine(speaker, NULL), (int)wb_speaker_set_language(speaker, NULL));
  printf("still %d %d %g %d\n", wb_connector_get_presence_sampling_period(dock), (int)wb_vacuum_gripper_is_on(gripper),
         wb_motor_get_multiplier(coupled), wb_robot_step(16));
  wb_robot_cleanup();
  return 0;
}
