/* Pattern textures of Blender's shader nodes, with Cycles' conventions:
 *
 * - Checker: unit cells of the scaled point (nudged off exact integers the
 *   way Blender does), Color1 where the cell parities of x, y and z agree in
 *   Blender's sense, Color2 elsewhere.
 * - Brick: rows of Row Height, bricks of Brick Width shifted by Offset on
 *   every Offset Frequency-th row and widened by Squash on every Squash
 *   Frequency-th row; a per-brick tint from Blender's integer noise plus
 *   Bias; mortar of Mortar Size, softened by Mortar Smooth.
 * - Gradient: linear, quadratic, easing, diagonal, spherical, quadratic
 *   sphere and radial ramps of the point, clamped to [0, 1].
 * - Magic: up to ten rounds of nested sines and cosines (Depth), scaled by
 *   Distortion.
 * - White Noise: the lookup3 hash of the point's float bits (1D: W, 2D: x y,
 *   3D: x y z, 4D: x y z W) mapped to [0, 1].
 *
 * Compiles as OpenCL C 1.2 and C++17 through mp_compat.h. */
#ifndef MP_TEX_PATTERN_H
#define MP_TEX_PATTERN_H

#include "core/mp_compat.h"
#include "textures/mp_blender_hash.h"

#define MP_PT_2PI 6.28318530717958647692f

/* Gradient types (the node's gradient_type, in this order). */
#define MP_GRADIENT_LINEAR 0
#define MP_GRADIENT_QUADRATIC 1
#define MP_GRADIENT_EASING 2
#define MP_GRADIENT_DIAGONAL 3
#define MP_GRADIENT_SPHERICAL 4
#define MP_GRADIENT_QUADRATIC_SPHERE 5
#define MP_GRADIENT_RADIAL 6

MP_INLINE float mp_pt_saturate(float x) { return fmin(fmax(x, 0.0f), 1.0f); }

MP_INLINE int mp_pt_iabs(int v) { return v < 0 ? -v : v; }

MP_INLINE float3 mp_pt_select3(int first, float3 a, float3 b) { return first ? a : b; }

/* ---- Checker ------------------------------------------------------------ */

/* Fac of the Checker Texture at point p (unscaled) and Scale: 1 for Color1
 * cells, 0 for Color2 cells. */
MP_INLINE float mp_tex_checker(float3 p, float scale) {
  float x = (p.x * scale + 0.000001f) * 0.999999f;
  float y = (p.y * scale + 0.000001f) * 0.999999f;
  float z = (p.z * scale + 0.000001f) * 0.999999f;
  int xi = mp_pt_iabs((int)floor(x)) % 2;
  int yi = mp_pt_iabs((int)floor(y)) % 2;
  int zi = mp_pt_iabs((int)floor(z)) % 2;
  int same_xy = xi == yi ? 1 : 0;
  return same_xy == zi ? 1.0f : 0.0f;
}

MP_INLINE float3 mp_tex_checker_color(float fac, float3 color1, float3 color2) {
  return mp_pt_select3(fac == 1.0f, color1, color2);
}

/* ---- Brick ----------------------------------------------------------------- */

/* Blender's integer noise for brick tints, in [0, 1). */
MP_INLINE float mp_pt_brick_noise(uint n) {
  n = (n + 1013u) & 0x7fffffffu;
  n = (n >> 13) ^ n;
  uint nn = (n * (n * n * 60493u + 19990303u) + 1376312589u) & 0x7fffffffu;
  return 0.5f * ((float)nn / 1073741824.0f);
}

/* Brick Texture: returns Fac (the mortar weight) and writes Color. p is the
 * unscaled point. offset_frequency and squash_frequency count only when
 * both are non-zero, as in Blender. Before Blender 4.0 a negative Mortar
 * Smooth gives full mortar at the edges; from 4.0 on it gives none. */
MP_INLINE float mp_tex_brick(float3 p, float3 color1, float3 color2, float3 mortar_color, float scale,
                             float mortar_size, float mortar_smooth, float bias, float brick_width, float row_height,
                             float offset_amount, int offset_frequency, float squash_amount, int squash_frequency,
                             int blender_version, float3* color) {
  float px = p.x * scale, py = p.y * scale;
  int rownum = (int)floor(py / row_height);
  float offset = 0.0f;
  if (offset_frequency != 0 && squash_frequency != 0) {
    brick_width *= (rownum % squash_frequency) != 0 ? 1.0f : squash_amount;
    offset = (rownum % offset_frequency) != 0 ? 0.0f : (brick_width * offset_amount);
  }
  int bricknum = (int)floor((px + offset) / brick_width);
  float x = (px + offset) - brick_width * (float)bricknum;
  float y = py - row_height * (float)rownum;

  uint key = ((uint)rownum << 16) + ((uint)bricknum & 0xffffu);
  float tint = mp_pt_saturate(mp_pt_brick_noise(key) + bias);
  float min_dist = fmin(fmin(x, y), fmin(brick_width - x, row_height - y));

  float mortar;
  if (min_dist >= mortar_size) {
    mortar = 0.0f;
  }
  else if (mortar_smooth == 0.0f) {
    mortar = 1.0f;
  }
  else {
    min_dist = 1.0f - min_dist / mortar_size;
    float f = min_dist / mortar_smooth;
    if (blender_version < 400) {
      mortar = min_dist < mortar_smooth ? (3.0f * (f * f) - 2.0f * (f * f) * f) : 1.0f;
    }
    else {
      mortar = f <= 0.0f ? 0.0f : (f >= 1.0f ? 1.0f : 3.0f * (f * f) - 2.0f * (f * f) * f);
    }
  }

  float3 c1 = color1;
  if (mortar != 1.0f) {
    float facm = 1.0f - tint;
    c1 = facm * color1 + tint * color2;
  }
  *color = c1 * (1.0f - mortar) + mortar_color * mortar;
  return mortar;
}

