/* Image Texture node: texel lookup with Blender's interpolation and extension
 * modes, following Cycles' conventions: texel centres at (i + 1/2) / width,
 * Linear blends the 4 nearest texels, Cubic weights the 4x4 nearest with the
 * uniform cubic B-spline, Closest takes the texel containing the point.
 * Repeat wraps, Extend clamps to the border texels, Clip reads zero outside
 * the image, Mirror reflects at every border. Compiles as OpenCL C and C++
 * (include mp_compat.h and mp_types.h first). */
#ifndef MP_TEX_IMAGE_H
#define MP_TEX_IMAGE_H

#include "closures/mp_world.h" /* the Environment Texture's projections */

#define MP_IMAGE_LINEAR 0
#define MP_IMAGE_CLOSEST 1
#define MP_IMAGE_CUBIC 2
#define MP_EXTENSION_REPEAT 0
#define MP_EXTENSION_EXTEND 1
#define MP_EXTENSION_CLIP 2
#define MP_EXTENSION_MIRROR 3

/* Texel index i of an axis n texels long under `extension`; -1 when Clip
 * leaves it outside. */
MP_INLINE int mp_image_index(int i, int n, int extension) {
  if (extension == MP_EXTENSION_REPEAT) {
    int m = i % n;
    return m < 0 ? m + n : m;
  }
  if (extension == MP_EXTENSION_MIRROR) {
    int period = 2 * n, m = i % period;
    m = m < 0 ? m + period : m;
    return m < n ? m : period - 1 - m;
  }
  if (extension == MP_EXTENSION_CLIP) return i >= 0 && i < n ? i : -1;
  return i < 0 ? 0 : i >= n ? n - 1 : i;
}

MP_INLINE float4 mp_image_texel(const MP_GLOBAL float4* texels, DeviceImage im, int x, int y, int extension) {
  int ix = mp_image_index(x, (int)im.width, extension), iy = mp_image_index(y, (int)im.height, extension);
  if (ix < 0 || iy < 0) return MP_F4(0.0f, 0.0f, 0.0f, 0.0f);
  return texels[(ulong)im.offset + (ulong)iy * im.width + (ulong)ix];
}

/* Uniform cubic B-spline weights at fraction t for texels -1, 0, 1, 2. */
MP_INLINE void mp_image_bspline(float t, float* w) {
  float t2 = t * t, t3 = t2 * t;
  w[0] = (1.0f / 6.0f) * (-t3 + 3.0f * t2 - 3.0f * t + 1.0f);
  w[1] = (1.0f / 6.0f) * (3.0f * t3 - 6.0f * t2 + 4.0f);
  w[2] = (1.0f / 6.0f) * (-3.0f * t3 + 3.0f * t2 + 3.0f * t + 1.0f);
  w[3] = (1.0f / 6.0f) * t3;
}

/* The sRGB transfer function's inverse (IEC 61966-2-1). */
MP_INLINE float mp_srgb_to_linear(float c) {
  return c <= 0.04045f ? c / 12.92f : pow((fmax(c, 0.0f) + 0.055f) / 1.055f, 2.4f);
}

/* Filtered texel values of one image at (u, v). */
MP_INLINE float4 mp_tex_image_filtered(const MP_GLOBAL float4* texels, DeviceImage im, float u, float v,
                                       int interpolation, int extension) {
  if (!(isfinite(u) && isfinite(v))) return MP_F4(0.0f, 0.0f, 0.0f, 0.0f);
  /* Keep coordinates where int conversion is defined. */
  u = fmin(fmax(u, -1.0e6f), 1.0e6f);
  v = fmin(fmax(v, -1.0e6f), 1.0e6f);
  float x = u * (float)im.width, y = v * (float)im.height;
  if (interpolation == MP_IMAGE_CLOSEST) {
    if (extension == MP_EXTENSION_CLIP && (u < 0.0f || v < 0.0f || u > 1.0f || v > 1.0f))
      return MP_F4(0.0f, 0.0f, 0.0f, 0.0f);
    return mp_image_texel(texels, im, (int)floor(x), (int)floor(y), extension);
  }
  x -= 0.5f;
  y -= 0.5f;
  float fx = floor(x), fy = floor(y);
  int ix = (int)fx, iy = (int)fy;
  float tx = x - fx, ty = y - fy;
  if (interpolation == MP_IMAGE_CUBIC) {
    float wx[4], wy[4];
    mp_image_bspline(tx, wx);
    mp_image_bspline(ty, wy);
    float4 sum = MP_F4(0.0f, 0.0f, 0.0f, 0.0f);
    for (int j = 0; j < 4; ++j) {
      float4 row = MP_F4(0.0f, 0.0f, 0.0f, 0.0f);
      for (int i = 0; i < 4; ++i) row += wx[i] * mp_image_texel(texels, im, ix - 1 + i, iy - 1 + j, extension);
      sum += wy[j] * row;
    }
    return sum;
  }
  float4 a = mp_image_texel(texels, im, ix, iy, extension), b = mp_image_texel(texels, im, ix + 1, iy, extension);
  float4 c = mp_image_texel(texels, im, ix, iy + 1, extension), d = mp_image_texel(texels, im, ix + 1, iy + 1, extension);
  return (1.0f - ty) * ((1.0f - tx) * a + tx * b) + ty * ((1.0f - tx) * c + tx * d);
}

