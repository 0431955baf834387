/* Occlusion culling of sub-patches against a hierarchical max-depth buffer
 * (Greene, Kass & Miller 1993; the hider of RenderMan culls primitives whose
 * bound lies behind its bucket's z-buffer before dicing them; Nanite's HZB).
 *
 * The pyramid is built from the sample buffer itself (occlusion.cl): a cell
 * holds the farthest depth any of its samples has so far, and an empty
 * sample counts as infinitely far. A sub-patch whose nearest depth (its
 * bound's, displacement included) lies beyond that depth in every cell its
 * raster bound touches can win no sample there: each sample keeps the
 * nearest depth it has seen, and depths only decrease. So culling never
 * changes the image, whatever the surfaces: a semi-transparent surface
 * writes only the samples its stochastic coverage keeps (the others stay as
 * they were), and a holdout hides what it hides in the image too. */
#ifndef MP_OCCLUSION_H
#define MP_OCCLUSION_H

#include "core/mp_compat.h"
#include "core/mp_types.h"

/* A sub-patch's nearest depth over a raster rectangle, from a plane it lies
 * beyond: every point p of the sub-patch has dot(n, p) >= h in the view's
 * space (plane = (n, h); mp_net_plane in mp_bound.h), so on the ray through
 * raster (x, y) its depth is at least h / dot(n, (u, v, -1)) for a
 * perspective view (u, v the ray's slopes) and (h - n.x u - n.y v) / -n.z
 * for an orthographic one, bounded over the rectangle by its corners. Where
 * no ray through the rectangle reaches the plane's far side, the sub-patch
 * covers nothing there (+infinity). Tighter than the bound's nearest depth
 * wherever the sub-patch is tilted or curved about the eye (layers seen
 * obliquely, shells around a lamp): each cell gets the depth the sub-patch
 * can have there, not its least anywhere. 0 where the plane tells nothing.
 * A sample's depth is that of a point of a flat micropolygon, a convex
 * combination of points of the sub-patch, so it keeps to the plane too. */
MP_INLINE float mp_plane_near_depth(float4 plane, FrameParams f, float x0, float y0, float x1, float y1) {
  /* A raster unit of margin: the rasteriser snaps vertices to fixed point. */
  x0 -= 1.0f, y0 -= 1.0f, x1 += 1.0f, y1 += 1.0f;
  float ua = (x0 - f.bx) / f.ax, ub = (x1 - f.bx) / f.ax, va = (y0 - f.by) / f.ay, vb = (y1 - f.by) / f.ay;
  float m = fmax(plane.x * ua, plane.x * ub) + fmax(plane.y * va, plane.y * vb);
  if (f.ortho) return plane.z < 0.0f ? (plane.w - m) / -plane.z : 0.0f;
  if (!(plane.w > 0.0f)) return 0.0f;
  float reach = m - plane.z;
  /* Slack for the rounding of the slopes (relative to their size). */
  reach += 1e-6f * (fabs(ua) + fabs(ub) + fabs(va) + fabs(vb) + 1.0f);
  return reach > 0.0f ? plane.w / reach : 3.0e38f;
}

/* The bits of a nearest depth less a relative margin of 2^-16 (rounding
 * between bound and raster), and of the plane's bound less 2^-12 (its
 * slopes' rounding). Depths are positive floats, whose bits order as the
 * floats. */
MP_INLINE uint mp_near_bits(float dmin, float plane_depth) {
  return as_uint(fmax(dmin * (1.0f - 1.0f / 65536.0f), plane_depth * (1.0f - 1.0f / 4096.0f)));
}

/* Shadow views (mp_shadow.h) cull against their own pyramid, laid out as the
 * view's page mask pyramid (mp_bound.h: from f.page_mask, f.page_side
 * pages per side at level 0, halving to one). Level 0 names each page this
 * pass renders (its physical page + 1; 0 for pages it does not render, where
 * nothing is written), whose 8 x 8 cells of 16 x 16 texels hold the farthest
 * depth any of their texels holds so far (MP_SHADOW_EMPTY, +infinity, while
 * one is empty) from o.page_cells on, and whose farthest depth in all is at
 * o.page_farthest + the physical page; every next level holds the farthest of
 * the 2 x 2 below. Texels keep the nearest depth they have seen, as samples
 * do, so a sub-patch whose nearest depth lies beyond that depth everywhere
 * its raster bound touches can change no texel: the maps are the same with
 * culling as without. The rectangle, with a texel of margin, is read at the
 * level where it spans at most two entries per axis, and at level 0 cell by
 * cell (pages are 128 texels wide). */
