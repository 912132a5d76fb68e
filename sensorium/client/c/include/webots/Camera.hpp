// Sensorium C++ controller layer: Camera (Webots' C++ names over the wb_camera_* functions).
#ifndef WEBOTS_CAMERA_HPP
#define WEBOTS_CAMERA_HPP

#include <string>

#include <webots/Device.hpp>
#include <webots/camera.h>

namespace webots {

typedef WbCameraRecognitionObject CameraRecognitionObject;

class Camera : public Device {
public:
  explicit Camera(WbDeviceTag tag) : Device(tag) {}
  explicit Camera(const std::string &name) : Device(name) {}  // Webots: prefer Robot::getDevice
  void enable(int samplingPeriod) { wb_camera_enable(tag_, samplingPeriod); }
  void disable() { wb_camera_disable(tag_); }
  int getSamplingPeriod() const { return wb_camera_get_sampling_period(tag_); }
  const unsigned char *getImage() const { return wb_camera_get_image(tag_); }
  int getWidth() const { return wb_camera_get_width(tag_); }
  int getHeight() const { return wb_camera_get_height(tag_); }
  double getFov() const { return wb_camera_get_fov(tag_); }
  double getMaxFov() const { return wb_camera_get_max_fov(tag_); }
  double getMinFov() const { return wb_camera_get_min_fov(tag_); }
  void setFov(double fov) { wb_camera_set_fov(tag_, fov); }
  double getExposure() const { return wb_camera_get_exposure(tag_); }
  void setExposure(double exposure) { wb_camera_set_exposure(tag_, exposure); }
  double getFocalLength() const { return wb_camera_get_focal_length(tag_); }
  double getFocalDistance() const { return wb_camera_get_focal_distance(tag_); }
  double getMaxFocalDistance() const { return wb_camera_get_max_focal_distance(tag_); }
  double getMinFocalDistance() const { return wb_camera_get_min_focal_distance(tag_); }
  void setFocalDistance(double focalDistance) { wb_camera_set_focal_distance(tag_, focalDistance); }
  double getNear() const { return wb_camera_get_near(tag_); }
  int saveImage(const std::string &filename, int quality) const { return wb_camera_save_image(tag_, filename.c_str(), quality); }
  bool hasRecognition() const { return wb_camera_has_recognition(tag_); }
  void recognitionEnable(int samplingPeriod) { wb_camera_recognition_enable(tag_, samplingPeriod); }
  void recognitionDisable() { wb_camera_recognition_disable(tag_); }
  int recognitionGetSamplingPeriod() const { return wb_camera_recognition_get_sampling_period(tag_); }
  int recognitionGetNumberOfObjects() const { return wb_camera_recognition_get_number_of_objects(tag_); }
  const WbCameraRecognitionObject *recognitionGetObjects() const { return wb_camera_recognition_get_objects(tag_); }
  bool recognitionHasSegmentation() const { return wb_camera_recognition_has_segmentation(tag_); }
  void recognitionEnableSegmentation() { wb_camera_recognition_enable_segmentation(tag_); }
  void recognitionDisableSegmentation() { wb_camera_recognition_disable_segmentation(tag_); }
  bool recognitionIsSegmentationEnabled() const { return wb_camera_recognition_is_segmentation_enabled(tag_); }
  const unsigned char *recognitionGetSegmentationImage() const { return wb_camera_recognition_get_segmentation_image(tag_); }
  int recognitionSaveSegmentationImage(const std::string &filename, int quality) { return wb_camera_recognition_save_segmentation_image(tag_, filename.c_str(), quality); }
  // Webots' C++ names of the recognition functions (the ones above are kept for existing code)
  int getRecognitionSamplingPeriod() const { return wb_camera_recognition_get_sampling_period(tag_); }
  int getRecognitionNumberOfObjects() const { return wb_camera_recognition_get_number_of_objects(tag_); }
  const CameraRecognitionObject *getRecognitionObjects() const { return wb_camera_recognition_get_objects(tag_); }
  bool hasRecognitionSegmentation() const { return wb_camera_recognition_has_segmentation(tag_); }
  void enableRecognitionSegmentation() { wb_camera_recognition_enable_segmentation(tag_); }
  void disableRecognitionSegmentation() { wb_camera_recognition_disable_segmentation(tag_); }
  bool isRecognitionSegmentationEnabled() const { return wb_camera_recognition_is_segmentation_enabled(tag_); }
  const unsigned char *getRecognitionSegmentationImage() const { return wb_camera_recognition_get_segmentation_image(tag_); }
  int saveRecognitionSegmentationImage(const std::string &filename, int quality) const {
    return wb_camera_recognition_save_segmentation_image(tag_, filename.c_str(), quality);
  }
  // pixels of a BGRA image (getImage())
  static unsigned char imageGetRed(const unsigned char *image, int width, int x, int y) { return wb_camera_image_get_red(image, width, x, y); }
  static unsigned char imageGetGreen(const unsigned char *image, int width, int x, int y) { return wb_camera_image_get_green(image, width, x, y); }
  static unsigned char imageGetBlue(const unsigned char *image, int width, int x, int y) { return wb_camera_image_get_blue(image, width, x, y); }
  static unsigned char imageGetGray(const unsigned char *image, int width, int x, int y) { return wb_camera_image_get_gray(image, width, x, y); }
  static unsigned char imageGetGrey(const unsigned char *image, int width, int x, int y) { return wb_camera_image_get_grey(image, width, x, y); }
};

}  // namespace webots

#endif
