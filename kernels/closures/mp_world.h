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
 * The stages' prefilter_world_glossy fills them on the device (texel by
 * texel, mp_world_glossy_texel below); shading reads them between the two
 * levels around a surface's roughness. */
#define MP_WORLD_GLOSSY_LEVELS 9
MP_INLINE int mp_world_glossy_width(int k) { return k == 0 ? 512 : k <= 2 ? 256 : k == 3 ? 128 : k == 4 ? 64 : 32; }
MP_INLINE int mp_world_glossy_offset(int k) {
  int offset = 0;
  for (int i = 0; i < k; ++i) offset += mp_world_glossy_width(i) * mp_world_glossy_width(i) / 2;
  return offset;
}

/* An equirectangular map of w x h texels starting at texels[base], at
 * world direction d, bilinear; longitude wraps, latitude clamps. */
MP_INLINE float3 mp_world_equirect_bilinear_uv(const MP_GLOBAL float4* texels, int base, int w, int h, float2 uv) {
  float x = uv.x * (float)w - 0.5f, y = uv.y * (float)h - 0.5f;
  float fx0 = floor(x), fy0 = floor(y);
  float fx = x - fx0, fy = y - fy0;
  int x0 = (int)fx0, y0 = (int)fy0;
  int xa = ((x0 % w) + w) % w, xb = (xa + 1) % w;
  int ya = clamp(y0, 0, h - 1), yb = clamp(y0 + 1, 0, h - 1);
  float4 c = (1.0f - fy) * ((1.0f - fx) * texels[base + ya * w + xa] + fx * texels[base + ya * w + xb]) +
             fy * ((1.0f - fx) * texels[base + yb * w + xa] + fx * texels[base + yb * w + xb]);
  return MP_F3(c.x, c.y, c.z);
}
MP_INLINE float3 mp_world_equirect_bilinear(const MP_GLOBAL float4* texels, int base, int w, int h, float3 d) {
  return mp_world_equirect_bilinear_uv(texels, base, w, h, mp_env_equirect_uv(d));
}

/* Level k at world direction d. */
MP_INLINE float3 mp_world_glossy_level(const MP_GLOBAL float4* maps, int k, float3 d) {
  int w = mp_world_glossy_width(k);
  return mp_world_equirect_bilinear(maps, mp_world_glossy_offset(k), w, w / 2, d);
}

/* The prefiltered radiance around world direction d for a GGX roughness. */
MP_INLINE float3 mp_world_glossy(const MP_GLOBAL float4* maps, float3 d, float roughness) {
  float r = clamp(roughness, 0.0f, 1.0f) * (float)(MP_WORLD_GLOSSY_LEVELS - 1);
  int k = (int)floor(r);
  if (k >= MP_WORLD_GLOSSY_LEVELS - 1) return mp_world_glossy_level(maps, MP_WORLD_GLOSSY_LEVELS - 1, d);
  float t = r - (float)k;
  return (1.0f - t) * mp_world_glossy_level(maps, k, d) + t * mp_world_glossy_level(maps, k + 1, d);
}

/* Prefiltering (world_lighting.cpp's world_glossy_maps on the host, the
 * stages' prefilter_world_glossy on the device). The source map of w x h
 * texels and its box-filtered halvings ("mips"), each half the one before
 * while the one before is at least 16 texels wide and 2 tall, lie one after
 * another: level l starts after the w_i * h_i texels of the levels before. */
MP_INLINE int mp_world_mip_count(int w, int h) {
  int n = 1;
  for (; w >= 16 && h >= 2; w /= 2, h /= 2) ++n;
  return n;
}

