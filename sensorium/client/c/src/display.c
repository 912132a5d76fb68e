/* Sensorium C controller library: the Display. As in Webots' libController, drawing costs no round
 * trip: each call is checked (Webots' error lines), packed into the Display's command list and sent
 * with the next step request ("displays": {name: [commands]}, PROTOCOL.md), where the server draws
 * it. Image references are ids this library gives out. wb_display_image_save sends the pending
 * commands at once with the "draw" service and gets the pixels back, then writes the file here: a
 * .png (RGBA) or a .jpg/.jpeg (RGB, quality 100, as libController writes it; jpeg_io.c);
 * wb_display_image_load reads a .png, .jpg or .jpeg file (by its content: png_read.c, jpeg_io.c) and
 * sends it as wb_display_image_new does. Written from Webots' documented signatures and
 * libController's rules. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/display.h>
#include <webots/nodes.h>

#include "internal.h"

struct WbImageStructPrivate {
  int id;
  WbDeviceTag tag;
};

/* What one request carries (the server's bounds: 4,096 commands per display, PROTOCOL's 1 MiB and
   100,000 values per request): a Display's list is sent ahead with the "draw" service when the next
   command would pass these, keeping the order. */
#define FLUSH_COMMANDS 4096
#define FLUSH_ITEMS 40000
#define FLUSH_BYTES (512u * 1024u)
#define MAX_IMAGE_PIXELS (1u << 22) /* the server's bound on one kept image */
#define BAND_BYTES FLUSH_BYTES      /* a larger image goes in bands of whole rows, each at most this (one request) */

static const char *g_func = "wb_display"; /* the drawing function being called (flush errors name it) */
static void flush(sn_device *d);

/* The Display of tag (Webots' error and NULL for another device; NULL after one warning when the
   server lists it only, or once the controller's steps are over). */
static sn_device *display(WbDeviceTag tag, const char *func, bool drawing) {
  g_func = func;
  sn_device *d = sn_device_get(tag, SN_OTHER, func);
  if (d == NULL)
    return NULL;
  if (d->node_type != WB_NODE_DISPLAY) {
    fprintf(stderr, "Error: %s(): device tag %u is '%s', a %s\n", func, (unsigned)tag, sn_shown(d->name), d->type_name);
    return NULL;
  }
  if (!drawing)
    return d;
  if (!d->simulated) {
    sn_unsimulated(tag, WB_NODE_DISPLAY, func);
    return NULL;
  }
  if (sn_robot_get(func)->terminated)
    return NULL;
  if (d->draw_buf == NULL) {
    d->draw_buf = msgpack_sbuffer_new();
    if (d->draw_buf == NULL)
      return NULL;
    msgpack_packer_init(&d->draw_pk, d->draw_buf, msgpack_sbuffer_write);
  }
  return d;
}

/* Start a command of n items (its name first) in d's list, of about items values and bytes more
   (a polygon's vertices, a text, an image); the list goes ahead first if it would grow too large. */
static msgpack_packer *command_sized(sn_device *d, const char *name, size_t n, size_t items, size_t bytes) {
  if (d->draw_n > 0 && (d->draw_n >= FLUSH_COMMANDS || (size_t)d->draw_items + n + items > FLUSH_ITEMS ||
                        d->draw_buf->size + 16 * n + bytes > FLUSH_BYTES))
    flush(d);
  d->draw_n++;
  d->draw_items += (int)(n + items);
  msgpack_pack_array(&d->draw_pk, n);
  size_t len = strlen(name);
  msgpack_pack_str(&d->draw_pk, len);
  msgpack_pack_str_body(&d->draw_pk, name, len);
  return &d->draw_pk;
}

static msgpack_packer *command(sn_device *d, const char *name, size_t n) {
  return command_sized(d, name, n, 0, 0);
}

int sn_display_pending(const sn_robot *rb) {
  int n = 0;
  for (int i = 0; i < rb->n_devices; i++)
    n += rb->devices[i].node_type == WB_NODE_DISPLAY && rb->devices[i].draw_n > 0;
  return n;
}

