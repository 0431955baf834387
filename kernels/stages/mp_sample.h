/* What the two samplers share (sample.cl: one work-item per micropolygon,
 * atomics into the frame's samples; sample_tiles.cl: one work-item per
 * screen tile, which owns its samples): the raster vertex, the triangle
 * set-up, the depth and attributes at a covered sample and the rules for
 * which micropolygon a sample keeps. Both run the same arithmetic on the same
 * inputs, so both choose the same winner for every sample. OpenCL C only. */
#ifndef MP_SAMPLE_H
#define MP_SAMPLE_H

#include "core/mp_compat.h"
#include "core/mp_types.h"
#include "core/mp_hash.h"
#include "geometry/mp_patch.h"
#include "stages/mp_raster.h"
#include "geometry/mp_grid.h"

typedef struct {
  MpFixed2 p;
  float inv_d;    /* 1/depth (perspective) or depth (orthographic) */
  float4 c_over_d; /* colour and opacity */
  float3 n_over_d;
} MpRasterVertex;

/* What a micropolygon's samples keep of it: its mean opacity (1: opaque,
 * no sample tests its opacity), its held-out share (Holdout), the surface
 * its stochastic opacity draws thresholds for (mp_opacity_keeps) and
 * whether a hard alpha cut crosses it (mp_quad_cut: a fixed threshold). */
typedef struct {
  float opacity;
  float holdout;
  uint surface;
  int cut;
} MpCover;

/* Raster position of camera-space point p; *ok = 0 where it lies behind the
 * eye or beyond the guard band. */
inline MpFixed2 mp_raster_position(float4 p, FrameParams f, float* inv_d, int* ok) {
  float d = -p.z;
  float inv = f.ortho ? 1.0f : 1.0f / d;
  float rx = f.ax * p.x * inv + f.frame_bx, ry = f.ay * p.y * inv + f.frame_by;
  if (!(fabs(rx) < MP_RASTER_GUARD && fabs(ry) < MP_RASTER_GUARD) || (!f.ortho && !(d > 0.0f))) *ok = 0;
  MpFixed2 q = mp_sample_fixed(rx, ry, f);
  *inv_d = f.ortho ? d : inv;
  return q;
}

/* Perspective-correct interpolation: attributes / d and 1/d are affine in
 * screen space. */
inline MpRasterVertex mp_raster_attributes(MpFixed2 q, float inv_d, float4 c, float4 n, FrameParams f) {
  MpRasterVertex v;
  v.p = q;
  v.inv_d = inv_d;
  float w = f.ortho ? 1.0f : inv_d;
  v.c_over_d = c * w;
  v.n_over_d = n.xyz * w;
  return v;
}

inline MpRasterVertex mp_raster_vertex(float4 p, float4 c, float4 n, FrameParams f, int* ok) {
  float inv_d;
  MpFixed2 q = mp_raster_position(p, f, &inv_d, ok);
  return mp_raster_attributes(q, inv_d, c, n, f);
}

/* A triangle set up for coverage tests (mp_edge_triangle) with the
 * attributes of its vertices in the same order. */
typedef struct {
  MpEdgeTriangle e;
  MpRasterVertex a, b, c;
} MpTriangle;

inline MpTriangle mp_setup_triangle(MpRasterVertex a, MpRasterVertex b, MpRasterVertex c) {
  MpTriangle t;
  t.e = mp_edge_triangle(a.p, b.p, c.p);
  t.a = a;
  t.b = t.e.swapped ? c : b;
  t.c = t.e.swapped ? b : c;
  return t;
}

/* The quad (v[0], v[1], v[2], v[3])'s triangles (v[0], v[1], v[2]) and
 * (v[0], v[2], v[3]), each dropped unless `keep` (mp_quad_facing) keeps it. */
inline void mp_setup_quad(const MpRasterVertex* v, uint keep, MpTriangle* tris) {
  tris[0] = mp_setup_triangle(v[0], v[1], v[2]);
  tris[1] = mp_setup_triangle(v[0], v[2], v[3]);
  tris[0].e.valid &= (int)(keep & 1u);
  tris[1].e.valid &= (int)(keep >> 1);
}

/* Which of a quad's triangles covers sample q (0 or 1, with its
 * barycentrics), or -1: the tie rule gives a sample on the diagonal to one. */
inline int mp_quad_covers(const MpTriangle* tris, MpFixed2 q, float* la, float* lb, float* lc) {
  if (mp_edge_triangle_covers(&tris[0].e, q, la, lb, lc)) return 0;
  return mp_edge_triangle_covers(&tris[1].e, q, la, lb, lc) ? 1 : -1;
}

