/* Refraction through an object's own shape: the paths the view takes
 * through a glass object, traced against a triangle proxy of its surface
 * (native/src/pipeline/materials/refraction_proxy.cpp builds it: the limit surface
 * tessellated per patch, camera space, in a bounding volume hierarchy).
 * The shading point refracts the view in; each hit on the proxy splits the
 * path by the dielectric Fresnel term (Glass) or passes it all through
 * (Refraction; lost under total internal reflection, as Cycles' refraction
 * lobe loses it), until the paths leave the object. The caller looks up the
 * world along the directions they leave in (mp_shade_closures).
 * Compiles as OpenCL C and C++ (include mp_compat.h first).
 *
 * Layout (float4s):
 *   node k: [2k] = (box min, a), [2k + 1] = (box max, b), a and b as
 *     uint bits: an inner node's children are nodes a and b; a leaf has
 *     b = count | MP_REFRACT_LEAF and holds triangles a .. a + count - 1.
 *   triangle t: [6t .. 6t + 2] its corners, [6t + 3 .. 6t + 5] the
 *     surface's normals there (interpolated across it).
 * roots: per object the node of its proxy's root, MP_REFRACT_NONE without. */
#ifndef MP_REFRACT_TRACE_H
#define MP_REFRACT_TRACE_H

#include "core/mp_compat.h"
#include "closures/mp_bsdf.h"

#define MP_REFRACT_LEAF 0x80000000u
#define MP_REFRACT_NONE 0xffffffffu
#define MP_REFRACT_STACK 32      /* traversal stack: deeper than any tree the builder makes */
#define MP_REFRACT_MAX_EXITS 8   /* directions a path set leaves in */
#define MP_REFRACT_MAX_SEGMENTS 32 /* rays traced per shading point */
#define MP_REFRACT_MAX_DEPTH 32  /* interfaces along one path: chains of total internal reflection run long */
#define MP_REFRACT_MIN_WEIGHT 2e-3f /* paths carrying less are dropped */

typedef struct {
  MP_GLOBAL const float4* nodes;
  MP_GLOBAL const float4* tris;
  uint root;
} MpRefractScene;

typedef struct {
  float t, u, v;
  uint tri;
} MpRefractHit;

/* Snell's law: d (unit, towards the surface) refracted through a surface of
 * normal n (facing against d) with relative IOR eta (incident over
 * transmitted), cos_i = -d.n as the caller takes it. Returns 0 under total
 * internal reflection. */
MP_INLINE int mp_refract_dir(float3 d, float3 n, float cos_i, float eta, float3* t) {
  float k2 = 1.0f - eta * eta * (1.0f - cos_i * cos_i);
  if (!(k2 > 0.0f)) return 0;
  *t = eta * d + (eta * cos_i - sqrt(k2)) * n;
  return 1;
}

/* Ray against a triangle, either side (Moller and Trumbore 1997). */
MP_INLINE int mp_refract_tri_hit(float3 o, float3 d, float3 p0, float3 p1, float3 p2, float tmin, float tmax,
                                 float* t, float* u, float* v) {
  float3 e1 = p1 - p0, e2 = p2 - p0, pv = cross(d, e2);
  float det = dot(e1, pv);
  if (fabs(det) < 1e-30f) return 0;
  float inv = 1.0f / det;
  float3 tv = o - p0;
  float a = dot(tv, pv) * inv;
  if (a < 0.0f || a > 1.0f) return 0;
  float3 qv = cross(tv, e1);
  float b = dot(d, qv) * inv;
  if (b < 0.0f || a + b > 1.0f) return 0;
  float tt = dot(e2, qv) * inv;
  if (!(tt > tmin && tt < tmax)) return 0;
  *t = tt, *u = a, *v = b;
  return 1;
}

/* Ray against a box (slabs); inv: 1 / d per axis. */
MP_INLINE int mp_refract_box_hit(float3 o, float3 inv, float4 lo, float4 hi, float tmin, float tmax) {
  float3 t0 = (MP_XYZ(lo) - o) * inv, t1 = (MP_XYZ(hi) - o) * inv;
  float3 tn = fmin(t0, t1), tf = fmax(t0, t1);
  float a = fmax(fmax(tn.x, tn.y), fmax(tn.z, tmin)), b = fmin(fmin(tf.x, tf.y), fmin(tf.z, tmax));
  return a <= b;
}

