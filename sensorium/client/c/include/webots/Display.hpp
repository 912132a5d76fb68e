// Sensorium C++ controller layer: Display (Webots' C++ names over the wb_display_* functions).
#ifndef WEBOTS_DISPLAY_HPP
#define WEBOTS_DISPLAY_HPP

#include <string>

#include <webots/Device.hpp>
#include <webots/ImageRef.hpp>
#include <webots/display.h>

namespace webots {

class Display : public Device {
public:
  enum { RGB = WB_IMAGE_RGB, RGBA = WB_IMAGE_RGBA, ARGB = WB_IMAGE_ARGB, BGRA = WB_IMAGE_BGRA, ABGR = WB_IMAGE_ABGR };
  explicit Display(WbDeviceTag tag) : Device(tag) {}
  explicit Display(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  int getWidth() const { return wb_display_get_width(tag_); }
  int getHeight() const { return wb_display_get_height(tag_); }
  void setColor(int color) { wb_display_set_color(tag_, color); }
  void setAlpha(double alpha) { wb_display_set_alpha(tag_, alpha); }
  void setOpacity(double opacity) { wb_display_set_opacity(tag_, opacity); }
  void setFont(const std::string &font, int size, bool antiAliasing) { wb_display_set_font(tag_, font.c_str(), size, antiAliasing); }
  void attachCamera(Device *cameraTag) { wb_display_attach_camera(tag_, cameraTag ? cameraTag->getTag() : 0); }
  void detachCamera() { wb_display_detach_camera(tag_); }
  void drawPixel(int x, int y) { wb_display_draw_pixel(tag_, x, y); }
  void drawLine(int x1, int y1, int x2, int y2) { wb_display_draw_line(tag_, x1, y1, x2, y2); }
  void drawRectangle(int x, int y, int width, int height) { wb_display_draw_rectangle(tag_, x, y, width, height); }
  void drawOval(int cx, int cy, int a, int b) { wb_display_draw_oval(tag_, cx, cy, a, b); }
  void drawPolygon(const int *x, const int *y, int size) { wb_display_draw_polygon(tag_, x, y, size); }
  void drawText(const std::string &text, int x, int y) { wb_display_draw_text(tag_, text.c_str(), x, y); }
  void fillRectangle(int x, int y, int width, int height) { wb_display_fill_rectangle(tag_, x, y, width, height); }
  void fillOval(int cx, int cy, int a, int b) { wb_display_fill_oval(tag_, cx, cy, a, b); }
  void fillPolygon(const int *x, const int *y, int size) { wb_display_fill_polygon(tag_, x, y, size); }
  ImageRef *imageNew(int width, int height, const void *data, int format) const { return wrap(wb_display_image_new(tag_, width, height, data, format)); }
  ImageRef *imageLoad(const std::string &filename) const { return wrap(wb_display_image_load(tag_, filename.c_str())); }
  ImageRef *imageCopy(int x, int y, int width, int height) const { return wrap(wb_display_image_copy(tag_, x, y, width, height)); }
  void imagePaste(ImageRef *ir, int x, int y, bool blend = false) { wb_display_image_paste(tag_, ir ? ir->getRef() : NULL, x, y, blend); }
  void imageSave(ImageRef *ir, const std::string &filename) const { wb_display_image_save(tag_, ir ? ir->getRef() : NULL, filename.c_str()); }
  void imageDelete(ImageRef *ir) const {  // the handle is gone with its image, as in Webots
    wb_display_image_delete(tag_, ir ? ir->getRef() : NULL);
    delete ir;
  }

private:
  static ImageRef *wrap(WbImageRef ref) { return ref ? new ImageRef(ref) : 0; }
};

}  // namespace webots

#endif
