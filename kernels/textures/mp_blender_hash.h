/* Hashes with the exact bit behaviour of Blender's procedural textures, so
 * that Noise, Voronoi and friends reproduce Blender's patterns cell for cell.
 *
 * - Bob Jenkins' lookup3 "final"/"mix" mixers over 1-4 32-bit words; the
 *   initial state is 0xdeadbeef + (words << 2) + 13. Floats are hashed by
 *   their bit patterns, so the same float always lands in the same cell.
 * - Results mapped to [0, 1] by multiplying by 2^-32 (the top value rounds
 *   to 1.0f in single precision).
 * - The PCG-style integer hashes (2D-4D, signed 32-bit arithmetic with
 *   wrap-around and arithmetic right shifts) that Blender 5.0's Voronoi uses
 *   for integer cell coordinates.
 *
 * Compiles as OpenCL C 1.2 and as C++17 through mp_compat.h. Vector results
 * are returned through private arrays (out[0..n-1]) so that the generic
 * 1D-4D texture code needs no vector types beyond float3. */
#ifndef MP_BLENDER_HASH_H
#define MP_BLENDER_HASH_H

#include "core/mp_compat.h"

/* ---- lookup3 building blocks -------------------------------------------- */

MP_INLINE uint mp_bhash_rot(uint x, uint k) { return (x << k) | (x >> (32u - k)); }

/* lookup3's final avalanche of the three-word state (a, b, c). */
MP_INLINE void mp_bhash_final(uint* a, uint* b, uint* c) {
  *c ^= *b; *c -= mp_bhash_rot(*b, 14u);
  *a ^= *c; *a -= mp_bhash_rot(*c, 11u);
  *b ^= *a; *b -= mp_bhash_rot(*a, 25u);
  *c ^= *b; *c -= mp_bhash_rot(*b, 16u);
  *a ^= *c; *a -= mp_bhash_rot(*c, 4u);
  *b ^= *a; *b -= mp_bhash_rot(*a, 14u);
  *c ^= *b; *c -= mp_bhash_rot(*b, 24u);
}

/* lookup3's reversible mixing step, used when more than three words go in. */
MP_INLINE void mp_bhash_mix(uint* a, uint* b, uint* c) {
  *a -= *c; *a ^= mp_bhash_rot(*c, 4u);  *c += *b;
  *b -= *a; *b ^= mp_bhash_rot(*a, 6u);  *a += *c;
  *c -= *b; *c ^= mp_bhash_rot(*b, 8u);  *b += *a;
  *a -= *c; *a ^= mp_bhash_rot(*c, 16u); *c += *b;
  *b -= *a; *b ^= mp_bhash_rot(*a, 19u); *a += *c;
  *c -= *b; *c ^= mp_bhash_rot(*b, 4u);  *b += *a;
}

#define MP_BHASH_SEED(words) (0xdeadbeefu + ((uint)(words) << 2) + 13u)

MP_INLINE uint mp_bhash_uint(uint kx) {
  uint a = MP_BHASH_SEED(1), b = a, c = a;
  a += kx;
  mp_bhash_final(&a, &b, &c);
  return c;
}

MP_INLINE uint mp_bhash_uint2(uint kx, uint ky) {
  uint a = MP_BHASH_SEED(2), b = a, c = a;
  b += ky;
  a += kx;
  mp_bhash_final(&a, &b, &c);
  return c;
}

MP_INLINE uint mp_bhash_uint3(uint kx, uint ky, uint kz) {
  uint a = MP_BHASH_SEED(3), b = a, c = a;
  c += kz;
  b += ky;
  a += kx;
  mp_bhash_final(&a, &b, &c);
  return c;
}

MP_INLINE uint mp_bhash_uint4(uint kx, uint ky, uint kz, uint kw) {
  uint a = MP_BHASH_SEED(4), b = a, c = a;
  a += kx;
  b += ky;
  c += kz;
  mp_bhash_mix(&a, &b, &c);
  a += kw;
  mp_bhash_final(&a, &b, &c);
  return c;
}

/* ---- to floats in [0, 1] -------------------------------------------------- */

MP_INLINE float mp_bhash_uint_to_unit(uint h) { return (float)h * (1.0f / 4294967296.0f); }

