/* Sensorium C controller library: wb_console_print. Webots sends the text to its console; here it goes
 * to the controller's own standard output (WB_STDOUT) or error (WB_STDERR), flushed at once, which is
 * what `sensorium controller` and a terminal show. Another stream number prints one error line. */
#ifndef WB_CONSOLE_H
#define WB_CONSOLE_H

#ifdef __cplusplus
extern "C" {
#endif

#define WB_STDOUT 1
#define WB_STDERR 2

void wb_console_print(const char *text, int stream);

#ifdef __cplusplus
}
#endif

#endif /* WB_CONSOLE_H */
