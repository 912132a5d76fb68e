/* Sensorium C controller library: the image devices, RangeFinder and Camera. Their images live in
 * per-device buffers filled at each step from the step reply (PROTOCOL.md 3.6; zeros before the
 * first image, Webots' black for a camera), so the pointers handed out stay valid until
 * wb_robot_cleanup(). Written from Webots' documented signatures and behaviour. */
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/camera.h>
#include <webots/nodes.h>
#include <webots/range_finder.h>

#include "internal.h"

struct sn_imaging {
  int width, height;
  double fov, near, min_range, max_range;
  double min_fov, max_fov; /* camera: its Zoom's range (fov, fov without a Zoom) */
  double focal_length, focal_distance, min_focal_distance, max_focal_distance; /* its Focus (0s without) */
  float *range;          /* range finder: height rows of width floats */
  unsigned char *image;  /* camera: BGRA, height rows of 4 * width bytes */
  double exposure;
  bool planar;
  /* camera recognition */
  bool has_recognition, has_segmentation, segmentation_enabled;
  int recognition_period;
  WbCameraRecognitionObject *objects;
  int n_objects;
  unsigned char *segmentation; /* BGRA like the image */
};

#define PI 3.14159265358979323846
#define MAX_PIXELS (1 << 28) /* the server's --allow-large bound on an image's rays */

int sn_imaging_describe(sn_device *d, const msgpack_object *desc) {
  if (d->kind != SN_RANGE_FINDER && d->kind != SN_CAMERA)
    return 0;
  struct sn_imaging *im = calloc(1, sizeof *im);
  if (im == NULL)
    return -1;
  d->imaging = im;
  im->width = (int)sn_int_or(desc, "width", 0);
  im->height = (int)sn_int_or(desc, "height", 0);
  if (im->width <= 0 || im->height <= 0 || (int64_t)im->width * im->height > MAX_PIXELS)
    return -1;
  im->fov = sn_double_or(desc, "fov", NAN);
  im->near = sn_double_or(desc, "near", NAN);
  im->min_range = sn_double_or(desc, "minRange", NAN);
  im->max_range = sn_double_or(desc, "maxRange", NAN);
  im->exposure = sn_double_or(desc, "exposure", NAN);
  im->min_fov = sn_double_or(desc, "min_fov", im->fov);
  im->max_fov = sn_double_or(desc, "max_fov", im->fov);
  im->focal_length = sn_double_or(desc, "focal_length", 0.0);
  im->focal_distance = sn_double_or(desc, "focal_distance", 0.0);
  im->min_focal_distance = sn_double_or(desc, "min_focal_distance", 0.0);
  im->max_focal_distance = sn_double_or(desc, "max_focal_distance", 0.0);
  char *projection = sn_strdup_obj(sn_get(desc, "projection"));
  im->planar = projection == NULL || strcmp(projection, "planar") == 0;
  free(projection);
  size_t n = (size_t)im->width * (size_t)im->height;
  if (d->kind == SN_RANGE_FINDER)
    return (im->range = calloc(n, sizeof(float))) == NULL ? -1 : 0;
  im->has_recognition = sn_bool_or(desc, "has_recognition", false);
  im->has_segmentation = sn_bool_or(desc, "has_segmentation", false);
  if ((im->image = malloc(4 * n)) == NULL || (im->segmentation = malloc(4 * n)) == NULL)
    return -1;
  for (size_t j = 0; j < n; j++) { /* Webots' black before the first image: 0xFF000000 */
    im->image[4 * j] = im->image[4 * j + 1] = im->image[4 * j + 2] = 0;
    im->image[4 * j + 3] = 255;
  }
  memcpy(im->segmentation, im->image, 4 * n);
  return 0;
}

static void free_objects(struct sn_imaging *im) {
  for (int i = 0; i < im->n_objects; i++) {
    free(im->objects[i].colors);
    free(im->objects[i].model);
  }
  free(im->objects);
  im->objects = NULL;
  im->n_objects = 0;
}

