/* Sensorium C controller library: Webots' cross-platform system helpers (POSIX answers, as Webots
 * gives on Linux and macOS). */
#ifndef WBU_SYSTEM_H
#define WBU_SYSTEM_H

#include "../types.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The variable's value (UTF-8), or NULL when it is not set. */
const char *wbu_system_getenv(const char *variable);
/* The path itself (only Windows shortens paths). */
const char *wbu_system_short_path(const char *path);
/* The temporary folder Webots uses on Linux and macOS: /tmp. */
const char *wbu_system_tmpdir(void);
/* $WEBOTS_INSTANCE_PATH when set and not empty (read again when refresh is true), else NULL: a
 * Sensorium server is no Webots instance and has no such folder. */
const char *wbu_system_webots_instance_path(bool refresh);

#ifdef __cplusplus
}
#endif

#endif /* WBU_SYSTEM_H */