/* A sample's visibility key: the nearest depth wins, ties go to the lower
 * micropolygon id (positive floats order as their bits). */
inline ulong mp_sample_key(float d, uint mp_id) { return ((ulong)as_uint(d) << 32) | (ulong)mp_id; }

/* Which of the quad (v00, v10, v11, v01)'s triangles (v00, v10, v11) (bit 0)
 * and (v00, v11, v01) (bit 1) face the camera, and twice their raster area
 * in fixed-point units. Front faces run counter-clockwise on screen, i.e.
 * negative raster area. Each triangle is culled on its own: a quad of a
 * stitching strip can turn one triangle away near a silhouette while the
 * other still faces the camera. */
inline uint mp_quad_facing(MpFixed2 p0, MpFixed2 p1, MpFixed2 p2, MpFixed2 p3, uint patch_flags, FrameParams f,
                           long* area2) {
  long a0 = mp_edge(p0, p1, p2), a1 = mp_edge(p0, p2, p3);
  uint keep = 3u;
  if (f.backface_culling && !(patch_flags & MP_PATCH_DOUBLE_SIDED)) {
    int flip = (patch_flags & MP_PATCH_FLIP_ORIENTATION) != 0u;
    keep = ((flip ? a0 > 0 : a0 < 0) ? 1u : 0u) | ((flip ? a1 > 0 : a1 < 0) ? 2u : 0u);
  }
  *area2 = ((keep & 1u) ? (a0 < 0 ? -a0 : a0) : 0) + ((keep & 2u) ? (a1 < 0 ? -a1 : a1) : 0);
  return keep;
}

/* A micropolygon's id in sample keys: its grid's (from the patch and the
 * corners) combined with its number m in the grid. */
inline uint mp_grid_id(const SubPatch* sp) {
  uint grid_id = mp_hash32(mp_placed_patch_id(sp->patch, sp->instance));
  for (int k = 0; k < 8; ++k) grid_id = mp_hash_combine(grid_id, as_uint(sp->corner[k]));
  return grid_id;
}

inline uint mp_micropolygon_id(uint grid_id, uint m) { return mp_hash_combine(grid_id, m); }

/* The depth at barycentrics (la, lb, lc) of t, and whether it lies within
 * the clip range. */
inline int mp_triangle_depth(const MpTriangle* t, float la, float lb, float lc, FrameParams f, float* d) {
  float inv_d = la * t->a.inv_d + lb * t->b.inv_d + lc * t->c.inv_d;
  *d = f.ortho ? inv_d : 1.0f / inv_d;
  return *d >= f.clip_near && *d <= f.clip_far;
}

/* Stochastic opacity, as hashed alpha testing (Wyman & McGuire 2017): sample
 * s of pixel (px, py) keeps a surface where the surface's opacity at the
 * sample exceeds a threshold drawn for that surface, pixel and sample. The
 * thresholds do not depend on the micropolygon, so neighbouring
 * micropolygons of a surface agree on each sample: a hard alpha cut keeps
 * a crisp edge through the opacity interpolated across the micropolygon,
 * with no isolated specks, and a surface of uniform opacity a covers a of
 * a pixel's samples. A pixel's thresholds follow the golden-ratio sequence
 * from a random start, so they spread over [0, 1) almost evenly. Surfaces
 * draw their own thresholds, so one seen through another keeps its share.
 * The hash follows whole-image pixels (the crop origin added), so a crop,
 * a bucket or a tile draws the same coverage as the whole frame. */
inline int mp_opacity_keeps(uint surface, int cut, int px, int py, int s, float opacity, FrameParams f) {
  if (opacity >= 1.0f) return 1;
  if (cut) return opacity > 0.5f;
  uint h = mp_hash_combine(mp_hash_combine(surface, (uint)(px + f.crop_x0)), (uint)(py + f.crop_y0));
  float t = mp_hash_unit(h) + (float)s * 0.61803398875f;
  return t - floor(t) < opacity;
}

/* The opacity at a covered sample of depth d (perspective-correct, as the
 * colour), or 1 where the whole micropolygon is opaque. */
inline float mp_sample_opacity(const MpTriangle* t, float la, float lb, float lc, float d, float mean, FrameParams f) {
  if (mean >= 1.0f) return 1.0f;
  float w = f.ortho ? 1.0f : d;
  return (la * t->a.c_over_d.w + lb * t->b.c_over_d.w + lc * t->c.c_over_d.w) * w;
}

/* Holdout (mp_closures.h): a sample's held-out share h travels in the 8
 * lowest mantissa bits of its blue (changing blue by at most 2^-15 of
 * itself), so samples need no fourth channel; its colour is stored times
 * 1 - h, and the resolve counts 1 - h of it in the alpha. Samples of
 * micropolygons with no holdout store h = 0. */