static void read_doubles(const msgpack_object *arr, double *out, int n) {
  for (int i = 0; i < n; i++)
    out[i] = NAN;
  if (arr == NULL || arr->type != MSGPACK_OBJECT_ARRAY)
    return;
  for (uint32_t i = 0; i < arr->via.array.size && (int)i < n; i++)
    if (!sn_as_double(&arr->via.array.ptr[i], &out[i]))
      out[i] = NAN;
}

static void read_ints(const msgpack_object *arr, int *out, int n) {
  for (int i = 0; i < n; i++)
    out[i] = 0;
  if (arr == NULL || arr->type != MSGPACK_OBJECT_ARRAY)
    return;
  for (uint32_t i = 0; i < arr->via.array.size && (int)i < n; i++) {
    int64_t v;
    if (sn_as_int64(&arr->via.array.ptr[i], &v))
      out[i] = (int)v;
  }
}

/* the step reply's "recognition": a list of object maps (PROTOCOL.md 3.6) */
static void read_objects(sn_device *d, const msgpack_object *list) {
  struct sn_imaging *im = d->imaging;
  if (list->type != MSGPACK_OBJECT_ARRAY || list->via.array.size > (1u << 20)) {
    fprintf(stderr, "Warning: camera '%s': recognition objects that are not a list: ignored\n", sn_shown(d->name));
    return;
  }
  free_objects(im);
  uint32_t n = list->via.array.size;
  if (n == 0)
    return;
  if ((im->objects = calloc(n, sizeof *im->objects)) == NULL)
    return;
  for (uint32_t i = 0; i < n; i++) {
    const msgpack_object *o = &list->via.array.ptr[i];
    WbCameraRecognitionObject *r = &im->objects[im->n_objects];
    if (o->type != MSGPACK_OBJECT_MAP)
      continue;
    r->id = (int)sn_int_or(o, "id", 0);
    read_doubles(sn_get(o, "position"), r->position, 3);
    read_doubles(sn_get(o, "orientation"), r->orientation, 4);
    read_doubles(sn_get(o, "size"), r->size, 2);
    read_ints(sn_get(o, "position_on_image"), r->position_on_image, 2);
    read_ints(sn_get(o, "size_on_image"), r->size_on_image, 2);
    const msgpack_object *colors = sn_get(o, "colors");
    int nc = colors && colors->type == MSGPACK_OBJECT_ARRAY ? (int)(colors->via.array.size / 3) : 0;
    r->number_of_colors = nc;
    r->colors = calloc(nc > 0 ? 3 * (size_t)nc : 1, sizeof(double));
    if (r->colors != NULL && nc > 0)
      read_doubles(colors, r->colors, 3 * nc);
    r->model = sn_strdup_obj(sn_get(o, "model"));
    if (r->model == NULL)
      r->model = strdup("");
    im->n_objects++;
  }
}

void sn_imaging_free(sn_device *d) {
  if (d->imaging == NULL)
    return;
  free(d->imaging->range);
  free(d->imaging->image);
  free(d->imaging->segmentation);
  free_objects(d->imaging);
  free(d->imaging);
  d->imaging = NULL;
}

static float le_float(const unsigned char *p) {
  uint32_t u = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
  float f;
  memcpy(&f, &u, sizeof f);
  return f;
}