/* Radiance at direction d from the mips at fractional level lod. */
MP_INLINE float3 mp_world_mip_lookup(const MP_GLOBAL float4* mips, int w, int h, int count, float3 d, float lod) {
  lod = clamp(lod, 0.0f, (float)(count - 1));
  int a = (int)lod, base = 0;
  for (int l = 0; l < a; ++l) base += w * h, w /= 2, h /= 2;
  float2 uv = mp_env_equirect_uv(d);
  float3 c = mp_world_equirect_bilinear_uv(mips, base, w, h, uv);
  if (a + 1 >= count) return c;
  return mix(c, mp_world_equirect_bilinear_uv(mips, base + w * h, w / 2, h / 2, uv), lod - (float)a);
}

/* Texel (x, y) of glossy level k from the mips of a w x h map: level 0 the
 * map resampled at the level texel's footprint; level k the map convolved
 * with the GGX lobe of roughness k / 8 around the texel's direction (view
 * = normal = that direction, as the split-sum approximation assumes), by
 * filtered importance sampling (Krivanek & Colbert 2008): Hammersley points
 * give GGX half vectors (Walter et al. 2007), each mirrored direction reads
 * the mip whose texel is as large as its share of the lobe, weighted by
 * the cosine. Narrow lobes read fine mips with few samples (the fine levels
 * hold most of the texels); wide ones take more. */
MP_INLINE float3 mp_world_glossy_texel(const MP_GLOBAL float4* mips, int w, int h, int k, int x, int y) {
  int lw = mp_world_glossy_width(k), lh = lw / 2, count = mp_world_mip_count(w, h);
  float3 n = mp_env_equirect_direction(((float)x + 0.5f) / (float)lw, ((float)y + 0.5f) / (float)lh);
  if (k == 0) return mp_world_mip_lookup(mips, w, h, count, n, log2(fmax((float)w / (float)lw, 1.0f)));
  float3 up = fabs(n.z) < 0.999f ? MP_F3(0.0f, 0.0f, 1.0f) : MP_F3(1.0f, 0.0f, 0.0f);
  float3 t = normalize(cross(up, n)), b = cross(n, t);
  int samples = k <= 2 ? 16 : k == 3 ? 32 : 64;
  float roughness = (float)k / (float)(MP_WORLD_GLOSSY_LEVELS - 1);
  float alpha = fmax(roughness * roughness, 1e-4f), a2 = alpha * alpha;
  /* The source's texel solid angle at the equator, mip 0. */
  float texel0 = (2.0f * MP_WORLD_PI / (float)w) * (MP_WORLD_PI / (float)h);
  float3 sum = MP_F3(0.0f, 0.0f, 0.0f);
  float weight = 0.0f;
  for (int i = 0; i < samples; ++i) {
    float u1 = ((float)i + 0.5f) / (float)samples, u2 = 0.0f, f = 0.5f;
    for (int bits = i; bits; bits >>= 1, f *= 0.5f) u2 += f * (float)(bits & 1);
    float phi = 2.0f * MP_WORLD_PI * u1;
    float cos_h = sqrt((1.0f - u2) / (1.0f + (a2 - 1.0f) * u2));
    float sin_h = sqrt(fmax(0.0f, 1.0f - cos_h * cos_h));
    float3 hv = t * (sin_h * cos(phi)) + b * (sin_h * sin(phi)) + n * cos_h;
    float3 l = 2.0f * cos_h * hv - n;
    float nl = dot(n, l);
    if (nl <= 0.0f) continue;
    /* pdf(l) = D(h) cos_h / (4 l.h) = D(h) / 4 with view = normal. */
    float q = cos_h * cos_h * (a2 - 1.0f) + 1.0f;
    float pdf = a2 / (MP_WORLD_PI * q * q) / 4.0f;
    float lat_cos = fmax(sqrt(fmax(0.0f, 1.0f - l.z * l.z)), 1e-3f);
    float lod = 0.5f * log2(1.0f / ((float)samples * pdf) / (texel0 * lat_cos)) + 1.0f;
    sum += mp_world_mip_lookup(mips, w, h, count, l, lod) * nl;
    weight += nl;
  }
  return weight > 0.0f ? sum / weight : MP_F3(0.0f, 0.0f, 0.0f);
}

#endif
