// The Doppler colour model of mesh4d/doppler_colour.h (docs/DOPPLER.md) for the web viewer: the same
// stated bands, the shift as the 3x3 matrix A(D) = D^3 M^-1 G(D), the tone map, and the modulation
// W(D) = toneMap(A(D) (1, 1, 1)) that `--shade doppler` writes as COLOR_0 on an object keeping its
// input's materials. tests/web/doppler_agree.js checks these against the colours the C++ wrote.
// Plain ES module without dependencies: the viewer imports it, and so can Node.

export const BAND_CENTRES_NM = [610, 550, 465];  // R, G, B
export const BAND_WIDTH_NM = 40;                  // Gaussian standard deviation

const band = (x) => Math.exp(-x * x / (2 * BAND_WIDTH_NM * BAND_WIDTH_NM));

// M^-1 of the bands' overlap matrix M_kc = g(l_k - l_c), rows of [R, G, B], by the adjugate.
export function unmixing() {
  const l = BAND_CENTRES_NM;
  const m = l.map((lk) => l.map((lc) => band(lk - lc)));
  const det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
    m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  const inv = [[0, 0, 0], [0, 0, 0], [0, 0, 0]];
  for (let i = 0; i < 3; ++i) {
    for (let j = 0; j < 3; ++j) {
      const r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
      inv[i][j] = (m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]) / det;
    }
  }
  return inv;
}

const kUnmix = unmixing();

// A(D), rows of [R, G, B]: channel i of the shifted colour from amplitude j; zero unless D > 0 and finite.
export function dopplerMatrix(d) {
  const a = [[0, 0, 0], [0, 0, 0], [0, 0, 0]];
  if (!(d > 0) || !Number.isFinite(d)) return a;
  const l = BAND_CENTRES_NM;
  const g = l.map((lk) => l.map((lc) => d * d * d * band(lk * d - lc)));  // D^3 G(D)
  for (let i = 0; i < 3; ++i) {
    for (let j = 0; j < 3; ++j) a[i][j] = kUnmix[i][0] * g[0][j] + kUnmix[i][1] * g[1][j] + kUnmix[i][2] * g[2][j];
  }
  return a;
}

// Negatives to 0, then divided by the largest channel when it exceeds 1.
export function toneMap(c) {
  const out = c.map((v) => (Number.isFinite(v) ? Math.max(0, v) : 0));
  const top = Math.max(...out);
  return top > 1 ? out.map((v) => v / top) : out;
}

// toneMap(A(D) a): the shaded colour of linear colour a.
export function dopplerColour(a, d) {
  const m = dopplerMatrix(d);
  return toneMap(m.map((row) => row[0] * a[0] + row[1] * a[1] + row[2] * a[2]));
}

// W(D): the shaded colour of white, the per-channel modulation COLOR_0 holds.
export function dopplerModulation(d) {
  return dopplerColour([1, 1, 1], d);
}

// GLSL of toneMap(A(D) a) for the viewer's fragment shader, A(D) formed from these uniforms, set by
// dopplerUniforms(): the unmixing M^-1, the band centres and the width.
export const DOPPLER_GLSL = /* glsl */`
uniform mat3 dopplerUnmix;
uniform vec3 dopplerCentres;
uniform float dopplerWidth;
vec3 dopplerShift(vec3 a, float d) {
  if (!(d > 0.0)) return vec3(0.0);
  vec3 s;
  for (int k = 0; k < 3; ++k) {
    vec3 x = dopplerCentres[k] * d - dopplerCentres;
    s[k] = d * d * d * dot(a, exp(-x * x / (2.0 * dopplerWidth * dopplerWidth)));
  }
  vec3 c = max(dopplerUnmix * s, 0.0);
  float top = max(c.r, max(c.g, c.b));
  return top > 1.0 ? c / top : c;
}
`;

// The uniforms' values: { dopplerUnmix: 9 numbers, column-major as GLSL's mat3, dopplerCentres, dopplerWidth }.
export function dopplerUniformValues() {
  const u = kUnmix;
  return {
    dopplerUnmix: [u[0][0], u[1][0], u[2][0], u[0][1], u[1][1], u[2][1], u[0][2], u[1][2], u[2][2]],
    dopplerCentres: BAND_CENTRES_NM.slice(),
    dopplerWidth: BAND_WIDTH_NM,
  };
}