void sn_imaging_apply(sn_device *d, const msgpack_object *reading) {
  struct sn_imaging *im = d->imaging;
  if (im == NULL)
    return;
  size_t n = (size_t)im->width * (size_t)im->height;
  if (d->kind == SN_CAMERA) {
    const msgpack_object *bgra = sn_get(reading, "image");
    if (bgra != NULL && bgra->type == MSGPACK_OBJECT_BIN && bgra->via.bin.size == 4 * n)
      memcpy(im->image, bgra->via.bin.ptr, 4 * n);
    else if (bgra != NULL)
      fprintf(stderr, "Warning: camera '%s': image of %u bytes, expected %zu: ignored\n", sn_shown(d->name),
              bgra->type == MSGPACK_OBJECT_BIN ? bgra->via.bin.size : 0u, 4 * n);
    const msgpack_object *seg = sn_get(reading, "segmentation_image");
    if (seg != NULL && seg->type == MSGPACK_OBJECT_BIN && seg->via.bin.size == 4 * n)
      memcpy(im->segmentation, seg->via.bin.ptr, 4 * n);
    const msgpack_object *objs = sn_get(reading, "recognition");
    if (objs != NULL)
      read_objects(d, objs);
    im->fov = sn_double_or(reading, "fov", im->fov); /* a zoomed camera's (a reset may change it) */
    return;
  }
  const msgpack_object *img = sn_get(reading, "range_image");
  if (img != NULL && img->type == MSGPACK_OBJECT_BIN && img->via.bin.size == 4 * n) {
    const unsigned char *p = (const unsigned char *)img->via.bin.ptr;
    for (size_t j = 0; j < n; j++)
      im->range[j] = le_float(p + 4 * j);
  } else if (img != NULL)
    fprintf(stderr, "Warning: range finder '%s': range image of %u bytes, expected %zu: ignored\n", sn_shown(d->name),
            img->type == MSGPACK_OBJECT_BIN ? img->via.bin.size : 0u, 4 * n);
}

/* ------------------------------------------------------------------ PNG (stored deflate: no zlib needed) */

static uint32_t crc_table[256];

uint32_t sn_crc32(uint32_t crc, const unsigned char *p, size_t n) {
  if (crc_table[1] == 0)
    for (uint32_t i = 0; i < 256; i++) {
      uint32_t c = i;
      for (int k = 0; k < 8; k++)
        c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      crc_table[i] = c;
    }
  crc = ~crc;
  for (size_t i = 0; i < n; i++)
    crc = crc_table[(crc ^ p[i]) & 0xFF] ^ (crc >> 8);
  return ~crc;
}

static void put32(unsigned char *p, uint32_t v) {
  p[0] = (unsigned char)(v >> 24);
  p[1] = (unsigned char)(v >> 16);
  p[2] = (unsigned char)(v >> 8);
  p[3] = (unsigned char)v;
}

static int chunk(FILE *f, const char *kind, const unsigned char *data, size_t n) {
  unsigned char head[8];
  put32(head, (uint32_t)n);
  memcpy(head + 4, kind, 4);
  uint32_t crc = sn_crc32(sn_crc32(0, (const unsigned char *)kind, 4), data, n);
  unsigned char tail[4];
  put32(tail, crc);
  return fwrite(head, 1, 8, f) == 8 && (n == 0 || fwrite(data, 1, n, f) == n) && fwrite(tail, 1, 4, f) == 4 ? 0 : -1;
}

static int write_png(const char *filename, const unsigned char *rgb, int width, int height) {
  return sn_write_png(filename, rgb, width, height, 3);
}