/* RGBA of image `index` at (u, v), scene-linear; magenta for an image index
 * the scene does not have (Blender's colour for a missing image). */
MP_INLINE float4 mp_tex_image(const MP_GLOBAL DeviceImage* images, uint image_count, const MP_GLOBAL float4* texels,
                              int index, float u, float v, int interpolation, int extension) {
  if (index < 0 || (uint)index >= image_count) return MP_F4(1.0f, 0.0f, 1.0f, 1.0f);
  DeviceImage im = images[index];
  float4 c = mp_tex_image_filtered(texels, im, u, v, interpolation, extension);
  if (im.srgb) c = MP_F4(mp_srgb_to_linear(c.x), mp_srgb_to_linear(c.y), mp_srgb_to_linear(c.z), c.w);
  return c;
}

/* ---- Projections (the node's Sphere, Tube and Box), as Cycles defines them:
 * Sphere and Tube first map the unit box [0, 1]^3 to [-1, 1]^3. */
#define MP_IMAGE_PI 3.14159265358979f

/* Longitude around z and latitude from the south pole, each in [0, 1]. */
MP_INLINE float2 mp_image_sphere_uv(float3 co) {
  co = 2.0f * co - MP_F3(1.0f, 1.0f, 1.0f);
  float len = sqrt(co.x * co.x + co.y * co.y + co.z * co.z);
  if (!(len > 0.0f)) return MP_F2(0.0f, 0.0f);
  float u = co.x == 0.0f && co.y == 0.0f ? 0.0f : (1.0f - atan2(co.x, co.y) / MP_IMAGE_PI) * 0.5f;
  return MP_F2(u, 1.0f - acos(clamp(co.z / len, -1.0f, 1.0f)) / MP_IMAGE_PI);
}

/* Longitude around z as for Sphere, height along z. */
MP_INLINE float2 mp_image_tube_uv(float3 co) {
  co = 2.0f * co - MP_F3(1.0f, 1.0f, 1.0f);
  float len = sqrt(co.x * co.x + co.y * co.y);
  if (!(len > 0.0f)) return MP_F2(0.0f, 0.0f);
  return MP_F2((1.0f - atan2(co.x / len, co.y / len) / MP_IMAGE_PI) * 0.5f, (co.z + 1.0f) * 0.5f);
}

/* Box: the image projected along x, y and z and blended by the object-space
 * normal n. |n| normalised to sum 1 places the point in a triangle whose
 * corners are the three projections: near a corner one projection alone,
 * along the sides a blend of two, in the middle of all three, the blend
 * zones widening with `blend` (0: hard seams). Each projection is mirrored
 * on the side of the axis where it would read backwards. */
MP_INLINE float4 mp_tex_image_box(const MP_GLOBAL DeviceImage* images, uint image_count, const MP_GLOBAL float4* texels,
                                  int index, float3 co, float3 n, float blend, int interpolation, int extension) {
  float3 a = MP_F3(fabs(n.x), fabs(n.y), fabs(n.z));
  float sum = a.x + a.y + a.z;
  a = sum > 0.0f ? a / sum : MP_F3(1.0f, 0.0f, 0.0f);
  float limit = 0.5f * (1.0f + blend);
  float3 w = MP_F3(0.0f, 0.0f, 0.0f);
  if (a.x > limit * (a.x + a.y) && a.x > limit * (a.x + a.z)) {
    w.x = 1.0f;
  } else if (a.y > limit * (a.x + a.y) && a.y > limit * (a.y + a.z)) {
    w.y = 1.0f;
  } else if (a.z > limit * (a.x + a.z) && a.z > limit * (a.y + a.z)) {
    w.z = 1.0f;
  } else if (blend > 0.0f) {
    if (a.z < (1.0f - limit) * (a.y + a.x)) {
      w.x = clamp((a.x / (a.x + a.y) - 0.5f * (1.0f - blend)) / blend, 0.0f, 1.0f);
      w.y = 1.0f - w.x;
    } else if (a.x < (1.0f - limit) * (a.y + a.z)) {
      w.y = clamp((a.y / (a.y + a.z) - 0.5f * (1.0f - blend)) / blend, 0.0f, 1.0f);
      w.z = 1.0f - w.y;
    } else if (a.y < (1.0f - limit) * (a.x + a.z)) {
      w.x = clamp((a.x / (a.x + a.z) - 0.5f * (1.0f - blend)) / blend, 0.0f, 1.0f);
      w.z = 1.0f - w.x;
    } else {
      w = ((2.0f - limit) * a + MP_F3(limit - 1.0f, limit - 1.0f, limit - 1.0f)) / (2.0f * limit - 1.0f);
    }
  } else {
    w.x = 1.0f;
  }
  float4 c = MP_F4(0.0f, 0.0f, 0.0f, 0.0f);
  if (w.x > 0.0f)
    c += w.x * mp_tex_image(images, image_count, texels, index, n.x < 0.0f ? 1.0f - co.y : co.y, co.z, interpolation,
                            extension);
  if (w.y > 0.0f)
    c += w.y * mp_tex_image(images, image_count, texels, index, n.y > 0.0f ? 1.0f - co.x : co.x, co.z, interpolation,
                            extension);
  if (w.z > 0.0f)
    c += w.z * mp_tex_image(images, image_count, texels, index, n.z > 0.0f ? 1.0f - co.y : co.y, co.x, interpolation,
                            extension);
  return c;
}

#endif
