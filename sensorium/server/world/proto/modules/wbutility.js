// Sensorium's wbutility: checks and helpers for procedural PROTO templates (Webots' documented API).

export function error(message) {
  console.error(String(message));
}

export function info(message) {
  console.log(String(message));
}

export function assert(statement, message) {
  if (!statement)
    error(message);
}

export function deepCopy(original) {
  if (original === null || typeof original !== 'object')
    return original;
  if (Array.isArray(original))
    return original.map(deepCopy);
  const copy = {};
  for (const key of Object.keys(original))
    copy[key] = deepCopy(original[key]);
  return copy;
}

export function degreesToRadians(angle) {
  return angle * Math.PI / 180;
}

export function radiansToDegrees(angle) {
  return angle * 180 / Math.PI;
}

export function isScalar(s) {
  return typeof s === 'number';
}

function hasExactly(o, keys) {
  if (o === null || typeof o !== 'object')
    return false;
  const own = Object.keys(o);
  return own.length === keys.length && keys.every((k) => typeof o[k] === 'number');
}

export function isVector2(v) {
  return hasExactly(v, ['x', 'y']);
}

export function isVector3(v) {
  return hasExactly(v, ['x', 'y', 'z']);
}

export function isAxisAngle(r) {
  return hasExactly(r, ['x', 'y', 'z', 'a']);
}

export function isQuaternion(q) {
  return hasExactly(q, ['w', 'x', 'y', 'z']);
}

export function isMatrix3(m) {
  return hasExactly(m, ['0', '1', '2', '3', '4', '5', '6', '7', '8']);
}

export function isArrayOfPoints(array, dim) {
  if (!Array.isArray(array))
    return false;
  const check = dim === 2 ? isVector2 : dim === 3 ? isVector3 : null;
  return check !== null && array.every(check);
}
