"""GPS (Webots' ``GPS`` node): position, speed and speed vector of the device, in the world's
local coordinates or as WGS84 latitude / longitude / altitude.

The formulas, as Webots computes them (``WbGps``):

* position ``p = t + reference``: ``t`` the device's world translation; ``reference`` is
  ``WorldInfo.gpsReference`` as given (local), or (WGS84) the reference latitude / longitude as UTM
  northing / easting and its altitude, placed on the world's N, E and U axes
  (``WorldInfo.coordinateSystem``);
* noise per axis, a Gauss-Markov process: ``ratio = noiseCorrelation ** (elapsed_s)`` (0 without
  correlation), ``n_i <- ratio·n_i + sqrt(1 - ratio²)·G``, ``p_i += accuracy·n_i``;
* ``resolution`` per axis: ``trunc(p/res + 0.5)·res`` (lookup.quantize_sensor), before the WGS84
  conversion;
* WGS84: the N and E coordinates back to latitude / longitude by the inverse UTM series of the
  reference's zone, altitude = the U coordinate;
* speed vector: ``(t - t_previous) / elapsed`` (Webots' rule for a device without physics, which a
  kinematic robot is), NaN at the first measurement; speed ``|v|·(1 + speedNoise·G)``, then
  ``speedResolution``.

Pure: arrays and floats in, values out; the noise state and the previous position are the caller's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sensorium.server.devices.lookup import quantize_sensor

__all__ = ["Utm", "position", "speed", "speed_vector"]

# WGS84 as Webots' converter takes it (its flattening is 1/298.2572236)
_A = 6378137.0
_F = 1.0 / 298.2572236
_K0 = 0.9996
_E0 = 500000.0


@dataclass(frozen=True)
class Utm:
    """The transverse Mercator projection of the UTM zone of a reference point (WGS84 ellipsoid):
    ``north_east`` and its inverse ``latitude_longitude`` (degrees), by the usual series."""

    reference_latitude: float
    reference_longitude: float

    @property
    def zone(self) -> int:
        return 1 + math.floor((self.reference_longitude + 180.0) / 6.0)

    @property
    def central_meridian(self) -> float:
        """radians"""
        return math.radians(6.0 * self.zone - 183.0)

    @property
    def false_northing(self) -> float:
        return 10_000_000.0 if self.reference_latitude < 0.0 else 0.0

    def north_east(self, latitude: float, longitude: float) -> tuple[float, float]:
        e2 = _F * (2.0 - _F)                       # first eccentricity squared
        ep2 = e2 / (1.0 - e2)                      # second eccentricity squared
        phi = math.radians(latitude)
        s, c = math.sin(phi), math.cos(phi)
        n = _A / math.sqrt(1.0 - e2 * s * s)       # prime vertical radius
        t = math.tan(phi) ** 2
        cc = ep2 * c * c
        a = (math.radians(longitude) - self.central_meridian) * c
        m = _A * _meridian_arc(phi, e2)
        east = _K0 * n * a * (1.0 + a * a * ((1.0 - t + cc) / 6.0
                                             + a * a * (5.0 - 18.0 * t + t * t + 72.0 * cc - 58.0 * ep2) / 120.0))
        north = _K0 * (m + n * math.tan(phi) * a * a * (
            0.5 + a * a * ((5.0 - t + 9.0 * cc + 4.0 * cc * cc) / 24.0
                           + a * a * (61.0 - 58.0 * t + t * t + 600.0 * cc - 330.0 * ep2) / 720.0)))
        return north + self.false_northing, east + _E0

    def latitude_longitude(self, north: float, east: float) -> tuple[float, float]:
        e2 = _F * (2.0 - _F)
        ep2 = e2 / (1.0 - e2)
        r = math.sqrt(1.0 - e2)
        e1 = (1.0 - r) / (1.0 + r)
        mu = (north - self.false_northing) / _K0 / (_A * (1.0 - e2 * (0.25 + e2 * (3.0 / 64.0 + 5.0 * e2 / 256.0))))
        phi1 = (mu + e1 * (1.5 - 27.0 * e1 * e1 / 32.0) * math.sin(2.0 * mu)
                + e1 * e1 * (21.0 / 16.0 - 55.0 * e1 * e1 / 32.0) * math.sin(4.0 * mu)
                + e1 ** 3 * (151.0 / 96.0 * math.sin(6.0 * mu) + e1 * 1097.0 / 512.0 * math.sin(8.0 * mu)))
        s1, c1 = math.sin(phi1), math.cos(phi1)
        cc1 = ep2 * c1 * c1
        t1 = math.tan(phi1) ** 2
        n1 = _A / math.sqrt(1.0 - e2 * s1 * s1)
        r1 = n1 * (1.0 - e2) / (1.0 - e2 * s1 * s1)
        d = (east - _E0) / (n1 * _K0)
        lat = phi1 - (n1 * math.tan(phi1) / r1) * (
            d * d * (0.5 - d * d * (5.0 + 3.0 * t1 + 10.0 * cc1 - 4.0 * cc1 * cc1 - 9.0 * ep2) / 24.0)
            + d ** 6 * (61.0 + 90.0 * t1 + 298.0 * cc1 + 45.0 * t1 * t1 - 252.0 * ep2 - 3.0 * cc1 * cc1) / 720.0)
        lon = self.central_meridian + d * (1.0 + d * d * ((-1.0 - 2.0 * t1 - cc1) / 6.0
                                                          + d * d * (5.0 - 2.0 * cc1 + 28.0 * t1 - 3.0 * cc1 * cc1
                                                                     + 8.0 * ep2 + 24.0 * t1 * t1) / 120.0)) / c1
        return math.degrees(lat), math.degrees(lon)


def _meridian_arc(phi: float, e2: float) -> float:
    """The meridian arc from the equator to latitude ``phi``, divided by the major radius."""
    return (phi * (1.0 - e2 * (0.25 + e2 * (3.0 / 64.0 + 5.0 * e2 / 256.0)))
            - math.sin(2.0 * phi) * e2 * (3.0 / 8.0 + e2 * (3.0 / 32.0 + 45.0 * e2 / 1024.0))
            + math.sin(4.0 * phi) * e2 * e2 * (15.0 / 256.0 + 45.0 * e2 / 1024.0)
            - math.sin(6.0 * phi) * e2 ** 3 * 35.0 / 3072.0)


def position(translation: np.ndarray, *, coordinate_system: str = "local", reference=(0.0, 0.0, 0.0),
             axes: str = "ENU", accuracy: float = 0.0, correlation: float = 0.0, elapsed_ms: int = 0,
             noise: np.ndarray | None = None, rng: np.random.Generator | None = None,
             resolution: float = -1.0) -> np.ndarray:
    """``wb_gps_get_values``: (x, y, z) in local coordinates, or (latitude°, longitude°, altitude m).

    ``noise`` (3,) is the Gauss-Markov state, updated in place when ``accuracy`` > 0 (three
    standard normals from ``rng``); ``elapsed_ms`` is the time since the previous measurement."""
    p = np.array(translation, dtype=np.float64)
    ref = np.array(reference, dtype=np.float64)
    utm = None
    if coordinate_system == "WGS84":
        utm = Utm(float(ref[0]), float(ref[1]))
        north, east = utm.north_east(float(ref[0]), float(ref[1]))
        ref = np.empty(3)
        ref[axes.index("E")], ref[axes.index("N")], ref[axes.index("U")] = east, north, float(reference[2])
    p += ref
    if accuracy != 0.0:
        assert noise is not None and rng is not None
        ratio = correlation ** (elapsed_ms / 1000.0) if correlation != 0.0 else 0.0
        noise *= ratio
        noise += math.sqrt(1.0 - ratio * ratio) * rng.standard_normal(3)
        p += accuracy * noise
    if resolution != -1.0:
        p = np.asarray(quantize_sensor(p, resolution), dtype=np.float64)
    if utm is not None:
        lat, lon = utm.latitude_longitude(float(p[axes.index("N")]), float(p[axes.index("E")]))
        p = np.array([lat, lon, p[axes.index("U")]])
    return p


def speed_vector(translation: np.ndarray, previous: np.ndarray | None, elapsed_ms: int) -> np.ndarray:
    """m/s in world coordinates: the displacement since the previous measurement over the time
    between them; NaN without a previous one (or no time between)."""
    if previous is None or elapsed_ms <= 0:
        return np.full(3, math.nan)
    return (np.asarray(translation, dtype=np.float64) - previous) * (1000.0 / elapsed_ms)


def speed(vector: np.ndarray, *, noise: float = 0.0, rng: np.random.Generator | None = None,
          resolution: float = -1.0) -> float:
    """``wb_gps_get_speed``: ``|v|``, times ``1 + noise·G`` when ``noise`` > 0, then ``resolution``."""
    v = math.sqrt(float(np.dot(vector, vector)))
    if noise > 0.0:
        assert rng is not None
        v *= 1.0 + noise * float(rng.standard_normal())
    if resolution != -1.0:
        v = float(quantize_sensor(v, resolution))
    return v
