/* Sensorium C controller library: one target a Radar reports (Webots' layout). */
#ifndef WB_RADAR_TARGET_H
#define WB_RADAR_TARGET_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  double distance;       /* m */
  double received_power; /* dBm */
  double speed;          /* m/s, radial */
  double azimuth;        /* rad */
} WbRadarTarget;

#ifdef __cplusplus
}
#endif

#endif /* WB_RADAR_TARGET_H */
