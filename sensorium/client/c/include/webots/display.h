/* Sensorium C controller library: Display (Webots' wb_display_* functions).
 * Sensorium lists this device (name, model, type, index) but does not simulate it: every function
 * answers Webots' "no value" (NaN, a NaN vector, NULL, 0, "") and the first call per device prints one
 * warning line, except that wb_display_get_width/height answer the world's size (no warning) and
 * wb_display_image_new/copy return a usable handle of no pixels (image_save writes no file, says so once). */
#ifndef WB_DISPLAY_H
#define WB_DISPLAY_H

#include "types.h"

#ifdef __cplusplus
extern "C" {
#endif

enum { WB_IMAGE_RGB = 3, WB_IMAGE_RGBA = 4, WB_IMAGE_ARGB = 5, WB_IMAGE_BGRA = 6, WB_IMAGE_ABGR = 7 };

int wb_display_get_width(WbDeviceTag tag);
int wb_display_get_height(WbDeviceTag tag);
void wb_display_set_color(WbDeviceTag tag, int color);
void wb_display_set_alpha(WbDeviceTag tag, double alpha);
void wb_display_set_opacity(WbDeviceTag tag, double opacity);
void wb_display_set_font(WbDeviceTag tag, const char *font, int size, bool anti_aliasing);
void wb_display_attach_camera(WbDeviceTag tag, WbDeviceTag camera_tag);
void wb_display_detach_camera(WbDeviceTag tag);
void wb_display_draw_pixel(WbDeviceTag tag, int x, int y);
void wb_display_draw_line(WbDeviceTag tag, int x1, int y1, int x2, int y2);
void wb_display_draw_rectangle(WbDeviceTag tag, int x, int y, int width, int height);
void wb_display_draw_oval(WbDeviceTag tag, int cx, int cy, int a, int b);
void wb_display_draw_polygon(WbDeviceTag tag, const int *x, const int *y, int size);
void wb_display_draw_text(WbDeviceTag tag, const char *text, int x, int y);
void wb_display_fill_rectangle(WbDeviceTag tag, int x, int y, int width, int height);
void wb_display_fill_oval(WbDeviceTag tag, int cx, int cy, int a, int b);
void wb_display_fill_polygon(WbDeviceTag tag, const int *x, const int *y, int size);
WbImageRef wb_display_image_new(WbDeviceTag tag, int width, int height, const void *data, int format);
WbImageRef wb_display_image_load(WbDeviceTag tag, const char *filename);
WbImageRef wb_display_image_copy(WbDeviceTag tag, int x, int y, int width, int height);
void wb_display_image_paste(WbDeviceTag tag, WbImageRef ir, int x, int y, bool blend);
void wb_display_image_save(WbDeviceTag tag, WbImageRef ir, const char *filename);
void wb_display_image_delete(WbDeviceTag tag, WbImageRef ir);

#ifdef __cplusplus
}
#endif

#endif /* WB_DISPLAY_H */
