// Sensorium's wbvector2: two-dimensional vectors {x, y} (Webots' documented API).

export function equal(a, b) {
  return a.x === b.x && a.y === b.y;
}

export function add(a, b) {
  return {x: a.x + b.x, y: a.y + b.y};
}

export function minus(a, b) {
  return {x: a.x - b.x, y: a.y - b.y};
}

export function multiply(v, s) {
  return {x: v.x * s, y: v.y * s};
}

export function dot(a, b) {
  return a.x * b.x + a.y * b.y;
}

export function cross(a, b) {
  return a.x * b.y - a.y * b.x;
}

export function norm(v) {
  return Math.hypot(v.x, v.y);
}

export function distance(a, b) {
  return norm(minus(a, b));
}

// the direction of a - b, as Webots' wbvector2.angle(a, b) gives it
export function angle(a, b) {
  return Math.atan2(a.y - b.y, a.x - b.x);
}

export function normalize(v) {
  const n = norm(v);
  if (n === 0) {
    console.error('wbvector2.normalize: a zero vector has no direction');
    return null;
  }
  return {x: v.x / n, y: v.y / n};
}

// the point where segments [p1, p2] and [p3, p4] cross, or null (parallel, apart or degenerate)
export function intersection(p1, p2, p3, p4) {
  const d1 = minus(p2, p1);
  const d2 = minus(p4, p3);
  const denominator = cross(d1, d2);
  if (denominator === 0 || (d1.x === 0 && d1.y === 0) || (d2.x === 0 && d2.y === 0))
    return null;
  const offset = minus(p3, p1);
  const t = cross(offset, d2) / denominator;
  const u = cross(offset, d1) / denominator;
  if (t < 0 || t > 1 || u < 0 || u > 1)
    return null;
  return {x: p1.x + t * d1.x, y: p1.y + t * d1.y};
}