MP_INLINE float mp_bhash_uint_to_float(uint kx) { return mp_bhash_uint_to_unit(mp_bhash_uint(kx)); }
MP_INLINE float mp_bhash_uint2_to_float(uint kx, uint ky) { return mp_bhash_uint_to_unit(mp_bhash_uint2(kx, ky)); }
MP_INLINE float mp_bhash_uint3_to_float(uint kx, uint ky, uint kz) {
  return mp_bhash_uint_to_unit(mp_bhash_uint3(kx, ky, kz));
}
MP_INLINE float mp_bhash_uint4_to_float(uint kx, uint ky, uint kz, uint kw) {
  return mp_bhash_uint_to_unit(mp_bhash_uint4(kx, ky, kz, kw));
}

MP_INLINE float mp_bhash_float_to_float(float k) { return mp_bhash_uint_to_float(as_uint(k)); }
MP_INLINE float mp_bhash_float2_to_float(float x, float y) { return mp_bhash_uint2_to_float(as_uint(x), as_uint(y)); }
MP_INLINE float mp_bhash_float3_to_float(float x, float y, float z) {
  return mp_bhash_uint3_to_float(as_uint(x), as_uint(y), as_uint(z));
}
MP_INLINE float mp_bhash_float4_to_float(float x, float y, float z, float w) {
  return mp_bhash_uint4_to_float(as_uint(x), as_uint(y), as_uint(z), as_uint(w));
}

/* Several independent values from one key: the extra components hash the key
 * with a constant appended (or with its components rotated, in 4D). */
MP_INLINE void mp_bhash_float2_to_float2(float x, float y, float* out) {
  out[0] = mp_bhash_float2_to_float(x, y);
  out[1] = mp_bhash_float3_to_float(x, y, 1.0f);
}

MP_INLINE void mp_bhash_float3_to_float3v(float x, float y, float z, float* out) {
  out[0] = mp_bhash_float3_to_float(x, y, z);
  out[1] = mp_bhash_float4_to_float(x, y, z, 1.0f);
  out[2] = mp_bhash_float4_to_float(x, y, z, 2.0f);
}

MP_INLINE float3 mp_bhash_float3_to_float3(float3 k) {
  float o[3];
  mp_bhash_float3_to_float3v(k.x, k.y, k.z, o);
  return MP_F3(o[0], o[1], o[2]);
}

MP_INLINE void mp_bhash_float4_to_float4(float x, float y, float z, float w, float* out) {
  out[0] = mp_bhash_float4_to_float(x, y, z, w);
  out[1] = mp_bhash_float4_to_float(w, x, y, z);
  out[2] = mp_bhash_float4_to_float(z, w, x, y);
  out[3] = mp_bhash_float4_to_float(y, z, w, x);
}

MP_INLINE float3 mp_bhash_float_to_float3(float k) {
  return MP_F3(mp_bhash_float_to_float(k), mp_bhash_float2_to_float(k, 1.0f), mp_bhash_float2_to_float(k, 2.0f));
}

MP_INLINE float3 mp_bhash_float2_to_float3(float x, float y) {
  return MP_F3(mp_bhash_float2_to_float(x, y), mp_bhash_float3_to_float(x, y, 1.0f),
               mp_bhash_float3_to_float(x, y, 2.0f));
}

MP_INLINE float3 mp_bhash_float4_to_float3(float x, float y, float z, float w) {
  return MP_F3(mp_bhash_float4_to_float(x, y, z, w), mp_bhash_float4_to_float(z, x, w, y),
               mp_bhash_float4_to_float(w, z, y, x));
}

/* ---- PCG-style integer hashes (Blender 5.0 Voronoi) ------------------------
 * Written on uint so that overflow wraps in both languages; the right shift
 * is made arithmetic by hand to match the signed original. */

#define MP_BHASH_PCG_MUL 1664525u
#define MP_BHASH_PCG_ADD 1013904223u

MP_INLINE uint mp_bhash_asr16(uint v) { return (v >> 16) | (((v >> 31) != 0u) ? 0xffff0000u : 0u); }

MP_INLINE void mp_bhash_pcg2d(int kx, int ky, uint* out) {
  uint x = (uint)kx * MP_BHASH_PCG_MUL + MP_BHASH_PCG_ADD;
  uint y = (uint)ky * MP_BHASH_PCG_MUL + MP_BHASH_PCG_ADD;
  x += y * MP_BHASH_PCG_MUL;
  y += x * MP_BHASH_PCG_MUL;
  x ^= mp_bhash_asr16(x);
  y ^= mp_bhash_asr16(y);
  x += y * MP_BHASH_PCG_MUL;
  y += x * MP_BHASH_PCG_MUL;
  out[0] = x & 0x7fffffffu;
  out[1] = y & 0x7fffffffu;
}

