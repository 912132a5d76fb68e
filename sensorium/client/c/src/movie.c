/* Sensorium C controller library: a Supervisor's movies (wb_supervisor_movie_*), as the Python
 * client's wb_movie.py. The server renders the Viewpoint's frames at the movie's frame times; this
 * library takes them after each step reply and writes them, raw RGB, into an ffmpeg it starts (H.264
 * in an MP4 file, written to a temporary file beside the movie's and renamed onto it once complete:
 * the server never writes a file a client names; a shell waiting for ffmpeg renames it, FINISHER, so a
 * controller killed while ffmpeg completes the file still leaves the movie). The world ending while
 * recording (the step answers -1) ends the movie with the frames taken, its status then Webots' for a
 * recording its world load cancels. Without ffmpeg on PATH a recording fails at its start with one
 * line. One robot per process, so the movie's state is this file's. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <webots/supervisor.h>

#include "internal.h"

extern char **environ;

#define FINISH_WAIT_MS 600000 /* how long a controller ending waits for its movie's encoder */
/* sh -c script run as FINISHER sh MOVIE TMP ffmpeg ARGS...: ffmpeg, then TMP renamed onto MOVIE (exit 99: the
   rename failed; ffmpeg's own status when it failed), TMP removed unless renamed: whether or not we live */
#define FINISHER                                                                                                     \
  "f=$1 t=$2; shift 2; \"$@\" || { s=$?; rm -f -- \"$t\"; exit $s; }; "                                         \
  "mv -f -- \"$t\" \"$f\" 2>/dev/null || { rm -f -- \"$t\"; exit 99; }"
#define RENAME_FAILED 99

static int g_status = WB_SUPERVISOR_MOVIE_READY;
static pid_t g_encoder = -1;
static int g_pipe = -1;
static char g_name[4096], g_tmp[4096 + 64];
#define TMP_BASE 192 /* bytes of the movie's name in its temporary's (wb_movie.TMP_BASE) */
static long long g_frames;
static bool g_said_full;
static bool g_world_ended; /* the world ended while recording: Webots' status for it once written */

static void fail(const char *func, const char *why, int status) {
  fprintf(stderr, "Error: %s(): %s.\n", func, why);
  g_status = status;
}

/* ffmpeg's path on PATH into out, or false */
static bool find_ffmpeg(char *out, size_t n) {
  const char *path = getenv("PATH");
  if (path == NULL)
    return false;
  while (*path) {
    const char *end = strchr(path, ':');
    size_t len = end ? (size_t)(end - path) : strlen(path);
    if (len > 0 && snprintf(out, n, "%.*s/ffmpeg", (int)len, path) < (int)n && access(out, X_OK) == 0)
      return true;
    path += len + (end ? 1 : 0);
  }
  return false;
}

