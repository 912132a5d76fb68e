// Sensorium's wbrotation: rotations as axis-angle {x, y, z, a}, quaternions {w, x, y, z} and 3x3
// matrices {0..8} (row major: element (row i, column j) is m[3 * i + j]) (Webots' documented API).

export function equal(a, b) {
  return a.x === b.x && a.y === b.y && a.z === b.z && a.a === b.a;
}

export function isIdentity(r) {
  return r.a === 0;
}

// the unit axis and the angle brought into [-pi, pi]; r itself is updated and returned
export function normalize(r) {
  const n = Math.hypot(r.x, r.y, r.z);
  if (n === 0)
    console.error('wbrotation.normalize: the rotation axis is zero');
  else {
    r.x /= n;
    r.y /= n;
    r.z /= n;
  }
  const turn = 2 * Math.PI;
  if (r.a > Math.PI || r.a < -Math.PI)
    r.a -= turn * Math.round(r.a / turn);
  return r;
}

export function toQuaternion(r) {
  const u = normalize({x: r.x, y: r.y, z: r.z, a: r.a});
  const s = Math.sin(u.a / 2);
  return {w: Math.cos(u.a / 2), x: u.x * s, y: u.y * s, z: u.z * s};
}

export function fromQuaternion(q) {
  const n = Math.hypot(q.w, q.x, q.y, q.z);
  const w = q.w / n;
  const v = Math.hypot(q.x, q.y, q.z) / n;
  if (v < 1e-12)
    return {x: 0, y: 0, z: 1, a: 0};
  const sign = w < 0 ? -1 : 1;                // the shorter way round
  return {x: sign * q.x / n / v, y: sign * q.y / n / v, z: sign * q.z / n / v, a: 2 * Math.atan2(v, Math.abs(w))};
}

export function toMatrix3(r) {
  const u = normalize({x: r.x, y: r.y, z: r.z, a: r.a});
  const c = Math.cos(u.a);
  const s = Math.sin(u.a);
  const k = 1 - c;
  const {x, y, z} = u;
  return {
    0: c + x * x * k, 1: x * y * k - z * s, 2: x * z * k + y * s,
    3: y * x * k + z * s, 4: c + y * y * k, 5: y * z * k - x * s,
    6: z * x * k - y * s, 7: z * y * k + x * s, 8: c + z * z * k
  };
}

export function fromMatrix3(m) {
  // through the quaternion (Shepperd's choice of the largest diagonal term keeps it accurate)
  const trace = m[0] + m[4] + m[8];
  let q;
  if (trace > 0) {
    const s = 2 * Math.sqrt(1 + trace);
    q = {w: s / 4, x: (m[7] - m[5]) / s, y: (m[2] - m[6]) / s, z: (m[3] - m[1]) / s};
  } else if (m[0] > m[4] && m[0] > m[8]) {
    const s = 2 * Math.sqrt(1 + m[0] - m[4] - m[8]);
    q = {w: (m[7] - m[5]) / s, x: s / 4, y: (m[1] + m[3]) / s, z: (m[2] + m[6]) / s};
  } else if (m[4] > m[8]) {
    const s = 2 * Math.sqrt(1 + m[4] - m[0] - m[8]);
    q = {w: (m[2] - m[6]) / s, x: (m[1] + m[3]) / s, y: s / 4, z: (m[5] + m[7]) / s};
  } else {
    const s = 2 * Math.sqrt(1 + m[8] - m[0] - m[4]);
    q = {w: (m[3] - m[1]) / s, x: (m[2] + m[6]) / s, y: (m[5] + m[7]) / s, z: s / 4};
  }
  return fromQuaternion(q);
}

// rA after rB: the quaternion product qA qB (as Webots combines them)
export function combine(rA, rB) {
  const a = toQuaternion(rA);
  const b = toQuaternion(rB);
  return fromQuaternion({
    w: a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
    x: a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
    y: a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
    z: a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w
  });
}

export function rotateVector3ByMatrix3(m, v) {
  return {
    x: m[0] * v.x + m[1] * v.y + m[2] * v.z,
    y: m[3] * v.x + m[4] * v.y + m[5] * v.z,
    z: m[6] * v.x + m[7] * v.y + m[8] * v.z
  };
}

export function rotateVector3ByRotation(r, v) {
  return rotateVector3ByMatrix3(toMatrix3(r), v);
}

export function rotateVector3ByQuaternion(q, v) {
  return rotateVector3ByRotation(fromQuaternion(q), v);
}
