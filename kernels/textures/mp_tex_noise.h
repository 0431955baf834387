/* Perlin noise and the fractal noise textures of Blender's shader nodes:
 * the Noise Texture (fBm; Blender 4.1+ also multifractal, ridged, hybrid and
 * hetero terrain, with Lacunarity/Normalize from 4.0) and the legacy
 * Musgrave Texture (Blender <= 4.0). Follows Blender's conventions for
 * lattice hashing, gradient sets, per-dimension output scales, seed offsets
 * for distortion and colour, and octave accumulation, so that a texture
 * evaluated here matches the one Cycles renders.
 *
 * Points of 1-4 dimensions travel as private float arrays p[0..dims-1]
 * (x, y, z, w); OpenCL C has no templates, and this keeps one code path per
 * fractal type. No recursion, no function pointers, no doubles. */
#ifndef MP_TEX_NOISE_H
#define MP_TEX_NOISE_H

#include "core/mp_compat.h"
#include "textures/mp_blender_hash.h"

#define MP_NOISE_FBM 0
#define MP_NOISE_MULTIFRACTAL 1
#define MP_NOISE_RIDGED 2
#define MP_NOISE_HYBRID 3
#define MP_NOISE_HETERO 4

/* ---- small scalar helpers ---------------------------------------------- */

MP_INLINE float mp_tx_mix(float a, float b, float t) { return a + t * (b - a); }

MP_INLINE int mp_tx_isfinite(float x) { return (as_uint(x) & 0x7f800000u) != 0x7f800000u; }

MP_INLINE float mp_tx_saturate(float x) { return x < 0.0f ? 0.0f : (x > 1.0f ? 1.0f : x); }

/* Blender's smoothstep: 0 below e0, 1 from e1 on, Hermite in between (also
 * for non-finite x, which matters for Smooth F1 at zero smoothness). */
MP_INLINE float mp_tx_smoothstep(float e0, float e1, float x) {
  if (x < e0) return 0.0f;
  if (x >= e1) return 1.0f;
  float t = (x - e0) / (e1 - e0);
  return (3.0f - 2.0f * t) * (t * t);
}

MP_INLINE float mp_tx_safe_divide(float a, float b) { return b != 0.0f ? a / b : 0.0f; }

/* Integer lattice cell and position inside it. */
MP_INLINE float mp_tx_floorfrac(float x, int* cell) {
  float f = floor(x);
  *cell = (int)f;
  return x - f;
}

/* ---- improved Perlin noise -------------------------------------------- */

MP_INLINE float mp_tx_fade(float t) { return (t * t) * (t * (t * (t * 6.0f - 15.0f) + 10.0f)); }

MP_INLINE float mp_tx_negate_if(float v, int cond) { return cond ? -v : v; }

MP_INLINE float mp_tx_grad1(uint hash, float x) {
  int h = (int)(hash & 15u);
  float g = (float)(1 + (h & 7));
  return mp_tx_negate_if(g, h & 8) * x;
}

MP_INLINE float mp_tx_grad2(uint hash, float x, float y) {
  int h = (int)(hash & 7u);
  float u = h < 4 ? x : y;
  float v = 2.0f * (h < 4 ? y : x);
  return mp_tx_negate_if(u, h & 1) + mp_tx_negate_if(v, h & 2);
}

MP_INLINE float mp_tx_grad3(uint hash, float x, float y, float z) {
  int h = (int)(hash & 15u);
  float u = h < 8 ? x : y;
  float vt = (h == 12 || h == 14) ? x : z;
  float v = h < 4 ? y : vt;
  return mp_tx_negate_if(u, h & 1) + mp_tx_negate_if(v, h & 2);
}

MP_INLINE float mp_tx_grad4(uint hash, float x, float y, float z, float w) {
  int h = (int)(hash & 31u);
  float u = h < 24 ? x : y;
  float v = h < 16 ? y : z;
  float s = h < 8 ? z : w;
  return mp_tx_negate_if(u, h & 1) + mp_tx_negate_if(v, h & 2) + mp_tx_negate_if(s, h & 4);
}

