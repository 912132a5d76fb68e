/* Sensorium C controller library: reading a PNG file for wb_display_image_load, with no codec
 * library. The zlib stream of the IDAT chunks is inflated here (RFC 1950 and 1951: stored, fixed and
 * dynamic Huffman blocks), each scanline unfiltered (the PNG specification's five filters) and the
 * pixels converted to 8-bit RGBA: grey, grey + alpha, RGB, RGBA (8 or 16 bits a sample: 16-bit
 * samples keep their high byte) and palette images (1, 2, 4 or 8 bits, with tRNS alpha), grey of 1,
 * 2 or 4 bits, a tRNS colour key of grey and RGB images. Interlaced (Adam7) images are refused. Every
 * read is bounds-checked and every chunk's CRC and the stream's Adler-32 checked, as libpng and zlib
 * do: a damaged file is a failure (a reason in `why`), never a crash nor wrong pixels. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

#define MAX_FILE_BYTES (64u * 1024u * 1024u)

/* ------------------------------------------------------------------------------------- inflate */

typedef struct {
  const unsigned char *in;
  size_t size, pos; /* pos in bits */
  unsigned char *out;
  size_t out_size, out_len;
} inflater;

static int bits(inflater *s, int n, unsigned *v) {
  unsigned r = 0;
  for (int i = 0; i < n; i++) {
    size_t byte = s->pos >> 3;
    if (byte >= s->size)
      return -1;
    r |= (unsigned)((s->in[byte] >> (s->pos & 7)) & 1u) << i;
    s->pos++;
  }
  *v = r;
  return 0;
}

typedef struct {
  uint16_t count[16];  /* codes of each length */
  uint16_t symbol[320]; /* symbols ordered by code */
} huffman;

static int build(huffman *h, const unsigned char *lengths, int n) {
  uint16_t offs[16];
  memset(h->count, 0, sizeof h->count);
  for (int i = 0; i < n; i++)
    h->count[lengths[i]]++;
  h->count[0] = 0;
  int left = 1;
  for (int len = 1; len < 16; len++) {
    left <<= 1;
    left -= h->count[len];
    if (left < 0)
      return -1; /* over-subscribed */
  }
  offs[1] = 0;
  for (int len = 1; len < 15; len++)
    offs[len + 1] = (uint16_t)(offs[len] + h->count[len]);
  for (int i = 0; i < n; i++)
    if (lengths[i] != 0)
      h->symbol[offs[lengths[i]]++] = (uint16_t)i;
  return 0;
}

static int decode(inflater *s, const huffman *h, int *sym) {
  int code = 0, first = 0, index = 0;
  for (int len = 1; len < 16; len++) {
    unsigned b;
    if (bits(s, 1, &b) != 0)
      return -1;
    code |= (int)b;
    int count = h->count[len];
    if (code - count < first) {
      *sym = h->symbol[index + (code - first)];
      return 0;
    }
    index += count;
    first += count;
    first <<= 1;
    code <<= 1;
  }
  return -1;
}

static int put(inflater *s, unsigned char c) {
  if (s->out_len >= s->out_size)
    return -1;
  s->out[s->out_len++] = c;
  return 0;
}

