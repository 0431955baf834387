/* The world's map (scene.h, World) and its irradiance harmonics, shared by
 * the kernels (baking, Environment Texture, shading) and the host
 * (pipeline/world/world_lighting.cpp). Compiles as OpenCL C and C++ (include
 * mp_compat.h first). */
#ifndef MP_WORLD_H
#define MP_WORLD_H

#include "core/mp_compat.h"

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

/* The world's glossy light: the map prefiltered by the GGX lobe of
 * roughness k / 8 for level k (level 0 the map itself, a mirror), each
 * level equirectangular, coarser as its lobe widens (the split-sum
 * prefiltering of Karis 2013, "Real Shading in Unreal Engine 4").
 * pipeline/world/world_lighting.cpp fills them; shading reads them between the
 * two levels around a surface's roughness. */
#define MP_WORLD_GLOSSY_LEVELS 9
MP_INLINE int mp_world_glossy_width(int k) { return k == 0 ? 512 : k <= 2 ? 256 : k == 3 ? 128 : k == 4 ? 64 : 32; }
MP_INLINE int mp_world_glossy_offset(int k) {
  int offset = 0;
  for (int i = 0; i < k; ++i) offset += mp_world_glossy_width(i) * mp_world_glossy_width(i) / 2;
  return offset;
}

/* Level k at world direction d, bilinear; longitude wraps. */
MP_INLINE float3 mp_world_glossy_level(const MP_GLOBAL float4* maps, int k, float3 d) {
  int w = mp_world_glossy_width(k), h = w / 2, base = mp_world_glossy_offset(k);
  float2 uv = mp_env_equirect_uv(d);
  float x = uv.x * (float)w - 0.5f, y = uv.y * (float)h - 0.5f;
  float fx0 = floor(x), fy0 = floor(y);
  float fx = x - fx0, fy = y - fy0;
  int x0 = (int)fx0, y0 = (int)fy0;
  int xa = ((x0 % w) + w) % w, xb = (xa + 1) % w;
  int ya = clamp(y0, 0, h - 1), yb = clamp(y0 + 1, 0, h - 1);
  float4 c = (1.0f - fy) * ((1.0f - fx) * maps[base + ya * w + xa] + fx * maps[base + ya * w + xb]) +
             fy * ((1.0f - fx) * maps[base + yb * w + xa] + fx * maps[base + yb * w + xb]);
  return MP_F3(c.x, c.y, c.z);
}

/* The prefiltered radiance around world direction d for a GGX roughness. */
MP_INLINE float3 mp_world_glossy(const MP_GLOBAL float4* maps, float3 d, float roughness) {
  float r = clamp(roughness, 0.0f, 1.0f) * (float)(MP_WORLD_GLOSSY_LEVELS - 1);
  int k = (int)floor(r);
  if (k >= MP_WORLD_GLOSSY_LEVELS - 1) return mp_world_glossy_level(maps, MP_WORLD_GLOSSY_LEVELS - 1, d);
  float t = r - (float)k;
  return (1.0f - t) * mp_world_glossy_level(maps, k, d) + t * mp_world_glossy_level(maps, k + 1, d);
}

#endif