MP_INLINE float mp_tx_perlin_1d(float x) {
  int X;
  float fx = mp_tx_floorfrac(x, &X);
  float u = mp_tx_fade(fx);
  return mp_tx_mix(mp_tx_grad1(mp_bhash_uint((uint)X), fx), mp_tx_grad1(mp_bhash_uint((uint)(X + 1)), fx - 1.0f), u);
}

/* The corners are blended along x first, then y, z and w, the order of
 * Blender's vectorised CPU kernels. */
MP_INLINE float mp_tx_perlin_2d(float x, float y) {
  int X, Y;
  float fx = mp_tx_floorfrac(x, &X);
  float fy = mp_tx_floorfrac(y, &Y);
  float u = mp_tx_fade(fx), v = mp_tx_fade(fy);
  uint X0 = (uint)X, X1 = (uint)(X + 1), Y0 = (uint)Y, Y1 = (uint)(Y + 1);
  float a = mp_tx_mix(mp_tx_grad2(mp_bhash_uint2(X0, Y0), fx, fy),
                      mp_tx_grad2(mp_bhash_uint2(X1, Y0), fx - 1.0f, fy), u);
  float b = mp_tx_mix(mp_tx_grad2(mp_bhash_uint2(X0, Y1), fx, fy - 1.0f),
                      mp_tx_grad2(mp_bhash_uint2(X1, Y1), fx - 1.0f, fy - 1.0f), u);
  return mp_tx_mix(a, b, v);
}

/* One z-slab of the 3D lattice, blended in x then y. */
MP_INLINE float mp_tx_perlin_3d_slab(uint X0, uint Y0, uint Z, float fx, float fy, float fz, float u, float v) {
  uint X1 = X0 + 1u, Y1 = Y0 + 1u;
  float a = mp_tx_mix(mp_tx_grad3(mp_bhash_uint3(X0, Y0, Z), fx, fy, fz),
                      mp_tx_grad3(mp_bhash_uint3(X1, Y0, Z), fx - 1.0f, fy, fz), u);
  float b = mp_tx_mix(mp_tx_grad3(mp_bhash_uint3(X0, Y1, Z), fx, fy - 1.0f, fz),
                      mp_tx_grad3(mp_bhash_uint3(X1, Y1, Z), fx - 1.0f, fy - 1.0f, fz), u);
  return mp_tx_mix(a, b, v);
}

MP_INLINE float mp_tx_perlin_3d(float x, float y, float z) {
  int X, Y, Z;
  float fx = mp_tx_floorfrac(x, &X);
  float fy = mp_tx_floorfrac(y, &Y);
  float fz = mp_tx_floorfrac(z, &Z);
  float u = mp_tx_fade(fx), v = mp_tx_fade(fy), w = mp_tx_fade(fz);
  float s0 = mp_tx_perlin_3d_slab((uint)X, (uint)Y, (uint)Z, fx, fy, fz, u, v);
  float s1 = mp_tx_perlin_3d_slab((uint)X, (uint)Y, (uint)(Z + 1), fx, fy, fz - 1.0f, u, v);
  return mp_tx_mix(s0, s1, w);
}

/* The 4D corner value at lattice offset (i, j, k, l) in {0, 1}^4. */
MP_INLINE float mp_tx_perlin_4d_corner(int X, int Y, int Z, int W, int i, int j, int k, int l, float fx, float fy,
                                        float fz, float fw) {
  uint h = mp_bhash_uint4((uint)(X + i), (uint)(Y + j), (uint)(Z + k), (uint)(W + l));
  return mp_tx_grad4(h, fx - (float)i, fy - (float)j, fz - (float)k, fw - (float)l);
}