static bool is_dir(const char *p) {
  struct stat st;
  return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

typedef struct {
  int width, height, acceleration;
  bool caption;
} start_args;

static void args_start(sn_req *r, const void *arg) {
  const start_args *a = arg;
  sn_req_key(r, "width");
  msgpack_pack_int(&r->pk, a->width);
  sn_req_key(r, "height");
  msgpack_pack_int(&r->pk, a->height);
  sn_req_key(r, "acceleration");
  msgpack_pack_int(&r->pk, a->acceleration);
  sn_req_key(r, "caption");
  sn_arg_bool(r, &a->caption);
}

static void server_stop(sn_robot *rb) {
  sn_reply rep;
  if (sn_robot_call(rb, "robot/movie_stop", 0, NULL, NULL, "wb_supervisor_movie_stop_recording", &rep) == 0)
    sn_reply_free(&rep);
}

/* the recording ends without a movie: the encoder stopped, its file removed */
static void abort_movie(const char *func, const char *why, int status) {
  if (g_pipe >= 0)
    close(g_pipe);
  g_pipe = -1;
  if (g_encoder > 0) {
    kill(-g_encoder, SIGKILL); /* its group: the shell that renames and ffmpeg */
    waitpid(g_encoder, NULL, 0);
  }
  g_encoder = -1;
  remove(g_tmp);
  fail(func, why, status);
}

static void start(sn_robot *rb, const char *func, const char *filename, int width, int height, int quality,
                  int acceleration, bool caption) {
  size_t n = strlen(filename);
  bool mp4 = n >= 4 && strcasecmp(filename + n - 4, ".mp4") == 0;
  if (snprintf(g_name, sizeof g_name, "%s%s", filename, mp4 ? "" : ".mp4") >= (int)sizeof g_name) {
    fail(func, "the movie's file name is too long", WB_SUPERVISOR_MOVIE_SIMULATION_ERROR);
    return;
  }
  char folder[4096];
  snprintf(folder, sizeof folder, "%s", g_name);
  char *slash = strrchr(folder, '/');
  const char *base = slash ? g_name + (slash - folder) + 1 : g_name;
  if (slash == NULL)
    snprintf(folder, sizeof folder, ".");
  else
    slash[slash == folder ? 1 : 0] = '\0'; /* "/name" is in "/" */
  char why[8400];
  if (is_dir(g_name) || !is_dir(folder)) {
    if (is_dir(g_name))
      snprintf(why, sizeof why, "cannot write the movie '%s': it is a folder", sn_shown(g_name));
    else
      snprintf(why, sizeof why, "cannot write the movie '%s': no folder '%s'", sn_shown(g_name), sn_shown(folder));
    fail(func, why, WB_SUPERVISOR_MOVIE_SIMULATION_ERROR);
    return;
  }
  char ffmpeg[4200];
  if (!find_ffmpeg(ffmpeg, sizeof ffmpeg)) {
    fail(func,
         "ffmpeg is not on PATH: Sensorium's movies are encoded by ffmpeg (install it, e.g. apt-get install ffmpeg); "
         "nothing recorded",
         WB_SUPERVISOR_MOVIE_ENCODING_ERROR);
    return;
  }
  if (rb->terminated) { /* the world ended before: a movie that ends with it, without a frame */
    fail(func, "nothing was recorded because the simulation did not run", WB_SUPERVISOR_MOVIE_SIMULATION_ERROR);
    return;
  }
  start_args a = {width, height, acceleration, caption};
  sn_reply rep;
  if (sn_robot_call(rb, "robot/movie_start", 4, args_start, &a, func, &rep) != 0) {
    g_status = WB_SUPERVISOR_MOVIE_SIMULATION_ERROR;
    return;
  }
  long long step_ms = sn_int_or(rep.result, "step_ms", 0);
  sn_reply_free(&rep);
  if (step_ms < 1) {
    server_stop(rb);
    fail(func, "the server sent no frame step", WB_SUPERVISOR_MOVIE_SIMULATION_ERROR);
    return;
  }
  /* Webots' bit rate: quality x fps x pixels / 256; its frame rate: acceleration x 1000 / step_ms */
  long long bitrate = (long long)quality * acceleration * 1000 * width * height / (256 * step_ms);
  if (bitrate < 1000)
    bitrate = 1000;
  /* the movie's name cut to TMP_BASE bytes: a name near the 255-byte limit would leave none for the rest */
  snprintf(g_tmp, sizeof g_tmp, "%s/.%.*s.%ld.tmp.mp4", folder, TMP_BASE, base, (long)getpid());
  char size[64], rate[64], bits[32];
  snprintf(size, sizeof size, "%dx%d", width, height);
  snprintf(rate, sizeof rate, "%lld/%lld", (long long)acceleration * 1000, step_ms);
  snprintf(bits, sizeof bits, "%lld", bitrate);
  char *argv[] = {"/bin/sh", "-c", FINISHER, "sh", g_name, g_tmp, ffmpeg, "-hide_banner", "-loglevel", "error", "-y",
                  "-f", "rawvideo", "-pix_fmt", "rgb24",
                  "-s", size, "-framerate", rate, "-i", "pipe:0", "-an", "-c:v", "libx264", "-b:v", bits, "-g", "132",
                  "-pix_fmt", "yuv420p", "-f", "mp4", g_tmp, NULL};
  int fds[2];
  if (pipe(fds) != 0) {
    server_stop(rb);
    fail(func, "cannot make a pipe to ffmpeg", WB_SUPERVISOR_MOVIE_ENCODING_ERROR);
    return;
  }
  fcntl(fds[1], F_SETFD, FD_CLOEXEC); /* later children do not hold the encoder's input open */
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[0], 0);
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP); /* its own group: a Ctrl-C does not cut the file short */
  posix_spawnattr_setpgroup(&attr, 0);
  pid_t pid;
  int rc = posix_spawn(&pid, "/bin/sh", &actions, &attr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  close(fds[0]);
  if (rc != 0) {
    close(fds[1]);
    server_stop(rb);
    snprintf(why, sizeof why, "cannot start ffmpeg: %s", strerror(rc));
    fail(func, why, WB_SUPERVISOR_MOVIE_ENCODING_ERROR);
    return;
  }
  /* a dead encoder is a write error here, not the end of the controller */
  struct sigaction old;
  if (sigaction(SIGPIPE, NULL, &old) == 0 && old.sa_handler == SIG_DFL)
    signal(SIGPIPE, SIG_IGN);
  g_encoder = pid;
  g_pipe = fds[1];
  g_frames = 0;
  g_said_full = false;
  g_world_ended = false;
  g_status = WB_SUPERVISOR_MOVIE_RECORDING;
}

