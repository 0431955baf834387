/* Bound & split decisions for one sub-patch (Cook et al. 1987, section 3;
 * the split and cull tests of Patney & Owens 2008 and Weber et al. 2015).
 *
 * The bound is conservative: a sub-patch [u0,u1]x[v0,v1] of a Bezier patch is
 * again a Bezier patch whose net is a non-negative, partition-of-unity
 * combination of the parent's net (blossoming). For Gregory patches each
 * interior point lies on the segment between itself and its partner, so the
 * sub-net's points lie in boxes obtained by applying the same weights to the
 * componentwise minima and maxima. The surface lies in the convex hull of the
 * sub-net, and a perspective projection of a convex set in front of the eye
 * plane is bounded by the projections of its extreme points. */
#ifndef MP_BOUND_H
#define MP_BOUND_H

#include "mp_compat.h"
#include "mp_patch.h"
#include "mp_types.h"

#define MP_CULL 0u
#define MP_DICE 1u
#define MP_SPLIT_U 2u
#define MP_SPLIT_V 3u

/* Decision word: action in bits 0-7, grid size nu, nv in bits 8-15, 16-23. */
#define MP_DECISION_ACTION(d) ((d) & 0xffu)

typedef struct {
  float xmin, ymin, xmax, ymax; /* raster space */
  float dmin, dmax;             /* depth in front of the eye */
} MpBound;

/* Cubic Bernstein polynomials' blossom at (t1, t2, t3). */
MP_INLINE void mp_blossom_weights(float t1, float t2, float t3, float* w) {
  float r1 = 1.0f - t1, r2 = 1.0f - t2, r3 = 1.0f - t3;
  w[0] = r1 * r2 * r3;
  w[1] = t1 * r2 * r3 + r1 * t2 * r3 + r1 * r2 * t3;
  w[2] = t1 * t2 * r3 + t1 * r2 * t3 + r1 * t2 * t3;
  w[3] = t1 * t2 * t3;
}

/* Weights W[4k+m] of the Bezier sub-segment [a,b]: Q_k = sum_m W[4k+m] P_m. */
MP_INLINE void mp_subsegment_weights(float a, float b, float* W) {
  mp_blossom_weights(a, a, a, W + 0);
  mp_blossom_weights(a, a, b, W + 4);
  mp_blossom_weights(a, b, b, W + 8);
  mp_blossom_weights(b, b, b, W + 12);
}

/* Applies the sub-rectangle weights to a 4x4 net (row-major, u fastest). */
MP_INLINE void mp_restrict_net(const float3* net, const float* Wu, const float* Wv, float3* out) {
  float3 tmp[16];
  for (int j = 0; j < 4; ++j)
    for (int k = 0; k < 4; ++k) {
      float3 s = MP_F3(0.0f, 0.0f, 0.0f);
      for (int i = 0; i < 4; ++i) s += Wu[4 * k + i] * net[4 * j + i];
      tmp[4 * j + k] = s;
    }
  for (int l = 0; l < 4; ++l)
    for (int k = 0; k < 4; ++k) {
      float3 s = MP_F3(0.0f, 0.0f, 0.0f);
      for (int j = 0; j < 4; ++j) s += Wv[4 * l + j] * tmp[4 * j + k];
      out[4 * l + k] = s;
    }
}

MP_INLINE int mp_interior_slot(int idx) {
  return idx == MP_INTERIOR_0 ? 0 : idx == MP_INTERIOR_1 ? 1 : idx == MP_INTERIOR_2 ? 2 : idx == MP_INTERIOR_3 ? 3 : -1;
}