int sn_write_png(const char *filename, const unsigned char *rgb, int width, int height, int channels) {
  size_t row = (size_t)channels * (size_t)width + 1, raw_n = row * (size_t)height;
  size_t blocks = (raw_n + 65534) / 65535;
  size_t z_n = 2 + raw_n + 5 * (blocks ? blocks : 1) + 4;
  unsigned char *z = malloc(z_n);
  if (z == NULL)
    return -1;
  size_t k = 0;
  z[k++] = 0x78;
  z[k++] = 0x01;
  uint32_t a = 1, b = 0;
  size_t pos = 0, left = raw_n;
  do {
    size_t len = left > 65535 ? 65535 : left;
    left -= len;
    z[k++] = left == 0 ? 1 : 0;
    z[k++] = (unsigned char)(len & 0xFF);
    z[k++] = (unsigned char)(len >> 8);
    z[k++] = (unsigned char)(~len & 0xFF);
    z[k++] = (unsigned char)((~len >> 8) & 0xFF);
    for (size_t i = 0; i < len; i++, pos++) {
      size_t y = pos / row, x = pos % row;
      unsigned char v = x == 0 ? 0 : rgb[y * (row - 1) + x - 1];
      z[k++] = v;
      a = (a + v) % 65521;
      b = (b + a) % 65521;
    }
  } while (left > 0);
  put32(z + k, (b << 16) | a);
  k += 4;
  FILE *f = fopen(filename, "wb");
  if (f == NULL) {
    free(z);
    return -1;
  }
  unsigned char ihdr[13];
  put32(ihdr, (uint32_t)width);
  put32(ihdr + 4, (uint32_t)height);
  ihdr[8] = 8;
  ihdr[9] = channels == 4 ? 6 : 2; /* RGBA or RGB */
  ihdr[10] = ihdr[11] = ihdr[12] = 0;
  int ret = fwrite("\x89PNG\r\n\x1a\n", 1, 8, f) == 8 && chunk(f, "IHDR", ihdr, 13) == 0 &&
                    chunk(f, "IDAT", z, k) == 0 && chunk(f, "IEND", NULL, 0) == 0
              ? 0
              : -1;
  free(z);
  if (fclose(f) != 0)
    ret = -1;
  return ret;
}

/* Webots' argument checks of every save_image: a filename, a quality in 1..100 (0: a camera's PNG,
   whose quality Webots ignores). */
static int check_save(const char *func, const char *filename, int quality) {
  if (filename == NULL || filename[0] == '\0') {
    fprintf(stderr, "Error: %s() called with NULL or empty 'filename' argument.\n", func);
    return -1;
  }
  if (quality != 0 && (quality < 1 || quality > 100)) {
    fprintf(stderr, "Error: %s() called with invalid 'quality' argument.\n", func);
    return -1;
  }
  return 0;
}

/* Whether filename ends with ext (lower case, with its dot), in any case. */
static int has_extension(const char *filename, const char *ext) {
  size_t n = strlen(filename), k = strlen(ext);
  if (n < k)
    return 0;
  for (size_t i = 0; i < k; i++)
    if (tolower((unsigned char)filename[n - k + i]) != ext[i])
      return 0;
  return 1;
}

/* A Radiance picture (#?RADIANCE, 32-bit RGBE, flat scanlines, top row first) of grey values, each
   in r, g and b: v = m 2^e (frexp) stored as int(m 256) thrice and e + 128; below 1e-32 four zeros. */