/* The commands of d as an array, appended to r; d's list starts over. */
static void pack_commands(sn_device *d, sn_req *r) {
  msgpack_pack_array(&r->pk, (size_t)d->draw_n);
  if (d->draw_n > 0)
    msgpack_sbuffer_write(&r->buf, d->draw_buf->data, d->draw_buf->size);
  if (d->draw_buf != NULL)
    msgpack_sbuffer_clear(d->draw_buf);
  d->draw_n = d->draw_items = 0;
}

void sn_display_pack(sn_robot *rb, sn_req *r) {
  sn_req_key(r, "displays");
  msgpack_pack_map(&r->pk, (size_t)sn_display_pending(rb));
  for (int i = 0; i < rb->n_devices; i++) {
    sn_device *d = &rb->devices[i];
    if (d->node_type == WB_NODE_DISPLAY && d->draw_n > 0) {
      sn_req_str(r, d->name);
      pack_commands(d, r);
    }
  }
}

void sn_display_free(sn_device *d) {
  if (d->draw_buf != NULL)
    msgpack_sbuffer_free(d->draw_buf);
  d->draw_buf = NULL;
  d->draw_n = d->draw_items = 0;
}

int wb_display_get_width(WbDeviceTag tag) {
  sn_device *d = display(tag, "wb_display_get_width", false);
  return d != NULL ? d->display_width : -1;
}

int wb_display_get_height(WbDeviceTag tag) {
  sn_device *d = display(tag, "wb_display_get_height", false);
  return d != NULL ? d->display_height : -1;
}

void wb_display_set_color(WbDeviceTag tag, int color) {
  const char *func = "wb_display_set_color";
  if (color > 0xFFFFFF || color < 0) {
    fprintf(stderr, "Error: %s(): 'color' argument out of bounds.\n", func);
    return;
  }
  sn_device *d = display(tag, func, true);
  if (d != NULL)
    msgpack_pack_int(command(d, "color", 2), color);
}

static void unit(WbDeviceTag tag, const char *func, const char *name, double v) {
  if (!(v >= 0.0 && v <= 1.0)) {
    fprintf(stderr, "Error: %s(): '%s' argument out of bounds.\n", func, name);
    return;
  }
  sn_device *d = display(tag, func, true);
  if (d != NULL)
    msgpack_pack_double(command(d, name, 2), v);
}

void wb_display_set_alpha(WbDeviceTag tag, double alpha) {
  unit(tag, "wb_display_set_alpha", "alpha", alpha);
}

void wb_display_set_opacity(WbDeviceTag tag, double opacity) {
  unit(tag, "wb_display_set_opacity", "opacity", opacity);
}

void wb_display_set_font(WbDeviceTag tag, const char *font, int size, bool anti_aliasing) {
  const char *func = "wb_display_set_font";
  if (size <= 0) {
    fprintf(stderr, "Error: %s(): 'size' argument is negative or null.\n", func);
    return;
  }
  sn_device *d = display(tag, func, true);
  if (d == NULL)
    return;
  const char *name = font != NULL ? font : "";
  size_t len = strlen(name) > 256 ? 256 : strlen(name);
  msgpack_packer *pk = command(d, "font", 4);
  msgpack_pack_str(pk, len);
  msgpack_pack_str_body(pk, name, len);
  msgpack_pack_int(pk, size);
  if (anti_aliasing)
    msgpack_pack_true(pk);
  else
    msgpack_pack_false(pk);
}

void wb_display_attach_camera(WbDeviceTag tag, WbDeviceTag camera_tag) {
  const char *func = "wb_display_attach_camera";
  sn_device *d = display(tag, func, true);
  if (d == NULL)
    return;
  sn_device *cam = sn_device_get(camera_tag, SN_OTHER, func);
  if (cam == NULL || cam->node_type != WB_NODE_CAMERA) {
    fprintf(stderr, "Error: %s(): invalid camera.\n", func);
    return;
  }
  if (d->camera_attached) {
    fprintf(stderr, "Error: %s(): a camera is already attached to the display.\n", func);
    return;
  }
  d->camera_attached = true;
  msgpack_packer *pk = command(d, "attach", 2);
  size_t len = strlen(cam->name);
  msgpack_pack_str(pk, len);
  msgpack_pack_str_body(pk, cam->name, len);
}

void wb_display_detach_camera(WbDeviceTag tag) {
  const char *func = "wb_display_detach_camera";
  sn_device *d = display(tag, func, true);
  if (d == NULL)
    return;
  if (!d->camera_attached) {
    fprintf(stderr, "Error: %s(): no camera to detach.\n", func);
    return;
  }
  d->camera_attached = false;
  command(d, "detach", 1);
}