/* ---- Gradient --------------------------------------------------------------- */

/* Gradient Texture Fac (Color is Fac in all three channels). */
MP_INLINE float mp_tex_gradient(float3 p, int type) {
  float x = p.x, y = p.y, z = p.z;
  float f;
  if (type == MP_GRADIENT_LINEAR) {
    f = x;
  }
  else if (type == MP_GRADIENT_QUADRATIC) {
    float r = fmax(x, 0.0f);
    f = r * r;
  }
  else if (type == MP_GRADIENT_EASING) {
    float r = fmin(fmax(x, 0.0f), 1.0f);
    float t = r * r;
    f = 3.0f * t - 2.0f * t * r;
  }
  else if (type == MP_GRADIENT_DIAGONAL) {
    f = (x + y) * 0.5f;
  }
  else if (type == MP_GRADIENT_RADIAL) {
    f = atan2(y, x) / MP_PT_2PI + 0.5f;
  }
  else {
    /* Biased so that points at unit distance give exactly zero. */
    float r = fmax(0.999999f - sqrt(x * x + y * y + z * z), 0.0f);
    f = type == MP_GRADIENT_QUADRATIC_SPHERE ? r * r : r;
  }
  return mp_pt_saturate(f);
}

/* ---- Magic ------------------------------------------------------------------ */

/* Magic Texture Color at point p (unscaled); depth 0-10. Coordinates are
 * first reduced modulo 2 pi, as Blender does to keep sines accurate. */
MP_INLINE float3 mp_tex_magic(float3 p, float scale, int depth, float distortion) {
  float px = MP_FMOD(p.x, MP_PT_2PI);
  float py = MP_FMOD(p.y, MP_PT_2PI);
  float pz = MP_FMOD(p.z, MP_PT_2PI);
  float x = sin((px + py + pz) * 5.0f * scale);
  float y = cos((-px + py - pz) * 5.0f * scale);
  float z = -cos((-px - py + pz) * 5.0f * scale);
  float d = distortion;
  if (depth > 0) {
    x *= d;
    y *= d;
    z *= d;
    y = -cos(x - y + z) * d;
    if (depth > 1) x = cos(x - y - z) * d;
    if (depth > 2) z = sin(-x - y - z) * d;
    if (depth > 3) x = -cos(-x + y - z) * d;
    if (depth > 4) y = -sin(-x + y + z) * d;
    if (depth > 5) y = -cos(-x + y + z) * d;
    if (depth > 6) x = cos(x + y + z) * d;
    if (depth > 7) z = sin(x + y - z) * d;
    if (depth > 8) x = -cos(-x - y + z) * d;
    if (depth > 9) y = -sin(x - y + z) * d;
  }
  if (d != 0.0f) {
    float d2 = d * 2.0f;
    x /= d2;
    y /= d2;
    z /= d2;
  }
  return MP_F3(0.5f - x, 0.5f - y, 0.5f - z);
}

/* The Magic Texture's Fac: the average of its colour. */
MP_INLINE float mp_tex_magic_fac(float3 c) { return (c.x + c.y + c.z) * (1.0f / 3.0f); }

/* ---- White Noise ------------------------------------------------------------- */

MP_INLINE float mp_tex_white_noise_value(float3 p, float w, int dims) {
  if (dims == 1) return mp_bhash_float_to_float(w);
  if (dims == 2) return mp_bhash_float2_to_float(p.x, p.y);
  if (dims == 4) return mp_bhash_float4_to_float(p.x, p.y, p.z, w);
  return mp_bhash_float3_to_float(p.x, p.y, p.z);
}

MP_INLINE float3 mp_tex_white_noise_color(float3 p, float w, int dims) {
  if (dims == 1) return mp_bhash_float_to_float3(w);
  if (dims == 2) return mp_bhash_float2_to_float3(p.x, p.y);
  if (dims == 4) return mp_bhash_float4_to_float3(p.x, p.y, p.z, w);
  return mp_bhash_float3_to_float3(p);
}

#endif
