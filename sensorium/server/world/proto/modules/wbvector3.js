// Sensorium's wbvector3: three-dimensional vectors {x, y, z} (Webots' documented API).

export function equal(a, b) {
  return a.x === b.x && a.y === b.y && a.z === b.z;
}

export function add(a, b) {
  return {x: a.x + b.x, y: a.y + b.y, z: a.z + b.z};
}

export function minus(a, b) {
  return {x: a.x - b.x, y: a.y - b.y, z: a.z - b.z};
}

export function multiply(v, s) {
  return {x: v.x * s, y: v.y * s, z: v.z * s};
}

export function dot(a, b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

export function cross(a, b) {
  return {x: a.y * b.z - a.z * b.y, y: a.z * b.x - a.x * b.z, z: a.x * b.y - a.y * b.x};
}

export function norm(v) {
  return Math.hypot(v.x, v.y, v.z);
}

export function distance(a, b) {
  return norm(minus(a, b));
}

export function normalize(v) {
  const n = norm(v);
  if (n === 0) {
    console.error('wbvector3.normalize: a zero vector has no direction');
    return null;
  }
  return {x: v.x / n, y: v.y / n, z: v.z / n};
}