static int write_hdr(const char *filename, const float *grey, int width, int height) {
  FILE *f = fopen(filename, "wb");
  if (f == NULL)
    return -1;
  int ok = fprintf(f, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n", height, width) > 0;
  size_t n = (size_t)width * (size_t)height;
  for (size_t j = 0; ok && j < n; j++) {
    unsigned char px[4] = {0, 0, 0, 0};
    if (grey[j] >= 1e-32f) {
      int e;
      double m = frexp(grey[j], &e);
      px[0] = px[1] = px[2] = (unsigned char)(m * 256.0);
      px[3] = (unsigned char)(e + 128);
    }
    ok = fwrite(px, 1, 4, f) == 4;
  }
  if (fclose(f) != 0)
    ok = 0;
  return ok ? 0 : -1;
}

/* Webots' argument checks; PNG only here (JPEG needs a codec this library does not carry). */
static int save_rgb(const char *func, const char *filename, int quality, const unsigned char *rgb, int w, int h) {
  if (check_save(func, filename, quality) != 0)
    return -1;
  size_t n = strlen(filename);
  if (n < 4 || (strcmp(filename + n - 4, ".png") != 0 && strcmp(filename + n - 4, ".PNG") != 0)) {
    fprintf(stderr, "Error: %s(): only .png images can be saved by this library ('%s').\n", func, sn_shown(filename));
    return -1;
  }
  if (write_png(filename, rgb, w, h) != 0) {
    fprintf(stderr, "Error: %s(): cannot write '%s'.\n", func, sn_shown(filename));
    return -1;
  }
  return 0;
}

/* ------------------------------------------------------------------ RangeFinder */

#define RANGE_FINDER(func) sn_device *d = sn_device_get(tag, SN_RANGE_FINDER, func)

void wb_range_finder_enable(WbDeviceTag tag, int sampling_period) {
  sn_sensor_enable(tag, SN_RANGE_FINDER, sampling_period, "wb_range_finder_enable");
}

void wb_range_finder_disable(WbDeviceTag tag) { sn_sensor_enable(tag, SN_RANGE_FINDER, 0, "wb_range_finder_disable"); }

int wb_range_finder_get_sampling_period(WbDeviceTag tag) {
  return sn_sensor_period(tag, SN_RANGE_FINDER, "wb_range_finder_get_sampling_period");
}

/* Webots' rule: a disabled range finder prints an error and still hands out its (last) image. */
const float *wb_range_finder_get_range_image(WbDeviceTag tag) {
  sn_device *d = sn_sensor_reading(tag, SN_RANGE_FINDER, "wb_range_finder_get_range_image", "wb_range_finder_enable");
  return d ? d->imaging->range : NULL;
}

int wb_range_finder_get_width(WbDeviceTag tag) {
  RANGE_FINDER("wb_range_finder_get_width");
  return d ? d->imaging->width : 0;
}

int wb_range_finder_get_height(WbDeviceTag tag) {
  RANGE_FINDER("wb_range_finder_get_height");
  return d ? d->imaging->height : 0;
}

double wb_range_finder_get_fov(WbDeviceTag tag) {
  RANGE_FINDER("wb_range_finder_get_fov");
  return d ? d->imaging->fov : NAN;
}

double wb_range_finder_get_min_range(WbDeviceTag tag) {
  RANGE_FINDER("wb_range_finder_get_min_range");
  return d ? d->imaging->min_range : NAN;
}

double wb_range_finder_get_max_range(WbDeviceTag tag) {
  RANGE_FINDER("wb_range_finder_get_max_range");
  return d ? d->imaging->max_range : NAN;
}

/* Webots' grey scale: (unsigned char)(255 clamp((v - minRange)/maxRange, 0, 1)), inf white. */
int wb_range_finder_save_image(WbDeviceTag tag, const char *filename, int quality) {
  const char *func = "wb_range_finder_save_image";
  RANGE_FINDER(func);
  if (d == NULL)
    return -1;
  struct sn_imaging *im = d->imaging;
  size_t n = (size_t)im->width * (size_t)im->height;
  int hdr = filename != NULL && has_extension(filename, ".hdr");
  if (filename != NULL && (hdr || has_extension(filename, ".tif") || has_extension(filename, ".tiff"))) {
    if (check_save(func, filename, quality == 0 ? -1 : quality) != 0) /* Webots: 1..100 here */
      return -1;
    if (!hdr) {
      fprintf(stderr, "Error: %s(): .tiff image not supported anymore, use .hdr instead.\n", func);
      return -1;
    }
  }
  float *grey = malloc(sizeof(float) * (n ? n : 1));
  unsigned char *rgb = malloc(3 * (n ? n : 1));
  if (grey == NULL || rgb == NULL) {
    free(grey);
    free(rgb);
    return -1;
  }
  for (size_t j = 0; j < n; j++) {
    double v = (im->range[j] - im->min_range) / im->max_range;
    v = !(v <= 1.0) ? 1.0 : v < 0.0 ? 0.0 : v;
    grey[j] = (float)v;
    rgb[3 * j] = rgb[3 * j + 1] = rgb[3 * j + 2] = (unsigned char)(v * 255.0);
  }
  int ret;
  if (hdr) {
    ret = write_hdr(filename, grey, im->width, im->height);
    if (ret != 0)
      fprintf(stderr, "Error: %s(): cannot write '%s'.\n", func, sn_shown(filename));
  } else
    ret = save_rgb(func, filename, quality, rgb, im->width, im->height);
  free(grey);
  free(rgb);
  return ret;
}

/* ------------------------------------------------------------------ Camera */

#define CAMERA(func) sn_device *d = sn_device_get(tag, SN_CAMERA, func)

void wb_camera_enable(WbDeviceTag tag, int sampling_period) {
  sn_sensor_enable(tag, SN_CAMERA, sampling_period, "wb_camera_enable");
}

void wb_camera_disable(WbDeviceTag tag) { sn_sensor_enable(tag, SN_CAMERA, 0, "wb_camera_disable"); }

int wb_camera_get_sampling_period(WbDeviceTag tag) {
  return sn_sensor_period(tag, SN_CAMERA, "wb_camera_get_sampling_period");
}

/* Webots' rule: NULL (and an error) while the camera is disabled. */
const unsigned char *wb_camera_get_image(WbDeviceTag tag) {
  CAMERA("wb_camera_get_image");
  if (d == NULL)
    return NULL;
  if (d->sampling_period <= 0) {
    sn_warn_disabled(d, "wb_camera_get_image", "wb_camera_enable", NULL);
    return NULL;
  }
  return d->imaging->image;
}

int wb_camera_get_width(WbDeviceTag tag) {
  CAMERA("wb_camera_get_width");
  return d ? d->imaging->width : 0;
}

int wb_camera_get_height(WbDeviceTag tag) {
  CAMERA("wb_camera_get_height");
  return d ? d->imaging->height : 0;
}

double wb_camera_get_fov(WbDeviceTag tag) {
  CAMERA("wb_camera_get_fov");
  return d ? d->imaging->fov : NAN;
}

/* the Zoom's range; without a Zoom node, Webots' zoom range is the field of view itself */
double wb_camera_get_min_fov(WbDeviceTag tag) {
  CAMERA("wb_camera_get_min_fov");
  return d ? d->imaging->min_fov : NAN;
}

double wb_camera_get_max_fov(WbDeviceTag tag) {
  CAMERA("wb_camera_get_max_fov");
  return d ? d->imaging->max_fov : NAN;
}

void wb_camera_set_fov(WbDeviceTag tag, double fov) {
  const char *func = "wb_camera_set_fov";
  CAMERA(func);
  if (d == NULL)
    return;
  double hi = d->imaging->planar ? PI : 2.0 * PI;
  if (!(fov >= 0.0 && fov <= hi))
    fprintf(stderr, "Error: %s() called with 'fov' argument outside of the [0, %s] range.\n", func,
            d->imaging->planar ? "pi" : "2.0*pi");
  else if (fov < d->imaging->min_fov || fov > d->imaging->max_fov)
    fprintf(stderr, "Error: %s() out of zoom range [%f, %f].\n", func, d->imaging->min_fov, d->imaging->max_fov);
  else if (fov != d->imaging->fov && sn_device_set(d, "set_fov", sn_arg_double, &fov, func))
    d->imaging->fov = fov; /* the next images see it; getFov answers it now, as Webots' library */
}

double wb_camera_get_exposure(WbDeviceTag tag) {
  CAMERA("wb_camera_get_exposure");
  return d ? d->imaging->exposure : NAN;
}

void wb_camera_set_exposure(WbDeviceTag tag, double exposure) {
  const char *func = "wb_camera_set_exposure";
  CAMERA(func);
  if (d == NULL)
    return;
  if (!(exposure >= 0.0) || isinf(exposure)) {
    fprintf(stderr, "Error: 'exposure' argument of %s() can't be negative.\n", func);
    return;
  }
  if (!sn_device_set(d, "set_exposure", sn_arg_double, &exposure, func))
    return;
  d->imaging->exposure = exposure;
}

/* the camera's Focus node (Webots' zeros without one) */
double wb_camera_get_focal_length(WbDeviceTag tag) {
  CAMERA("wb_camera_get_focal_length");
  return d ? d->imaging->focal_length : NAN;
}

double wb_camera_get_focal_distance(WbDeviceTag tag) {
  CAMERA("wb_camera_get_focal_distance");
  return d ? d->imaging->focal_distance : NAN;
}

double wb_camera_get_max_focal_distance(WbDeviceTag tag) {
  CAMERA("wb_camera_get_max_focal_distance");
  return d ? d->imaging->max_focal_distance : NAN;
}

double wb_camera_get_min_focal_distance(WbDeviceTag tag) {
  CAMERA("wb_camera_get_min_focal_distance");
  return d ? d->imaging->min_focal_distance : NAN;
}

void wb_camera_set_focal_distance(WbDeviceTag tag, double focal_distance) {
  const char *func = "wb_camera_set_focal_distance";
  CAMERA(func);
  if (d == NULL)
    return;
  if (!d->imaging->planar)
    fprintf(stderr, "Error: %s() can only be called on a planar camera.\n", func);
  else if (!(focal_distance >= d->imaging->min_focal_distance && focal_distance <= d->imaging->max_focal_distance))
    fprintf(stderr, "Error: %s() out of focus range [%f, %f].\n", func, d->imaging->min_focal_distance,
            d->imaging->max_focal_distance);
  else
    d->imaging->focal_distance = focal_distance; /* kept here, as Webots' library: no depth of field drawn */
}

double wb_camera_get_near(WbDeviceTag tag) {
  CAMERA("wb_camera_get_near");
  return d ? d->imaging->near : NAN;
}

static int save_bgra(const char *func, const char *filename, int quality, const unsigned char *bgra, int w, int h) {
  size_t n = (size_t)w * (size_t)h;
  unsigned char *rgb = malloc(3 * n + 1);
  if (rgb == NULL)
    return -1;
  for (size_t j = 0; j < n; j++) {
    rgb[3 * j] = bgra[4 * j + 2];
    rgb[3 * j + 1] = bgra[4 * j + 1];
    rgb[3 * j + 2] = bgra[4 * j];
  }
  int ret = save_rgb(func, filename, quality, rgb, w, h);
  free(rgb);
  return ret;
}

int wb_camera_save_image(WbDeviceTag tag, const char *filename, int quality) {
  const char *func = "wb_camera_save_image";
  CAMERA(func);
  (void)quality; /* Webots checks it for JPEG only; this library writes PNG */
  if (d == NULL)
    return -1;
  return save_bgra(func, filename, 0, d->imaging->image, d->imaging->width, d->imaging->height);
}

/* ------------------------------------------------------------------ Camera recognition */

/* the camera, or NULL with Webots' error if it has no Recognition node */
static sn_device *recognition(WbDeviceTag tag, const char *func) {
  sn_device *d = sn_device_get(tag, SN_CAMERA, func);
  if (d != NULL && !d->imaging->has_recognition) {
    fprintf(stderr, "Error: %s() called on a Camera without Recognition node.\n", func);
    return NULL;
  }
  return d;
}

bool wb_camera_has_recognition(WbDeviceTag tag) {
  CAMERA("wb_camera_has_recognition");
  return d ? d->imaging->has_recognition : false;
}

void wb_camera_recognition_enable(WbDeviceTag tag, int sampling_period) {
  const char *func = "wb_camera_recognition_enable";
  if (sampling_period < 0) {
    fprintf(stderr, "Error: %s() called with negative sampling period.\n", func);
    return;
  }
  sn_device *d = recognition(tag, func);
  if (d == NULL)
    return;
  if (!sn_device_set(d, "recognition_enable", sn_arg_int, &sampling_period, func))
    return;
  d->imaging->recognition_period = sampling_period;
  if (sampling_period == 0)
    d->imaging->segmentation_enabled = false;
}

void wb_camera_recognition_disable(WbDeviceTag tag) {
  if (recognition(tag, "wb_camera_recognition_disable") != NULL)
    wb_camera_recognition_enable(tag, 0);
}

int wb_camera_recognition_get_sampling_period(WbDeviceTag tag) {
  sn_device *d = recognition(tag, "wb_camera_recognition_get_sampling_period");
  return d ? d->imaging->recognition_period : 0;
}

static sn_device *recognition_enabled(WbDeviceTag tag, const char *func) {
  sn_device *d = recognition(tag, func);
  if (d != NULL && d->imaging->recognition_period <= 0) {
    fprintf(stderr, "Error: %s() called for a disabled device! Please use: wb_camera_recognition_enable().\n", func);
    return NULL;
  }
  return d;
}

int wb_camera_recognition_get_number_of_objects(WbDeviceTag tag) {
  sn_device *d = recognition_enabled(tag, "wb_camera_recognition_get_number_of_objects");
  return d ? d->imaging->n_objects : 0;
}

const WbCameraRecognitionObject *wb_camera_recognition_get_objects(WbDeviceTag tag) {
  sn_device *d = recognition_enabled(tag, "wb_camera_recognition_get_objects");
  return d ? d->imaging->objects : NULL;
}

bool wb_camera_recognition_has_segmentation(WbDeviceTag tag) {
  CAMERA("wb_camera_recognition_has_segmentation");
  return d ? d->imaging->has_segmentation : false;
}

static void segmentation(WbDeviceTag tag, bool on, const char *func) {
  sn_device *d = recognition(tag, func);
  if (d == NULL)
    return;
  if (!d->imaging->has_segmentation) {
    fprintf(stderr, "Error: %s() called on a Camera whose Recognition node has no segmentation.\n", func);
    return;
  }
  if (on && d->imaging->recognition_period <= 0) {
    fprintf(stderr, "Error: %s() called while the recognition is disabled! Please use: wb_camera_recognition_enable().\n",
            func);
    return;
  }
  if (!sn_device_set(d, "enable_segmentation", sn_arg_bool, &on, func))
    return;
  d->imaging->segmentation_enabled = on;
}

void wb_camera_recognition_enable_segmentation(WbDeviceTag tag) {
  segmentation(tag, true, "wb_camera_recognition_enable_segmentation");
}

void wb_camera_recognition_disable_segmentation(WbDeviceTag tag) {
  segmentation(tag, false, "wb_camera_recognition_disable_segmentation");
}

bool wb_camera_recognition_is_segmentation_enabled(WbDeviceTag tag) {
  CAMERA("wb_camera_recognition_is_segmentation_enabled");
  return d ? d->imaging->segmentation_enabled : false;
}

const unsigned char *wb_camera_recognition_get_segmentation_image(WbDeviceTag tag) {
  const char *func = "wb_camera_recognition_get_segmentation_image";
  CAMERA(func);
  if (d == NULL)
    return NULL;
  if (!d->imaging->segmentation_enabled) {
    fprintf(stderr, "Error: %s() called while the segmentation is disabled! Please use: "
                    "wb_camera_recognition_enable_segmentation().\n", func);
    return NULL;
  }
  return d->imaging->segmentation;
}

int wb_camera_recognition_save_segmentation_image(WbDeviceTag tag, const char *filename, int quality) {
  const char *func = "wb_camera_recognition_save_segmentation_image";
  (void)quality;
  const unsigned char *img = wb_camera_recognition_get_segmentation_image(tag);
  if (img == NULL)
    return -1;
  sn_device *d = sn_device_get(tag, SN_CAMERA, func);
  return save_bgra(func, filename, 0, img, d->imaging->width, d->imaging->height);
}