/* Boxes [lo[k], hi[k]] containing the sub-patch's Bezier net (camera space). */
MP_INLINE void mp_subpatch_net_boxes(const MP_GLOBAL float4* cp, uint type, SubPatch sp, float3* lo, float3* hi) {
  float Wu[16], Wv[16];
  mp_subsegment_weights(sp.u0, sp.u1, Wu);
  mp_subsegment_weights(sp.v0, sp.v1, Wv);
  float3 a[16];
  for (int k = 0; k < 16; ++k) a[k] = MP_XYZ(cp[k]);
  if (type == MP_PATCH_GREGORY) {
    float3 b[16];
    for (int k = 0; k < 16; ++k) b[k] = a[k];
    for (int k = 0; k < 16; ++k) {
      int s = mp_interior_slot(k);
      if (s >= 0) {
        float3 partner = MP_XYZ(cp[16 + s]);
        a[k] = fmin(a[k], partner);
        b[k] = fmax(b[k], partner);
      }
    }
    mp_restrict_net(a, Wu, Wv, lo);
    mp_restrict_net(b, Wu, Wv, hi);
  } else {
    mp_restrict_net(a, Wu, Wv, lo);
    for (int k = 0; k < 16; ++k) hi[k] = lo[k];
  }
}

/* Raster position of a camera-space point (d > 0 for perspective cameras). */
MP_INLINE float2 mp_project(float3 p, FrameParams f) {
  float inv = f.ortho ? 1.0f : 1.0f / (-p.z);
#ifdef __OPENCL_VERSION__
  return (float2)(f.ax * p.x * inv + f.bx, f.ay * p.y * inv + f.by);
#else
  return float2(f.ax * p.x * inv + f.bx, f.ay * p.y * inv + f.by);
#endif
}

/* Range of a * x / d + b over x in [xl, xh], d in [dl, dh] (dl > 0). */
MP_INLINE void mp_project_range(float xl, float xh, float dl, float dh, float a, float b, int ortho, float* lo, float* hi) {
  float qmin, qmax;
  if (ortho) {
    qmin = xl;
    qmax = xh;
  } else {
    qmin = xl >= 0.0f ? xl / dh : xl / dl;
    qmax = xh >= 0.0f ? xh / dl : xh / dh;
  }
  float r0 = a * qmin + b, r1 = a * qmax + b;
  *lo = fmin(r0, r1);
  *hi = fmax(r0, r1);
}

/* Raster/depth bound of the boxes. Only meaningful when dmin > 0 (or ortho). */
MP_INLINE MpBound mp_bound_boxes(const float3* lo, const float3* hi, FrameParams f) {
  MpBound b;
  b.dmin = 3.0e38f;
  b.dmax = -3.0e38f;
  for (int k = 0; k < 16; ++k) {
    b.dmin = fmin(b.dmin, -hi[k].z);
    b.dmax = fmax(b.dmax, -lo[k].z);
  }
  b.xmin = b.ymin = 3.0e38f;
  b.xmax = b.ymax = -3.0e38f;
  if (!f.ortho && b.dmin <= f.eye_epsilon) return b;
  for (int k = 0; k < 16; ++k) {
    float dl = -hi[k].z, dh = -lo[k].z, l, h;
    mp_project_range(lo[k].x, hi[k].x, dl, dh, f.ax, f.bx, f.ortho, &l, &h);
    b.xmin = fmin(b.xmin, l);
    b.xmax = fmax(b.xmax, h);
    mp_project_range(lo[k].y, hi[k].y, dl, dh, f.ay, f.by, f.ortho, &l, &h);
    b.ymin = fmin(b.ymin, l);
    b.ymax = fmax(b.ymax, h);
  }
  return b;
}

/* Screen lengths of the net along u (max over rows) and v (max over columns). */
MP_INLINE void mp_net_screen_lengths(const float3* lo, const float3* hi, FrameParams f, float* lu, float* lv) {
  float2 q[16];
  for (int k = 0; k < 16; ++k) q[k] = mp_project(0.5f * (lo[k] + hi[k]), f);
  float mu = 0.0f, mv = 0.0f;
  for (int j = 0; j < 4; ++j) {
    float su = 0.0f, sv = 0.0f;
    for (int i = 0; i < 3; ++i) {
      float2 du = q[4 * j + i + 1] - q[4 * j + i];
      float2 dv = q[4 * (i + 1) + j] - q[4 * i + j];
      su += sqrt(du.x * du.x + du.y * du.y);
      sv += sqrt(dv.x * dv.x + dv.y * dv.y);
    }
    mu = fmax(mu, su);
    mv = fmax(mv, sv);
  }
  *lu = mu;
  *lv = mv;
}