/* The nearest hit of o + t d, tmin < t < tmax, on the proxy from `root`. */
MP_INLINE int mp_refract_trace(const MpRefractScene* sc, float3 o, float3 d, float tmin, float tmax,
                               MpRefractHit* hit) {
  uint stack[MP_REFRACT_STACK];
  int top = 0, found = 0;
  float3 inv = MP_F3(1.0f / (d.x != 0.0f ? d.x : 1e-30f), 1.0f / (d.y != 0.0f ? d.y : 1e-30f),
                     1.0f / (d.z != 0.0f ? d.z : 1e-30f));
  stack[top++] = sc->root;
  while (top > 0) {
    uint k = stack[--top];
    float4 lo = sc->nodes[2 * (ulong)k], hi = sc->nodes[2 * (ulong)k + 1];
    if (!mp_refract_box_hit(o, inv, lo, hi, tmin, tmax)) continue;
    uint a = as_uint(lo.w), b = as_uint(hi.w);
    if (b & MP_REFRACT_LEAF) {
      uint count = b & ~MP_REFRACT_LEAF;
      for (uint i = a; i < a + count; ++i) {
        MP_GLOBAL const float4* tri = sc->tris + 6 * (ulong)i;
        float t, u, v;
        if (mp_refract_tri_hit(o, d, MP_XYZ(tri[0]), MP_XYZ(tri[1]), MP_XYZ(tri[2]), tmin, tmax, &t, &u, &v)) {
          tmax = t, found = 1;
          hit->t = t, hit->u = u, hit->v = v, hit->tri = i;
        }
      }
    } else if (top + 2 <= MP_REFRACT_STACK) {
      stack[top++] = b;
      stack[top++] = a;
    }
  }
  return found;
}

/* The proxy's box (its root node's). */
MP_INLINE void mp_refract_box(const MpRefractScene* sc, float3* lo, float3* hi) {
  *lo = MP_XYZ(sc->nodes[2 * (ulong)sc->root]);
  *hi = MP_XYZ(sc->nodes[2 * (ulong)sc->root + 1]);
}

/* Whether the camera (camera space: the origin; an orthographic camera
 * lies at infinity) is within the proxy's box, so that it may see the
 * object's surface from inside. */
MP_INLINE int mp_refract_camera_inside(const MpRefractScene* sc, int ortho) {
  float3 lo, hi;
  mp_refract_box(sc, &lo, &hi);
  return !ortho && lo.x <= 0.0f && lo.y <= 0.0f && lo.z <= 0.0f && hi.x >= 0.0f && hi.y >= 0.0f && hi.z >= 0.0f;
}

/* The hit's geometric and interpolated normals, both turned to face
 * against d; returns whether the ray enters there (the triangle's wound
 * normal faces it: the proxy keeps the surface's outward winding). */
MP_INLINE int mp_refract_hit_normal(const MpRefractScene* sc, const MpRefractHit* h, float3 d, float3* n,
                                    float3* geometric) {
  MP_GLOBAL const float4* tri = sc->tris + 6 * (ulong)h->tri;
  float3 p0 = MP_XYZ(tri[0]);
  float3 ng = cross(MP_XYZ(tri[1]) - p0, MP_XYZ(tri[2]) - p0);
  float w = 1.0f - h->u - h->v;
  float3 ns = w * MP_XYZ(tri[3]) + h->u * MP_XYZ(tri[4]) + h->v * MP_XYZ(tri[5]);
  int entering = dot(ng, d) < 0.0f;
  float3 face = normalize(entering ? ng : -ng);
  *geometric = face;
  if (!(dot(ns, ns) > 0.0f)) ns = face;
  ns = normalize(ns);
  if (dot(ns, face) < 0.0f) ns = -ns;
  *n = ns;
  return entering;
}

