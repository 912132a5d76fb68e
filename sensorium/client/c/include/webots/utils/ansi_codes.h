/* Sensorium C controller library: terminal escape sequences (Webots' utils/ansi_codes.h names; the
 * codes are the standard ANSI ones). The ANSI_PRINTF_IN_* macros take printf's arguments. */
#ifndef WBU_ANSI_CODES_H
#define WBU_ANSI_CODES_H

#ifndef __cplusplus
#include <stdio.h>
#endif

#define ANSI_RESET "\x1b[0m"
#define ANSI_BOLD "\x1b[1m"
#define ANSI_UNDERLINE "\x1b[4m"

#define ANSI_BLACK_BACKGROUND "\x1b[40m"
#define ANSI_RED_BACKGROUND "\x1b[41m"
#define ANSI_GREEN_BACKGROUND "\x1b[42m"
#define ANSI_YELLOW_BACKGROUND "\x1b[43m"
#define ANSI_BLUE_BACKGROUND "\x1b[44m"
#define ANSI_MAGENTA_BACKGROUND "\x1b[45m"
#define ANSI_CYAN_BACKGROUND "\x1b[46m"
#define ANSI_WHITE_BACKGROUND "\x1b[47m"

#define ANSI_BLACK_FOREGROUND "\x1b[30m"
#define ANSI_RED_FOREGROUND "\x1b[31m"
#define ANSI_GREEN_FOREGROUND "\x1b[32m"
#define ANSI_YELLOW_FOREGROUND "\x1b[33m"
#define ANSI_BLUE_FOREGROUND "\x1b[34m"
#define ANSI_MAGENTA_FOREGROUND "\x1b[35m"
#define ANSI_CYAN_FOREGROUND "\x1b[36m"
#define ANSI_WHITE_FOREGROUND "\x1b[37m"

#define ANSI_CLEAR_SCREEN "\x1b[2J"

#ifndef __cplusplus
/* (C99: the colour, then printf's own arguments, then the reset) */
#define WBU_ANSI_PRINTF_(colour, ...) (printf("%s", colour), printf(__VA_ARGS__), printf("%s", ANSI_RESET))
#define ANSI_PRINTF_IN_BLACK(...) WBU_ANSI_PRINTF_(ANSI_BLACK_FOREGROUND, __VA_ARGS__)
#define ANSI_PRINTF_IN_RED(...) WBU_ANSI_PRINTF_(ANSI_RED_FOREGROUND, __VA_ARGS__)
#define ANSI_PRINTF_IN_GREEN(...) WBU_ANSI_PRINTF_(ANSI_GREEN_FOREGROUND, __VA_ARGS__)
#define ANSI_PRINTF_IN_YELLOW(...) WBU_ANSI_PRINTF_(ANSI_YELLOW_FOREGROUND, __VA_ARGS__)
#define ANSI_PRINTF_IN_BLUE(...) WBU_ANSI_PRINTF_(ANSI_BLUE_FOREGROUND, __VA_ARGS__)
#define ANSI_PRINTF_IN_MAGENTA(...) WBU_ANSI_PRINTF_(ANSI_MAGENTA_FOREGROUND, __VA_ARGS__)
#define ANSI_PRINTF_IN_CYAN(...) WBU_ANSI_PRINTF_(ANSI_CYAN_FOREGROUND, __VA_ARGS__)
#define ANSI_PRINTF_IN_WHITE(...) WBU_ANSI_PRINTF_(ANSI_WHITE_FOREGROUND, __VA_ARGS__)
#define ANSI_CLEAR_CONSOLE() printf("%s\n", ANSI_CLEAR_SCREEN)
#endif

#endif /* WBU_ANSI_CODES_H */