static void ints(msgpack_packer *pk, const int *v, int n) {
  for (int i = 0; i < n; i++)
    msgpack_pack_int(pk, v[i]);
}

void wb_display_draw_pixel(WbDeviceTag tag, int x, int y) {
  sn_device *d = display(tag, "wb_display_draw_pixel", true);
  if (d != NULL)
    ints(command(d, "pixel", 3), (const int[]){x, y}, 2);
}

void wb_display_draw_line(WbDeviceTag tag, int x1, int y1, int x2, int y2) {
  sn_device *d = display(tag, "wb_display_draw_line", true);
  if (d != NULL)
    ints(command(d, "line", 5), (const int[]){x1, y1, x2, y2}, 4);
}

static void box(WbDeviceTag tag, const char *func, const char *op, const int v[4], const char *w_name,
                const char *h_name, bool fill) {
  if (v[2] <= 0 || v[3] <= 0) {
    fprintf(stderr, "Error: %s(): '%s' argument is negative or null.\n", func, v[2] <= 0 ? w_name : h_name);
    return;
  }
  sn_device *d = display(tag, func, true);
  if (d == NULL)
    return;
  msgpack_packer *pk = command(d, op, 6);
  ints(pk, v, 4);
  if (fill)
    msgpack_pack_true(pk);
  else
    msgpack_pack_false(pk);
}

void wb_display_draw_rectangle(WbDeviceTag tag, int x, int y, int width, int height) {
  box(tag, "wb_display_draw_rectangle", "rectangle", (const int[]){x, y, width, height}, "width", "height", false);
}

void wb_display_fill_rectangle(WbDeviceTag tag, int x, int y, int width, int height) {
  box(tag, "wb_display_fill_rectangle", "rectangle", (const int[]){x, y, width, height}, "width", "height", true);
}

void wb_display_draw_oval(WbDeviceTag tag, int cx, int cy, int a, int b) {
  box(tag, "wb_display_draw_oval", "oval", (const int[]){cx, cy, a, b}, "horizontal_radius", "vertical_radius", false);
}

void wb_display_fill_oval(WbDeviceTag tag, int cx, int cy, int a, int b) {
  box(tag, "wb_display_fill_oval", "oval", (const int[]){cx, cy, a, b}, "horizontal_radius", "vertical_radius", true);
}

static void polygon(WbDeviceTag tag, const char *func, const int *x, const int *y, int size, bool fill) {
  if (x == NULL || y == NULL) {
    fprintf(stderr, "Error: %s(): 'x' or 'y' argument is NULL.\n", func);
    return;
  }
  if (size < 1) {
    fprintf(stderr, "Error: %s(): 'size' argument is negative or null.\n", func);
    return;
  }
  sn_device *d = display(tag, func, true);
  if (d == NULL)
    return;
  msgpack_packer *pk = command_sized(d, "polygon", 4, 2 * (size_t)size, 10 * (size_t)size);
  msgpack_pack_array(pk, (size_t)size);
  ints(pk, x, size);
  msgpack_pack_array(pk, (size_t)size);
  ints(pk, y, size);
  if (fill)
    msgpack_pack_true(pk);
  else
    msgpack_pack_false(pk);
}

void wb_display_draw_polygon(WbDeviceTag tag, const int *x, const int *y, int size) {
  polygon(tag, "wb_display_draw_polygon", x, y, size, false);
}

void wb_display_fill_polygon(WbDeviceTag tag, const int *x, const int *y, int size) {
  polygon(tag, "wb_display_fill_polygon", x, y, size, true);
}

void wb_display_draw_text(WbDeviceTag tag, const char *text, int x, int y) {
  const char *func = "wb_display_draw_text";
  if (text == NULL || text[0] == '\0') {
    fprintf(stderr, "Error: %s(): 'text' argument is NULL or empty.\n", func);
    return;
  }
  sn_device *d = display(tag, func, true);
  if (d == NULL)
    return;
  size_t len = strlen(text);
  msgpack_packer *pk = command_sized(d, "text", 4, 0, len);
  msgpack_pack_str(pk, len);
  msgpack_pack_str_body(pk, text, len);
  ints(pk, (const int[]){x, y}, 2);
}