inline float mp_pack_holdout(float blue, float h) {
  uint q = (uint)(clamp(h, 0.0f, 1.0f) * 255.0f + 0.5f);
  return as_float((as_uint(blue) & ~0xffu) | q);
}
inline float mp_unpack_holdout(float blue) { return (float)(as_uint(blue) & 0xffu) * (1.0f / 255.0f); }

/* The colour a sample stores, its held-out share h packed in. */
inline float3 mp_sample_color(float3 col, float h) {
  col *= 1.0f - h;
  col.z = mp_pack_holdout(col.z, h);
  return col;
}

/* Color and normal at a covered sample of depth d. */
inline void mp_triangle_attributes(const MpTriangle* t, float la, float lb, float lc, float d, FrameParams f,
                                   float3* col, float3* nrm) {
  float w = f.ortho ? 1.0f : d;
  *col = (la * t->a.c_over_d.xyz + lb * t->b.c_over_d.xyz + lc * t->c.c_over_d.xyz) * w;
  *nrm = (la * t->a.n_over_d + lb * t->b.n_over_d + lc * t->c.n_over_d) * w;
}

/* Sample colors: with f.planar_colors (the tile sampler), per pixel its
 * samples' reds, then their greens, then their blues, so a pixel's samples
 * of one channel lie together (16 are loaded and stored at once); else
 * sample by sample, RGB together (one work-item per micropolygon writes a
 * sample's three at once: what GPUs want). */
inline ulong mp_color_index(ulong pixel, int spp, int channel) { return (pixel * 3u + (ulong)channel) * (ulong)spp; }

inline void mp_store_color(__global float* colors, ulong pixel, int s, int spp, float3 c, FrameParams f) {
  if (!f.planar_colors) {
    vstore3(c, pixel * (ulong)spp + (ulong)s, colors);
    return;
  }
  colors[mp_color_index(pixel, spp, 0) + (ulong)s] = c.x;
  colors[mp_color_index(pixel, spp, 1) + (ulong)s] = c.y;
  colors[mp_color_index(pixel, spp, 2) + (ulong)s] = c.z;
}

inline float3 mp_load_color(__global const float* colors, ulong pixel, int s, int spp, FrameParams f) {
  if (!f.planar_colors) return vload3(pixel * (ulong)spp + (ulong)s, colors);
  return (float3)(colors[mp_color_index(pixel, spp, 0) + (ulong)s], colors[mp_color_index(pixel, spp, 1) + (ulong)s],
                  colors[mp_color_index(pixel, spp, 2) + (ulong)s]);
}

/* Work-item gid's run of MP_TILE_RUN micropolygons among the batch's
 * grids [first, first + count) (runs_per_grid a grid, in the grid's order):
 * its grid's shape, the first slot of its vertices and its micropolygons
 * [*m0, *m1); 0 past the batch. The tile sampler and the bins bound runs. */
inline int mp_grid_run(__global const SubPatch* diceable, uint first, uint count, uint gid, uint runs_per_grid,
                       FrameParams f, MpGridShape* g, ulong* base, uint* m0, uint* m1) {
  uint k = gid / runs_per_grid, run = gid % runs_per_grid;
  if (k >= count) return 0;
  uint slot = first + k, stride = (uint)f.max_grid + 1u;
  SubPatch sp = diceable[slot];
  *g = mp_grid_shape(&sp, (uint)f.max_grid);
  *base = (ulong)slot * stride * stride;
  *m0 = run * MP_TILE_RUN;
  *m1 = min(mp_grid_micropolygons(g), (run + 1u) * MP_TILE_RUN);
  return 1;
}

/* Marks the occlusion pyramid's level-0 cells (mp_occlusion.h) under the
 * raster rectangle [x0, x1] x [y0, y1] (pixels, clamped to the frame) as
 * changed: occlusion.cl rebuilds only those. */
inline void mp_mark_occlusion_rect(__global uchar* dirty, OcclusionParams o, FrameParams f, long x0, long y0, long x1,
                                   long y1) {
  int cx0 = (int)clamp(x0, (long)0, (long)f.width - 1) >> o.cell_shift;
  int cx1 = (int)clamp(x1, (long)0, (long)f.width - 1) >> o.cell_shift;
  int cy0 = (int)clamp(y0, (long)0, (long)f.height - 1) >> o.cell_shift;
  int cy1 = (int)clamp(y1, (long)0, (long)f.height - 1) >> o.cell_shift;
  for (int y = cy0; y <= cy1; ++y)
    for (int x = cx0; x <= cx1; ++x) dirty[y * o.base_w + x] = (uchar)1;
}

#endif
