/* Sensorium C controller library: a controller's side of Webots' robot window messages. A headless
 * server has no robot window page: what is sent is published on the topic /<robot>/robot_window
 * (std_msgs/String; with $SENSORIUM_ROBOT_WINDOW_LOG=1, sensorium run --robot-window-log, also printed
 * on stderr as "robot window: TEXT"), and what the window side sends (`sensorium window ROBOT TEXT`)
 * comes with the step replies, read one text per wb_robot_wwi_receive_text call as in Webots; as the
 * Python client (Robot.wwiSendText / wwiReceiveText). */
#ifndef WB_ROBOT_WWI_H
#define WB_ROBOT_WWI_H

#ifdef __cplusplus
#include <cstring>
extern "C" {
#else
#include <string.h>
#endif

void wb_robot_wwi_send(const char *data, int size);
const char *wb_robot_wwi_receive(int *size);
const char *wb_robot_wwi_receive_text(void);
/* the text with its terminating NUL, as Webots sends it */
#define wb_robot_wwi_send_text(text) wb_robot_wwi_send((text), (int)strlen(text) + 1)

#ifdef __cplusplus
}
#endif

#endif /* WB_ROBOT_WWI_H */
