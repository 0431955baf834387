/* Surface points for dicing and edge measurement, watertight across patches.
 *
 * Inside a patch a point is the patch evaluated at (u, v) (mp_patch_eval.h).
 * A point on the patch boundary is instead evaluated from the edge's shared
 * curve (mp_patch.h), with the parameter mapped into the curve's own
 * direction, so the two patches that share an edge compute it with the same
 * operations on the same numbers. This relies on every (u, v) on a boundary
 * being a binary fraction with few bits (see mp_bound.h), which makes
 * t -> 1 - t and t -> 2t - 1 exact in float.
 *
 * Compiles as OpenCL C and C++ (include mp_compat.h, mp_patch.h,
 * mp_patch_eval.h and mp_types.h first). */
#ifndef MP_SURFACE_H
#define MP_SURFACE_H

#include "geometry/mp_instance.h"
#include "geometry/mp_ribbon.h"

/* Bernstein evaluation of curve `ref` at t along the referring edge: its
 * position (which = 0) or its normal cubic (which = 1, not normalised). */
MP_INLINE float3 mp_curve_eval(const MP_GLOBAL float4* curves, uint ref, float t, uint which) {
  const MP_GLOBAL float4* c = curves + (ulong)(ref >> 1) * MP_CURVE_FLOAT4S + 4u * which;
  float s = (ref & 1u) ? 1.0f - t : t;
  float r = 1.0f - s;
  return (r * r * r) * MP_XYZ(c[0]) + (3.0f * s * r * r) * MP_XYZ(c[1]) + (3.0f * s * s * r) * MP_XYZ(c[2]) +
         (s * s * s) * MP_XYZ(c[3]);
}

MP_INLINE float3 mp_curve_point(const MP_GLOBAL float4* curves, uint ref, float t) {
  return mp_curve_eval(curves, ref, t, 0u);
}

/* The curve and curve-relative parameter of edge e at t. On a transition
 * edge the halves meet at t = 1/2, the shared end point of both half curves. */
MP_INLINE uint mp_edge_curve(const MP_GLOBAL uint* edges, uint patch, uint e, float* t) {
  const MP_GLOBAL uint* refs = edges + (ulong)patch * MP_EDGE_REFS + 2u * e;
  if (refs[1] == MP_NO_CURVE) return refs[0];
  if (*t <= 0.5f) {
    *t = 2.0f * *t;
    return refs[0];
  }
  *t = 2.0f * *t - 1.0f;
  return refs[1];
}

/* Which patch edge (u, v) lies on, and its parameter there; -1 inside. */
MP_INLINE int mp_boundary_edge(float u, float v, float* t) {
  if (v == 0.0f) { *t = u; return 0; }
  if (u == 1.0f) { *t = v; return 1; }
  if (v == 1.0f) { *t = u; return 2; }
  if (u == 0.0f) { *t = v; return 3; }
  return -1;
}

/* Position and derivatives at (u, v) of patch `patch`, placed (camera
 * space); on the boundary the position comes from the shared edge curve. */
MP_INLINE void mp_surface_point(const MP_GLOBAL float4* points, const MP_GLOBAL uint* patch_info,
                                const MP_GLOBAL uint* edges, const MP_GLOBAL float4* curves, uint patch, float u,
                                float v, const MpPlacement* place, float3* P, float3* dPdu, float3* dPdv) {
  const MP_GLOBAL float4* cp = points + (ulong)patch * MP_PATCH_POINTS;
  uint type = patch_info[4 * (ulong)patch];
  if (type == MP_PATCH_CURVE) {
    /* A ribbon faces each view: its edges are not stored curves. Segments
     * meet at a shared centre point and radius, where both evaluate the
     * same end of their Bezier bases. */
    float3 n;
    mp_eval_ribbon(cp, u, v, place, P, dPdu, dPdv, &n);
    return;
  }
  mp_eval_patch(cp, type, u, v, P, dPdu, dPdv);
  float t;
  int e = mp_boundary_edge(u, v, &t);
  if (e >= 0) {
    uint ref = mp_edge_curve(edges, patch, (uint)e, &t);
    *P = mp_curve_point(curves, ref, t);
  }
  *P = mp_place_point(place, *P);
  *dPdu = mp_place_vector(place, *dPdu);
  *dPdv = mp_place_vector(place, *dPdv);
}

/* Unit normal of the patch at (u, v) from its derivatives. Where they are
 * parallel or vanish (collapsed corners, poles) the normal is taken a little
 * way towards the patch centre, which is its limit along that direction. */
