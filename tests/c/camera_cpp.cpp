// Webots' C++ Camera and RangeFinder names (static pixel helpers, getRecognition*) and the Robot's
// path getters, against tests/worlds/supervisor_remove.yaml: boss's range finder and camera look
// along +x at the crate, whose face is 1 m away (the centre depth pixel reads 1.0). Each line also
// says whether the C++ answer equals the C function's.
#include <cstdio>

#include <webots/Camera.hpp>
#include <webots/RangeFinder.hpp>
#include <webots/Robot.hpp>

using namespace webots;

int main() {
  Robot *robot = new Robot();
  int timestep = static_cast<int>(robot->getBasicTimeStep());
  Camera *cam = robot->getCamera("cam");
  RangeFinder *depth = robot->getRangeFinder("depth");
  cam->enable(timestep);
  cam->recognitionEnable(timestep);
  depth->enable(timestep);
  robot->step(timestep);

  const float *range = depth->getRangeImage();
  int w = depth->getWidth(), cx = w / 2, cy = depth->getHeight() / 2;
  float d = RangeFinder::rangeImageGetDepth(range, w, cx, cy);
  std::printf("depth %.9g %d\n", d, d == wb_range_finder_image_get_depth(range, w, cx, cy));

  const unsigned char *image = cam->getImage();
  int cw = cam->getWidth(), px = cw / 2, py = cam->getHeight() / 2;
  unsigned char r = Camera::imageGetRed(image, cw, px, py), g = Camera::imageGetGreen(image, cw, px, py);
  unsigned char b = Camera::imageGetBlue(image, cw, px, py), gray = Camera::imageGetGray(image, cw, px, py);
  std::printf("pixel %d %d\n", r == wb_camera_image_get_red(image, cw, px, py) && g == wb_camera_image_get_green(image, cw, px, py) &&
                                   b == wb_camera_image_get_blue(image, cw, px, py),
              gray == wb_camera_image_get_gray(image, cw, px, py) && Camera::imageGetGrey(image, cw, px, py) == gray);

  int n = cam->getRecognitionNumberOfObjects();
  const CameraRecognitionObject *objects = cam->getRecognitionObjects();
  std::printf("recognition %d %d %d %d %d\n", cam->getRecognitionSamplingPeriod(), n,
              n == wb_camera_recognition_get_number_of_objects(cam->getTag()), n > 0 ? objects[0].id : -1,
              cam->hasRecognitionSegmentation() ? 1 : 0);
  std::printf("paths [%s] [%s] [%s]\n", robot->getProjectPath().c_str(), robot->getWorldPath().c_str(),
              robot->getUrdf("b_").substr(0, 21).c_str()); /* the URDF's XML declaration */
  delete robot;
  return 0;
}
