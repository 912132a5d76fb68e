/* tests/controllers/movie.py in C (tests/test_movie.py, tests/worlds/movie.wbt): a movie of the wall
 * red for 20 basic steps, blue for 20 more, stopped and waited for; then the arguments Webots'
 * libController refuses and those Sensorium refuses beyond it, one line each. Prints the same lines
 * (with $MOVIE_LEAVE set: 10 steps of a movie, $MOVIE_LEFT_NAME else left.mp4, then the end without stopping
 * it, "left"; with $MOVIE_QUIT set: 10 steps of a movie, then simulation_quit while recording, the states once
 * it is written, then a movie started after the end). */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

static const char *yes(bool b) {
  return b ? "True" : "False";
}

static void states(const char *what) {
  printf("%s %s %s\n", what, yes(wb_supervisor_movie_is_ready()), yes(wb_supervisor_movie_failed()));
}

int main(void) {
  wb_robot_init();
  const char *out = getenv("MOVIE_OUT");
  char run[4096], again[4096], bad[4096], folder[4096], controls[4096];
  snprintf(run, sizeof run, "%s/run", out); /* ".mp4" added */
  snprintf(again, sizeof again, "%s/again.mp4", out);
  snprintf(bad, sizeof bad, "%s/bad.mp4", out);
  snprintf(folder, sizeof folder, "%s/no/such/folder.mp4", out);
  snprintf(controls, sizeof controls, "%s/no\nsuch/a\tb.mp4", out);
  WbFieldRef colour = wb_supervisor_node_get_field(wb_supervisor_node_get_from_def("WALL_APP"), "baseColor");
  if (getenv("MOVIE_LEAVE") != NULL) { /* ends while recording: the controller's end writes the movie */
    char left[4096];
    const char *name = getenv("MOVIE_LEFT_NAME");
    snprintf(left, sizeof left, "%s/%s", out, name != NULL ? name : "left.mp4");
    wb_supervisor_movie_start_recording(left, 160, 120, 0, 90, 1, false);
    for (int i = 0; i < 10; i++)
      wb_robot_step(16);
    printf("left\n");
    fflush(stdout);
    wb_robot_cleanup();
    return 0;
  }
  if (getenv("MOVIE_QUIT") != NULL) { /* the world quits while recording: the frames so far are the movie */
    char name[4096];
    snprintf(name, sizeof name, "%s/quit.mp4", out);
    wb_supervisor_movie_start_recording(name, 160, 120, 0, 90, 1, false);
    for (int i = 0; i < 10; i++)
      wb_robot_step(16);
    wb_supervisor_simulation_quit(0);
    printf("quit %d\n", wb_robot_step(16));
    struct timespec ts = {0, 10 * 1000 * 1000};
    while (!wb_supervisor_movie_is_ready()) /* (a step after -1 would end the process, as Webots' library does) */
      nanosleep(&ts, NULL);
    states("saved");
    snprintf(name, sizeof name, "%s/late.mp4", out);
    wb_supervisor_movie_start_recording(name, 160, 120, 0, 90, 1, false); /* one line */
    states("late");
    fflush(stdout);
    wb_robot_cleanup();
    return 0;
  }
  states("before");
  wb_supervisor_movie_start_recording(run, 160, 120, 0, 90, 1, false);
  states("recording");
  wb_supervisor_movie_start_recording(again, 160, 120, 0, 90, 1, false); /* refused: one line */
  for (int i = 0; i < 20; i++)
    wb_robot_step(16);
  const double blue[3] = {0, 0, 1};
  wb_supervisor_field_set_sf_color(colour, blue);
  for (int i = 0; i < 20; i++)
    wb_robot_step(16);
  wb_supervisor_movie_stop_recording();
  while (!wb_supervisor_movie_is_ready())
    wb_robot_step(16);
  states("stopped");
  wb_supervisor_movie_start_recording("", 160, 120, 0, 90, 1, false);
  wb_supervisor_movie_start_recording(bad, 0, 120, 0, 90, 1, false);
  wb_supervisor_movie_start_recording(bad, 160, 120, 0, 0, 1, false);
  wb_supervisor_movie_start_recording(bad, 160, 120, 0, 90, 0, false);
  states("checked");
  wb_supervisor_movie_start_recording(bad, 161, 120, 0, 90, 1, false); /* the server's refusal */
  states("odd");
  wb_supervisor_movie_start_recording(folder, 160, 120, 0, 90, 1, false);
  states("folder");
  wb_supervisor_movie_start_recording(controls, 160, 120, 0, 90, 1, false); /* one line */
  wb_robot_step(16);
  printf("done\n");
  fflush(stdout);
  wb_robot_cleanup();
  return 0;
}