MP_INLINE float mp_tx_perlin_4d(float x, float y, float z, float w) {
  int X, Y, Z, W;
  float fx = mp_tx_floorfrac(x, &X);
  float fy = mp_tx_floorfrac(y, &Y);
  float fz = mp_tx_floorfrac(z, &Z);
  float fw = mp_tx_floorfrac(w, &W);
  float u = mp_tx_fade(fx), v = mp_tx_fade(fy), t = mp_tx_fade(fz), s = mp_tx_fade(fw);
  /* Blender's AVX2 kernel blends the two w-slabs first, then x, y, z. */
  float c[8];
  for (int n = 0; n < 8; n++) {
    int i = n & 1, j = (n >> 1) & 1, k = (n >> 2) & 1;
    c[n] = mp_tx_mix(mp_tx_perlin_4d_corner(X, Y, Z, W, i, j, k, 0, fx, fy, fz, fw),
                     mp_tx_perlin_4d_corner(X, Y, Z, W, i, j, k, 1, fx, fy, fz, fw), s);
  }
  float a0 = mp_tx_mix(c[0], c[1], u), a1 = mp_tx_mix(c[2], c[3], u);
  float a2 = mp_tx_mix(c[4], c[5], u), a3 = mp_tx_mix(c[6], c[7], u);
  return mp_tx_mix(mp_tx_mix(a0, a1, v), mp_tx_mix(a2, a3, v), t);
}

/* Signed noise in about [-1, 1] of a 1-4 dimensional point. Blender 4.x
 * repeats the pattern every 100000 units (with a half-cell shift beyond
 * 10^6); earlier versions replace non-finite results by 0. */
MP_INLINE float mp_tx_snoise(const float* p, int dims, int blender_version) {
  float q[4];
  for (int i = 0; i < dims; i++) {
    q[i] = p[i];
    if (blender_version >= 400) {
      float correction = fabs(q[i]) >= 1000000.0f ? 0.5f : 0.0f;
      q[i] = MP_FMOD(q[i], 100000.0f) + correction;
    }
  }
  float r, scale;
  if (dims == 1) {
    r = mp_tx_perlin_1d(q[0]);
    scale = 0.2500f;
  }
  else if (dims == 2) {
    r = mp_tx_perlin_2d(q[0], q[1]);
    scale = 0.6616f;
  }
  else if (dims == 3) {
    r = mp_tx_perlin_3d(q[0], q[1], q[2]);
    scale = 0.9820f;
  }
  else {
    r = mp_tx_perlin_4d(q[0], q[1], q[2], q[3]);
    scale = 0.8344f;
  }
  if (blender_version < 400 && !mp_tx_isfinite(r)) r = 0.0f;
  return scale * r;
}

/* Signed noise at p * s (each component scaled). */
MP_INLINE float mp_tx_snoise_at(const float* p, float s, int dims, int blender_version) {
  float q[4];
  for (int i = 0; i < dims; i++) q[i] = s * p[i];
  return mp_tx_snoise(q, dims, blender_version);
}

/* Unsigned noise in about [0, 1]. */
MP_INLINE float mp_tx_noise_at(const float* p, float s, int dims, int blender_version) {
  return 0.5f * mp_tx_snoise_at(p, s, dims, blender_version) + 0.5f;
}

MP_INLINE void mp_tx_scale_point(float* p, int dims, float s) {
  for (int i = 0; i < dims; i++) p[i] *= s;
}

/* ---- fractal sums --------------------------------------------------------- */

/* Blender < 4.0 Noise Texture: octaves of unsigned noise at doubling
 * frequency, averaged by their amplitudes; detail clamped to [0, 15],
 * roughness to [0, 1]; a fractional detail blends in one more octave. */
MP_INLINE float mp_tx_fractal_noise_legacy(const float* p, int dims, float octaves, float roughness, int ver) {
  float fscale = 1.0f, amp = 1.0f, maxamp = 0.0f, sum = 0.0f;
  octaves = clamp(octaves, 0.0f, 15.0f);
  float rough = clamp(roughness, 0.0f, 1.0f);
  int n = (int)octaves;
  for (int i = 0; i <= n; i++) {
    float t = mp_tx_noise_at(p, fscale, dims, ver);
    sum += t * amp;
    maxamp += amp;
    amp *= rough;
    fscale *= 2.0f;
  }
  float rmd = octaves - floor(octaves);
  if (rmd != 0.0f) {
    float t = mp_tx_noise_at(p, fscale, dims, ver);
    float sum2 = sum + t * amp;
    sum /= maxamp;
    sum2 /= maxamp + amp;
    return (1.0f - rmd) * sum + rmd * sum2;
  }
  return sum / maxamp;
}

