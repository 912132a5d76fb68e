/* Sensorium C controller library: console printing (console.h) and Webots' system and string helpers
 * (utils/system.h, utils/string.h), and how the library shows a caller's string in an error line. None of
 * them talks to the server. Written from Webots' documented behaviour. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/console.h>
#include <webots/utils/string.h>
#include <webots/utils/system.h>

#include "internal.h"

/* ------------------------------------------------------------------ console */
void wb_console_print(const char *text, int stream) {
  FILE *out = stream == WB_STDOUT ? stdout : stream == WB_STDERR ? stderr : NULL;
  if (out == NULL) {
    fprintf(stderr, "Error: wb_console_print(): unknown stream %d (WB_STDOUT is 1, WB_STDERR is 2)\n", stream);
    return;
  }
  if (text != NULL)
    fputs(text, out);
  fflush(out); /* the text shows at once, interleaved as the controller printed it */
}

/* ------------------------------------------------------------------ system */
const char *wbu_system_getenv(const char *variable) {
  return variable != NULL ? getenv(variable) : NULL;
}

const char *wbu_system_short_path(const char *path) {
  return path;
}

const char *wbu_system_tmpdir(void) {
  return "/tmp";
}

const char *wbu_system_webots_instance_path(bool refresh) {
  static const char *path = NULL;
  if (path == NULL || refresh) {
    path = getenv("WEBOTS_INSTANCE_PATH");
    if (path != NULL && path[0] == '\0')
      path = NULL;
  }
  return path;
}

/* ------------------------------------------------------------------ string */
char *wbu_string_strsep(char **stringp, const char *delim) {
  if (stringp == NULL || *stringp == NULL)
    return NULL;
  char *token = *stringp;
  const char *set = delim != NULL ? delim : "";
  for (char *p = token; *p != '\0'; p++) {
    if (strchr(set, *p) != NULL && (p == token || p[-1] != '\\')) {
      *p = '\0';
      *stringp = p + 1;
      return token;
    }
  }
  *stringp = NULL; /* the last token */
  return token;
}

char *wbu_string_replace(char *value, const char *before, const char *after) {
  if (value == NULL || before == NULL || before[0] == '\0')
    return NULL;
  if (after == NULL)
    after = "";
  const size_t nb = strlen(before), na = strlen(after);
  size_t count = 0;
  for (const char *p = strstr(value, before); p != NULL; p = strstr(p + nb, before))
    count++;
  const size_t size = strlen(value) - count * nb + count * na + 1;
  char *out = malloc(size);
  if (out == NULL)
    return NULL;
  char *w = out;
  const char *r = value;
  for (const char *p = strstr(r, before); p != NULL; p = strstr(r, before)) {
    memcpy(w, r, (size_t)(p - r));
    w += p - r;
    memcpy(w, after, na);
    w += na;
    r = p + nb;
  }
  strcpy(w, r);
  return out;
}

/* ------------------------------------------------------------------ names in error lines */
const char *sn_shown(const char *s) { return s == NULL ? "(null)" : sn_shown_n(s, strlen(s)); }

const char *sn_shown_n(const char *s, size_t size) {
  static _Thread_local char slots[SN_SHOWN_SLOTS][SN_SHOWN_MAX + 8];
  static _Thread_local int next = 0;
  char *out = slots[next];
  next = (next + 1) % SN_SHOWN_SLOTS;
  if (s == NULL)
    return "(null)";
  size_t n = 0;
  for (const unsigned char *p = (const unsigned char *)s, *end = p + size; p < end; p++) {
    char piece[5];
    if (*p == '\n' || *p == '\t' || *p == '\r')
      snprintf(piece, sizeof piece, "\\%c", *p == '\n' ? 'n' : *p == '\t' ? 't' : 'r');
    else if (*p < 0x20 || *p == 0x7f)
      snprintf(piece, sizeof piece, "\\x%02x", *p);
    else {
      piece[0] = (char)*p;
      piece[1] = '\0';
    }
    size_t len = strlen(piece);
    if (n + len > SN_SHOWN_MAX) {
      if ((*p & 0xC0) == 0x80) { /* the cut is inside a UTF-8 character: its first bytes go too */
        while (n > 0 && ((unsigned char)out[n - 1] & 0xC0) == 0x80)
          n--;
        if (n > 0 && (unsigned char)out[n - 1] >= 0xC0)
          n--;
      }
      memcpy(out + n, "...", 4);
      return out;
    }
    memcpy(out + n, piece, len);
    n += len;
  }
  out[n] = '\0';
  return out;
}