static WbImageRef new_ref(sn_device *d, WbDeviceTag tag) {
  WbImageRef ir = malloc(sizeof *ir);
  if (ir != NULL) {
    ir->id = ++d->image_ids;
    ir->tag = tag;
  }
  return ir;
}

static WbImageRef image_new(const char *func, WbDeviceTag tag, int width, int height, const void *data, int format);

WbImageRef wb_display_image_new(WbDeviceTag tag, int width, int height, const void *data, int format) {
  return image_new("wb_display_image_new", tag, width, height, data, format);
}

/* wb_display_image_new's work, its error lines naming ``func`` */
static WbImageRef image_new(const char *func, WbDeviceTag tag, int width, int height, const void *data, int format) {
  if (data == NULL) {
    fprintf(stderr, "Error: %s(): 'data' argument is NULL.\n", func);
    return NULL;
  }
  if (width < 1 || height < 1) {
    fprintf(stderr, "Error: %s(): 'width' or 'height' argument is invalid.\n", func);
    return NULL;
  }
  if (format != WB_IMAGE_RGB && format != WB_IMAGE_RGBA && format != WB_IMAGE_ARGB && format != WB_IMAGE_BGRA &&
      format != WB_IMAGE_ABGR) {
    fprintf(stderr, "Error: %s(): 'format' argument is invalid.\n", func);
    return NULL;
  }
  size_t n = (size_t)width * (size_t)height;
  if (n > MAX_IMAGE_PIXELS) {
    fprintf(stderr, "Error: %s(): a %d x %d image is %zu pixels, more than a Display keeps (%u).\n", func, width,
            height, n, MAX_IMAGE_PIXELS);
    return NULL;
  }
  if (4 * (size_t)width > BAND_BYTES) {
    fprintf(stderr, "Error: %s(): a row of %d pixels is %zu bytes, more than one request carries (%u).\n", func,
            width, 4 * (size_t)width, BAND_BYTES);
    return NULL;
  }
  sn_device *d = display(tag, func, true);
  if (d == NULL)
    return NULL;
  unsigned char *bgra = malloc(4 * n);
  WbImageRef ir = bgra != NULL ? new_ref(d, tag) : NULL;
  if (ir == NULL) {
    free(bgra);
    return NULL;
  }
  /* each pixel as the word 0xAARRGGBB (bytes B, G, R, A): WbDisplay's conversions of each format */
  const unsigned char *s = data;
  for (size_t i = 0; i < n; i++) {
    unsigned char *o = bgra + 4 * i;
    const unsigned char *p = s + (format == WB_IMAGE_RGB ? 3 : 4) * i;
    switch (format) {
      case WB_IMAGE_RGB:
        o[0] = p[2], o[1] = p[1], o[2] = p[0], o[3] = 0xFF;
        break;
      case WB_IMAGE_RGBA:
        o[0] = p[2], o[1] = p[1], o[2] = p[0], o[3] = p[3];
        break;
      case WB_IMAGE_ARGB:
        o[0] = p[3], o[1] = p[2], o[2] = p[1], o[3] = p[0];
        break;
      case WB_IMAGE_BGRA:
        memcpy(o, p, 4);
        break;
      default: /* ABGR */
        o[0] = p[1], o[1] = p[2], o[2] = p[3], o[3] = p[0];
        break;
    }
  }
  if (4 * n <= BAND_BYTES) {
    msgpack_packer *pk = command_sized(d, "load", 5, 0, 4 * n);
    ints(pk, (const int[]){ir->id, width, height}, 3);
    msgpack_pack_bin(pk, 4 * n);
    msgpack_pack_bin_body(pk, bgra, 4 * n);
  } else { /* rows per request; the server keeps the image at its last row */
    const int band = (int)(BAND_BYTES / (4 * (size_t)width));
    for (int y = 0; y < height; y += band) {
      const size_t bytes = 4 * (size_t)width * (size_t)(y + band < height ? band : height - y);
      msgpack_packer *pk = command_sized(d, "rows", 6, 0, bytes);
      ints(pk, (const int[]){ir->id, width, height, y}, 4);
      msgpack_pack_bin(pk, bytes);
      msgpack_pack_bin_body(pk, bgra + 4 * (size_t)width * (size_t)y, bytes);
    }
  }
  free(bgra);
  return ir;
}