/* Blender 4.x fBm: signed octaves, optionally remapped to [0, 1]. */
MP_INLINE float mp_tx_noise_fbm(const float* p, int dims, float detail, float roughness, float lacunarity,
                                int normalize, int ver) {
  float fscale = 1.0f, amp = 1.0f, maxamp = 0.0f, sum = 0.0f;
  int n = (int)detail;
  for (int i = 0; i <= n; i++) {
    float t = mp_tx_snoise_at(p, fscale, dims, ver);
    sum += t * amp;
    maxamp += amp;
    amp *= roughness;
    fscale *= lacunarity;
  }
  float rmd = detail - floor(detail);
  if (rmd != 0.0f) {
    float t = mp_tx_snoise_at(p, fscale, dims, ver);
    float sum2 = sum + t * amp;
    return normalize ? mp_tx_mix(0.5f * sum / maxamp + 0.5f, 0.5f * sum2 / (maxamp + amp) + 0.5f, rmd)
                     : mp_tx_mix(sum, sum2, rmd);
  }
  return normalize ? 0.5f * sum / maxamp + 0.5f : sum;
}

/* The multiplicative, terrain and ridged types follow Musgrave's recurrences.
 * `count` is the number of whole octaves (the Noise Texture of 4.1+ runs
 * floor(detail) + 1, the legacy Musgrave node floor(detail)), `rmd` the
 * weight of one more fractional octave and `step` the amplitude factor from
 * one octave to the next (roughness, or lacunarity^-dimension). */

MP_INLINE float mp_tx_multi_fractal(const float* p0, int dims, int count, float rmd, float step, float lacunarity,
                                    int ver) {
  float p[4];
  for (int i = 0; i < dims; i++) p[i] = p0[i];
  float value = 1.0f, pwr = 1.0f;
  for (int i = 0; i < count; i++) {
    value *= (pwr * mp_tx_snoise(p, dims, ver) + 1.0f);
    pwr *= step;
    mp_tx_scale_point(p, dims, lacunarity);
  }
  if (rmd != 0.0f) value *= (rmd * pwr * mp_tx_snoise(p, dims, ver) + 1.0f);
  return value;
}

MP_INLINE float mp_tx_hetero_terrain(const float* p0, int dims, int count, float rmd, float step, float lacunarity,
                                     float offset, int ver) {
  float p[4];
  for (int i = 0; i < dims; i++) p[i] = p0[i];
  float pwr = step;
  /* The first octave is unscaled, later ones are weighted by the height so far. */
  float value = offset + mp_tx_snoise(p, dims, ver);
  mp_tx_scale_point(p, dims, lacunarity);
  for (int i = 1; i < count; i++) {
    float increment = (mp_tx_snoise(p, dims, ver) + offset) * pwr * value;
    value += increment;
    pwr *= step;
    mp_tx_scale_point(p, dims, lacunarity);
  }
  if (rmd != 0.0f) {
    float increment = (mp_tx_snoise(p, dims, ver) + offset) * pwr * value;
    value += rmd * increment;
  }
  return value;
}

MP_INLINE float mp_tx_hybrid_multi_fractal(const float* p0, int dims, int count, float rmd, float step,
                                           float lacunarity, float offset, float gain, int ver) {
  float p[4];
  for (int i = 0; i < dims; i++) p[i] = p0[i];
  float pwr = 1.0f, value = 0.0f, weight = 1.0f;
  for (int i = 0; (weight > 0.001f) && (i < count); i++) {
    if (weight > 1.0f) weight = 1.0f;
    float signal = (mp_tx_snoise(p, dims, ver) + offset) * pwr;
    pwr *= step;
    value += weight * signal;
    weight *= gain * signal;
    mp_tx_scale_point(p, dims, lacunarity);
  }
  if ((rmd != 0.0f) && (weight > 0.001f)) {
    if (weight > 1.0f) weight = 1.0f;
    float signal = (mp_tx_snoise(p, dims, ver) + offset) * pwr;
    value += rmd * weight * signal;
  }
  return value;
}

