/* C twin of tests/controllers/motion_player.py (same output lines) on tests/worlds/motion.yaml,
 * robot leg: motion_player DIR NAME..., DIR holding the motion files tests/test_motion_clients.py
 * writes. Loads DIR/NAME.motion for each NAME (missing, damaged, naming unknown motors: "NAME 0|1"),
 * then plays wave.motion forwards to its end,
 * in a loop (with lift.motion playing beside it, both setting the slide), and in reverse from 200 ms.
 * Each step prints: phase, simulated time (ms), the motion's time, is_over, then the float64 bits of
 * the hip, knee and slide target positions and of the hip sensor. */
#include <math.h>
#include <stdlib.h>

#include <webots/motor.h>
#include <webots/position_sensor.h>
#include <webots/robot.h>
#include <webots/utils/motion.h>

#include "common.h"

static WbDeviceTag motors[3], hip_sensor;
static int dt;

static WbMotionRef load(const char *folder, const char *name) {
  char path[4096];
  snprintf(path, sizeof path, "%s/%s.motion", folder, name);
  return wbu_motion_new(path);
}

static void bits(double v) {
  uint64_t b;
  memcpy(&b, &v, sizeof b);
  printf(" %016" PRIx64, b);
}

static void run(const char *phase, int steps, WbMotionRef wave) {
  for (int s = 0; s < steps; s++) {
    if (wb_robot_step(dt) == -1)
      exit(1);
    int time = wbu_motion_get_time(wave), over = wbu_motion_is_over(wave);
    printf("%s %.0f %d %d", phase, wb_robot_get_time() * 1000.0, time, over);
    for (int i = 0; i < 3; i++)
      bits(wb_motor_get_target_position(motors[i]));
    bits(wb_position_sensor_get_value(hip_sensor));
    printf("\n");
    fflush(stdout);
  }
}

int main(int argc, char **argv) {
  wb_robot_init();
  const char *folder = argc > 1 ? argv[1] : ".";
  dt = (int)wb_robot_get_basic_time_step();
  const char *names[3] = {"hip", "knee", "slide"};
  for (int i = 0; i < 3; i++)
    motors[i] = wb_robot_get_device(names[i]);
  hip_sensor = wb_robot_get_device("hip sensor");
  wb_position_sensor_enable(hip_sensor, dt);

  for (int i = 2; i < argc; i++) {
    WbMotionRef m = load(folder, argv[i]);
    printf("%s %d\n", argv[i], m != NULL);
    fflush(stdout);
    wbu_motion_delete(m);
  }
  WbMotionRef null = load(folder, "absent");
  wbu_motion_play(null);
  wbu_motion_set_loop(null, true);
  int over = wbu_motion_is_over(null), duration = wbu_motion_get_duration(null), time = wbu_motion_get_time(null);
  printf("null %d %d %d\n", over, duration, time); /* (called in the Python twin's order) */

  WbMotionRef wave = load(folder, "wave");
  int duration_w = wbu_motion_get_duration(wave), time_w = wbu_motion_get_time(wave), over_w = wbu_motion_is_over(wave);
  printf("wave %d %d %d\n", duration_w, time_w, over_w);
  fflush(stdout);

  wbu_motion_play(wave);
  run("forward", 33, wave);
  WbMotionRef lift = load(folder, "lift");
  wbu_motion_set_loop(wave, true);
  wbu_motion_play(wave);
  wbu_motion_play(lift);
  run("loop", 36, wave);
  wbu_motion_stop(wave);
  wbu_motion_stop(lift);
  wbu_motion_set_loop(wave, false);
  wbu_motion_set_reverse(wave, true);
  wbu_motion_set_time(wave, 200);
  wbu_motion_play(wave);
  run("reverse", 15, wave);
  int time_e = wbu_motion_get_time(wave), over_e = wbu_motion_is_over(wave), time_l = wbu_motion_get_time(lift);
  printf("end %d %d %d\n", time_e, over_e, time_l);
  fflush(stdout);
  wbu_motion_delete(lift);
  wbu_motion_delete(wave);
  wb_robot_cleanup();
  return 0;
}