static bool ends_with(const char *s, const char *ext);

/* An image file as RGBA rows: as libController, a name ending in .png, .jpg or .jpeg (any case),
   whose content, PNG or JPEG, decides how it is read (the name's type need not match it). */
static int read_image(const char *filename, int *width, int *height, unsigned char **rgba, char *why, size_t why_len) {
  static const unsigned char PNG[4] = {0x89, 'P', 'N', 'G'}, JPEG[3] = {0xFF, 0xD8, 0xFF};
  *rgba = NULL;
  if (!ends_with(filename, ".png") && !ends_with(filename, ".jpg") && !ends_with(filename, ".jpeg")) {
    snprintf(why, why_len, "unsupported image type: a .png, .jpg or .jpeg file is read");
    return -1;
  }
  FILE *f = fopen(filename, "rb");
  if (f == NULL) {
    snprintf(why, why_len, "cannot be opened");
    return -1;
  }
  unsigned char head[4] = {0};
  size_t n = fread(head, 1, sizeof head, f);
  fclose(f);
  const long max_pixels = (long)MAX_IMAGE_PIXELS;
  if (n >= 3 && memcmp(head, JPEG, 3) == 0)
    return sn_read_jpeg(filename, max_pixels, width, height, rgba, why, why_len);
  if (n == 4 && memcmp(head, PNG, 4) == 0)
    return sn_read_png(filename, max_pixels, width, height, rgba, why, why_len);
  snprintf(why, why_len, "neither a PNG nor a JPEG file");
  return -1;
}

WbImageRef wb_display_image_load(WbDeviceTag tag, const char *filename) {
  const char *func = "wb_display_image_load";
  if (filename == NULL || filename[0] == '\0') {
    fprintf(stderr, "Error: %s(): 'filename' argument is NULL or empty.\n", func);
    return NULL;
  }
  if (display(tag, func, true) == NULL)
    return NULL;
  int width, height;
  unsigned char *rgba;
  char why[256];
  if (read_image(filename, &width, &height, &rgba, why, sizeof why) != 0) {
    fprintf(stderr, "Error: %s(): the \"%s\" image is unreadable (%s).\n", func, sn_shown(filename), why);
    return NULL;
  }
  WbImageRef ir = image_new(func, tag, width, height, rgba, WB_IMAGE_RGBA);
  free(rgba);
  return ir;
}

WbImageRef wb_display_image_copy(WbDeviceTag tag, int x, int y, int width, int height) {
  const char *func = "wb_display_image_copy";
  if (width < 1 || height < 1) {
    fprintf(stderr, "Error: %s(): 'width' or 'height' argument is invalid.\n", func);
    return NULL;
  }
  sn_device *d = display(tag, func, true);
  if (d == NULL)
    return NULL;
  WbImageRef ir = new_ref(d, tag);
  if (ir != NULL)
    ints(command(d, "copy", 6), (const int[]){ir->id, x, y, width, height}, 5);
  return ir;
}

/* Webots' checks of an image reference (NULL allowed when null_ok); its id, or -1. */
static int ref_id(WbDeviceTag tag, WbImageRef ir, const char *func, const char *what) {
  if (ir == NULL || ir->id <= 0) {
    fprintf(stderr, "Error: %s(): %s\n", func, what);
    return -1;
  }
  if (ir->tag != tag) {
    fprintf(stderr, "Error: %s(): invalid WbImageRef created by a different Display device.\n", func);
    return -1;
  }
  return ir->id;
}

void wb_display_image_paste(WbDeviceTag tag, WbImageRef ir, int x, int y, bool blend) {
  const char *func = "wb_display_image_paste";
  int id = ref_id(tag, ir, func, "invalid WbImageRef argument.");
  sn_device *d = id > 0 ? display(tag, func, true) : NULL;
  if (d == NULL)
    return;
  msgpack_packer *pk = command(d, "paste", 5);
  ints(pk, (const int[]){id, x, y}, 3);
  if (blend)
    msgpack_pack_true(pk);
  else
    msgpack_pack_false(pk);
}