/* Camera-space lengths of the net, for splitting patches that straddle the eye plane. */
MP_INLINE void mp_net_space_lengths(const float3* lo, const float3* hi, float* lu, float* lv) {
  float mu = 0.0f, mv = 0.0f;
  for (int j = 0; j < 4; ++j) {
    float su = 0.0f, sv = 0.0f;
    for (int i = 0; i < 3; ++i) {
      su += length(0.5f * (lo[4 * j + i + 1] + hi[4 * j + i + 1] - lo[4 * j + i] - hi[4 * j + i]));
      sv += length(0.5f * (lo[4 * (i + 1) + j] + hi[4 * (i + 1) + j] - lo[4 * i + j] - hi[4 * i + j]));
    }
    mu = fmax(mu, su);
    mv = fmax(mv, sv);
  }
  *lu = mu;
  *lv = mv;
}

MP_INLINE uint mp_grid_rate(float screen_length, FrameParams f) {
  float n = ceil(screen_length / f.micropoly_edge);
  return (uint)clamp(n, 1.0f, (float)f.max_grid);
}

/* The bound & split decision for one sub-patch: cull, dice (with grid size)
 * or split along the longer parametric direction. A pure function of its
 * inputs, so every bound & split strategy reaches the same diced set. */
MP_INLINE uint mp_classify(const MP_GLOBAL float4* points, const MP_GLOBAL uint* patch_info, SubPatch sp, FrameParams f) {
  const MP_GLOBAL float4* cp = points + (ulong)sp.patch * MP_PATCH_POINTS;
  float3 lo[16], hi[16];
  mp_subpatch_net_boxes(cp, patch_info[4 * (ulong)sp.patch], sp, lo, hi);
  MpBound b = mp_bound_boxes(lo, hi, f);
  uint depth = MP_INFO_DEPTH(sp.info);
  int can_split = (int)depth < f.max_depth;

  if (b.dmax < f.clip_near || b.dmin > f.clip_far) return MP_CULL;
  if (!f.ortho && b.dmin <= f.eye_epsilon) {
    /* Straddles the eye plane: no screen bound exists. Split, or give up. */
    if (!can_split) return MP_CULL;
    float lu, lv;
    mp_net_space_lengths(lo, hi, &lu, &lv);
    return lu >= lv ? MP_SPLIT_U : MP_SPLIT_V;
  }
  if (b.xmax < -f.ribbon || b.ymax < -f.ribbon || b.xmin > (float)f.width + f.ribbon ||
      b.ymin > (float)f.height + f.ribbon)
    return MP_CULL;

  float lu, lv;
  mp_net_screen_lengths(lo, hi, f, &lu, &lv);
  float limit = (float)f.max_grid * f.micropoly_edge;
  if ((lu > limit || lv > limit) && can_split) return lu >= lv ? MP_SPLIT_U : MP_SPLIT_V;
  return MP_DICE | (mp_grid_rate(lu, f) << 8) | (mp_grid_rate(lv, f) << 16);
}

MP_INLINE void mp_split(SubPatch sp, uint action, SubPatch* a, SubPatch* b) {
  uint info = MP_MAKE_INFO(MP_INFO_DEPTH(sp.info) + 1u, 0u, 0u);
  *a = sp;
  *b = sp;
  a->info = info;
  b->info = info;
  if (action == MP_SPLIT_U) {
    float m = 0.5f * (sp.u0 + sp.u1);
    a->u1 = m;
    b->u0 = m;
  } else {
    float m = 0.5f * (sp.v0 + sp.v1);
    a->v1 = m;
    b->v0 = m;
  }
}

#endif
