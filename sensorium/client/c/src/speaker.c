/* Sensorium C controller library: Speaker. A headless server plays no audio, but the speaker's state
 * follows Webots (README "The Speaker"): play_sound reads the WAV file here, as libController reads
 * it (relative to the controller's folder, or absolute), and tells the server its frames and rate;
 * the sound plays in simulated time and the step reply that ends it says so. is_sound_playing and
 * is_speaking answer this controller's copy at once (true from the call, false once a step reply
 * says it is over, or after stop), as libController's do. The engine and language are
 * libController's own: "pico" and "en-US" at start, the setters accepting what Webots' accept off
 * Windows. The same lines as the Python client for out-of-range values and bad files. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/nodes.h>
#include <webots/speaker.h>

#include "internal.h"

typedef struct sn_sound {
  struct sn_sound *next;
  int64_t frames;
  int64_t rate;
  bool playing;
  char name[];
} sn_sound;

static const char *const LANGUAGES[] = {"en-US", "en-UK", "de-DE", "es-ES", "fr-FR", "it-IT"};
#define N_LANGUAGES (sizeof LANGUAGES / sizeof LANGUAGES[0])
#define MAX_PITCH 1e9 /* the greatest pitch the server takes (wb_speaker.py MAX_PITCH) */

static sn_sound *find(sn_device *d, const char *name) {
  for (sn_sound *s = d->sounds; s != NULL; s = s->next)
    if (strcmp(s->name, name) == 0)
      return s;
  return NULL;
}