void wb_display_image_delete(WbDeviceTag tag, WbImageRef ir) {
  const char *func = "wb_display_image_delete";
  int id = ref_id(tag, ir, func, "invalid WbImageRef.");
  if (id <= 0)
    return;
  sn_device *d = display(tag, func, true);
  if (d != NULL)
    ints(command(d, "delete", 2), &id, 1);
  free(ir);
}

typedef struct {
  sn_device *d;
  int id;
} save_args;

static void add_save(sn_req *r, const void *p) {
  const save_args *a = p;
  sn_req_key(r, "commands");
  pack_commands(a->d, r);
  if (a->id >= 0) {
    sn_req_key(r, "save");
    msgpack_pack_int(&r->pk, a->id);
  }
}

/* d's commands sent at once (the "draw" service), in order, before the one being added. */
static void flush(sn_device *d) {
  sn_robot *rb = sn_robot_get(g_func);
  char item[512];
  snprintf(item, sizeof item, "%s/draw", d->name);
  save_args a = {d, -1};
  sn_reply rep;
  if (sn_robot_call(rb, item, 1, add_save, &a, g_func, &rep) == 0)
    sn_reply_free(&rep);
}

static bool ends_with(const char *s, const char *ext) {
  size_t n = strlen(s), k = strlen(ext);
  if (n < k)
    return false;
  for (size_t i = 0; i < k; i++) {
    char c = s[n - k + i];
    if ((c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c) != ext[i])
      return false;
  }
  return true;
}

void wb_display_image_save(WbDeviceTag tag, WbImageRef ir, const char *filename) {
  const char *func = "wb_display_image_save";
  if (filename == NULL || filename[0] == '\0') {
    fprintf(stderr, "Error: %s(): 'filename' argument is NULL or empty.\n", func);
    return;
  }
  int id = 0;
  if (ir != NULL && (id = ref_id(tag, ir, func, "invalid WbImageRef.")) <= 0)
    return;
  const bool jpeg = ends_with(filename, ".jpg") || ends_with(filename, ".jpeg");
  if (!jpeg && !ends_with(filename, ".png")) {
    fprintf(stderr, "Error: %s(): unsupported file format. Supported file formats are \".jpg\" and \".png\".\n", func);
    return;
  }
  sn_device *d = display(tag, func, true);
  if (d == NULL)
    return;
  sn_robot *rb = sn_robot_get(func);
  char item[512];
  snprintf(item, sizeof item, "%s/draw", d->name);
  save_args a = {d, id};
  sn_reply rep;
  if (sn_robot_call(rb, item, 2, add_save, &a, func, &rep) != 0)
    return;
  const msgpack_object *data = sn_get(rep.result, "data");
  int w = (int)sn_int_or(rep.result, "width", 0), h = (int)sn_int_or(rep.result, "height", 0);
  if (data == NULL || data->type != MSGPACK_OBJECT_BIN || w < 1 || h < 1 ||
      data->via.bin.size != 4 * (size_t)w * (size_t)h) {
    fprintf(stderr, "Error: %s(): image %d of Display '%s' holds no pixels (a copy outside the display, or "
                    "deleted): '%s' is not written.\n", func, id, sn_shown(d->name), sn_shown(filename));
    sn_reply_free(&rep);
    return;
  }
  /* B, G, R, A words to R, G, B, A rows (PNG), or R, G, B with the alpha dropped (JPEG, as libController) */
  const size_t n = (size_t)w * (size_t)h, channels = jpeg ? 3 : 4;
  unsigned char *out = malloc(channels * n);
  if (out != NULL) {
    const unsigned char *s = (const unsigned char *)data->via.bin.ptr;
    for (size_t i = 0; i < n; i++) {
      unsigned char *o = out + channels * i;
      o[0] = s[4 * i + 2];
      o[1] = s[4 * i + 1];
      o[2] = s[4 * i];
      if (!jpeg)
        o[3] = s[4 * i + 3];
    }
    char why[256] = "";
    const int rc = jpeg ? sn_write_jpeg(filename, out, w, h, 100, why, sizeof why) : sn_write_png(filename, out, w, h, 4);
    if (rc != 0)
      fprintf(stderr, "Error: %s(): cannot write '%s'%s%s%s.\n", func, sn_shown(filename), why[0] ? " (" : "", why,
              why[0] ? ")" : "");
    free(out);
  }
  sn_reply_free(&rep);
}