/* Ridged multifractal ignores a fractional detail (as in Blender). */
MP_INLINE float mp_tx_ridged_multi_fractal(const float* p0, int dims, int count, float step, float lacunarity,
                                           float offset, float gain, int ver) {
  float p[4];
  for (int i = 0; i < dims; i++) p[i] = p0[i];
  float pwr = step;
  float signal = offset - fabs(mp_tx_snoise(p, dims, ver));
  signal *= signal;
  float value = signal;
  float weight = 1.0f;
  for (int i = 1; i < count; i++) {
    mp_tx_scale_point(p, dims, lacunarity);
    weight = mp_tx_saturate(signal * gain);
    signal = offset - fabs(mp_tx_snoise(p, dims, ver));
    signal *= signal;
    signal *= weight;
    value += signal * pwr;
    pwr *= step;
  }
  return value;
}

/* Blender 4.1+ Noise Texture types: `detail` full octaves after the first. */
MP_INLINE float mp_tx_noise_select(const float* p, int dims, int type, float detail, float roughness,
                                   float lacunarity, float offset, float gain, int normalize, int ver) {
  int count = (int)detail + 1;
  float rmd = detail - floor(detail);
  if (type == MP_NOISE_MULTIFRACTAL) return mp_tx_multi_fractal(p, dims, count, rmd, roughness, lacunarity, ver);
  if (type == MP_NOISE_RIDGED)
    return mp_tx_ridged_multi_fractal(p, dims, count, roughness, lacunarity, offset, gain, ver);
  if (type == MP_NOISE_HYBRID)
    return mp_tx_hybrid_multi_fractal(p, dims, count, rmd, roughness, lacunarity, offset, gain, ver);
  if (type == MP_NOISE_HETERO)
    return mp_tx_hetero_terrain(p, dims, count, rmd, roughness, lacunarity, offset, ver);
  return mp_tx_noise_fbm(p, dims, detail, roughness, lacunarity, normalize, ver);
}

/* The value the Noise Texture computes at an already distorted point. */
MP_INLINE float mp_tx_noise_value(const float* p, int dims, int type, int normalize, float detail, float roughness,
                                  float lacunarity, float offset, float gain, int ver) {
  if (ver < 400) return mp_tx_fractal_noise_legacy(p, dims, detail, roughness, ver);
  if (ver < 401) return mp_tx_noise_fbm(p, dims, detail, roughness, lacunarity, normalize, ver);
  return mp_tx_noise_select(p, dims, type, detail, roughness, lacunarity, offset, gain, normalize, ver);
}

/* Per-texture seed offsets in [100, 200] that decorrelate the distortion
 * and colour channels from the main value. */
MP_INLINE void mp_tx_random_offset(float seed, int dims, float* out) {
  if (dims == 1) {
    out[0] = 100.0f + mp_bhash_float_to_float(seed) * 100.0f;
    return;
  }
  for (int i = 0; i < dims; i++) out[i] = 100.0f + mp_bhash_float2_to_float(seed, (float)i) * 100.0f;
}

/* Noise Texture node. Inputs as the sockets receive them (Vector p, W,
 * Scale, ...). dims 1 uses W only, 2 uses p.xy, 3 p.xyz, 4 (p, W).
 * type: 0 fBm, 1 multifractal, 2 ridged, 3 hybrid, 4 hetero terrain (4.1+;
 * earlier versions are fBm only). lacunarity/normalize count from 4.0 on
 * (before: 2 and on); offset/gain from 4.1 on. */