static uint32_t le32(const unsigned char *p) {
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* A WAV file's frames and rate: 0; -1 when it is missing; -2 when it is no 8 or 16 bit mono or stereo
 * PCM wave (what Python's wave module reads: the data chunk's size over the frame size). */
static int wav_length(const char *path, int64_t *frames, int64_t *rate) {
  FILE *f = fopen(path, "rb");
  if (f == NULL)
    return -1;
  unsigned char h[12], c[8], fmt[16];
  int ok = -2, have_fmt = 0;
  unsigned channels = 0, bits = 0;
  uint32_t sample_rate = 0;
  if (fread(h, 1, 12, f) != 12 || memcmp(h, "RIFF", 4) != 0 || memcmp(h + 8, "WAVE", 4) != 0)
    goto done;
  while (fread(c, 1, 8, f) == 8) {
    uint32_t size = le32(c + 4);
    if (memcmp(c, "fmt ", 4) == 0) {
      if (size < 16 || fread(fmt, 1, 16, f) != 16)
        goto done;
      if ((fmt[0] | fmt[1] << 8) != 1) /* WAVE_FORMAT_PCM */
        goto done;
      channels = fmt[2] | fmt[3] << 8;
      sample_rate = le32(fmt + 4);
      bits = fmt[14] | fmt[15] << 8;
      have_fmt = 1;
      size -= 16;
    } else if (memcmp(c, "data", 4) == 0) {
      if (!have_fmt || (channels != 1 && channels != 2) || (bits != 8 && bits != 16) || sample_rate == 0 ||
          sample_rate >= UINT32_C(1) << 31) /* a damaged header: the server takes rates below 2^31 */
        goto done;
      *frames = (int64_t)size / (int64_t)(channels * (bits / 8));
      *rate = sample_rate;
      ok = 0;
      goto done;
    }
    if (fseek(f, (long)size + (size & 1), SEEK_CUR) != 0) /* chunks are padded to even sizes */
      goto done;
  }
done:
  fclose(f);
  return ok;
}

typedef struct {
  const char *name;
  int64_t frames, rate;
  double volume, pitch, balance;
  bool loop;
  int side;
} play_args;

static void pack_play(sn_req *r, const void *arg) {
  const play_args *a = arg;
  sn_req_key(r, "sound");
  sn_req_str(r, a->name);
  sn_req_key(r, "frames");
  msgpack_pack_int64(&r->pk, a->frames);
  sn_req_key(r, "rate");
  msgpack_pack_int64(&r->pk, a->rate);
  sn_req_key(r, "volume");
  msgpack_pack_double(&r->pk, a->volume);
  sn_req_key(r, "pitch");
  msgpack_pack_double(&r->pk, a->pitch);
  sn_req_key(r, "balance");
  msgpack_pack_double(&r->pk, a->balance);
  sn_req_key(r, "loop");
  if (a->loop)
    msgpack_pack_true(&r->pk);
  else
    msgpack_pack_false(&r->pk);
  sn_req_key(r, "side");
  msgpack_pack_int(&r->pk, a->side);
}

static bool call(sn_device *d, const char *item, uint32_t nargs, sn_arg_fn add, const void *arg, const char *func) {
  sn_robot *rb = sn_robot_get(func);
  if (rb->terminated)
    return true;
  char service[512];
  snprintf(service, sizeof service, "%s/%s", d->name, item);
  sn_reply rep;
  if (sn_robot_call(rb, service, nargs, add, arg, func, &rep) != 0)
    return false;
  sn_reply_free(&rep);
  return true;
}

static void play(sn_device *d, const char *sound, double volume, double pitch, double balance, bool loop, int side) {
  const char *func = "wb_speaker_play_sound";
  sn_sound *s = find(d, sound);
  if (s == NULL) {
    int64_t frames = 0, rate = 0;
    int got = wav_length(sound, &frames, &rate);
    if (got == -1) {
      fprintf(stderr, "Warning: %s(): Sound file '%s' not found. The sound file should be defined relatively to the "
              "controller, the PROTO or absolutely.\n", func, sn_shown(sound));
      return;
    }
    if (got != 0) {
      fprintf(stderr, "Warning: %s(): Impossible to play '%s'. Make sure the file format is supported (8 or 16 bits, "
              "mono or stereo wave).\n", func, sn_shown(sound));
      return;
    }
    size_t n = strlen(sound) + 1;
    s = malloc(sizeof *s + n);
    if (s == NULL)
      return;
    memcpy(s->name, sound, n);
    s->frames = frames;
    s->rate = rate;
    s->playing = false;
    s->next = d->sounds;
    d->sounds = s;
  }
  play_args a = {sound, s->frames, s->rate, volume, pitch, balance, loop, side};
  if (call(d, "play_sound", 8, pack_play, &a, func))
    s->playing = true;
}

static sn_device *speaker_tag(WbDeviceTag tag, const char *which, const char *func) {
  sn_robot *rb = sn_robot_get(func);
  if (tag < 1 || tag > (WbDeviceTag)rb->n_devices || rb->devices[tag - 1].node_type != WB_NODE_SPEAKER) {
    fprintf(stderr, "Error: %s(): invalid '%s' device tag.\n", func, which);
    return NULL;
  }
  return sn_device_get(tag, SN_SPEAKER, func); /* NULL (and its line) for a speaker the server only lists */
}

void wb_speaker_play_sound(WbDeviceTag left, WbDeviceTag right, const char *sound, double volume, double pitch,
                           double balance, bool loop) {
  const char *func = "wb_speaker_play_sound";
  sn_device *l = NULL, *r = NULL;
  if (left && (l = speaker_tag(left, "left", func)) == NULL)
    return;
  if (right && (r = speaker_tag(right, "right", func)) == NULL)
    return;
  if (sound == NULL || isnan(volume) || isnan(pitch) || isnan(balance)) {
    fprintf(stderr, "Error: %s() called with an invalid argument (a NULL sound or a NaN value).\n", func);
    return;
  }
  if (volume < 0) {
    fprintf(stderr, "Warning: %s() called with a negative volume value: %g. Setting volume to 0.\n", func, volume);
    volume = 0;
  }
  if (volume > 1) {
    fprintf(stderr, "Warning: %s() called with a volume value greater than 1: %g. Setting volume to 1.\n", func, volume);
    volume = 1;
  }
  if (pitch < 0) {
    fprintf(stderr, "Warning: %s() called with a negative pitch value: %g. Setting pitch to 0.\n", func, pitch);
    pitch = 0;
  }
  if (pitch > MAX_PITCH) { /* ours: the server takes at most this (+inf too is clamped) */
    fprintf(stderr, "Warning: %s() called with a pitch value greater than %g: %g. Setting pitch to %g.\n", func,
            MAX_PITCH, pitch, MAX_PITCH);
    pitch = MAX_PITCH;
  }
  if (balance < -1) {
    fprintf(stderr, "Warning: %s() called with a balance value less than -1: %g. Setting balance to -1.\n", func,
            balance);
    balance = -1;
  }
  if (balance > 1) {
    fprintf(stderr, "Warning: %s() called with a balance value greater than 1: %g. Setting balance to 1.\n", func,
            balance);
    balance = 1;
  }
  double lv = balance <= 0 ? volume : volume * (1 - balance), rv = balance <= 0 ? volume * (1 + balance) : volume;
  if (left == right && volume > 0 && l != NULL) {
    play(l, sound, volume, pitch, balance, loop, 0);
    return;
  }
  if (lv > 0 && l != NULL)
    play(l, sound, lv, pitch, 0.0, loop, -1);
  if (rv > 0 && r != NULL)
    play(r, sound, rv, pitch, 0.0, loop, 1);
}

static void pack_value_str(sn_req *r, const void *arg) {
  sn_req_key(r, "value");
  sn_req_str(r, (const char *)arg);
}

void wb_speaker_stop(WbDeviceTag tag, const char *sound) {
  sn_device *d = sn_device_get(tag, SN_SPEAKER, "wb_speaker_stop");
  if (d == NULL)
    return;
  const char *name = sound ? sound : "";
  if (!call(d, "stop", 1, pack_value_str, name, "wb_speaker_stop"))
    return;
  for (sn_sound *s = d->sounds; s != NULL; s = s->next)
    if (name[0] == '\0' || strcmp(s->name, name) == 0)
      s->playing = false;
  if (name[0] == '\0') {
    free(d->speech);
    d->speech = NULL;
  }
}

bool wb_speaker_is_sound_playing(WbDeviceTag tag, const char *sound) {
  sn_device *d = sn_device_get(tag, SN_SPEAKER, "wb_speaker_is_sound_playing");
  if (d == NULL)
    return false;
  if (sound == NULL || sound[0] == '\0') {
    if (d->speech != NULL)
      return true;
    for (sn_sound *s = d->sounds; s != NULL; s = s->next)
      if (s->playing)
        return true;
    return false;
  }
  sn_sound *s = find(d, sound);
  return s != NULL && s->playing;
}

bool wb_speaker_set_engine(WbDeviceTag tag, const char *engine) {
  sn_device *d = sn_device_get(tag, SN_SPEAKER, "wb_speaker_set_engine");
  if (d == NULL || engine == NULL || strcmp(engine, "pico") != 0)
    return false;
  snprintf(d->engine, sizeof d->engine, "pico");
  return true;
}

bool wb_speaker_set_language(WbDeviceTag tag, const char *language) {
  const char *func = "wb_speaker_set_language";
  sn_device *d = sn_device_get(tag, SN_SPEAKER, func);
  if (d == NULL)
    return false;
  const char *l = language ? language : "";
  if (strlen(l) != 5 || l[2] != '-' || l[0] < 'a' || l[0] > 'z' || l[1] < 'a' || l[1] > 'z' || l[3] < 'A' ||
      l[3] > 'Z' || l[4] < 'A' || l[4] > 'Z') {
    fprintf(stderr, "Error: %s() called with an invalid 'language' argument: \"%s\". 'language' should follow the "
            "\"ll-CC\" format where ll is the ISO 639-1 language code and CC is the ISO 3166 country code, for example, "
            "\"en-US\" or \"fr-FR\"; the \"%s\" engine speaks ", func, sn_shown(l), d->engine);
    for (size_t i = 0; i < N_LANGUAGES; i++)
      fprintf(stderr, "\"%s\"%s", LANGUAGES[i], i + 1 < N_LANGUAGES ? ", " : ".\n");
    return false;
  }
  for (size_t i = 0; i < N_LANGUAGES; i++)
    if (strcmp(l, LANGUAGES[i]) == 0) {
      snprintf(d->language, sizeof d->language, "%s", l);
      return true;
    }
  return false; /* well formed, not spoken: false without a line, as libController */
}

const char *wb_speaker_get_engine(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_SPEAKER, "wb_speaker_get_engine");
  return d ? d->engine : NULL;
}

