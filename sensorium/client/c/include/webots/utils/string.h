/* Sensorium C controller library: Webots' string helpers for parsing messages. */
#ifndef WBU_STRING_H
#define WBU_STRING_H

#ifdef __cplusplus
extern "C" {
#endif

/* strsep() that does not split at a delimiter escaped by a backslash: returns the token that starts at
 * *stringp (NULL when *stringp is NULL), ends it with a NUL and moves *stringp past the delimiter
 * (NULL after the last token). */
char *wbu_string_strsep(char **stringp, const char *delim);
/* A new string (free() it) with every occurrence of before replaced by after (NULL: ""); NULL when
 * value or before is NULL, before is "", or memory runs out. */
char *wbu_string_replace(char *value, const char *before, const char *after);

#ifdef __cplusplus
}
#endif

#endif /* WBU_STRING_H */
