/* Sensorium C controller library: reading a PNG file for wb_display_image_load through libpng. Every
 * colour type, bit depth, palette, tRNS and interlacing becomes 8-bit RGBA with libpng's own
 * transforms and no gamma correction: a 16-bit sample keeps its high byte, as Webots' image loader
 * shows it. A damaged file (a chunk's CRC, the zlib stream) is refused with libpng's reason. */
#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

typedef struct {
  char *why;
  size_t why_len;
} reader_error;

static void on_error(png_structp png, png_const_charp message) {
  reader_error *e = png_get_error_ptr(png);
  snprintf(e->why, e->why_len, "%s", message);
  png_longjmp(png, 1);
}

static void on_warning(png_structp png, png_const_charp message) {
  (void)png;
  (void)message; /* benign (an unknown chunk, a bad gamma value): the pixels are still read */
}

int sn_read_png(const char *filename, long max_pixels, int *width, int *height, unsigned char **rgba, char *why,
                size_t why_len) {
  static const unsigned char SIGNATURE[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  *rgba = NULL;
  FILE *f = fopen(filename, "rb");
  if (f == NULL) {
    snprintf(why, why_len, "cannot be opened");
    return -1;
  }
  unsigned char head[8];
  if (fread(head, 1, 8, f) != 8 || memcmp(head, SIGNATURE, 8) != 0) {
    fclose(f);
    snprintf(why, why_len, "is not a PNG file");
    return -1;
  }
  reader_error err = {why, why_len};
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &err, on_error, on_warning);
  png_infop info = png != NULL ? png_create_info_struct(png) : NULL;
  if (info == NULL) {
    png_destroy_read_struct(&png, NULL, NULL);
    fclose(f);
    snprintf(why, why_len, "out of memory");
    return -1;
  }
  /* volatile: set after setjmp, read after a longjmp back to it */
  unsigned char *volatile out = NULL;
  png_bytep *volatile rows = NULL;
  if (setjmp(png_jmpbuf(png))) {
    free(out);
    free(rows);
    png_destroy_read_struct(&png, &info, NULL);
    fclose(f);
    return -1;
  }
  png_init_io(png, f);
  png_set_sig_bytes(png, 8);
  png_read_info(png, info);
  const png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
  if ((long)w > max_pixels / (long)h) {
    char too_large[96];
    snprintf(too_large, sizeof too_large, "%lu x %lu pixels, more than one image may hold (%ld)", (unsigned long)w,
             (unsigned long)h, max_pixels);
    png_error(png, too_large);
  }
  const int ctype = png_get_color_type(png, info);
  png_set_expand(png);   /* palette to RGB, grey below 8 bits to 8, tRNS to an alpha channel */
  png_set_strip_16(png); /* 16 bits a sample: the high byte */
  if (ctype == PNG_COLOR_TYPE_GRAY || ctype == PNG_COLOR_TYPE_GRAY_ALPHA)
    png_set_gray_to_rgb(png);
  png_set_add_alpha(png, 0xff, PNG_FILLER_AFTER); /* opaque where the file has no alpha */
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  if (png_get_rowbytes(png, info) != (size_t)w * 4)
    png_error(png, "unexpected row layout");
  out = malloc((size_t)w * h * 4);
  rows = malloc(sizeof(png_bytep) * h);
  if (out == NULL || rows == NULL)
    png_error(png, "out of memory");
  for (png_uint_32 y = 0; y < h; y++)
    rows[y] = out + (size_t)y * w * 4;
  png_read_image(png, rows);
  png_read_end(png, NULL);
  free(rows);
  png_destroy_read_struct(&png, &info, NULL);
  fclose(f);
  *width = (int)w;
  *height = (int)h;
  *rgba = out;
  return 0;
}