MP_INLINE float3 mp_patch_normal(const MP_GLOBAL float4* cp, uint type, float u, float v, float3 dpdu, float3 dpdv,
                                 const MpPlacement* place) {
  float3 n = cross(dpdu, dpdv);
  float scale = length(dpdu) * length(dpdv);
  for (int k = 0; k < 3 && !(length(n) > 1e-7f * scale && length(n) > 0.0f); ++k) {
    float t = k == 0 ? 1e-4f : k == 1 ? 1e-3f : 1e-2f;
    float3 p;
    mp_eval_placed(cp, type, u + (0.5f - u) * t, v + (0.5f - v) * t, place, &p, &dpdu, &dpdv);
    n = cross(dpdu, dpdv);
    scale = length(dpdu) * length(dpdv);
  }
  float len = length(n);
  return len > 0.0f ? n / len : MP_F3(0.0f, 0.0f, 1.0f);
}

/* Unit normal for dicing (before the object's orientation flip), from
 * placed derivatives. On the patch boundary it comes from the edge's shared normal cubic, oriented like
 * this patch, so both sides displace a shared vertex identically. */
MP_INLINE float3 mp_surface_normal(const MP_GLOBAL float4* points, const MP_GLOBAL uint* patch_info,
                                   const MP_GLOBAL uint* edges, const MP_GLOBAL float4* curves, uint patch, float u,
                                   float v, float3 dPdu, float3 dPdv, const MpPlacement* place) {
  const MP_GLOBAL float4* cp = points + (ulong)patch * MP_PATCH_POINTS;
  uint type = patch_info[4 * (ulong)patch];
  float3 n = mp_patch_normal(cp, type, u, v, dPdu, dPdv, place);
  if (type == MP_PATCH_CURVE) return n;
  float t;
  int e = mp_boundary_edge(u, v, &t);
  if (e >= 0) {
    uint ref = mp_edge_curve(edges, patch, (uint)e, &t);
    float3 c = mp_place_normal(place, mp_curve_eval(curves, ref, t, 1u));
    float len = length(c);
    if (len > 0.0f) n = dot(c, n) < 0.0f ? -(c / len) : c / len;
  }
  return n;
}

/* Corner c (counter-clockwise from (0,0)) of a patch's UVs (mp_patch.h). */
MP_INLINE float2 mp_uv_corner(const MP_GLOBAL float4* uvs, ulong base, uint c) {
  float4 q = uvs[base + (c >> 1)];
#ifdef __OPENCL_VERSION__
  return (c & 1u) ? q.zw : q.xy;
#else
  return (c & 1u) ? float2(q.z, q.w) : float2(q.x, q.y);
#endif
}

/* a + (b - a) s, returning the end points themselves at s = 0 and 1. */
MP_INLINE float2 mp_uv_lerp(float2 a, float2 b, float s) {
  return s == 0.0f ? a : s == 1.0f ? b : a + (b - a) * s;
}

/* UV of `layer` at (u, v) of patch `patch`. Inside, bilinear in the corner
 * UVs. On the boundary, interpolated along the edge in its shared curve's
 * direction between end points the host made bit-identical on both sides
 * (patch_edges.cpp), so a shared vertex gets the same UV, and thus the same
 * UV-driven displacement, from both patches. The coarse side of a
 * transition edge interpolates each half from the edge's midpoint, which is
 * the value the host gave the fine side's corner. */
MP_INLINE float2 mp_patch_uv(const MP_GLOBAL float4* uvs, uint layers, const MP_GLOBAL uint* edges, uint patch,
                             uint layer, float u, float v) {
  ulong base = 2u * ((ulong)patch * layers + layer);
  float t;
  int e = mp_boundary_edge(u, v, &t);
  if (e < 0) {
    float2 c0 = mp_uv_corner(uvs, base, 0u), c1 = mp_uv_corner(uvs, base, 1u);
    float2 c2 = mp_uv_corner(uvs, base, 2u), c3 = mp_uv_corner(uvs, base, 3u);
    return (1.0f - v) * ((1.0f - u) * c0 + u * c1) + v * ((1.0f - u) * c3 + u * c2);
  }
  uint ea = e == 0 ? 0u : e == 1 ? 1u : e == 2 ? 3u : 0u;
  uint eb = e == 0 ? 1u : e == 1 ? 2u : e == 2 ? 2u : 3u;
  float2 a = mp_uv_corner(uvs, base, ea), b = mp_uv_corner(uvs, base, eb);
  const MP_GLOBAL uint* refs = edges + (ulong)patch * MP_EDGE_REFS + 2u * (uint)e;
  uint ref = refs[0];
  if (refs[1] != MP_NO_CURVE) {
    float2 m = a + (b - a) * 0.5f;
    if (t <= 0.5f) {
      b = m;
      t = 2.0f * t;
    } else {
      a = m;
      t = 2.0f * t - 1.0f;
      ref = refs[1];
    }
  }
  if (ref & 1u) {
    float2 swap = a;
    a = b;
    b = swap;
    t = 1.0f - t;
  }
  return mp_uv_lerp(a, b, t);
}

#endif
