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

#include "core/mp_compat.h"
#include "geometry/mp_patch.h"
#include "core/mp_types.h"
#include "geometry/mp_patch_eval.h"
#include "geometry/mp_surface.h"
#include "geometry/mp_grid.h" /* mp_corner */
#include "stages/mp_occlusion.h"
#include "stages/mp_blur.h"
#include "stages/mp_raster.h" /* the camera's sample pattern */

#define MP_CULL 0u
#define MP_DICE 1u
#define MP_SPLIT_U 2u
#define MP_SPLIT_V 3u
#define MP_SPLIT_NODE 4u /* a node of an instance's tree of patches opens into its children (mp_instance.h) */

/* Decision word: action in bits 0-7, grid size nu, nv in bits 8-15, 16-23;
 * a cull for occlusion has bit 8 set (counted apart). */
#define MP_DECISION_ACTION(d) ((d) & 0xffu)
#define MP_CULL_OCCLUDED (MP_CULL | 0x100u)

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
MP_INLINE void mp_subpatch_net_boxes(const MP_GLOBAL float4* cp, uint type, float u0, float v0, float u1, float v1,
                                      float3* lo, float3* hi) {
  float Wu[16], Wv[16];
  mp_subsegment_weights(u0, u1, Wu);
  mp_subsegment_weights(v0, v1, Wv);
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

/* Boxes (camera space) holding the sub-patch's net, widened by the patch's
 * displacement bound (mp_patch.h) so that culling and splitting never clip
 * displaced geometry: the sub-patch's surface lies in their convex hull. */
MP_INLINE void mp_subpatch_hull(const MP_GLOBAL float4* cp, uint type, const SubPatch* sp, float3* lo, float3* hi) {
  float u0, v0, u1, v1;
  mp_subpatch_range(sp, &u0, &v0, &u1, &v1);
  mp_subpatch_net_boxes(cp, type, u0, v0, u1, v1, lo, hi);
  float reach = MP_PATCH_DISPLACEMENT_BOUND(cp);
  /* Moving patches: the sub-net at every step lies within the centre's
   * boxes grown by the patch's motion reach (its points are the same convex
   * combinations of control points that each moved at most that far). */
  float3 grow = MP_F3(reach, reach, reach) + MP_PATCH_MOTION_REACH(cp);
  if (grow.x > 0.0f || grow.y > 0.0f || grow.z > 0.0f)
    for (int k = 0; k < 16; ++k) {
      lo[k] -= grow;
      hi[k] += grow;
    }
}

/* Boxes (camera space) holding a ribbon's sub-patch (mp_ribbon.h), as
 * mp_subpatch_hull does for other patches, but placed already: the
 * sub-segment's centre net (blossoming along v), each point grown by the
 * largest placed radius of the segment in every direction, which holds the
 * strip whichever way it turns (by sqrt 2 radii in a light's view, where
 * the strip also moves a radius away from the light). The net is repeated across u (u spans the
 * width, which the radius covers), so its u lengths are zero and a ribbon
 * straddling the eye plane is cut along its length. */
MP_INLINE void mp_ribbon_hull(const MP_GLOBAL float4* cp, const SubPatch* sp, const MpPlacement* place, float3* lo,
                              float3* hi) {
  float u0, v0, u1, v1;
  mp_subpatch_range(sp, &u0, &v0, &u1, &v1);
  float Wv[16];
  mp_subsegment_weights(v0, v1, Wv);
  float r = 0.0f;
  for (int j = 0; j < 4; ++j) r = fmax(r, mp_ribbon_radius(cp, j, place));
  if (place->push > 0.0f) r *= 1.41422f;
  float reach = MP_PATCH_DISPLACEMENT_BOUND(cp);
  float3 grow = MP_F3(r + reach, r + reach, r + reach) + MP_PATCH_MOTION_REACH(cp);
  for (int l = 0; l < 4; ++l) {
    float3 c = MP_F3(0.0f, 0.0f, 0.0f);
    for (int j = 0; j < 4; ++j) c += Wv[4 * l + j] * MP_XYZ(cp[4 * j]);
    c = mp_place_point(place, c);
    for (int i = 0; i < 4; ++i) {
      lo[4 * l + i] = c - grow;
      hi[4 * l + i] = c + grow;
    }
  }
}

/* A camera-space point in the view's space (FrameParams.view). */
MP_INLINE float3 mp_to_view(float3 p, FrameParams f) {
  if (!f.has_view) return p;
  const float* m = f.view;
  return MP_F3(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
               m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
}

/* Raster position of a view-space point (d > 0 for perspective views). */
MP_INLINE float2 mp_project_view(float3 v, FrameParams f) {
  float inv = f.ortho ? 1.0f : 1.0f / (-v.z);
  return MP_F2(f.ax * v.x * inv + f.bx, f.ay * v.y * inv + f.by);
}

/* The same without the raster's offset: differences of these are raster
 * lengths that do not depend on where the raster's origin lies (a bucket's,
 * buckets.h, or the whole frame's), so a sub-patch gets the same rates in
 * every bucket. */
MP_INLINE float2 mp_project_view_unplaced(float3 v, FrameParams f) {
  float inv = f.ortho ? 1.0f : 1.0f / (-v.z);
  return MP_F2(f.ax * v.x * inv, f.ay * v.y * inv);
}

/* Raster position of a camera-space point in the view. */
MP_INLINE float2 mp_project(float3 p, FrameParams f) { return mp_project_view(mp_to_view(p, f), f); }

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

/* Camera-space boxes [lo[k], hi[k]] as boxes of the view's space: each
 * box's centre moves, its half extents go through |rotation| (exact for
 * boxes that are points, as Bezier nets' are). */
MP_INLINE void mp_boxes_to_view(float3* lo, float3* hi, int count, FrameParams f) {
  if (!f.has_view) return;
  const float* m = f.view;
  for (int k = 0; k < count; ++k) {
    float3 c = mp_to_view(0.5f * (lo[k] + hi[k]), f), h = 0.5f * (hi[k] - lo[k]);
    float3 e = MP_F3(fabs(m[0]) * h.x + fabs(m[1]) * h.y + fabs(m[2]) * h.z,
                     fabs(m[4]) * h.x + fabs(m[5]) * h.y + fabs(m[6]) * h.z,
                     fabs(m[8]) * h.x + fabs(m[9]) * h.y + fabs(m[10]) * h.z);
    lo[k] = c - e;
    hi[k] = c + e;
  }
}

/* Raster/depth bound of view-space boxes. Only meaningful when dmin > 0 (or ortho). */
MP_INLINE MpBound mp_bound_boxes(const float3* lo, const float3* hi, int count, FrameParams f) {
  MpBound b;
  b.dmin = 3.0e38f;
  b.dmax = -3.0e38f;
  for (int k = 0; k < count; ++k) {
    b.dmin = fmin(b.dmin, -hi[k].z);
    b.dmax = fmax(b.dmax, -lo[k].z);
  }
  b.xmin = b.ymin = 3.0e38f;
  b.xmax = b.ymax = -3.0e38f;
  if (!f.ortho && b.dmin <= f.eye_epsilon) return b;
  for (int k = 0; k < count; ++k) {
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

/* A plane that view-space boxes lie beyond (mp_occlusion.h,
 * mp_plane_near_depth): every point p of them, and so of the sub-patch
 * whose net they bound and of every micropolygon diced from it, has
 * dot(n, p) >= h, h the least of that linear function over the boxes. n is
 * the net's normal, from its diagonals between the corner boxes of a 4 x 4
 * net (16 boxes), or the direction to a single box; it faces away from the
 * eye. Zero where it would tell nothing beyond the nearest depth (a single
 * box seen orthographically, a normal that vanishes). */
MP_INLINE float4 mp_net_plane(const float3* lo, const float3* hi, int count, FrameParams f) {
  float3 g = MP_F3(0.0f, 0.0f, 0.0f);
  for (int k = 0; k < count; ++k) g += 0.5f * (lo[k] + hi[k]);
  g = g / (float)count;
  float3 n;
  if (count == 16) {
    float3 d1 = 0.5f * (lo[15] + hi[15] - lo[0] - hi[0]), d2 = 0.5f * (lo[12] + hi[12] - lo[3] - hi[3]);
    n = cross(d1, d2);
  } else {
    if (f.ortho) return MP_F4(0.0f, 0.0f, 0.0f, 0.0f);
    n = g;
  }
  float len = length(n);
  if (!(len > 0.0f)) return MP_F4(0.0f, 0.0f, 0.0f, 0.0f);
  n = n / len;
  if (f.ortho ? n.z > 0.0f : dot(n, g) < 0.0f) n = -n;
  float3 an = fabs(n);
  float h = 3.0e38f, size = 0.0f;
  for (int k = 0; k < count; ++k) {
    float3 c = 0.5f * (lo[k] + hi[k]), e = 0.5f * (hi[k] - lo[k]);
    float along = dot(n, c), reach = dot(an, e);
    h = fmin(h, along - reach);
    size = fmax(size, fabs(along) + reach);
  }
  /* Rounding of the products above, relative to their size. */
  return MP_F4(n.x, n.y, n.z, h - size * (1.0f / 16384.0f));
}

/* Occlusion culling tests sub-patches against their plane as well as
 * their nearest depth where the stages are built with MP_OCCLUSION_PLANES:
 * on CPU devices (DeviceSession), which take the roots in waves and so cull
 * much. A GPU takes the roots at once and culls little; there the planes
 * cost more than they save (docs/performance.md, "Planes for occlusion
 * culling"), and a zero plane leaves the test the nearest depth's. */
#ifdef MP_OCCLUSION_PLANES
#define MP_CULLING_PLANE(lo, hi, count, f) mp_net_plane(lo, hi, count, f)
#else
#define MP_CULLING_PLANE(lo, hi, count, f) MP_F4(0.0f, 0.0f, 0.0f, 0.0f)
#endif

/* Camera-space lengths of the net along u and v: the split direction for a
 * sub-patch that straddles the eye plane, where screen lengths do not exist. */
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

/* ---- Dicing rates per edge (DiagSplit, Fisher et al. 2009) ----------------
 *
 * Every edge of a sub-patch gets its own rate from its own screen length, and
 * that rate is a function of the edge alone: the two sub-patches (or
 * patches) sharing an edge measure it from the same points in the same order
 * and reach the same rate, whatever their other edges or split depths. An
 * edge too long to dice is split at its midpoint, and a sub-patch is diced
 * only once all four of its edges have rates, so both sides of an edge cut it
 * at the same points and place the same vertices along it (mp_surface.h).
 *
 * Rates are powers of two, the nearest to the edge's length over the target
 * micropolygon edge (sqrt of the shading rate), so micropolygon edges run
 * between 0.71 and 1.41 times the target. Powers of two keep every split
 * point and every edge vertex a binary fraction that float holds exactly,
 * which is what makes shared vertices bit-identical from both sides; it also
 * makes a rated edge divisible: splitting a sub-patch across an edge of rate
 * n >= 2 cuts it at its middle vertex into two edges of rate n/2. An edge of
 * rate 1 has no middle vertex: the cut runs through its first corner instead
 * and one child becomes a triangle (a quad with one zero-length edge). Only
 * that case makes the cut line diagonal in (u, v). */

/* Sub-patch edges are measured with this many straight segments. */
#define MP_EDGE_SEGMENTS 4
/* A length that cannot be measured: the edge crosses the eye plane, or spans
 * both halves of a transition edge (mp_patch.h) and must be cut at its middle. */
#define MP_UNMEASURABLE -1.0f

MP_INLINE int mp_view_point_usable(float3 v, FrameParams f) { return f.ortho || -v.z > f.eye_epsilon; }

/* Screen length of a camera-space polyline in the view; the points are
 * left in the view's space. */
MP_INLINE float mp_polyline_screen_length(float3* p, int count, FrameParams f) {
  float len = 0.0f;
  for (int k = 0; k < count; ++k) {
    p[k] = mp_to_view(p[k], f);
    if (!mp_view_point_usable(p[k], f)) return MP_UNMEASURABLE;
  }
  for (int k = 0; k + 1 < count; ++k) {
    float2 d = mp_project_view_unplaced(p[k + 1], f) - mp_project_view_unplaced(p[k], f);
    len += sqrt(d.x * d.x + d.y * d.y);
  }
  /* Out of focus, the target edge grows with the circle of confusion of the
   * line's sharpest point (RenderMan's focus factor): a function of the
   * line alone, so both sides of a shared edge still agree. */
  if (mp_lens_on(f)) {
    float coc = 3.0e38f;
    for (int k = 0; k < count; ++k) coc = fmin(coc, mp_coc_diameter(f, -p[k].z));
    len *= f.micropoly_edge / fmax(f.micropoly_edge, f.dof_dice_factor * coc);
  }
  return len;
}

/* Screen length of the sub-patch edge a -> b of patch `patch`, measured from
 * a canonical direction: along the shared curve's own parameter for an edge
 * on the patch boundary, else from the lexicographically smaller end. */
MP_INLINE float mp_edge_screen_length(const MP_GLOBAL float4* points, const MP_GLOBAL uint* patch_info,
                                      const MP_GLOBAL uint* edges, const MP_GLOBAL float4* curves, uint patch,
                                      float2 a, float2 b, FrameParams f, const MpPlacement* place) {
  float3 p[MP_EDGE_SEGMENTS + 1];
  int e = a.y == 0.0f && b.y == 0.0f ? 0 : a.x == 1.0f && b.x == 1.0f ? 1 : a.y == 1.0f && b.y == 1.0f ? 2
        : a.x == 0.0f && b.x == 0.0f ? 3 : -1;
  uint type = patch_info[4 * (ulong)patch];
  if (type == MP_PATCH_CURVE) e = -1; /* ribbons have no stored edges (mp_surface_point) */
  if (e >= 0) {
    float ta = (e & 1) ? a.y : a.x, tb = (e & 1) ? b.y : b.x;
    const MP_GLOBAL uint* refs = edges + (ulong)patch * MP_EDGE_REFS + 2u * (uint)e;
    uint ref = refs[0];
    if (refs[1] != MP_NO_CURVE) {
      if (fmax(ta, tb) <= 0.5f) {
        ta *= 2.0f, tb *= 2.0f;
      } else if (fmin(ta, tb) >= 0.5f) {
        ta = 2.0f * ta - 1.0f, tb = 2.0f * tb - 1.0f, ref = refs[1];
      } else {
        return MP_UNMEASURABLE;
      }
    }
    if (ref & 1u) ta = 1.0f - ta, tb = 1.0f - tb;
    float lo = fmin(ta, tb), hi = fmax(ta, tb);
    for (int k = 0; k <= MP_EDGE_SEGMENTS; ++k)
      p[k] = mp_curve_point(curves, ref & ~1u, lo + (hi - lo) * ((float)k / (float)MP_EDGE_SEGMENTS));
  } else {
    int swap = b.x < a.x || (b.x == a.x && b.y < a.y);
    float2 lo = swap ? b : a, hi = swap ? a : b;
    const MP_GLOBAL float4* cp = points + (ulong)patch * MP_PATCH_POINTS;
    for (int k = 0; k <= MP_EDGE_SEGMENTS; ++k) {
      float2 uv = lo + (hi - lo) * ((float)k / (float)MP_EDGE_SEGMENTS);
      float3 du, dv;
      mp_eval_placed(cp, type, uv.x, uv.y, place, &p[k], &du, &dv);
    }
  }
  if (e >= 0)
    for (int k = 0; k <= MP_EDGE_SEGMENTS; ++k) p[k] = mp_place_point(place, p[k]);
  return mp_polyline_screen_length(p, MP_EDGE_SEGMENTS + 1, f);
}

/* Rate code (1 + log2 rate) for an edge of `len` pixels; 0 when the edge is
 * longer than the largest grid allows (or unmeasurable) and must be split. */
MP_INLINE uint mp_edge_rate_code(float len, FrameParams f) {
  if (!(len >= 0.0f)) return 0u;
  float x = len / f.micropoly_edge;
  uint code = 1u, n = 1u;
  while (x > 1.41421356f * (float)n) {
    n *= 2u;
    ++code;
    if (n > (uint)f.max_grid) return 0u;
  }
  return code;
}


/* Screen length through the middle of the sub-patch, from the middle of edge
 * 3 to the middle of edge 1 (dir 0) or of edge 0 to edge 2 (dir 1): the
 * interior's own size, which may exceed its edges' (a bulge, or a patch with
 * collapsed edges). *chord is the line's end minus its start on screen. Only
 * this sub-patch uses it, so it needs no canonical order. */
MP_INLINE float mp_mid_screen_length(const MP_GLOBAL float4* cp, uint type, const SubPatch* sp, int dir, FrameParams f,
                                     float2* chord, const MpPlacement* place) {
  float2 c0 = mp_corner(sp, 0), c1 = mp_corner(sp, 1), c2 = mp_corner(sp, 2), c3 = mp_corner(sp, 3);
  float2 a = dir == 0 ? 0.5f * (c3 + c0) : 0.5f * (c0 + c1);
  float2 b = dir == 0 ? 0.5f * (c1 + c2) : 0.5f * (c2 + c3);
  float3 p[MP_EDGE_SEGMENTS + 1];
  for (int k = 0; k <= MP_EDGE_SEGMENTS; ++k) {
    float2 uv = a + (b - a) * ((float)k / (float)MP_EDGE_SEGMENTS);
    float3 du, dv;
    mp_eval_placed(cp, type, uv.x, uv.y, place, &p[k], &du, &dv);
  }
  float len = mp_polyline_screen_length(p, MP_EDGE_SEGMENTS + 1, f);
  *chord = len >= 0.0f ? mp_project_view_unplaced(p[MP_EDGE_SEGMENTS], f) - mp_project_view_unplaced(p[0], f)
                        : MP_F2(0.0f, 0.0f);
  return len;
}

/* Longest a micropolygon edge may grow, in target edges, where the interior
 * is diced by area (below). */
#define MP_SHEAR_STRETCH 2.0f

/* Interior grid rates (nu, nv) of a sub-patch to dice: its mid-line lengths
 * over the target edge, within the largest grid. Where the sub-patch's
 * iso-lines cross at an angle theta on screen (a surface seen towards its
 * vanishing point), a grid rated by lengths alone would make micropolygons of
 * sin(theta) times the target area. RenderMan's shading rate is an area, so
 * the longer direction is diced more coarsely by sin(theta), but by no more
 * than MP_SHEAR_STRETCH, which bounds how long a micropolygon gets. A grid
 * one micropolygon across with rate-1 edges on that side becomes a single
 * strip (mp_grid.h); any other grid keeps at least 2 x 2 so its edges can be
 * stitched to an interior. */
MP_INLINE void mp_interior_rates(float mid_u, float mid_v, float2 chord_u, float2 chord_v, const uint* codes,
                                 FrameParams f, uint* nu, uint* nv) {
  float lu = sqrt(chord_u.x * chord_u.x + chord_u.y * chord_u.y);
  float lv = sqrt(chord_v.x * chord_v.x + chord_v.y * chord_v.y);
  if (mid_u > 0.0f && mid_v > 0.0f && lu > 0.0f && lv > 0.0f) {
    float sin_theta = fabs(chord_u.x * chord_v.y - chord_u.y * chord_v.x) / (lu * lv);
    float k = fmax(sin_theta, 1.0f / MP_SHEAR_STRETCH);
    if (mid_u >= mid_v) mid_u *= k;
    else mid_v *= k;
  }
  float mg = (float)f.max_grid;
  uint iu = (uint)clamp(mid_u >= 0.0f ? ceil(mid_u / f.micropoly_edge) : 1.0f, 1.0f, mg);
  uint iv = (uint)clamp(mid_v >= 0.0f ? ceil(mid_v / f.micropoly_edge) : 1.0f, 1.0f, mg);
  if (iv == 1u && codes[1] == 1u && codes[3] == 1u) {
    *nu = iu, *nv = 1u;
  } else if (iu == 1u && codes[0] == 1u && codes[2] == 1u) {
    *nu = 1u, *nv = 2u;
  } else {
    *nu = max(iu, min(2u, (uint)f.max_grid)), *nv = max(iv, min(2u, (uint)f.max_grid));
  }
}

/* Whether a shadow view renders any page under the raster rectangle: its
 * page mask pyramid (levels of side, side / 2, ... 1 bytes per side, each
 * byte set where a page below it is rendered) is read at the level where
 * the rectangle spans at most two cells per axis. */
MP_INLINE int mp_page_mask_overlaps(const MP_GLOBAL uchar* mask, int side, float xmin, float ymin, float xmax,
                                    float ymax) {
  float last = (float)(side * 128 - 1);
  int x0 = (int)(fmin(fmax(xmin, 0.0f), last)) >> 7, x1 = (int)(fmin(fmax(xmax, 0.0f), last)) >> 7;
  int y0 = (int)(fmin(fmax(ymin, 0.0f), last)) >> 7, y1 = (int)(fmin(fmax(ymax, 0.0f), last)) >> 7;
  uint offset = 0u;
  int k = 0, n = side;
  while ((x1 >> k) - (x0 >> k) > 1 || (y1 >> k) - (y0 >> k) > 1) {
    offset += (uint)(n * n);
    n >>= 1;
    ++k;
  }
  for (int y = y0 >> k; y <= y1 >> k; ++y)
    for (int x = x0 >> k; x <= x1 >> k; ++x)
      if (mask[offset + (uint)(y * n + x)]) return 1;
  return 0;
}

/* Largest a * x + c * d over view-space boxes (d = -z), for a side plane
 * of a perspective view's frustum through the eye. */
MP_INLINE float mp_boxes_plane_max(const float3* lo, const float3* hi, int count, float a, float c) {
  float m = -3.0e38f;
  for (int k = 0; k < count; ++k)
    m = fmax(m, fmax(a * lo[k].x, a * hi[k].x) + fmax(-c * hi[k].z, -c * lo[k].z));
  return m;
}

/* Whether view-space boxes lie wholly outside one side of a perspective
 * view's frustum (plus the ribbon): the side planes pass through the eye, so
 * the test holds for boxes that reach behind it too, which the raster bound
 * cannot judge. rx >= -r is ax x + (bx + r) d >= 0, rx <= w + r is
 * (w + r - bx) d - ax x >= 0, and likewise in y. */
MP_INLINE int mp_boxes_beside_frustum(const float3* lo, const float3* hi, int count, FrameParams f) {
  float r = f.ribbon;
  /* A lens widens the frustum into the union of those of its points. */
  float sx = 0.0f, sy = 0.0f;
  if (mp_lens_on(f)) {
    float dmin = 3.0e38f, dmax = -3.0e38f;
    for (int k = 0; k < count; ++k) dmin = fmin(dmin, -hi[k].z), dmax = fmax(dmax, -lo[k].z);
    sx = mp_lens_plane_slack(f, f.ax, f.lens_radius * f.lens_x_scale, dmin, dmax);
    sy = mp_lens_plane_slack(f, f.ay, f.lens_radius, dmin, dmax);
  }
  return mp_boxes_plane_max(lo, hi, count, f.ax, f.bx + r) + sx < 0.0f ||
         mp_boxes_plane_max(lo, hi, count, -f.ax, (float)f.width + r - f.bx) + sx < 0.0f ||
         mp_boxes_plane_max(lo, hi, count, f.ay, f.by + r) + sy < 0.0f ||
         mp_boxes_plane_max(lo, hi, count, -f.ay, (float)f.height + r - f.by) + sy < 0.0f;
}

/* Bounds at most this many pixels across are tested against the view's
 * samples: few enough to enumerate, and what a distant instance's subtree
 * or a sub-pixel patch shrinks to. */
#define MP_SAMPLE_TEST_SPAN 2.0f

/* Whether the raster rectangle holds none of the view's samples
 * (FrameParams.samples), so that nothing inside it can be sampled: a tree
 * of patches far smaller than a pixel (a distant instance) is then dropped
 * where it falls between samples, not diced a patch at a time. The
 * rectangle is widened by a few sub-pixel steps for the rounding between
 * this bound and the sampler's fixed-point vertices; a wider rectangle, or
 * a view whose grids serve more than its samples, is never culled here. The
 * samples are the camera's pattern (mp_sample_offset_packed, the table
 * the samplers read) or texel centres (shadow maps, shadow_sample). */
MP_INLINE int mp_bound_misses_samples(float xmin, float ymin, float xmax, float ymax, FrameParams f) {
  if (f.samples == MP_SAMPLES_UNKNOWN || !(xmax - xmin <= MP_SAMPLE_TEST_SPAN) ||
      !(ymax - ymin <= MP_SAMPLE_TEST_SPAN))
    return 0;
  const float one = (float)MP_SUBPIXEL_ONE, margin = 4.0f;
  float lx = floor(xmin * one) - margin, hx = ceil(xmax * one) + margin;
  float ly = floor(ymin * one) - margin, hy = ceil(ymax * one) + margin;
  int px0 = (int)floor(lx / one), px1 = (int)floor(hx / one);
  int py0 = (int)floor(ly / one), py1 = (int)floor(hy / one);
  int spp = f.samples == MP_SAMPLES_CENTRES ? 1 : f.spp_x * f.spp_y;
  for (int py = py0; py <= py1; ++py)
    for (int px = px0; px <= px1; ++px)
      for (int s = 0; s < spp; ++s) {
        uint o = f.samples == MP_SAMPLES_CENTRES
                     ? (uint)(MP_SUBPIXEL_ONE / 2) * 0x101u
                     : mp_sample_offset_packed((px + f.crop_x0) & (MP_SAMPLE_TILE - 1),
                                               (py + f.crop_y0) & (MP_SAMPLE_TILE - 1), s, f);
        float x = (float)px * one + (float)(o & 0xffu), y = (float)py * one + (float)(o >> 8);
        if (x >= lx && x <= hx && y >= ly && y <= hy) return 0;
      }
  return 1;
}

/* Whether view-space boxes with bound b lie outside the view: beyond its
 * clipping planes, beside its frustum, outside its frame (plus the ribbon),
 * or (shadow views) outside every page it renders; boxes that reach the eye
 * plane inside the frustum are kept while they can still be split. */
MP_INLINE int mp_bound_culled(MpBound b, const float3* lo, const float3* hi, int count, FrameParams f,
                              const MP_GLOBAL uchar* page_masks, int can_split) {
  if (b.dmax < f.clip_near || b.dmin > f.clip_far) return 1;
  int straddles = !f.ortho && b.dmin <= f.eye_epsilon;
  if (straddles) return !can_split || mp_boxes_beside_frustum(lo, hi, count, f);
  /* Seen through a lens, a point may land anywhere in its circle of confusion. */
  float rx = f.ribbon + mp_lens_slack_x(f, b.dmin, b.dmax), ry = f.ribbon + mp_lens_slack_y(f, b.dmin, b.dmax);
  if (b.xmax < -rx || b.ymax < -ry || b.xmin > (float)f.width + rx || b.ymin > (float)f.height + ry) return 1;
  float sx = rx - f.ribbon, sy = ry - f.ribbon; /* the lens's reach */
  if (mp_bound_misses_samples(b.xmin - sx, b.ymin - sy, b.xmax + sx, b.ymax + sy, f)) return 1;
  return f.view_kind == MP_VIEW_SHADOW && page_masks &&
         !mp_page_mask_overlaps(page_masks + f.page_mask, f.page_side, b.xmin - f.ribbon, b.ymin - f.ribbon,
                                b.xmax + f.ribbon, b.ymax + f.ribbon);
}

/* The bound & split decision for one sub-patch: cull, dice (with grid size)
 * or split across edges 0 and 2 (MP_SPLIT_U) or 1 and 3 (MP_SPLIT_V). Rates of
 * edges measured here are stored into *sp for its children or its dicing. A
 * pure function of its inputs, so every bound & split strategy reaches the
 * same diced set, less what the occlusion pyramid (occ.levels > 0; the
 * camera's view) shows hidden by what is already sampled (MP_CULL_OCCLUDED).
 * The view is f's (the camera or a shadow map); shadow views also cull what
 * lies under none of their rendered pages (page_masks). */
/* The box test of mp_classify for a camera-space box: cull, occluded, or 0. */
MP_INLINE uint mp_classify_box(float3 blo, float3 bhi, FrameParams f, const MP_GLOBAL uchar* page_masks,
                               const MP_GLOBAL uint* occlusion, OcclusionParams occ, int can_split) {
  mp_boxes_to_view(&blo, &bhi, 1, f);
  MpBound bb = mp_bound_boxes(&blo, &bhi, 1, f);
  if (mp_bound_culled(bb, &blo, &bhi, 1, f, page_masks, can_split)) return MP_CULL;
  /* A box that straddles the eye plane has no raster rectangle (an empty
   * one would read as hidden everywhere): only its sub-patches are tested. */
  int straddles = !f.ortho && bb.dmin <= f.eye_epsilon;
  if (!straddles && occ.levels > 0 &&
      mp_occluded(occlusion, occ, f, bb.xmin, bb.ymin, bb.xmax, bb.ymax, bb.dmin, MP_CULLING_PLANE(&blo, &bhi, 1, f)))
    return MP_CULL_OCCLUDED;
  return 0u;
}

/* Grows camera-space boxes by an instance's motion reach (mp_types.h). */
MP_INLINE void mp_grow_boxes(float3* lo, float3* hi, int count, float3 grow) {
  if (grow.x > 0.0f || grow.y > 0.0f || grow.z > 0.0f)
    for (int k = 0; k < count; ++k) {
      lo[k] -= grow;
      hi[k] += grow;
    }
}

/* A sub-patch that is a node of an instance's tree (mp_instance.h): culled
 * when its box, carried into the view by the instance (and grown by its
 * motion), is; else opened (MP_SPLIT_NODE), its children stored in *sp for
 * mp_split. The tree's root is met through the instance's own box, which
 * follows its motion step by step. Ray visibility is the instance's: a
 * prototype's patches may still differ below. */
MP_INLINE uint mp_classify_node(const MP_GLOBAL DevicePatchNode* nodes, const MP_GLOBAL DeviceInstance* instances,
                                SubPatch* sp, FrameParams f, const MP_GLOBAL uchar* page_masks,
                                const MP_GLOBAL uint* occlusion, OcclusionParams occ) {
  const MP_GLOBAL DeviceInstance* in = instances + sp->instance;
  if (in->flags & (f.view_kind == MP_VIEW_SHADOW ? MP_PATCH_NO_SHADOW : MP_PATCH_NO_CAMERA)) return MP_CULL;
  const MP_GLOBAL DevicePatchNode* node = nodes + MP_NODE_INDEX(sp->patch);
  float3 lo, hi;
  if (sp->patch == in->root) {
    lo = MP_F3(in->box_lo[0], in->box_lo[1], in->box_lo[2]);
    hi = MP_F3(in->box_hi[0], in->box_hi[1], in->box_hi[2]);
  } else {
    MpPlacement place = mp_instance_placement(instances, sp->instance);
    lo = MP_F3(node->lo[0], node->lo[1], node->lo[2]);
    hi = MP_F3(node->hi[0], node->hi[1], node->hi[2]);
    mp_place_boxes(&place, &lo, &hi, 1);
    mp_grow_boxes(&lo, &hi, 1, MP_F3(in->reach[0], in->reach[1], in->reach[2]));
  }
  uint d = mp_classify_box(lo, hi, f, page_masks, occlusion, occ, 1);
  if (d) return d;
  mp_node_store_children(sp, node);
  return MP_SPLIT_NODE;
}

MP_INLINE uint mp_classify(const MP_GLOBAL float4* points, const MP_GLOBAL uint* patch_info,
                           const MP_GLOBAL uint* edges, const MP_GLOBAL float4* curves,
                           const MP_GLOBAL float4* patch_bounds, const MP_GLOBAL DeviceInstance* instances,
                           const MP_GLOBAL DevicePatchNode* nodes, SubPatch* sp, FrameParams f,
                           const MP_GLOBAL uchar* page_masks, const MP_GLOBAL uint* occlusion, OcclusionParams occ) {
  if (MP_IS_NODE(sp->patch)) return mp_classify_node(nodes, instances, sp, f, page_masks, occlusion, occ);
  const MP_GLOBAL float4* cp = points + (ulong)sp->patch * MP_PATCH_POINTS;
  uint type = patch_info[4 * (ulong)sp->patch];
  /* Ray visibility: objects hidden from the camera still cast shadows, and
   * objects that cast none stay out of the lights' views. */
  uint flags = mp_placed_flags(patch_info, instances, sp->patch, sp->instance);
  if (flags & (f.view_kind == MP_VIEW_SHADOW ? MP_PATCH_NO_SHADOW : MP_PATCH_NO_CAMERA)) return MP_CULL;
  uint depth = MP_INFO_DEPTH(sp->info);
  int can_split = (int)depth < f.max_depth;
  MpPlacement place = mp_instance_placement(instances, sp->instance);
  mp_place_facing(&place, f);
  float3 reach = MP_F3(0.0f, 0.0f, 0.0f);
  if (sp->instance != MP_NO_INSTANCE)
    reach = MP_F3(instances[sp->instance].reach[0], instances[sp->instance].reach[1], instances[sp->instance].reach[2]);
  /* Whole patches meet the view through their box first: a pass over many
   * views (shadow maps) sees most patches outside most views, and a box is
   * far cheaper to bound than the net. */
  if (depth == 0u && patch_bounds) {
    float3 blo = MP_XYZ(patch_bounds[2 * (ulong)sp->patch]), bhi = MP_XYZ(patch_bounds[2 * (ulong)sp->patch + 1]);
    mp_place_boxes(&place, &blo, &bhi, 1);
    mp_grow_boxes(&blo, &bhi, 1, reach);
    uint d = mp_classify_box(blo, bhi, f, page_masks, occlusion, occ, can_split);
    if (d) return d;
  }
  float3 lo[16], hi[16];
  if (type == MP_PATCH_CURVE) {
    mp_ribbon_hull(cp, sp, &place, lo, hi);
  } else {
    mp_subpatch_hull(cp, type, sp, lo, hi);
    mp_place_boxes(&place, lo, hi, 16);
  }
  mp_grow_boxes(lo, hi, 16, reach);
  mp_boxes_to_view(lo, hi, 16, f);
  MpBound b = mp_bound_boxes(lo, hi, 16, f);
  if (mp_bound_culled(b, lo, hi, 16, f, page_masks, can_split)) return MP_CULL;
  int straddles = !f.ortho && b.dmin <= f.eye_epsilon;
  if (!straddles && occ.levels > 0 &&
      mp_occluded(occlusion, occ, f, b.xmin, b.ymin, b.xmax, b.ymax, b.dmin, MP_CULLING_PLANE(lo, hi, 16, f)))
    return MP_CULL_OCCLUDED;

  /* Rate every edge that has none yet; score = length in target edges. */
  int round = (flags & MP_PATCH_ROUND_U) != 0;
  uint round_code = mp_edge_rate_code(0.0f, f);
  while (round && MP_CODE_RATE(round_code) < MP_ROUND_MIN_RATE && MP_CODE_RATE(round_code) < (uint)f.max_grid)
    ++round_code;
  /* Ribbons (mp_ribbon.h) thinner than the target micropolygon: RenderMan's
   * shading rate is an area, so along the strand their micropolygons may
   * grow by as much as the strand is thin, up to MP_SHEAR_STRETCH, as a
   * sheared grid's may (mp_interior_rates). Only a ribbon's sides are
   * stretched, which no other patch shares (its ends, which the next
   * segment shares, keep their own rate). Across is the direction of the
   * patch's u (the split corners may turn it). */
  float stretch = 1.0f;
  int across = mp_edge_runs_along_u(sp, 0) ? 0 : 1; /* mid-line direction across the strand */
  if (type == MP_PATCH_CURVE && !straddles) {
    float2 chord;
    float width = mp_mid_screen_length(cp, type, sp, across, f, &chord, &place);
    if (width >= 0.0f) stretch = clamp(f.micropoly_edge / fmax(width, 1e-6f), 1.0f, MP_SHEAR_STRETCH);
  }
  uint codes[4];
  float score[4];
  int any_long = 0;
  for (int e = 0; e < 4; ++e) {
    uint code = MP_EDGE_CODE(sp->rates, e);
    float len = 0.0f;
    if (code == 0u) {
      len = mp_edge_screen_length(points, patch_info, edges, curves, sp->patch, mp_corner(sp, e), mp_corner(sp, e + 1), f,
                                  &place);
      if (stretch > 1.0f && len > 0.0f && (e & 1) != across) len /= stretch;
      code = mp_edge_rate_code(len, f);
      if (round && code && mp_edge_runs_along_u(sp, e)) code = max(code, round_code);
      sp->rates |= code << (8u * (uint)e);
    }
    codes[e] = code;
    score[e] = code ? (float)MP_CODE_RATE(code) : len >= 0.0f ? len / f.micropoly_edge : 3.0e38f;
    any_long |= code == 0u;
  }
  float2 chord_u, chord_v;
  float mid_u = mp_mid_screen_length(cp, type, sp, 0, f, &chord_u, &place);
  float mid_v = mp_mid_screen_length(cp, type, sp, 1, f, &chord_v, &place);
  if (straddles) mid_u = mid_v = MP_UNMEASURABLE;
  if (stretch > 1.0f) {
    if (across == 0 && mid_v > 0.0f) mid_v /= stretch;
    if (across == 1 && mid_u > 0.0f) mid_u /= stretch;
  }
  float limit = 1.41421356f * (float)f.max_grid * f.micropoly_edge;
  int long_u = mid_u > limit, long_v = mid_v > limit;

  if ((any_long || straddles || long_u || long_v) && can_split) {
    float su = fmax(fmax(score[0], score[2]), long_u ? mid_u / f.micropoly_edge : 0.0f);
    float sv = fmax(fmax(score[1], score[3]), long_v ? mid_v / f.micropoly_edge : 0.0f);
    if (straddles) {
      /* Cut the longer side in camera space, which separates what lies
       * behind the eye from what lies in front. For a sub-patch whose corners
       * are not axis-aligned this is the bound's rectangle, a fair guide. */
      float lu, lv;
      mp_net_space_lengths(lo, hi, &lu, &lv);
      int rot = fabs(sp->corner[2] - sp->corner[0]) + fabs(sp->corner[4] - sp->corner[6]) <
                fabs(sp->corner[3] - sp->corner[1]) + fabs(sp->corner[5] - sp->corner[7]);
      su = rot ? lv : lu;
      sv = rot ? lu : lv;
    }
    /* A pair of rate-1 edges cannot be cut (the cut would run along an edge). */
    int ok_u = !(codes[0] == 1u && codes[2] == 1u), ok_v = !(codes[1] == 1u && codes[3] == 1u);
    if (ok_u && (su >= sv || !ok_v)) return MP_SPLIT_U;
    if (ok_v) return MP_SPLIT_V;
  }
  uint nu, nv;
  mp_interior_rates(mid_u, mid_v, chord_u, chord_v, codes, f, &nu, &nv);
  if (round) {
    /* Across u as many as the u edges have, which the round minimum raised
     * (an unrated edge at the depth limit is diced at the largest grid). */
    int e = mp_edge_runs_along_u(sp, 0) ? 0 : 1;
    uint mg = (uint)f.max_grid;
    uint across = max(codes[e] ? MP_CODE_RATE(codes[e]) : mg, codes[e + 2] ? MP_CODE_RATE(codes[e + 2]) : mg);
    if (e == 0) nu = max(nu, across);
    else nv = max(nv, across);
  }
  return MP_DICE | (nu << 8) | (nv << 16);
}

/* Splits across edges 0 and 2 (MP_SPLIT_U) or 1 and 3 (MP_SPLIT_V; done as
 * the same cut on the corners rotated by one, which keeps the orientation). */
MP_INLINE void mp_split(const SubPatch* sp, uint action, SubPatch* a, SubPatch* b) {
  if (action == MP_SPLIT_NODE) { /* its children, whole and unrated, as roots are */
    mp_whole_subpatch(mp_node_child(sp, 0), sp->instance, sp->info & MP_INFO_VIEW_BITS, a);
    mp_whole_subpatch(mp_node_child(sp, 1), sp->instance, sp->info & MP_INFO_VIEW_BITS, b);
    return;
  }
  int rot = action == MP_SPLIT_V ? 1 : 0;
  float2 c[4];
  uint r[4];
  for (int k = 0; k < 4; ++k) {
    c[k] = mp_corner(sp, k + rot);
    r[k] = MP_EDGE_CODE(sp->rates, (k + rot) & 3);
  }
  /* Cut point on edge 0 (c0 -> c1) and on edge 2 (c2 -> c3), and the rate
   * codes of the two parts: a middle vertex, or the first corner of a rate-1 edge. */
  float2 x = r[0] == 1u ? c[0] : 0.5f * (c[0] + c[1]);
  float2 y = r[2] == 1u ? c[3] : 0.5f * (c[2] + c[3]);
  uint x_first = r[0] > 1u ? r[0] - 1u : r[0], x_second = r[0] > 1u ? r[0] - 1u : r[0];
  uint y_first = r[2] > 1u ? r[2] - 1u : r[2], y_second = r[2] > 1u ? r[2] - 1u : r[2];
  float2 ca[4] = {c[0], x, y, c[3]}, cb[4] = {x, c[1], c[2], y};
  uint ra[4] = {x_first, 0u, y_second, r[3]}, rb[4] = {x_second, r[1], y_first, 0u};
  uint info = MP_MAKE_INFO(MP_INFO_DEPTH(sp->info) + 1u, 0u, 0u) | (sp->info & MP_INFO_VIEW_BITS);
  a->patch = b->patch = sp->patch;
  a->instance = b->instance = sp->instance;
  a->info = b->info = info;
  a->rates = b->rates = 0u;
  for (int k = 0; k < 4; ++k) {
    a->corner[2 * k] = ca[k].x, a->corner[2 * k + 1] = ca[k].y;
    b->corner[2 * k] = cb[k].x, b->corner[2 * k + 1] = cb[k].y;
    a->rates |= ra[k] << (8u * (uint)k);
    b->rates |= rb[k] << (8u * (uint)k);
  }
}

#endif
