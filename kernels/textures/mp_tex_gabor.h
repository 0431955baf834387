/* Gabor Texture node (Blender 4.3+) with Cycles' conventions: sparse
 * convolution noise of 8 impulses per unit cell, searched over the 3x3 (2D)
 * or 3x3x3 (3D) surrounding cells; each impulse a Gabor kernel (a Gaussian
 * times a Hann window of unit radius, modulating a complex sinusoid of the
 * given Frequency) at a hashed position, with a hashed sign and an
 * orientation blended from the given one towards a random one by
 * 1 - Anisotropy. Value is the imaginary part of the summed phasor,
 * Phase its angle and Intensity its magnitude, normalised by six standard
 * deviations and remapped as Blender does.
 *
 * Compiles as OpenCL C 1.2 and C++17 through mp_compat.h. */
#ifndef MP_TEX_GABOR_H
#define MP_TEX_GABOR_H

#include "core/mp_compat.h"
#include "textures/mp_blender_hash.h"

#define MP_GABOR_2D 0
#define MP_GABOR_3D 1

#define MP_GB_IMPULSES 8
#define MP_GB_PI 3.14159265358979323846f
#define MP_GB_SQRT2 1.41421356237309504880f

/* The kernel's complex value at `pos` (relative to its centre) for a
 * frequency vector (fx, fy, fz): the windowed Gaussian envelope times
 * (cos, sin) of the phase 2 pi <pos, f>. Returns the real part, writes the
 * imaginary part. */
MP_INLINE float mp_gb_kernel(float d2, float phase_dot, float* imag) {
  float hann = 0.5f + 0.5f * cos(MP_GB_PI * d2);
  float gauss = exp(-MP_GB_PI * d2);
  float envelope = gauss * hann;
  float angle = 2.0f * MP_GB_PI * phase_dot;
  *imag = envelope * sin(angle);
  return envelope * cos(angle);
}

/* The sum of the impulses of one 2D cell, (*re, *im). */
MP_INLINE void mp_gb_cell_2d(float cx, float cy, float px, float py, float frequency, float isotropy,
                             float base_orientation, float* re, float* im) {
  *re = 0.0f;
  *im = 0.0f;
  for (int i = 0; i < MP_GB_IMPULSES; ++i) {
    float s = (float)(i * 3);
    float random_orientation = (mp_bhash_float3_to_float(cx, cy, s) - 0.5f) * MP_GB_PI;
    float orientation = base_orientation + random_orientation * isotropy;
    float s1 = (float)(i * 3 + 1);
    float kx = mp_bhash_float3_to_float(cx, cy, s1);
    float ky = mp_bhash_float3_to_float(s1, cx, cy);
    float qx = px - kx, qy = py - ky;
    float d2 = qx * qx + qy * qy;
    if (d2 >= 1.0f) continue;
    float weight = mp_bhash_float3_to_float(cx, cy, (float)(i * 3 + 2)) < 0.5f ? -1.0f : 1.0f;
    float fx = frequency * cos(orientation), fy = frequency * sin(orientation);
    float kim;
    float kre = mp_gb_kernel(d2, qx * fx + qy * fy, &kim);
    *re += weight * kre;
    *im += weight * kim;
  }
}

/* The impulse orientation of a 3D kernel: the base orientation turned by
 * hashed inclination and azimuth amounts scaled by the isotropy. */
MP_INLINE float3 mp_gb_orientation_3d(float3 o, float isotropy, float sx, float sy, float sz, float sw) {
  if (isotropy == 0.0f) return o;
  float inclination = acos(o.z);
  float azimuth = (o.y < 0.0f ? -1.0f : 1.0f) * acos(o.x / sqrt(o.x * o.x + o.y * o.y));
  float ra = mp_bhash_float4_to_float(sx, sy, sz, sw) * MP_GB_PI;
  float rb = mp_bhash_float4_to_float(sz, sx, sw, sy) * MP_GB_PI;
  inclination += ra * isotropy;
  azimuth += rb * isotropy;
  float si = sin(inclination);
  return MP_F3(si * cos(azimuth), si * sin(azimuth), cos(inclination));
}

