/* The world's map (scene.h, World) and its irradiance harmonics, shared by
 * the kernels (baking, Environment Texture, shading) and the host
 * (pipeline/world_lighting.cpp). Compiles as OpenCL C and C++ (include
 * mp_compat.h first). */
#ifndef MP_WORLD_H
#define MP_WORLD_H

#include "mp_compat.h"

#define MP_WORLD_PI 3.14159265358979f

/* Equirectangular, as Cycles maps it: longitude from -X at u = 0 through
 * +X at u = 0.5, latitude from -Z at v = 0 to +Z at v = 1. */
MP_INLINE float2 mp_env_equirect_uv(float3 d) {
  float len = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
  if (!(len > 0.0f)) return MP_F2(0.0f, 0.0f);
  return MP_F2(0.5f - atan2(d.y, d.x) / (2.0f * MP_WORLD_PI),
               0.5f + asin(clamp(d.z / len, -1.0f, 1.0f)) / MP_WORLD_PI);
}
MP_INLINE float3 mp_env_equirect_direction(float u, float v) {
  float phi = MP_WORLD_PI * (1.0f - 2.0f * u), elevation = MP_WORLD_PI * (v - 0.5f);
  return MP_F3(cos(elevation) * cos(phi), cos(elevation) * sin(phi), sin(elevation));
}

/* Mirror ball: a ball photographed from -Y. */
MP_INLINE float2 mp_env_mirror_ball_uv(float3 d) {
  float len = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
  if (!(len > 0.0f)) return MP_F2(0.5f, 0.5f);
  d = d / len;
  d.y -= 1.0f;
  float div = 2.0f * sqrt(fmax(-0.5f * d.y, 0.0f));
  if (div > 0.0f) d = d / div;
  return MP_F2(0.5f * (d.x + 1.0f), 0.5f * (d.z + 1.0f));
}

/* The 9 real spherical harmonics of order <= 2 at unit direction d, in the
 * order l = 0; l = 1, m = -1..1; l = 2, m = -2..2 (Ramamoorthi & Hanrahan
 * 2001, "An efficient representation for irradiance environment maps"). */
MP_INLINE void mp_sh9_basis(float3 d, float* b) {
  b[0] = 0.282095f;
  b[1] = 0.488603f * d.y;
  b[2] = 0.488603f * d.z;
  b[3] = 0.488603f * d.x;
  b[4] = 1.092548f * d.x * d.y;
  b[5] = 1.092548f * d.y * d.z;
  b[6] = 0.315392f * (3.0f * d.z * d.z - 1.0f);
  b[7] = 1.092548f * d.x * d.z;
  b[8] = 0.546274f * (d.x * d.x - d.y * d.y);
}

#endif
