// Sensorium C++ controller layer: ImageRef, a Display image handle (Display.hpp), in its own header as
// in Webots: an image the server keeps for the Display (imageNew, imageLoad, imageCopy).
#ifndef WEBOTS_IMAGEREF_HPP
#define WEBOTS_IMAGEREF_HPP

#include <webots/types.h>

namespace webots {

class ImageRef {
public:
  explicit ImageRef(WbImageRef ref) : ref_(ref) {}
  WbImageRef getRef() const { return ref_; }

private:
  WbImageRef ref_;
};

}  // namespace webots

#endif  // WEBOTS_IMAGEREF_HPP
