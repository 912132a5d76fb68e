/* Sensorium C controller library: one object a Camera's recognition reports (Webots' layout). */
#ifndef WB_CAMERA_RECOGNITION_OBJECT_H
#define WB_CAMERA_RECOGNITION_OBJECT_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  int id;                   /* the node id of the object */
  double position[3];       /* relative to the camera (m) */
  double orientation[4];    /* axis-angle relative to the camera */
  double size[2];           /* width, height (m) */
  int position_on_image[2]; /* pixel of its centre */
  int size_on_image[2];     /* pixels */
  int number_of_colors;
  double *colors;           /* number_of_colors x RGB */
  char *model;
} WbCameraRecognitionObject;

#ifdef __cplusplus
}
#endif

#endif /* WB_CAMERA_RECOGNITION_OBJECT_H */