static bool write_all(int fd, const char *p, size_t n) {
  while (n > 0) {
    ssize_t k = write(fd, p, n);
    if (k < 0 && errno == EINTR)
      continue;
    if (k <= 0)
      return false;
    p += k;
    n -= (size_t)k;
  }
  return true;
}

static void stop(sn_robot *rb, const char *func);

/* the world ended while recording (its step answered -1: a worldReload, a worldLoad, a quit): Webots cancels
   the recording at a world load; here the frames taken so far are the movie, encoded at once (while the
   controller is given its last second), its status Webots' once the file is written */
static void end_with_world(sn_robot *rb) {
  if (g_status != WB_SUPERVISOR_MOVIE_RECORDING || !rb->terminated || g_world_ended)
    return;
  g_world_ended = true;
  const char *func = "wb_supervisor_movie_start_recording";
  if (g_frames > 0)
    fprintf(stderr,
            "Warning: %s(): the world ended while recording (a reload, a load, a quit): the movie is written with its "
            "%lld frames; movieFailed() is then true, as Webots reports a recording a world load cancels.\n",
            func, g_frames);
  stop(rb, func);
}

/* after each step reply: the frames the server rendered, into the encoder. Also the one place the world's end is
   seen: every way the controller's steps end calls it (sn_steps_ended) */
void sn_movie_after_step(sn_robot *rb) {
  const char *func = "wb_supervisor_movie_start_recording";
  bool more = true;
  end_with_world(rb);
  while (g_status == WB_SUPERVISOR_MOVIE_RECORDING && !rb->terminated && more) {
    sn_reply rep;
    if (sn_robot_call(rb, "robot/movie_frames", 0, NULL, NULL, func, &rep) != 0) {
      abort_movie(func, "the server ended the movie", WB_SUPERVISOR_MOVIE_SIMULATION_ERROR);
      return;
    }
    const msgpack_object *frames = sn_get(rep.result, "frames");
    const msgpack_object *m = sn_get(rep.result, "more"), *full = sn_get(rep.result, "full");
    more = m != NULL && m->type == MSGPACK_OBJECT_BOOLEAN && m->via.boolean;
    bool written = true;
    if (frames != NULL && frames->type == MSGPACK_OBJECT_ARRAY)
      for (uint32_t i = 0; written && i < frames->via.array.size; i++) {
        const msgpack_object *f = &frames->via.array.ptr[i];
        written = f->type == MSGPACK_OBJECT_BIN && write_all(g_pipe, f->via.bin.ptr, f->via.bin.size);
        g_frames += written;
      }
    if (full != NULL && full->type == MSGPACK_OBJECT_BOOLEAN && full->via.boolean && !g_said_full) {
      g_said_full = true;
      fprintf(stderr, "Warning: %s(): the movie reached its frame limit; later frames are not recorded.\n", func);
    }
    char *failed = sn_strdup_obj(sn_get(rep.result, "failed"));
    sn_reply_free(&rep);
    if (!written) {
      server_stop(rb);
      abort_movie(func, "ffmpeg stopped encoding the movie", WB_SUPERVISOR_MOVIE_ENCODING_ERROR);
    } else if (failed != NULL && failed[0]) {
      server_stop(rb);
      abort_movie(func, failed, WB_SUPERVISOR_MOVIE_SIMULATION_ERROR);
    }
    free(failed);
  }
}

static void stop(sn_robot *rb, const char *func) {
  if (g_status != WB_SUPERVISOR_MOVIE_RECORDING)
    return;
  if (!rb->terminated) { /* (the world ended: the frames taken so far are the movie) */
    sn_movie_after_step(rb);
    if (g_status != WB_SUPERVISOR_MOVIE_RECORDING)
      return;
    server_stop(rb);
  }
  if (g_frames == 0) {
    abort_movie(func, "nothing was recorded because the simulation did not run",
                WB_SUPERVISOR_MOVIE_SIMULATION_ERROR);
    return;
  }
  close(g_pipe); /* ffmpeg ends the file and exits */
  g_pipe = -1;
  g_status = WB_SUPERVISOR_MOVIE_SAVING;
}

