/* Sensorium C controller library: JPEG files through libjpeg, for wb_display_image_load (reading) and
 * wb_display_image_save (writing). Reading gives 8-bit RGBA rows, opaque: colour, greyscale and CMYK
 * files, baseline or progressive, every chroma subsampling, with libjpeg's default decoding (the
 * accurate integer IDCT, smooth chroma upsampling) and Pillow's CMYK to RGB rule, as Pillow decodes
 * them for the Python client. A file that
 * ends early is refused, as Pillow refuses it; libjpeg's other warnings (corrupt data it decodes
 * past) are not, as in Pillow. Writing: quality 100 and no chroma subsampling (4:4:4), what Webots'
 * image writer does at that quality. */
#include <setjmp.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jpeglib.h>
#include <jerror.h>

#include "internal.h"

typedef struct {
  struct jpeg_error_mgr pub; /* first: libjpeg hands this pointer back */
  jmp_buf jump;
  char *why;
  size_t why_len;
} jpeg_failure;

static void on_error(j_common_ptr cinfo) {
  jpeg_failure *f = (jpeg_failure *)cinfo->err;
  char message[JMSG_LENGTH_MAX];
  cinfo->err->format_message(cinfo, message);
  snprintf(f->why, f->why_len, "%s", message);
  longjmp(f->jump, 1);
}

/* libjpeg's messages: errors stop (on_error); of the warnings only a premature end does */
static void on_message(j_common_ptr cinfo, int level) {
  if (level == -1 && cinfo->err->msg_code == JWRN_JPEG_EOF)
    on_error(cinfo);
}

/* v / 255 rounded to the nearest, for v in 0..255·255 (the integer form Pillow's colour conversion uses) */
static unsigned char scale255(unsigned v) {
  v += 128;
  return (unsigned char)(((v >> 8) + v) >> 8);
}

int sn_read_jpeg(const char *filename, long max_pixels, int *width, int *height, unsigned char **rgba, char *why,
                 size_t why_len) {
  *rgba = NULL;
  FILE *f = fopen(filename, "rb");
  if (f == NULL) {
    snprintf(why, why_len, "cannot be opened");
    return -1;
  }
  struct jpeg_decompress_struct cinfo;
  jpeg_failure err;
  cinfo.err = jpeg_std_error(&err.pub);
  err.pub.error_exit = on_error;
  err.pub.emit_message = on_message;
  err.why = why;
  err.why_len = why_len;
  /* volatile: set after setjmp, read after a longjmp back to it */
  unsigned char *volatile out = NULL;
  unsigned char *volatile row = NULL;
  if (setjmp(err.jump)) {
    free(out);
    free(row);
    jpeg_destroy_decompress(&cinfo);
    fclose(f);
    return -1;
  }
  jpeg_create_decompress(&cinfo);
  jpeg_stdio_src(&cinfo, f);
  jpeg_read_header(&cinfo, TRUE);
  const long w = (long)cinfo.image_width, h = (long)cinfo.image_height;
  if (w < 1 || h < 1 || w > max_pixels / h) {
    snprintf(why, why_len, "%ld x %ld pixels, more than one image may hold (%ld)", w, h, max_pixels);
    longjmp(err.jump, 1);
  }
  /* RGB, a greyscale file too (each grey level as r = g = b); CMYK (and YCCK) as CMYK, made RGB below */
  const bool cmyk = cinfo.jpeg_color_space == JCS_CMYK || cinfo.jpeg_color_space == JCS_YCCK;
  cinfo.out_color_space = cmyk ? JCS_CMYK : JCS_RGB;
  jpeg_start_decompress(&cinfo);
  const int n = cinfo.output_components;
  if (n != (cmyk ? 4 : 3)) {
    snprintf(why, why_len, "%d colour components where %d were asked for", n, cmyk ? 4 : 3);
    longjmp(err.jump, 1);
  }
  /* an Adobe file keeps its inks inverted (255 - ink): the light each leaves, as stored */
  const bool inverted = cinfo.saw_Adobe_marker;
  out = malloc((size_t)w * (size_t)h * 4);
  row = malloc((size_t)w * (size_t)n);
  if (out == NULL || row == NULL) {
    snprintf(why, why_len, "out of memory");
    longjmp(err.jump, 1);
  }
  while (cinfo.output_scanline < cinfo.output_height) {
    unsigned char *dst = out + (size_t)cinfo.output_scanline * (size_t)w * 4;
    JSAMPROW rows[1] = {row};
    jpeg_read_scanlines(&cinfo, rows, 1);
    for (long x = 0; x < w; x++) {
      const unsigned char *p = row + (size_t)n * (size_t)x;
      if (cmyk) { /* each colour: the light its ink leaves times the light black leaves, /255 rounded */
        const unsigned k = inverted ? p[3] : 255u - p[3];
        for (int c = 0; c < 3; c++)
          dst[4 * x + c] = scale255((inverted ? p[c] : 255u - p[c]) * k);
      } else {
        dst[4 * x] = p[0];
        dst[4 * x + 1] = p[1];
        dst[4 * x + 2] = p[2];
      }
      dst[4 * x + 3] = 0xFF;
    }
  }
  free(row);
  row = NULL;
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  fclose(f);
  *width = (int)w;
  *height = (int)h;
  *rgba = out;
  return 0;
}

int sn_write_jpeg(const char *filename, const unsigned char *rgb, int width, int height, int quality, char *why,
                  size_t why_len) {
  FILE *f = fopen(filename, "wb");
  if (f == NULL) {
    snprintf(why, why_len, "cannot be opened for writing");
    return -1;
  }
  struct jpeg_compress_struct cinfo;
  jpeg_failure err;
  cinfo.err = jpeg_std_error(&err.pub);
  err.pub.error_exit = on_error;
  err.why = why;
  err.why_len = why_len;
  if (setjmp(err.jump)) {
    jpeg_destroy_compress(&cinfo);
    fclose(f);
    return -1;
  }
  jpeg_create_compress(&cinfo);
  jpeg_stdio_dest(&cinfo, f);
  cinfo.image_width = (JDIMENSION)width;
  cinfo.image_height = (JDIMENSION)height;
  cinfo.input_components = 3;
  cinfo.in_color_space = JCS_RGB;
  jpeg_set_defaults(&cinfo);
  jpeg_set_quality(&cinfo, quality, TRUE);
  for (int c = 0; c < cinfo.num_components; c++) /* 4:4:4 */
    cinfo.comp_info[c].h_samp_factor = cinfo.comp_info[c].v_samp_factor = 1;
  jpeg_start_compress(&cinfo, TRUE);
  while (cinfo.next_scanline < cinfo.image_height) {
    JSAMPROW rows[1] = {(JSAMPROW)(rgb + (size_t)cinfo.next_scanline * (size_t)width * 3)};
    jpeg_write_scanlines(&cinfo, rows, 1);
  }
  jpeg_finish_compress(&cinfo);
  jpeg_destroy_compress(&cinfo);
  if (fclose(f) != 0) {
    snprintf(why, why_len, "the file could not be written whole");
    return -1;
  }
  return 0;
}
