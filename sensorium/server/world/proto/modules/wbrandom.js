// Sensorium's wbrandom: seeded pseudo-random numbers (Webots' documented API). A linear
// congruential generator modulo 2^24 with Microsoft Visual Basic's coefficients, as Webots
// documents; the seed starts at 0 in every template run, so a PROTO that never calls seed() is
// reproducible.

const MODULUS = 16777216;   // 2^24
let state = 0;

export function seed(s) {
  state = s;
}

function next() {
  state = (1140671485 * state + 12820163) % MODULUS;
  return state;
}

// a number in [min, max]: real() in [0, 1], real(max) in [0, max]
export function real(min, max) {
  if (min === undefined)
    [min, max] = [0, 1];
  else if (max === undefined)
    [min, max] = [0, min];
  return min + next() * (max - min) / (MODULUS - 1);
}

// an integer in [min, max]: integer() in [0, 2^24 - 1], integer(max) in [1, max] (as Webots has it)
export function integer(min, max) {
  if (min === undefined)
    [min, max] = [0, MODULUS - 1];
  else if (max === undefined)
    [min, max] = [1, min];
  return min + next() % (1 + max - min);
}
