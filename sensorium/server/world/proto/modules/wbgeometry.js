// Sensorium's wbgeometry: circles, polygons and B-splines for procedural PROTOs (Webots' documented API).

import * as wbvector2 from 'wbvector2.js';

// div + 1 points of a circle (the first repeated last, closing it), starting at angle shift
export function circle(radius, div, center, shift) {
  const points = [];
  const step = 2 * Math.PI / div;
  for (let i = 0; i <= div; ++i) {
    const t = shift + i * step;
    points.push({x: center.x + radius * Math.cos(t), y: center.y + radius * Math.sin(t)});
  }
  return points;
}

// even-odd rule: does a horizontal ray from p cross the polygon's edges an odd number of times
export function isPoint2InPolygon(p, polygon) {
  let inside = false;
  const n = polygon.length;
  if (n < 3)
    return false;
  for (let i = 0, j = n - 1; i < n; j = i++) {
    const a = polygon[i];
    const b = polygon[j];
    if ((a.y > p.y) !== (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x)
      inside = !inside;
  }
  return inside;
}

export function findClosestPoint2InArray(reference, points) {
  let best = reference;
  let bestDistance = Infinity;
  for (const p of points) {
    const d = wbvector2.distance(reference, p);
    if (d < bestDistance) {
      bestDistance = d;
      best = p;
    }
  }
  return best;
}

// the shoelace sum: negative area (in x right, y up axes) means clockwise
export function isPoint2ArrayClockwise(points) {
  let twiceArea = 0;
  for (let i = 0; i < points.length; ++i) {
    const a = points[i];
    const b = points[(i + 1) % points.length];
    twiceArea += a.x * b.y - b.x * a.y;
  }
  return twiceArea < 0;
}

// a uniform cubic B-spline through the control points, each end extended by mirroring its
// neighbour so that the curve starts at the first point and ends at the last; `subdivision`
// points per segment after the first point
function bSpline(points, subdivision, keys) {
  const n = points.length;
  if (n < 2)
    return points.slice();
  const mirror = (p, q) => {
    const out = {};
    for (const k of keys)
      out[k] = 2 * p[k] - q[k];
    return out;
  };
  const before = mirror(points[0], points[1]);
  const after = mirror(points[n - 1], points[n - 2]);
  const c = [before, ...points, after];
  const spline = [points[0]];
  for (let i = 1; i < c.length - 2; ++i) {
    const p0 = c[i - 1], p1 = c[i], p2 = c[i + 1], p3 = c[i + 2];
    for (let j = 1; j <= subdivision; ++j) {
      const t = j / subdivision;
      const b0 = (1 - t) * (1 - t) * (1 - t) / 6;
      const b1 = (3 * t * t * t - 6 * t * t + 4) / 6;
      const b2 = (-3 * t * t * t + 3 * t * t + 3 * t + 1) / 6;
      const b3 = t * t * t / 6;
      const p = {};
      for (const k of keys)
        p[k] = b0 * p0[k] + b1 * p1[k] + b2 * p2[k] + b3 * p3[k];
      spline.push(p);
    }
  }
  return spline;
}

export function bSpline2(points, subdivision) {
  return bSpline(points, subdivision, ['x', 'y']);
}

export function bSpline3(points, subdivision) {
  return bSpline(points, subdivision, ['x', 'y', 'z']);
}