MP_INLINE void mp_bhash_pcg3d(int kx, int ky, int kz, uint* out) {
  uint x = (uint)kx * MP_BHASH_PCG_MUL + MP_BHASH_PCG_ADD;
  uint y = (uint)ky * MP_BHASH_PCG_MUL + MP_BHASH_PCG_ADD;
  uint z = (uint)kz * MP_BHASH_PCG_MUL + MP_BHASH_PCG_ADD;
  x += y * z;
  y += z * x;
  z += x * y;
  x ^= mp_bhash_asr16(x);
  y ^= mp_bhash_asr16(y);
  z ^= mp_bhash_asr16(z);
  x += y * z;
  y += z * x;
  z += x * y;
  out[0] = x & 0x7fffffffu;
  out[1] = y & 0x7fffffffu;
  out[2] = z & 0x7fffffffu;
}

MP_INLINE void mp_bhash_pcg4d(int kx, int ky, int kz, int kw, uint* out) {
  uint x = (uint)kx * MP_BHASH_PCG_MUL + MP_BHASH_PCG_ADD;
  uint y = (uint)ky * MP_BHASH_PCG_MUL + MP_BHASH_PCG_ADD;
  uint z = (uint)kz * MP_BHASH_PCG_MUL + MP_BHASH_PCG_ADD;
  uint w = (uint)kw * MP_BHASH_PCG_MUL + MP_BHASH_PCG_ADD;
  x += y * w;
  y += z * x;
  z += x * y;
  w += y * z;
  x ^= mp_bhash_asr16(x);
  y ^= mp_bhash_asr16(y);
  z ^= mp_bhash_asr16(z);
  w ^= mp_bhash_asr16(w);
  x += y * w;
  y += z * x;
  z += x * y;
  w += y * z;
  out[0] = x & 0x7fffffffu;
  out[1] = y & 0x7fffffffu;
  out[2] = z & 0x7fffffffu;
  out[3] = w & 0x7fffffffu;
}

/* 31-bit hash to [0, 1]: scaled by 2^-31 (0x7fffffff rounds to 2^31 as a float). */
MP_INLINE float mp_bhash_int31_to_unit(uint h) { return (float)(int)h * (1.0f / 2147483648.0f); }

MP_INLINE void mp_bhash_int2_to_float2(int x, int y, float* out) {
  uint h[2];
  mp_bhash_pcg2d(x, y, h);
  out[0] = mp_bhash_int31_to_unit(h[0]);
  out[1] = mp_bhash_int31_to_unit(h[1]);
}

MP_INLINE void mp_bhash_int3_to_float3v(int x, int y, int z, float* out) {
  uint h[3];
  mp_bhash_pcg3d(x, y, z, h);
  out[0] = mp_bhash_int31_to_unit(h[0]);
  out[1] = mp_bhash_int31_to_unit(h[1]);
  out[2] = mp_bhash_int31_to_unit(h[2]);
}

MP_INLINE void mp_bhash_int4_to_float4(int x, int y, int z, int w, float* out) {
  uint h[4];
  mp_bhash_pcg4d(x, y, z, w, h);
  out[0] = mp_bhash_int31_to_unit(h[0]);
  out[1] = mp_bhash_int31_to_unit(h[1]);
  out[2] = mp_bhash_int31_to_unit(h[2]);
  out[3] = mp_bhash_int31_to_unit(h[3]);
}

/* 2D cells take their colour from the 3D hash with z = 0; 4D cells from the
 * first three components of the 4D hash. */
MP_INLINE float3 mp_bhash_int2_to_float3(int x, int y) {
  float o[3];
  mp_bhash_int3_to_float3v(x, y, 0, o);
  return MP_F3(o[0], o[1], o[2]);
}

MP_INLINE float3 mp_bhash_int3_to_float3(int x, int y, int z) {
  float o[3];
  mp_bhash_int3_to_float3v(x, y, z, o);
  return MP_F3(o[0], o[1], o[2]);
}

MP_INLINE float3 mp_bhash_int4_to_float3(int x, int y, int z, int w) {
  float o[4];
  mp_bhash_int4_to_float4(x, y, z, w, o);
  return MP_F3(o[0], o[1], o[2]);
}

#endif
