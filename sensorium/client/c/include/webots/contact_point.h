/* Sensorium C controller library: WbContactPoint (supervisor.h's contact point functions), in its own
 * header as in Webots. */
#ifndef WB_CONTACT_POINT_H
#define WB_CONTACT_POINT_H

/* A contact point: where it is in the world frame (m) and the id of the solid node touching there. */
typedef struct {
  double point[3];
  int node_id;
} WbContactPoint;

#endif /* WB_CONTACT_POINT_H */