static const uint16_t LEN_BASE[29] = {3,  4,  5,  6,  7,  8,  9,  10, 11,  13,  15,  17,  19,  23, 27,
                                      31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
static const uint16_t LEN_EXTRA[29] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
static const uint16_t DIST_BASE[30] = {1,   2,   3,   4,   5,   7,    9,    13,   17,   25,   33,   49,   65,    97,    129,
                                       193, 257, 385, 513, 769, 1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
static const uint16_t DIST_EXTRA[30] = {0, 0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 6, 6, 7, 7, 8, 8, 9, 9, 10, 10, 11, 11, 12, 12, 13, 13};

static int codes(inflater *s, const huffman *lit, const huffman *dist) {
  for (;;) {
    int sym;
    if (decode(s, lit, &sym) != 0)
      return -1;
    if (sym < 256) {
      if (put(s, (unsigned char)sym) != 0)
        return -1;
    } else if (sym == 256) {
      return 0;
    } else {
      sym -= 257;
      if (sym >= 29)
        return -1;
      unsigned extra;
      if (bits(s, LEN_EXTRA[sym], &extra) != 0)
        return -1;
      size_t len = LEN_BASE[sym] + extra;
      int dsym;
      if (decode(s, dist, &dsym) != 0 || dsym >= 30)
        return -1;
      if (bits(s, DIST_EXTRA[dsym], &extra) != 0)
        return -1;
      size_t d = DIST_BASE[dsym] + extra;
      if (d > s->out_len)
        return -1;
      for (size_t i = 0; i < len; i++)
        if (put(s, s->out[s->out_len - d]) != 0)
          return -1;
    }
  }
}

static int inflate_stored(inflater *s) {
  s->pos = (s->pos + 7) & ~(size_t)7;
  size_t byte = s->pos >> 3;
  if (byte + 4 > s->size)
    return -1;
  unsigned len = s->in[byte] | (unsigned)s->in[byte + 1] << 8;
  unsigned nlen = s->in[byte + 2] | (unsigned)s->in[byte + 3] << 8;
  if ((len ^ 0xFFFFu) != nlen || byte + 4 + len > s->size)
    return -1;
  for (unsigned i = 0; i < len; i++)
    if (put(s, s->in[byte + 4 + i]) != 0)
      return -1;
  s->pos = (byte + 4 + len) << 3;
  return 0;
}

static int inflate_fixed(inflater *s) {
  unsigned char lengths[288 + 30];
  huffman lit, dist;
  int i = 0;
  for (; i < 144; i++)
    lengths[i] = 8;
  for (; i < 256; i++)
    lengths[i] = 9;
  for (; i < 280; i++)
    lengths[i] = 7;
  for (; i < 288; i++)
    lengths[i] = 8;
  build(&lit, lengths, 288);
  memset(lengths, 5, 30);
  build(&dist, lengths, 30);
  return codes(s, &lit, &dist);
}

static int inflate_dynamic(inflater *s) {
  static const unsigned char ORDER[19] = {16, 17, 18, 0, 8, 7, 9, 6, 10, 5, 11, 4, 12, 3, 13, 2, 14, 1, 15};
  unsigned nlen, ndist, ncode;
  if (bits(s, 5, &nlen) != 0 || bits(s, 5, &ndist) != 0 || bits(s, 4, &ncode) != 0)
    return -1;
  nlen += 257, ndist += 1, ncode += 4;
  if (nlen > 286 || ndist > 30)
    return -1;
  unsigned char lengths[320];
  memset(lengths, 0, sizeof lengths);
  for (unsigned i = 0; i < ncode; i++) {
    unsigned v;
    if (bits(s, 3, &v) != 0)
      return -1;
    lengths[ORDER[i]] = (unsigned char)v;
  }
  huffman lencode, lit, dist;
  if (build(&lencode, lengths, 19) != 0)
    return -1;
  unsigned index = 0;
  while (index < nlen + ndist) {
    int sym;
    if (decode(s, &lencode, &sym) != 0)
      return -1;
    if (sym < 16) {
      lengths[index++] = (unsigned char)sym;
      continue;
    }
    unsigned char len = 0;
    unsigned rep;
    if (sym == 16) {
      if (index == 0 || bits(s, 2, &rep) != 0)
        return -1;
      len = lengths[index - 1];
      rep += 3;
    } else if (sym == 17) {
      if (bits(s, 3, &rep) != 0)
        return -1;
      rep += 3;
    } else {
      if (bits(s, 7, &rep) != 0)
        return -1;
      rep += 11;
    }
    if (index + rep > nlen + ndist)
      return -1;
    while (rep--)
      lengths[index++] = len;
  }
  if (lengths[256] == 0 || build(&lit, lengths, (int)nlen) != 0 || build(&dist, lengths + nlen, (int)ndist) != 0)
    return -1;
  return codes(s, &lit, &dist);
}

/* a zlib stream (2-byte header, deflate blocks) into out[out_size]; the length written, or -1 */
static long zlib_inflate(const unsigned char *in, size_t size, unsigned char *out, size_t out_size) {
  if (size < 2 || (in[0] & 0x0F) != 8 || ((in[0] << 8) | in[1]) % 31 != 0 || (in[1] & 0x20))
    return -1;
  inflater s = {in + 2, size - 2, 0, out, out_size, 0};
  unsigned last, type;
  do {
    if (bits(&s, 1, &last) != 0 || bits(&s, 2, &type) != 0)
      return -1;
    int r = type == 0 ? inflate_stored(&s) : type == 1 ? inflate_fixed(&s) : type == 2 ? inflate_dynamic(&s) : -1;
    if (r != 0)
      return -1;
  } while (!last);
  size_t end = (s.pos + 7) >> 3; /* the Adler-32 of what was inflated follows, byte-aligned */
  if (end + 4 > s.size)
    return -1;
  uint32_t a = 1, b = 0;
  for (size_t i = 0; i < s.out_len; i++) {
    a = (a + out[i]) % 65521u;
    b = (b + a) % 65521u;
  }
  const unsigned char *q = s.in + end;
  if (((uint32_t)q[0] << 24 | (uint32_t)q[1] << 16 | (uint32_t)q[2] << 8 | q[3]) != (b << 16 | a))
    return -1;
  return (long)s.out_len;
}

/* ----------------------------------------------------------------------------------------- PNG */

static uint32_t be32(const unsigned char *p) {
  return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

static int paeth(int a, int b, int c) {
  int p = a + b - c, pa = abs(p - a), pb = abs(p - b), pc = abs(p - c);
  return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
}

static int fail(char *why, size_t why_len, const char *what) {
  snprintf(why, why_len, "%s", what);
  return -1;
}

int sn_read_png(const char *filename, long max_pixels, int *width, int *height, unsigned char **rgba, char *why,
                size_t why_len) {
  static const unsigned char SIGNATURE[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  *rgba = NULL;
  FILE *f = fopen(filename, "rb");
  if (f == NULL)
    return fail(why, why_len, "cannot be opened");
  unsigned char *file = NULL;
  size_t n = 0, cap = 0;
  for (;;) {
    if (n == cap) {
      cap = cap ? 2 * cap : 65536;
      unsigned char *grown = cap <= MAX_FILE_BYTES ? realloc(file, cap) : NULL;
      if (grown == NULL) {
        free(file);
        fclose(f);
        return fail(why, why_len, "is too large");
      }
      file = grown;
    }
    size_t got = fread(file + n, 1, cap - n, f);
    n += got;
    if (got == 0)
      break;
  }
  fclose(f);
  int rc = -1;
  unsigned char *idat = NULL, *raw = NULL, *out = NULL;
  size_t idat_len = 0;
  uint32_t w = 0, h = 0;
  int depth = 0, ctype = -1, interlace = 0;
  unsigned char palette[256][4];
  int npalette = 0;
  int key[3] = {-1, -1, -1}; /* tRNS colour key of grey or RGB images */
  if (n < 8 || memcmp(file, SIGNATURE, 8) != 0) {
    fail(why, why_len, "is not a PNG file");
    goto done;
  }
  for (int i = 0; i < 256; i++)
    palette[i][0] = palette[i][1] = palette[i][2] = 0, palette[i][3] = 255;
  size_t at = 8;
  for (;;) {
    if (at + 12 > n) {
      fail(why, why_len, "ends before its IEND chunk");
      goto done;
    }
    uint32_t len = be32(file + at);
    const unsigned char *type = file + at + 4, *data = file + at + 8;
    if (len > n - at - 12) {
      fail(why, why_len, "has a chunk longer than the file");
      goto done;
    }
    if (sn_crc32(0, type, 4 + (size_t)len) != be32(data + len)) {
      fail(why, why_len, "has a chunk whose CRC is wrong");
      goto done;
    }
    if (memcmp(type, "IHDR", 4) == 0) {
      if (len != 13) {
        fail(why, why_len, "has a bad IHDR chunk");
        goto done;
      }
      w = be32(data), h = be32(data + 4), depth = data[8], ctype = data[9], interlace = data[12];
    } else if (memcmp(type, "PLTE", 4) == 0) {
      npalette = (int)(len / 3 > 256 ? 256 : len / 3);
      for (int i = 0; i < npalette; i++)
        memcpy(palette[i], data + 3 * i, 3);
    } else if (memcmp(type, "tRNS", 4) == 0) {
      if (ctype == 3)
        for (uint32_t i = 0; i < len && i < 256; i++)
          palette[i][3] = data[i];
      else if (ctype == 0 && len >= 2)
        key[0] = (int)(data[0] << 8 | data[1]);
      else if (ctype == 2 && len >= 6)
        for (int c = 0; c < 3; c++)
          key[c] = (int)(data[2 * c] << 8 | data[2 * c + 1]);
    } else if (memcmp(type, "IDAT", 4) == 0) {
      unsigned char *grown = realloc(idat, idat_len + len + 1);
      if (grown == NULL) {
        fail(why, why_len, "is too large");
        goto done;
      }
      idat = grown;
      memcpy(idat + idat_len, data, len);
      idat_len += len;
    } else if (memcmp(type, "IEND", 4) == 0) {
      break;
    }
    at += 12 + (size_t)len;
  }
  int channels = ctype == 0 ? 1 : ctype == 2 ? 3 : ctype == 3 ? 1 : ctype == 4 ? 2 : ctype == 6 ? 4 : 0;
  int depth_ok = ctype == 3 ? (depth == 1 || depth == 2 || depth == 4 || depth == 8)
                 : ctype == 0 ? (depth == 1 || depth == 2 || depth == 4 || depth == 8 || depth == 16)
                              : (depth == 8 || depth == 16);
  if (channels == 0 || !depth_ok || w == 0 || h == 0) {
    fail(why, why_len, "has a colour type, bit depth or size this reader does not know");
    goto done;
  }
  if (interlace != 0) {
    fail(why, why_len, "is interlaced (Adam7), which this reader does not read");
    goto done;
  }
  if (w > 65536 || h > 65536 || (long)w * (long)h > max_pixels) {
    fail(why, why_len, "has more pixels than a display image may have");
    goto done;
  }
  size_t bpp_bits = (size_t)channels * (size_t)depth;
  size_t stride = ((size_t)w * bpp_bits + 7) / 8;
  size_t bpp = (bpp_bits + 7) / 8; /* bytes a filter looks back (at least 1) */
  size_t raw_len = (stride + 1) * h;
  raw = malloc(raw_len);
  out = malloc((size_t)w * h * 4);
  if (raw == NULL || out == NULL) {
    fail(why, why_len, "is too large");
    goto done;
  }
  if (idat == NULL || zlib_inflate(idat, idat_len, raw, raw_len) != (long)raw_len) {
    fail(why, why_len, "has damaged or missing image data");
    goto done;
  }
  for (uint32_t y = 0; y < h; y++) {
    unsigned char *line = raw + y * (stride + 1);
    unsigned char *cur = line + 1;
    const unsigned char *prev = y > 0 ? raw + (y - 1) * (stride + 1) + 1 : NULL;
    int filter = line[0];
    for (size_t x = 0; x < stride; x++) {
      int a = x >= bpp ? cur[x - bpp] : 0, b = prev ? prev[x] : 0, c = (prev && x >= bpp) ? prev[x - bpp] : 0;
      switch (filter) {
        case 0:
          break;
        case 1:
          cur[x] = (unsigned char)(cur[x] + a);
          break;
        case 2:
          cur[x] = (unsigned char)(cur[x] + b);
          break;
        case 3:
          cur[x] = (unsigned char)(cur[x] + ((a + b) >> 1));
          break;
        case 4:
          cur[x] = (unsigned char)(cur[x] + paeth(a, b, c));
          break;
        default:
          fail(why, why_len, "has a scanline with an unknown filter");
          goto done;
      }
    }
    for (uint32_t x = 0; x < w; x++) {
      unsigned char *o = out + 4 * ((size_t)y * w + x);
      int s[4]; /* samples at full precision (for the colour key), then shown as 8 bits */
      for (int k = 0; k < channels; k++) {
        if (depth == 16) {
          const unsigned char *p = cur + 2 * ((size_t)x * channels + k);
          s[k] = p[0] << 8 | p[1];
        } else if (depth == 8) {
          s[k] = cur[(size_t)x * channels + k];
        } else { /* 1, 2 or 4 bits: one channel, packed from the high bits */
          size_t bit = (size_t)x * depth;
          s[k] = (cur[bit / 8] >> (8 - depth - (int)(bit % 8))) & ((1 << depth) - 1);
        }
      }
      int scale_grey = depth < 8 ? 255 / ((1 << depth) - 1) : 1;
      int shift = depth == 16 ? 8 : 0;
      switch (ctype) {
        case 0:
          o[0] = o[1] = o[2] = (unsigned char)(depth < 8 ? s[0] * scale_grey : s[0] >> shift);
          o[3] = s[0] == key[0] ? 0 : 255;
          break;
        case 2:
          for (int k = 0; k < 3; k++)
            o[k] = (unsigned char)(s[k] >> shift);
          o[3] = (s[0] == key[0] && s[1] == key[1] && s[2] == key[2]) ? 0 : 255;
          break;
        case 3:
          if (s[0] >= npalette) {
            fail(why, why_len, "has a palette index past its palette");
            goto done;
          }
          memcpy(o, palette[s[0]], 4);
          break;
        case 4:
          o[0] = o[1] = o[2] = (unsigned char)(s[0] >> shift);
          o[3] = (unsigned char)(s[1] >> shift);
          break;
        default: /* 6 */
          for (int k = 0; k < 4; k++)
            o[k] = (unsigned char)(s[k] >> shift);
          break;
      }
    }
  }
  *width = (int)w;
  *height = (int)h;
  *rgba = out;
  out = NULL;
  rc = 0;
done:
  free(file);
  free(idat);
  free(raw);
  free(out);
  return rc;
}