/* Webots' status, the encoder's end looked at (waited for up to wait_ms) */
static int poll_movie(int wait_ms) {
  if (g_status != WB_SUPERVISOR_MOVIE_SAVING || g_encoder <= 0)
    return g_status;
  const char *func = "wb_supervisor_movie_stop_recording";
  int st = 0;
  pid_t done = waitpid(g_encoder, &st, WNOHANG);
  for (int waited = 0; done == 0 && waited < wait_ms; waited += 10) {
    struct timespec ts = {0, 10 * 1000 * 1000};
    nanosleep(&ts, NULL);
    done = waitpid(g_encoder, &st, WNOHANG);
  }
  if (done == 0)
    return g_status;
  g_encoder = -1;
  char why[8400];
  if (done > 0 && WIFEXITED(st) && WEXITSTATUS(st) == RENAME_FAILED) {
    remove(g_tmp);
    snprintf(why, sizeof why, "cannot write '%s': the encoded movie could not be renamed onto it", sn_shown(g_name));
    fail(func, why, WB_SUPERVISOR_MOVIE_WRITE_ERROR);
  } else if (done < 0 || !WIFEXITED(st) || WEXITSTATUS(st) != 0) {
    remove(g_tmp);
    snprintf(why, sizeof why, "ffmpeg failed to encode the movie (exit status %d)", WIFEXITED(st) ? WEXITSTATUS(st) : -1);
    fail(func, why, WB_SUPERVISOR_MOVIE_ENCODING_ERROR);
  } else
    g_status = g_world_ended ? WB_SUPERVISOR_MOVIE_SIMULATION_ERROR : WB_SUPERVISOR_MOVIE_READY;
  return g_status;
}

/* the controller ends: a movie still recording is stopped and its file completed */
void sn_movie_finish(sn_robot *rb) {
  const char *func = "wb_supervisor_movie_stop_recording";
  stop(rb, func);
  poll_movie(FINISH_WAIT_MS);
  if (g_status == WB_SUPERVISOR_MOVIE_SAVING)
    abort_movie(func, "ffmpeg did not finish the movie in time", WB_SUPERVISOR_MOVIE_ENCODING_ERROR);
}

void wb_supervisor_movie_start_recording(const char *filename, int width, int height, int codec, int quality,
                                         int acceleration, bool caption) {
  const char *func = "wb_supervisor_movie_start_recording";
  (void)codec; /* ignored, as in Webots */
  sn_robot *rb = sn_supervisor(func);
  if (rb == NULL)
    return;
  int status = poll_movie(0);
  if (status == WB_SUPERVISOR_MOVIE_RECORDING || status == WB_SUPERVISOR_MOVIE_SAVING) {
    fprintf(stderr, "Error: %s(): movie recording has already been started.\n", func);
    return;
  }
  if (filename == NULL || filename[0] == '\0') {
    fprintf(stderr, "Error: %s() called with NULL or empty 'filename' argument.\n", func);
    return;
  }
  if (width <= 0 || height <= 0) {
    fprintf(stderr, "Error: %s(): 'width' and 'height' arguments must be postitive.\n", func);
    return;
  }
  if (quality < 1 || quality > 100) {
    fprintf(stderr, "Error: %s(): 'quality' argument (%d) must be between 1 and 100.\n", func, quality);
    return;
  }
  if (acceleration < 1) {
    fprintf(stderr, "Error: %s(): 'acceleration' argument must be greater than or equal to 1.\n", func);
    return;
  }
  start(rb, func, filename, width, height, quality, acceleration, caption);
}

void wb_supervisor_movie_stop_recording(void) {
  const char *func = "wb_supervisor_movie_stop_recording";
  sn_robot *rb = sn_supervisor(func);
  if (rb != NULL)
    stop(rb, func);
}

bool wb_supervisor_movie_is_ready(void) {
  sn_robot *rb = sn_supervisor("wb_supervisor_movie_is_ready");
  if (rb == NULL)
    return false;
  int status = poll_movie(0);
  return status == WB_SUPERVISOR_MOVIE_READY || status > WB_SUPERVISOR_MOVIE_SAVING;
}

bool wb_supervisor_movie_failed(void) {
  sn_robot *rb = sn_supervisor("wb_supervisor_movie_failed");
  if (rb == NULL)
    return true;
  return poll_movie(0) > WB_SUPERVISOR_MOVIE_SAVING;
}

int wb_supervisor_movie_get_status(void) {
  static bool warned = false;
  if (!warned) {
    fprintf(stderr, "Warning: %s() is deprecated, use wb_supervisor_movie_is_ready() and wb_supervisor_movie_failed() "
                    "instead.\n", __func__);
    warned = true;
  }
  sn_robot *rb = sn_supervisor(__func__);
  if (rb == NULL)
    return WB_SUPERVISOR_MOVIE_SIMULATION_ERROR;
  return poll_movie(0);
}

void wb_supervisor_start_movie(const char *file, int width, int height, int codec, int quality, int acceleration,
                               bool caption) {
  wb_supervisor_movie_start_recording(file, width, height, codec, quality, acceleration, caption);
}

void wb_supervisor_stop_movie(void) {
  wb_supervisor_movie_stop_recording();
}

int wb_supervisor_get_movie_status(void) {
  return wb_supervisor_movie_get_status();
}