/* The sum of the impulses of one 3D cell, (*re, *im). */
MP_INLINE void mp_gb_cell_3d(float3 cell, float3 p, float frequency, float isotropy, float3 base_orientation,
                             float* re, float* im) {
  *re = 0.0f;
  *im = 0.0f;
  for (int i = 0; i < MP_GB_IMPULSES; ++i) {
    float s0 = (float)(i * 3), s1 = (float)(i * 3 + 1), s2 = (float)(i * 3 + 2);
    float3 orientation = mp_gb_orientation_3d(base_orientation, isotropy, cell.x, cell.y, cell.z, s0);
    float3 centre = mp_bhash_float4_to_float3(cell.x, cell.y, cell.z, s1);
    float qx = p.x - centre.x, qy = p.y - centre.y, qz = p.z - centre.z;
    float d2 = qx * qx + qy * qy + qz * qz;
    if (d2 >= 1.0f) continue;
    float weight = mp_bhash_float4_to_float(cell.x, cell.y, cell.z, s2) < 0.5f ? -1.0f : 1.0f;
    float fx = frequency * orientation.x, fy = frequency * orientation.y, fz = frequency * orientation.z;
    float kim;
    float kre = mp_gb_kernel(d2, qx * fx + qy * fy + qz * fz, &kim);
    *re += weight * kre;
    *im += weight * kim;
  }
}

/* Gabor Texture node. p is the unscaled point; type MP_GABOR_2D uses p.xy
 * and orientation_2d (radians), MP_GABOR_3D p and orientation_3d (any
 * length). */
MP_INLINE void mp_tex_gabor(float3 p, int type, float scale, float frequency, float anisotropy, float orientation_2d,
                            float3 orientation_3d, float* value, float* phase, float* intensity) {
  float3 q = p * scale;
  float isotropy = 1.0f - clamp(anisotropy, 0.0f, 1.0f);
  frequency = fmax(0.001f, frequency);
  float re = 0.0f, im = 0.0f;
  float sd;
  if (type == MP_GABOR_3D) {
    float len3 = sqrt(orientation_3d.x * orientation_3d.x + orientation_3d.y * orientation_3d.y +
                      orientation_3d.z * orientation_3d.z);
    float3 o = orientation_3d / len3;
    float3 cell = MP_F3(floor(q.x), floor(q.y), floor(q.z));
    float3 lpos = q - cell;
    for (int k = -1; k <= 1; k++) {
      for (int j = -1; j <= 1; j++) {
        for (int i = -1; i <= 1; i++) {
          float3 off = MP_F3((float)i, (float)j, (float)k);
          float cre, cim;
          mp_gb_cell_3d(cell + off, lpos - off, frequency, isotropy, o, &cre, &cim);
          re += cre;
          im += cim;
        }
      }
    }
    float integral_of_gabor_squared = 1.0f / (4.0f * MP_GB_SQRT2);
    sd = sqrt((float)MP_GB_IMPULSES * 0.5f * integral_of_gabor_squared);
  }
  else {
    float cx = floor(q.x), cy = floor(q.y);
    float lx = q.x - cx, ly = q.y - cy;
    for (int j = -1; j <= 1; j++) {
      for (int i = -1; i <= 1; i++) {
        float ox = (float)i, oy = (float)j;
        float cre, cim;
        mp_gb_cell_2d(cx + ox, cy + oy, lx - ox, ly - oy, frequency, isotropy, orientation_2d, &cre, &cim);
        re += cre;
        im += cim;
      }
    }
    sd = sqrt((float)MP_GB_IMPULSES * 0.5f * 0.25f);
  }
  float norm = 6.0f * sd;
  *value = (im / norm) * 0.5f + 0.5f;
  *phase = (atan2(im, re) + MP_GB_PI) / (2.0f * MP_GB_PI);
  *intensity = sqrt(re * re + im * im) / norm;
}

#endif