MP_INLINE int mp_page_occluded(const MP_GLOBAL uint* pyramid, OcclusionParams o, FrameParams f, float xmin,
                               float ymin, float xmax, float ymax, float dmin, float4 plane) {
  if (!(dmin > 0.0f) || (!f.ortho && dmin <= f.eye_epsilon)) return 0;
  float last = (float)(f.page_side * 128 - 1);
  int tx0 = (int)fmin(fmax(xmin - 1.0f, 0.0f), last), tx1 = (int)fmin(fmax(xmax + 1.0f, 0.0f), last);
  int ty0 = (int)fmin(fmax(ymin - 1.0f, 0.0f), last), ty1 = (int)fmin(fmax(ymax + 1.0f, 0.0f), last);
  int x0 = tx0 >> 7, x1 = tx1 >> 7, y0 = ty0 >> 7, y1 = ty1 >> 7;
  uint offset = f.page_mask;
  int k = 0, n = f.page_side;
  while ((x1 >> k) - (x0 >> k) > 1 || (y1 >> k) - (y0 >> k) > 1) {
    offset += (uint)(n * n);
    n >>= 1;
    ++k;
  }
  int planar = plane.x != 0.0f || plane.y != 0.0f || plane.z != 0.0f;
  for (int y = y0 >> k; y <= y1 >> k; ++y)
    for (int x = x0 >> k; x <= x1 >> k; ++x) {
      uint e = pyramid[offset + (uint)(y * n + x)];
      /* The entry's texels: 128 << k per side. */
      float ex = (float)((x << k) * 128), ey = (float)((y << k) * 128), es = (float)(128 << k);
      uint near_bits =
          mp_near_bits(dmin, planar ? mp_plane_near_depth(plane, f, ex, ey, ex + es, ey + es) : 0.0f);
      if (k > 0) {
        if (e >= near_bits) return 0;
        continue;
      }
      if (e == 0u) continue; /* a page this pass does not render */
      if (pyramid[o.page_farthest + e - 1u] < near_bits) continue; /* the whole page is in front */
      const MP_GLOBAL uint* cells = pyramid + o.page_cells + (e - 1u) * 64u;
      int cx0 = x == x0 ? (tx0 >> 4) & 7 : 0, cx1 = x == x1 ? (tx1 >> 4) & 7 : 7;
      int cy0 = y == y0 ? (ty0 >> 4) & 7 : 0, cy1 = y == y1 ? (ty1 >> 4) & 7 : 7;
      for (int cy = cy0; cy <= cy1; ++cy)
        for (int cx = cx0; cx <= cx1; ++cx) {
          float cxs = ex + (float)(cx * 16), cys = ey + (float)(cy * 16);
          uint cell_bits =
              planar ? mp_near_bits(dmin, mp_plane_near_depth(plane, f, cxs, cys, cxs + 16.0f, cys + 16.0f))
                     : near_bits;
          if (cells[cy * 8 + cx] >= cell_bits) return 0;
        }
    }
  return 1;
}

/* Cells per side of level `level` of a pyramid whose level 0 has `n`. */
MP_INLINE int mp_occlusion_side(int n, int level) { return (n + (1 << level) - 1) >> level; }

/* First cell of level `level`. */
MP_INLINE uint mp_occlusion_offset(OcclusionParams o, int level) {
  uint offset = 0u;
  for (int k = 0; k < level; ++k)
    offset += (uint)(mp_occlusion_side(o.base_w, k) * mp_occlusion_side(o.base_h, k));
  return offset;
}

/* Cells of all levels. */
MP_INLINE uint mp_occlusion_cells(OcclusionParams o) { return mp_occlusion_offset(o, o.levels); }

/* Whether what lies in the raster rectangle [xmin, xmax] x [ymin, ymax] at
 * depths from dmin on is hidden at every sample. The rectangle is read at the
 * level where it spans at most four cells per axis; a pixel of margin covers
 * the difference between the bound's arithmetic and the rasteriser's. */
MP_INLINE int mp_occluded(const MP_GLOBAL uint* pyramid, OcclusionParams o, FrameParams f, float xmin, float ymin,
                          float xmax, float ymax, float dmin, float4 plane) {
  if (o.levels <= 0 || !(dmin > 0.0f)) return 0;
  if (f.view_kind == MP_VIEW_SHADOW) return mp_page_occluded(pyramid, o, f, xmin, ymin, xmax, ymax, dmin, plane);
  float wx = (float)(f.width - 1), wy = (float)(f.height - 1);
  int x0 = (int)clamp(xmin - 1.0f, 0.0f, wx) >> o.cell_shift, x1 = (int)clamp(xmax + 1.0f, 0.0f, wx) >> o.cell_shift;
  int y0 = (int)clamp(ymin - 1.0f, 0.0f, wy) >> o.cell_shift, y1 = (int)clamp(ymax + 1.0f, 0.0f, wy) >> o.cell_shift;
  int k = 0;
  while (k + 1 < o.levels && ((x1 >> k) - (x0 >> k) > 3 || (y1 >> k) - (y0 >> k) > 3)) ++k;
  uint offset = mp_occlusion_offset(o, k);
  int side = mp_occlusion_side(o.base_w, k);
  int planar = plane.x != 0.0f || plane.y != 0.0f || plane.z != 0.0f;
  uint near_bits = mp_near_bits(dmin, 0.0f);
  float cell = (float)(1 << (o.cell_shift + k));
  for (int y = y0 >> k; y <= y1 >> k; ++y)
    for (int x = x0 >> k; x <= x1 >> k; ++x) {
      uint bits = planar ? mp_near_bits(dmin, mp_plane_near_depth(plane, f, (float)x * cell, (float)y * cell,
                                                                  (float)(x + 1) * cell, (float)(y + 1) * cell))
                         : near_bits;
      if (pyramid[offset + (uint)(y * side + x)] >= bits) return 0;
    }
  return 1;
}

#endif