const char *wb_speaker_get_language(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_SPEAKER, "wb_speaker_get_language");
  return d ? d->language : NULL;
}

typedef struct {
  const char *text;
  double volume;
} speak_args;

static void pack_speak(sn_req *r, const void *arg) {
  const speak_args *a = arg;
  sn_req_key(r, "text");
  sn_req_str(r, a->text);
  sn_req_key(r, "volume");
  msgpack_pack_double(&r->pk, a->volume);
}

void wb_speaker_speak(WbDeviceTag tag, const char *text, double volume) {
  const char *func = "wb_speaker_speak";
  sn_device *d = sn_device_get(tag, SN_SPEAKER, func);
  if (d == NULL)
    return;
  if (text == NULL || isnan(volume)) {
    fprintf(stderr, "Error: %s() called with an invalid argument (a NULL text or a NaN volume).\n", func);
    return;
  }
  if (volume < 0) {
    fprintf(stderr, "Warning: %s() called with negative volume value: %g. Setting volume to 0.\n", func, volume);
    volume = 0;
  }
  if (volume > 1) {
    fprintf(stderr, "Warning: %s() called with volume value greater than 1: %g. Setting volume to 1.\n", func, volume);
    volume = 1;
  }
  speak_args a = {text, volume};
  if (!call(d, "speak", 2, pack_speak, &a, func))
    return;
  size_t n = strlen(text) + 1;
  char *copy = malloc(n);
  if (copy == NULL)
    return;
  memcpy(copy, text, n);
  free(d->speech);
  d->speech = copy;
}

bool wb_speaker_is_speaking(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_SPEAKER, "wb_speaker_is_speaking");
  return d != NULL && d->speech != NULL;
}

void sn_speaker_apply(sn_device *dev, const msgpack_object *reading) {
  const msgpack_object *sounds = sn_get(reading, "sounds");
  if (sounds != NULL && sounds->type == MSGPACK_OBJECT_ARRAY)
    for (sn_sound *s = dev->sounds; s != NULL; s = s->next) {
      bool still = false;
      for (uint32_t i = 0; i < sounds->via.array.size && !still; i++) {
        const msgpack_object *o = &sounds->via.array.ptr[i];
        still = o->type == MSGPACK_OBJECT_STR && o->via.str.size == strlen(s->name) &&
                memcmp(o->via.str.ptr, s->name, o->via.str.size) == 0;
      }
      s->playing = s->playing && still;
    }
  if (sounds != NULL && !sn_bool_or(reading, "speaking", false)) {
    free(dev->speech);
    dev->speech = NULL;
  }
}

void sn_speaker_free(sn_device *dev) {
  while (dev->sounds != NULL) {
    sn_sound *next = dev->sounds->next;
    free(dev->sounds);
    dev->sounds = next;
  }
  free(dev->speech);
  dev->speech = NULL;
}