MP_INLINE void mp_tex_noise(float3 p, float w, int dims, int type, int normalize, float scale, float detail,
                            float roughness, float lacunarity, float offset, float gain, float distortion,
                            int blender_version, float* fac, float3* color) {
  int ver = blender_version;
  dims = clamp(dims, 1, 4);
  if (ver >= 400) {
    detail = clamp(detail, 0.0f, 15.0f);
    roughness = fmax(roughness, 0.0f);
  }
  float pt[4];
  float sp0 = p.x * scale, sp1 = p.y * scale, sp2 = p.z * scale, sw = w * scale;
  if (dims == 1) {
    pt[0] = sw;
  }
  else {
    pt[0] = sp0;
    pt[1] = sp1;
    pt[2] = sp2;
    pt[3] = sw;
  }

  /* Seeds: the first `dims` offsets distort (one, seed 0, in 1D), the next
   * two give the colour's green and blue channels. */
  if (distortion != 0.0f) {
    float d[4];
    for (int i = 0; i < dims; i++) {
      float off[4], q[4];
      mp_tx_random_offset((float)i, dims, off);
      for (int k = 0; k < dims; k++) q[k] = pt[k] + off[k];
      d[i] = mp_tx_snoise(q, dims, ver) * distortion;
    }
    for (int i = 0; i < dims; i++) pt[i] += d[i];
  }
  int seed = dims == 1 ? 1 : dims;

  float value = mp_tx_noise_value(pt, dims, type, normalize, detail, roughness, lacunarity, offset, gain, ver);
  *fac = value;
  float ch[2];
  for (int c = 0; c < 2; c++) {
    float off[4], q[4];
    mp_tx_random_offset((float)(seed + c), dims, off);
    for (int k = 0; k < dims; k++) q[k] = pt[k] + off[k];
    ch[c] = mp_tx_noise_value(q, dims, type, normalize, detail, roughness, lacunarity, offset, gain, ver);
  }
  *color = MP_F3(value, ch[0], ch[1]);
}

/* Legacy Musgrave Texture node (Blender <= 4.0; 4.1 turned it into Noise
 * Texture types). type codes as mp_tex_noise. `dimension` is the fractal
 * increment H: octave amplitudes fall by lacunarity^-H. Here detail counts
 * all octaves (the loop runs floor(detail) times plus a fractional one). */
MP_INLINE float mp_tex_musgrave(float3 p, float w, int dims, int type, float scale, float detail, float dimension,
                                float lacunarity, float offset, float gain, int blender_version) {
  int ver = blender_version;
  dims = clamp(dims, 1, 4);
  dimension = fmax(dimension, 1e-5f);
  detail = clamp(detail, 0.0f, 15.0f);
  lacunarity = fmax(lacunarity, 1e-5f);
  float pt[4];
  if (dims == 1) {
    pt[0] = w * scale;
  }
  else {
    pt[0] = p.x * scale;
    pt[1] = p.y * scale;
    pt[2] = p.z * scale;
    pt[3] = w * scale;
  }
  float step = pow(lacunarity, -dimension);
  int count = (int)detail;
  float rmd = detail - floor(detail);
  if (type == MP_NOISE_MULTIFRACTAL) return mp_tx_multi_fractal(pt, dims, count, rmd, step, lacunarity, ver);
  if (type == MP_NOISE_RIDGED) return mp_tx_ridged_multi_fractal(pt, dims, count, step, lacunarity, offset, gain, ver);
  if (type == MP_NOISE_HYBRID)
    return mp_tx_hybrid_multi_fractal(pt, dims, count, rmd, step, lacunarity, offset, gain, ver);
  if (type == MP_NOISE_HETERO) return mp_tx_hetero_terrain(pt, dims, count, rmd, step, lacunarity, offset, ver);

  /* fBm: plain sum of signed octaves. */
  float q[4];
  for (int i = 0; i < dims; i++) q[i] = pt[i];
  float value = 0.0f, pwr = 1.0f;
  for (int i = 0; i < count; i++) {
    value += mp_tx_snoise(q, dims, ver) * pwr;
    pwr *= step;
    mp_tx_scale_point(q, dims, lacunarity);
  }
  if (rmd != 0.0f) value += rmd * mp_tx_snoise(q, dims, ver) * pwr;
  return value;
}

#endif