typedef struct {
  float3 dir[MP_REFRACT_MAX_EXITS];
  float3 weight[MP_REFRACT_MAX_EXITS];
  int interfaces[MP_REFRACT_MAX_EXITS]; /* surfaces crossed or reflected from */
  int count;
  float3 lost; /* weight of paths cut short by the budgets (segments, exits) */
} MpRefractExits;

typedef struct {
  float3 o, d, w;
  int depth;
  float tmin;
} MpRefractRay;

/* Follows the paths of a ray that has just crossed the surface at o into
 * direction d (carrying weight 1) through the proxy: at each hit the
 * relative IOR is ior entering and 1 / ior leaving; glass splits by the
 * exact Fresnel term, a refraction lobe passes everything it can refract;
 * tint multiplies every hit. tmin0: the first ray's offset past the
 * proxy's tessellation error around o; each later ray starts `offset` off
 * the triangle it leaves, on its side (camera-space positions carry float
 * error proportional to their distance: a ray started on the surface
 * itself may hit it again and bounce in place). */
MP_INLINE void mp_refract_paths(const MpRefractScene* sc, float3 o, float3 d, float tmin0, float offset, float ior,
                                int glass, float3 tint, MpRefractExits* ex) {
  MpRefractRay stack[MP_REFRACT_MAX_EXITS];
  int top = 0, segments = 0;
  ex->count = 0;
  ex->lost = MP_F3(0.0f, 0.0f, 0.0f);
  MpRefractRay r0 = {o, d, MP_F3(1.0f, 1.0f, 1.0f), 1, tmin0};
  stack[top++] = r0;
  while (top > 0) {
    MpRefractRay r = stack[--top];
    MpRefractHit h;
    if (segments >= MP_REFRACT_MAX_SEGMENTS) {
      ex->lost += r.w;
      continue;
    }
    ++segments;
    if (!mp_refract_trace(sc, r.o, r.d, r.tmin, 1e30f, &h)) {
      if (ex->count < MP_REFRACT_MAX_EXITS) {
        ex->dir[ex->count] = r.d, ex->weight[ex->count] = r.w, ex->interfaces[ex->count] = r.depth;
        ex->count++;
      } else {
        ex->lost += r.w;
      }
      continue;
    }
    if (r.depth >= MP_REFRACT_MAX_DEPTH) continue; /* as Cycles ends a path at its bounce limit */
    float3 n, ng, p = r.o + h.t * r.d;
    int entering = mp_refract_hit_normal(sc, &h, r.d, &n, &ng);
    float3 p_in = p - offset * ng, p_out = p + offset * ng; /* ng faces where the ray came from */
    float eta = entering ? 1.0f / ior : ior;
    float cos_i = fmin(-dot(r.d, n), 1.0f);
    float3 td;
    int passes = mp_refract_dir(r.d, n, cos_i, eta, &td);
    float fr = glass ? mp_fresnel_dielectric(cos_i, entering ? ior : 1.0f / ior) : (passes ? 0.0f : 1.0f);
    float3 w = r.w * tint;
    if (passes) {
      MpRefractRay t = {p_in, normalize(td), w * (1.0f - fr), r.depth + 1, 0.0f};
      if (fmax(t.w.x, fmax(t.w.y, t.w.z)) > MP_REFRACT_MIN_WEIGHT) {
        if (top < MP_REFRACT_MAX_EXITS) stack[top++] = t;
        else ex->lost += t.w;
      }
    }
    /* Reflected inside (or outside): glass's Fresnel share. A refraction
     * lobe reflects nothing, so its totally reflected light is lost. */
    if (glass) {
      float3 rw = w * fr;
      MpRefractRay rr = {p_out, normalize(r.d + 2.0f * cos_i * n), rw, r.depth + 1, 0.0f};
      if (fmax(rw.x, fmax(rw.y, rw.z)) > MP_REFRACT_MIN_WEIGHT) {
        if (top < MP_REFRACT_MAX_EXITS) stack[top++] = rr;
        else ex->lost += rw;
      }
    }
  }
}

#endif
