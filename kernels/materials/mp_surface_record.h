/* What a material program hands to the light program (light_program.cl):
 * the closures its node tree made at one grid vertex, with normals and
 * tangents already in camera space, and the few values lighting needs that
 * only the program's kernel knows.
 *
 * Why two programs: lighting (every lamp, shadow pages, the world, the
 * refraction proxy, every BSDF) is most of a shading kernel's code, and
 * compiling it into each node tree's program made a tree take about 6 s to
 * build on PoCL; built once in its own program it is shared by every tree,
 * which then builds in about half the time. Cycles splits its shaders the
 * same way: the node program fills a closure array, the integrator lights
 * it. The record's size compiles in C++ too, for the host to size the pool
 * (MaterialPrograms, kRecordPoolMiB). */
#ifndef MP_SURFACE_RECORD_H
#define MP_SURFACE_RECORD_H

#include "closures/mp_closures.h"

/* A record is MP_RECORD_SLOTS float4 slots, and the pool is laid out slot
 * by slot (slot s of record k at s * stride + k), so that neighbouring
 * work-items' stores and loads of a slot coalesce on a GPU:
 *   0      flag (1: a surface to light), grid index, object, faced
 *   1      count, normals, dropped, holdout's bits
 *   2      emission, alpha
 *   3      transparent, spread2 (the normal's spread, mp_normal_spread2)
 *   4..    normals (xyz, mode's bits), then 5 slots per closure
 * Only the normals and closures the surface has are stored. */
#define MP_RECORD_NORMALS 4
#define MP_RECORD_CLOSURES (MP_RECORD_NORMALS + MP_MAX_CLOSURE_NORMALS)
#define MP_RECORD_SLOTS (MP_RECORD_CLOSURES + 5 * MP_MAX_CLOSURES)
#define MP_SURFACE_RECORD_BYTES (16 * MP_RECORD_SLOTS)

#ifndef __OPENCL_VERSION__
/* The record holds every field of a closure and a surface (with float3 as
 * the host's 12 bytes): a field added to either must be added to
 * mp_record_store, mp_record_load and tests/native/test_surface_record.cpp. */
static_assert(sizeof(MpClosure) == 4 * 12 + 2 * 4 + 4 * 4 + 2 * 4, "MpClosure changed: update the surface record");
static_assert(sizeof(MpSurface) == MP_MAX_CLOSURES * sizeof(MpClosure) + 4 + MP_MAX_CLOSURE_NORMALS * (12 + 4) + 4 +
                                       2 * 12 + 2 * 4,
              "MpSurface changed: update the surface record");
#endif

#ifdef __OPENCL_VERSION__
#define MP_RECORD(pool, stride, k, slot) (pool)[(ulong)(slot) * (stride) + (k)]

/* Record k holds no surface to light. */
inline void mp_record_skip(__global float4* pool, uint stride, uint k) {
  MP_RECORD(pool, stride, k, 0) = as_float4((int4)(0));
}

inline void mp_record_store(__global float4* pool, uint stride, uint k, const MpSurface* s, uint index, uint object,
                            int faced, float alpha, float spread2) {
  MP_RECORD(pool, stride, k, 0) = as_float4((int4)(1, (int)index, (int)object, faced));
  MP_RECORD(pool, stride, k, 1) = as_float4((int4)(s->count, s->normals, s->dropped, as_int(s->holdout)));
  MP_RECORD(pool, stride, k, 2) = (float4)(s->emission, alpha);
  MP_RECORD(pool, stride, k, 3) = (float4)(s->transparent, spread2);
  for (int n = 0; n < s->normals; ++n)
    MP_RECORD(pool, stride, k, MP_RECORD_NORMALS + n) = (float4)(s->normal[n], as_float(s->normal_mode[n]));
  for (int c = 0; c < s->count; ++c) {
    const MpClosure* cl = &s->c[c];
    const uint at = MP_RECORD_CLOSURES + 5 * c;
    MP_RECORD(pool, stride, k, at) = (float4)(cl->weight, cl->a);
    MP_RECORD(pool, stride, k, at + 1) = (float4)(cl->f0, cl->b);
    MP_RECORD(pool, stride, k, at + 2) = (float4)(cl->f82, cl->film);
    MP_RECORD(pool, stride, k, at + 3) = (float4)(cl->tangent, cl->film_ior);
    MP_RECORD(pool, stride, k, at + 4) = as_float4((int4)(cl->kind, cl->fresnel, cl->slot, cl->multiscatter));
  }
}

/* Record k's surface (0 when it holds none): the grid index, object and
 * faced flag in `head`, alpha and spread2 beside the surface. */
inline int mp_record_load(__global const float4* pool, uint stride, uint k, MpSurface* s, int4* head, float* alpha,
                          float* spread2) {
  *head = as_int4(MP_RECORD(pool, stride, k, 0));
  if (head->x == 0) return 0;
  const int4 counts = as_int4(MP_RECORD(pool, stride, k, 1));
  s->count = counts.x;
  s->normals = counts.y;
  s->dropped = counts.z;
  s->holdout = as_float(counts.w);
  const float4 e = MP_RECORD(pool, stride, k, 2), t = MP_RECORD(pool, stride, k, 3);
  s->emission = e.xyz;
  *alpha = e.w;
  s->transparent = t.xyz;
  *spread2 = t.w;
  for (int n = 0; n < s->normals; ++n) {
    const float4 v = MP_RECORD(pool, stride, k, MP_RECORD_NORMALS + n);
    s->normal[n] = v.xyz;
    s->normal_mode[n] = as_int(v.w);
  }
  for (int c = 0; c < s->count; ++c) {
    MpClosure* cl = &s->c[c];
    const uint at = MP_RECORD_CLOSURES + 5 * c;
    float4 v = MP_RECORD(pool, stride, k, at);
    cl->weight = v.xyz, cl->a = v.w;
    v = MP_RECORD(pool, stride, k, at + 1);
    cl->f0 = v.xyz, cl->b = v.w;
    v = MP_RECORD(pool, stride, k, at + 2);
    cl->f82 = v.xyz, cl->film = v.w;
    v = MP_RECORD(pool, stride, k, at + 3);
    cl->tangent = v.xyz, cl->film_ior = v.w;
    const int4 kinds = as_int4(MP_RECORD(pool, stride, k, at + 4));
    cl->kind = kinds.x, cl->fresnel = kinds.y, cl->slot = kinds.z, cl->multiscatter = kinds.w;
  }
  return 1;
}
#endif

#endif
