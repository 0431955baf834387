/* The rasteriser of one micropolygon, shared by the samplers that take a
 * micropolygon per work-item (sample.cl: atomics into the frame's keys;
 * sample_bins.cl: a work-group per screen tile, its keys in local memory).
 * A micropolygon (two triangles of a quad of a stitched grid, mp_grid.h; one
 * of them empty where the quad has collapsed into a triangle) finds the
 * jittered samples it covers with fixed-point edge tests and keeps, per
 * sample, the nearest key of (depth, micropolygon id) by an atomic minimum;
 * a second pass lets the owner of each sample's key write its colour and
 * normal, so the result never depends on execution order. OpenCL C only. */
#ifndef MP_QUAD_SAMPLER_H
#define MP_QUAD_SAMPLER_H
#pragma OPENCL EXTENSION cl_khr_int64_base_atomics : enable
#pragma OPENCL EXTENSION cl_khr_int64_extended_atomics : enable
#include "core/mp_compat.h"
#include "geometry/mp_patch.h"
#include "core/mp_types.h"
#include "core/mp_hash.h"
#include "stages/mp_raster.h"
#include "geometry/mp_grid.h"
#include "stages/mp_occlusion.h"
#include "stages/mp_sample.h"
#include "core/mp_scene_data.h"

/* Where a sampler keeps each sample's nearest key: in the frame's buffer
 * (`frame`, index pixel * spp + s), or, where `tile` is set, in a screen
 * tile's copy in local memory (laid out as the frame's, rows of `stride`
 * pixels from pixel (x0, y0)) whose work-group alone samples that tile.
 * Either way only pixels [x0, x1] x [y0, y1] are sampled: the frame's, or
 * the tile's. */
typedef struct {
  volatile __global ulong* frame;
  volatile __local ulong* tile;
  int x0, y0, x1, y1, stride;
} MpKeys;

inline MpKeys mp_frame_keys(volatile __global ulong* keys, FrameParams f) {
  MpKeys k;
  k.frame = keys;
  k.tile = 0;
  k.x0 = 0, k.y0 = 0, k.x1 = f.width - 1, k.y1 = f.height - 1, k.stride = 0;
  return k;
}

/* Sample s of pixel (px, py), covered by triangle t at barycentrics (la,
 * lb, lc): within the clip range and the stochastic opacity, the depth
 * passes keep the nearest key, the mark pass marks the grid (*mark) where
 * the micropolygon owns the sample, and the attribute pass lets its owner
 * write. pass: its kind (MP_SAMPLE_KIND bits). cover: what its samples keep
 * of the micropolygon (MpCover). */
inline void mp_sample_write(const MpTriangle* t, float la, float lb, float lc, int px, int py, int s, int spp,
                            uint mp_id, MpCover cover, FrameParams f, uint pass, MpKeys keys,
                            __global float* colors, __global uint* normals, __global uchar* mark) {
  float d;
  if (!mp_triangle_depth(t, la, lb, lc, f, &d)) return;
  if (!mp_opacity_keeps(cover.surface, cover.cut, px, py, s, mp_sample_opacity(t, la, lb, lc, d, cover.opacity, f), f)) return;
  ulong pixel = (ulong)py * (ulong)f.width + (ulong)px, index = pixel * (ulong)spp + (ulong)s;
  uint local_index = (uint)(((py - keys.y0) * keys.stride + (px - keys.x0)) * spp + s);
  ulong key = mp_sample_key(d, mp_id);
  ulong old = keys.tile ? keys.tile[local_index] : keys.frame[index];
  if (pass == MP_SAMPLE_DEPTH || pass == MP_SAMPLE_OPAQUE_DEPTH) {
    if (key < old) {
      if (keys.tile)
        atom_min(&keys.tile[local_index], key);
      else
        atom_min(&keys.frame[index], key);
    }
  } else if (pass == MP_SAMPLE_MARK) {
    if (old == key) *mark = (uchar)1;
  } else if (old == key) {
    float3 col, nrm;
    mp_triangle_attributes(t, la, lb, lc, d, f, &col, &nrm);
    mp_store_color(colors, pixel, s, spp, mp_sample_color(col, cover.holdout), f);
    if (f.normal_pass) normals[index] = mp_encode_normal(normalize(nrm));
  }
}

/* A triangle's corners relative to its quad's raster bound corner, in
 * int32 (mp_raster_quad_small). */
typedef struct {
  int ax, ay, bx, by, cx, cy;
} MpSmallTriangle;

inline MpSmallTriangle mp_small_triangle(const MpEdgeTriangle* t, long x0, long y0) {
  MpSmallTriangle r;
  r.ax = (int)(t->a.x - x0), r.ay = (int)(t->a.y - y0);
  r.bx = (int)(t->b.x - x0), r.by = (int)(t->b.y - y0);
  r.cx = (int)(t->c.x - x0), r.cy = (int)(t->c.y - y0);
  return r;
}

/* mp_edge_triangle_covers for a sample (sx, sy) inside the bound, in the
 * same relative coordinates: every factor is a difference of two points of
 * the bound, at most MP_FAST_SPAN (2^13) apart, so each edge value stays
 * below 2^27 in magnitude and equals mp_edge's 64-bit one exactly (as do
 * the barycentrics made from it). */
inline int mp_small_covers(const MpEdgeTriangle* t, const MpSmallTriangle* r, int sx, int sy, float* la, float* lb,
                           float* lc) {
  if (!t->valid) return 0;
  int e0 = (r->cy - r->by) * (sx - r->bx) - (r->cx - r->bx) * (sy - r->by);
  int e1 = (r->ay - r->cy) * (sx - r->cx) - (r->ax - r->cx) * (sy - r->cy);
  int e2 = (r->by - r->ay) * (sx - r->ax) - (r->bx - r->ax) * (sy - r->ay);
  if (!((e0 > 0 || (e0 == 0 && t->own0)) && (e1 > 0 || (e1 == 0 && t->own1)) && (e2 > 0 || (e2 == 0 && t->own2))))
    return 0;
  *la = (float)e0 * t->inv_area;
  *lb = (float)e1 * t->inv_area;
  *lc = (float)e2 * t->inv_area;
  return 1;
}

/* mp_raster_quad for a quad whose raster bound [xmin, xmax] x [ymin, ymax]
 * spans at most MP_FAST_SPAN per axis (nearly every micropolygon): the
 * same samples tested in the same order with the same results, in 32-bit
 * integers relative to the bound's corner. 64-bit integer arithmetic is
 * several instructions per operation on GPUs, and these tests are the
 * sampler's inner loop. */
inline void mp_raster_quad_small(const MpTriangle* tris, long xmin, long ymin, int span_x, int span_y, int px0, int px1,
                                 int py0, int py1, uint mp_id, MpCover cover, FrameParams f,
                                 __global const ushort* offsets, uint pass, MpKeys keys,
                                 __global float* colors, __global uint* normals, __global uchar* mark, uint* tests) {
  MpSmallTriangle r0 = mp_small_triangle(&tris[0].e, xmin, ymin), r1 = mp_small_triangle(&tris[1].e, xmin, ymin);
  int spp = f.spp_x * f.spp_y;
  /* Raster positions fit in int32 (the guard band: MP_RASTER_GUARD). */
  int row0 = (int)(((long)py0 << MP_SUBPIXEL_BITS) - ymin), col0 = (int)(((long)px0 << MP_SUBPIXEL_BITS) - xmin);
  for (int py = py0, ry = row0; py <= py1; ++py, ry += MP_SUBPIXEL_ONE) {
    int ty = ((py + f.crop_y0) & (MP_SAMPLE_TILE - 1)) * MP_SAMPLE_TILE;
    for (int px = px0, rx = col0; px <= px1; ++px, rx += MP_SUBPIXEL_ONE) {
      __global const ushort* o = offsets + (ty + ((px + f.crop_x0) & (MP_SAMPLE_TILE - 1))) * spp;
      for (int s = 0; s < spp; ++s) {
        uint packed = o[s];
        int sx = rx + (int)(packed & 0xffu), sy = ry + (int)(packed >> 8);
        if (sx < 0 || sx > span_x || sy < 0 || sy > span_y) continue;
        ++*tests;
        float la, lb, lc;
        int k = mp_small_covers(&tris[0].e, &r0, sx, sy, &la, &lb, &lc)   ? 0
                : mp_small_covers(&tris[1].e, &r1, sx, sy, &la, &lb, &lc) ? 1
                                                                           : -1;
        if (k >= 0)
          mp_sample_write(&tris[k], la, lb, lc, px, py, s, spp, mp_id, cover, f, pass, keys, colors, normals, mark);
      }
    }
  }
}

/* Rasterises the quad v[0..3]'s triangles that `keep` selects
 * (mp_setup_quad). */
inline void mp_raster_quad(const MpRasterVertex* v, uint keep, uint mp_id, MpCover cover, FrameParams f,
                           __global const ushort* offsets, uint pass, MpKeys keys,
                           __global float* colors, __global uint* normals, __global uchar* mark, uint* tests) {
  MpTriangle tris[2];
  mp_setup_quad(v, keep, tris);
  long xmin = min(min(v[0].p.x, v[1].p.x), min(v[2].p.x, v[3].p.x)), xmax = max(max(v[0].p.x, v[1].p.x), max(v[2].p.x, v[3].p.x));
  long ymin = min(min(v[0].p.y, v[1].p.y), min(v[2].p.y, v[3].p.y)), ymax = max(max(v[0].p.y, v[1].p.y), max(v[2].p.y, v[3].p.y));
  int px0 = (int)max(xmin >> MP_SUBPIXEL_BITS, (long)keys.x0), px1 = (int)min(xmax >> MP_SUBPIXEL_BITS, (long)keys.x1);
  int py0 = (int)max(ymin >> MP_SUBPIXEL_BITS, (long)keys.y0), py1 = (int)min(ymax >> MP_SUBPIXEL_BITS, (long)keys.y1);
  if (xmax - xmin <= MP_FAST_SPAN && ymax - ymin <= MP_FAST_SPAN) {
    mp_raster_quad_small(tris, xmin, ymin, (int)(xmax - xmin), (int)(ymax - ymin), px0, px1, py0, py1, mp_id, cover, f,
                         offsets, pass, keys, colors, normals, mark, tests);
    return;
  }
  int spp = f.spp_x * f.spp_y;
  for (int py = py0; py <= py1; ++py)
    for (int px = px0; px <= px1; ++px)
      for (int s = 0; s < spp; ++s) {
        MpFixed2 q = mp_sample_position(px, py, s, spp, f, offsets);
        if (q.x < xmin || q.x > xmax || q.y < ymin || q.y > ymax) continue;
        ++*tests;
        float la, lb, lc;
        int k = mp_quad_covers(tris, q, &la, &lb, &lc);
        if (k >= 0)
          mp_sample_write(&tris[k], la, lb, lc, px, py, s, spp, mp_id, cover, f, pass, keys, colors, normals, mark);
      }
}

/* Grows the raster box by view-space point p seen from every lens position
 * of the box bx (x range) by (y range); 0 where p is behind the lens. */
inline int mp_blur_box(float3 p, float2 bx, float2 by, FrameParams f, float* box) {
  float x0, x1, y0, y1;
  if (f.ortho) {
    x0 = x1 = f.ax * p.x + f.frame_bx, y0 = y1 = f.ay * p.y + f.frame_by;
  } else {
    float d = -p.z;
    if (!(d > 0.0f)) return 0;
    float inv = 1.0f / d, k = 1.0f / f.focus_distance - inv;
    x0 = f.ax * (p.x * inv + bx.x * k) + f.frame_bx, x1 = f.ax * (p.x * inv + bx.y * k) + f.frame_bx;
    y0 = f.ay * (p.y * inv + by.x * k) + f.frame_by, y1 = f.ay * (p.y * inv + by.y * k) + f.frame_by;
  }
  box[0] = fmin(box[0], fmin(x0, x1)), box[1] = fmax(box[1], fmax(x0, x1));
  box[2] = fmin(box[2], fmin(y0, y1)), box[3] = fmax(box[3], fmax(y0, y1));
  return 1;
}

/* Motion steps a work-item keeps in registers per vertex; with more, the
 * positions are read from the grid's step buffer at each test. */
#define MP_BLUR_LOCAL_STEPS 3
/* A quad whose whole blurred bound covers at most this many pixels has all
 * the samples of those pixels tested, with no bound per sample slot (which
 * costs more than it saves on so few). */
#ifndef MP_BLUR_SMALL_PIXELS
#define MP_BLUR_SMALL_PIXELS 9
#endif

/* Position at time t of vertex i (mp_motion_position over its steps, from
 * registers when they are there). */
inline float3 mp_blur_position(int i, float t, int steps, const float4* p, float4 ps[4][MP_BLUR_LOCAL_STEPS],
                               __global const float4* pm, const ulong* idx, ulong stride) {
  if (!steps) return p[i].xyz;
  if (steps > MP_BLUR_LOCAL_STEPS) return mp_motion_position(pm + idx[i], stride, steps, t).xyz;
  float w;
  int k = mp_motion_segment(t, steps, &w);
  return (ps[i][k] + w * (ps[i][k + 1] - ps[i][k])).xyz;
}

/* Whether triangle (a, b, c) of relative int32 positions (the sample at the
 * origin) covers the sample, by mp_edge_triangle's orientation and tie
 * rule and mp_edge_triangle_covers' test. */
inline int mp_small_triangle_covers(int2 a, int2 b, int2 c) {
  int area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  if (area == 0) return 0;
  if (area > 0) {
    int2 t = b;
    b = c;
    c = t;
  }
  int e0 = (c.x - b.x) * b.y - (c.y - b.y) * b.x;
  int e1 = (a.x - c.x) * c.y - (a.y - c.y) * c.x;
  int e2 = (b.x - a.x) * a.y - (b.y - a.y) * a.x;
  int own0 = c.y - b.y > 0 || (c.y == b.y && c.x - b.x < 0);
  int own1 = a.y - c.y > 0 || (a.y == c.y && a.x - c.x < 0);
  int own2 = b.y - a.y > 0 || (b.y == a.y && b.x - a.x < 0);
  return (e0 > 0 || (e0 == 0 && own0)) && (e1 > 0 || (e1 == 0 && own1)) && (e2 > 0 || (e2 == 0 && own2));
}

/* Whether sample q surely misses the quad v[0..3]'s triangles that `keep`
 * selects (mp_setup_quad), told in 32-bit integers relative to the sample
 * where every vertex lies within MP_FAST_SPAN of it: the areas and edge
 * values then stay below 2^29 and equal mp_edge's 64-bit ones exactly, so
 * this answers as mp_quad_covers would. 0 (not sure) otherwise. */
inline int mp_quad_misses_small(const MpRasterVertex* v, uint keep, MpFixed2 q) {
  int2 r[4];
  for (int i = 0; i < 4; ++i) {
    long dx = v[i].p.x - q.x, dy = v[i].p.y - q.y;
    if (dx < -MP_FAST_SPAN || dx > MP_FAST_SPAN || dy < -MP_FAST_SPAN || dy > MP_FAST_SPAN) return 0;
    r[i] = (int2)((int)dx, (int)dy);
  }
  if ((keep & 1u) && mp_small_triangle_covers(r[0], r[1], r[2])) return 0;
  if ((keep & 2u) && mp_small_triangle_covers(r[0], r[2], r[3])) return 0;
  return 1;
}

/* One sample of a blurred quad: its four vertices at the sample's time and
 * lens position, a cheap box rejection, a test in 32-bit integers that
 * drops the samples the quad misses (most of those inside its box), then
 * the attributes' set-up and the fixed-point edge tests. */
inline void mp_blur_sample(int px, int py, int s, int spp, MpFixed2 sq, float4 e, int steps, const float4* p,
                           float4 ps[4][MP_BLUR_LOCAL_STEPS], __global const float4* pm, const ulong* idx, ulong stride,
                           float8* still, const float4* c, const float4* n, uint keep, uint mp_id, MpCover cover,
                           FrameParams f, uint pass, MpKeys keys, __global float* colors,
                           __global uint* normals, __global uchar* mark) {
  float3 q[4];
  MpRasterVertex v[4];
  for (int i = 0; i < 4; ++i) {
    float rx, ry, inv_d;
    if (!steps) {
      /* Without motion the lens alone moves the vertex: two multiply-adds. */
      rx = still[i].s0 + e.x * still[i].s2, ry = still[i].s1 + e.y * still[i].s3, inv_d = still[i].s4;
      if (!(fabs(rx) < MP_RASTER_GUARD && fabs(ry) < MP_RASTER_GUARD)) return;
      v[i].p = mp_sample_fixed(rx, ry, f);
      v[i].inv_d = inv_d;
      continue;
    }
    q[i] = mp_blur_position(i, e.z, steps, p, ps, pm, idx, stride);
    if (f.ortho) {
      rx = f.ax * q[i].x + f.frame_bx, ry = f.ay * q[i].y + f.frame_by, inv_d = -q[i].z;
    } else if (!mp_project_lens(q[i], (float2)(e.x, e.y), f, &rx, &ry, &inv_d)) {
      return;
    }
    if (!(fabs(rx) < MP_RASTER_GUARD && fabs(ry) < MP_RASTER_GUARD)) return;
    v[i].p = mp_sample_fixed(rx, ry, f);
    v[i].inv_d = inv_d;
  }
  /* Most samples of a slot's bound miss the quad where it is at their time. */
  if (sq.x < min(min(v[0].p.x, v[1].p.x), min(v[2].p.x, v[3].p.x)) ||
      sq.x > max(max(v[0].p.x, v[1].p.x), max(v[2].p.x, v[3].p.x)) ||
      sq.y < min(min(v[0].p.y, v[1].p.y), min(v[2].p.y, v[3].p.y)) ||
      sq.y > max(max(v[0].p.y, v[1].p.y), max(v[2].p.y, v[3].p.y)))
    return;
  if (mp_quad_misses_small(v, keep, sq)) return;
  for (int i = 0; i < 4; ++i) {
    float w = f.ortho ? 1.0f : v[i].inv_d;
    v[i].c_over_d = c[i] * w;
    v[i].n_over_d = n[i].xyz * w;
  }
  MpTriangle tris[2];
  mp_setup_quad(v, keep, tris);
  float la, lb, lc;
  int t = mp_quad_covers(tris, sq, &la, &lb, &lc);
  if (t >= 0)
    mp_sample_write(&tris[t], la, lb, lc, px, py, s, spp, mp_id, cover, f, pass, keys, colors, normals, mark);
}

/* Grows the raster box by vertex i over the times [t0, t1] (its positions
 * there and at the steps between: straight lines in between stay straight
 * in perspective) seen from every lens position of the box (bx, by). */
inline int mp_blur_path_box(int i, float t0, float t1, float2 bx, float2 by, int steps, const float4* p,
                            float4 ps[4][MP_BLUR_LOCAL_STEPS], __global const float4* pm, const ulong* idx,
                            ulong stride, FrameParams f, float* box) {
  if (!steps) return mp_blur_box(p[i].xyz, bx, by, f, box);
  int ok = mp_blur_box(mp_blur_position(i, t0, steps, p, ps, pm, idx, stride), bx, by, f, box) &&
           mp_blur_box(mp_blur_position(i, t1, steps, p, ps, pm, idx, stride), bx, by, f, box);
  for (int k = 1; k + 1 < steps && ok; ++k) {
    float tk = (float)k / (float)(steps - 1);
    if (tk > t0 && tk < t1) ok = mp_blur_box(mp_blur_position(i, tk, steps, p, ps, pm, idx, stride), bx, by, f, box);
  }
  return ok;
}

/* The quad as samples that carry times and lens positions see it
 * (mp_blur.h): each sample moves the four vertices to its own time and lens
 * position before the same fixed-point edge tests, so shared vertices move
 * alike in every sample and the grid stays watertight in each. Which
 * samples are tested: where the quad's whole blurred bound (all times, the
 * whole aperture) covers few pixels (MP_BLUR_SMALL_PIXELS), every sample of
 * those pixels;
 * else each sample slot s apart, over the quad's bound for the times and
 * lens positions its slot takes (the table's box of slot s after the tile's
 * entries: (lx0, lx1, ly0, ly1), (t0, t1)). Triangles keep the shutter
 * centre's culling (`keep`); attributes are the centre's (shading once per
 * grid vertex). Motion positions: pm[idx[i] + k * stride] for step k. */
inline void mp_raster_quad_blur(const float4* p, __global const float4* pm, const ulong* idx, ulong stride,
                                const float4* c, const float4* n, uint keep, uint mp_id, MpCover cover, FrameParams f,
                                __global const ushort* offsets, __global const float4* table, uint pass,
                                MpKeys keys, __global float* colors, __global uint* normals,
                                __global uchar* mark, uint* tests) {
  int spp = f.spp_x * f.spp_y;
  int steps = mp_motion_on(f) ? f.motion_steps : 0;
  float4 ps[4][MP_BLUR_LOCAL_STEPS];
  if (steps && steps <= MP_BLUR_LOCAL_STEPS)
    for (int i = 0; i < 4; ++i)
      for (int k = 0; k < steps; ++k) ps[i][k] = pm[idx[i] + (ulong)k * stride];
  /* Without motion (a lens only; mp_project_lens): each vertex's pinhole
   * raster position, its raster shift per unit of lens offset, and 1/d. */
  float8 still[4];
  if (!steps)
    for (int i = 0; i < 4; ++i) {
      float inv = 1.0f / (-p[i].z), k = 1.0f / f.focus_distance - inv;
      still[i] = (float8)(f.ax * p[i].x * inv + f.frame_bx, f.ay * p[i].y * inv + f.frame_by, f.ax * k, f.ay * k, inv, 0.0f,
                          0.0f, 0.0f);
    }
  __global const float4* slot_boxes = table + MP_SAMPLE_TILE * MP_SAMPLE_TILE * spp;
  /* The whole bound: every time, the whole aperture. */
  float rx = mp_lens_on(f) ? f.lens_radius * f.lens_x_scale : 0.0f, ry = mp_lens_on(f) ? f.lens_radius : 0.0f;
  float whole[4] = {3.0e38f, -3.0e38f, 3.0e38f, -3.0e38f};
  int ok = 1;
  for (int i = 0; i < 4 && ok; ++i)
    ok = mp_blur_path_box(i, 0.0f, 1.0f, (float2)(-rx, rx), (float2)(-ry, ry), steps, p, ps, pm, idx, stride, f,
                          whole);
  if (!ok) return;
  int small = ((int)floor(whole[1]) - (int)floor(whole[0]) + 1) * ((int)floor(whole[3]) - (int)floor(whole[2]) + 1) <=
              MP_BLUR_SMALL_PIXELS;
  for (int s = 0; s < (small ? 1 : spp); ++s) {
    float box[4] = {whole[0], whole[1], whole[2], whole[3]};
    if (!small) {
      float4 lb = slot_boxes[2 * s], tb = slot_boxes[2 * s + 1];
      box[0] = box[2] = 3.0e38f, box[1] = box[3] = -3.0e38f;
      for (int i = 0; i < 4 && ok; ++i)
        ok = mp_blur_path_box(i, tb.x, tb.y, (float2)(lb.x, lb.y), (float2)(lb.z, lb.w), steps, p, ps, pm, idx,
                              stride, f, box);
      if (!ok) return;
    }
    /* One fixed-point unit of slack for the rounding of positions. */
    MpFixed2 lo = mp_sample_fixed(box[0], box[2], f), hi = mp_sample_fixed(box[1], box[3], f);
    long fx0 = lo.x - 1, fx1 = hi.x + 1, fy0 = lo.y - 1, fy1 = hi.y + 1;
    int px0 = (int)max(fx0 >> MP_SUBPIXEL_BITS, (long)keys.x0), px1 = (int)min(fx1 >> MP_SUBPIXEL_BITS, (long)keys.x1);
    int py0 = (int)max(fy0 >> MP_SUBPIXEL_BITS, (long)keys.y0), py1 = (int)min(fy1 >> MP_SUBPIXEL_BITS, (long)keys.y1);
    for (int py = py0; py <= py1; ++py)
      for (int px = px0; px <= px1; ++px) {
        int tx = (px + f.crop_x0) & (MP_SAMPLE_TILE - 1), ty = (py + f.crop_y0) & (MP_SAMPLE_TILE - 1);
        for (int k = small ? 0 : s; k < (small ? spp : s + 1); ++k) {
          MpFixed2 sq = mp_sample_position(px, py, k, spp, f, offsets);
          if (sq.x < fx0 || sq.x > fx1 || sq.y < fy0 || sq.y > fy1) continue;
          ++*tests;
          mp_blur_sample(px, py, k, spp, sq, table[(ty * MP_SAMPLE_TILE + tx) * spp + k], steps, p, ps, pm, idx,
                         stride, still, c, n, keep, mp_id, cover, f, pass, keys, colors, normals, mark);
        }
      }
  }
}

/* Micropolygons that reach the rasteriser and their total screen area, summed
 * per work-group in local memory (one atomic per group): the dicing density
 * the benchmarks report as micropolygons per pixel of surface; and the
 * samples tested against micropolygon edges (inside a micropolygon's
 * bound): the rasteriser's work per sample, which blur multiplies. Counted
 * in the pass that finds the micropolygon's depth (`counts`). */
inline void mp_count_sampled(uint l, ulong area2, uint micropolygons, uint tests, int counts,
                             volatile __global ulong* totals, __local ulong* area_sum, __local uint* count_sum,
                             __local uint* test_sum) {
  area_sum[l] = area2;
  count_sum[l] = micropolygons;
  test_sum[l] = tests;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint s = (uint)get_local_size(0) / 2u; s > 0u; s >>= 1) {
    if (l < s) {
      area_sum[l] += area_sum[l + s];
      count_sum[l] += count_sum[l + s];
      test_sum[l] += test_sum[l + s];
    }
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (counts && l == 0u && count_sum[0] > 0u) {
    atom_add(&totals[0], (ulong)count_sum[0]);
    atom_add(&totals[1], area_sum[0]);
    atom_add(&totals[2], (ulong)test_sum[0]);
  }
}

/* Marks the occlusion cells under the micropolygon's raster bound. */
inline void mp_mark_occlusion_cells(__global uchar* dirty, OcclusionParams o, FrameParams f, MpFixed2 a, MpFixed2 b,
                                    MpFixed2 c, MpFixed2 d) {
  long xmin = min(min(a.x, b.x), min(c.x, d.x)), xmax = max(max(a.x, b.x), max(c.x, d.x));
  long ymin = min(min(a.y, b.y), min(c.y, d.y)), ymax = max(max(a.y, b.y), max(c.y, d.y));
  mp_mark_occlusion_rect(dirty, o, f, xmin >> MP_SUBPIXEL_BITS, ymin >> MP_SUBPIXEL_BITS, xmax >> MP_SUBPIXEL_BITS,
                         ymax >> MP_SUBPIXEL_BITS);
}

/* What one micropolygon adds to its pass's counts (mp_count_sampled): twice
 * its area in fixed-point units and the samples tested. */
typedef struct {
  long area2;
  uint tests;
} MpSampled;

/* Micropolygon m of the grid in slot `slot` through one pass (pass: a kind
 * of MP_SAMPLE_KIND, and MP_SAMPLE_AFTER_MARK): whether the pass takes its
 * grid (visibility first's rules, mp_raster.h), its raster vertices and
 * facing, what its samples keep of it, then its samples among the pixels of
 * `keys`. The pass that finds its depth counts it and marks the occlusion
 * cells under it; a tile's pass (keys.tile) only in the tile that holds the
 * first pixel of its bound, so each micropolygon is counted once. `blur` (a
 * constant where inlined) picks the stochastic path. */
inline MpSampled mp_sample_micropolygon(__global const uint* patch_info, __global const DeviceInstance* instances,
                                        __global const DeviceMaterial* materials,
                                        __global const SubPatch* diceable, uint slot, uint m, FrameParams f,
                                        __global const float4* grid_p, __global const float4* grid_c,
                                        __global const float4* grid_n, __global const ushort* sample_offsets,
                                        __global const float4* sample_table, __global const float4* grid_pm,
                                        ulong motion_stride, uint pass, MpKeys keys, __global float* colors,
                                        __global uint* normals, __global uchar* occlusion_dirty, OcclusionParams occ,
                                        __global uchar* visible, const int blur) {
  MpSampled r = {0, 0u};
  uint stride = (uint)f.max_grid + 1u;
  SubPatch sp = diceable[slot];
  MpGridShape g = mp_grid_shape(&sp, (uint)f.max_grid);
  uint q[4];
  if (!mp_grid_micropolygon(&g, m, q)) return r;
  /* Visibility first (MP_SAMPLE_OPAQUE_DEPTH): which grids this pass takes,
   * and whether it is the one that finds their depth (and counts them). */
  uint kind = pass & MP_SAMPLE_KIND;
  int after = (pass & MP_SAMPLE_AFTER_MARK) != 0u;
  int opaque = mp_material_opaque(materials, patch_info, sp.patch);
  int live = 1;
  if (kind == MP_SAMPLE_OPAQUE_DEPTH)
    live = opaque;
  else if (kind == MP_SAMPLE_MARK)
    live = opaque && !visible[slot];
  else if (after && opaque)
    live = kind == MP_SAMPLE_ATTRIBUTES && visible[slot];
  if (!live) return r;
  int finds_depth = kind == MP_SAMPLE_OPAQUE_DEPTH || (kind == MP_SAMPLE_DEPTH && !(after && opaque));
  MpRasterVertex v[4]; /* counter-clockwise in (u, v) */
  float4 vp[4], vc[4], vn[4];
  ulong grid_base = (ulong)slot * stride * stride;
  int ok = 1;
  for (int k = 0; k < 4; ++k) {
    ulong idx = grid_base + q[k];
    vp[k] = grid_p[idx], vc[k] = grid_c[idx], vn[k] = grid_n[idx];
    v[k] = mp_raster_vertex(vp[k], vc[k], vn[k], f, &ok);
  }
  if (!ok) return r;
  long area2 = 0;
  uint keep = mp_quad_facing(v[0].p, v[1].p, v[2].p, v[3].p, mp_placed_flags(patch_info, instances, sp.patch, sp.instance), f, &area2);
  if (finds_depth && keys.tile) {
    long hx = clamp(min(min(v[0].p.x, v[1].p.x), min(v[2].p.x, v[3].p.x)) >> MP_SUBPIXEL_BITS, (long)0, (long)f.width - 1);
    long hy = clamp(min(min(v[0].p.y, v[1].p.y), min(v[2].p.y, v[3].p.y)) >> MP_SUBPIXEL_BITS, (long)0, (long)f.height - 1);
    finds_depth = hx >= keys.x0 && hx <= keys.x1 && hy >= keys.y0 && hy <= keys.y1;
  }
  r.area2 = finds_depth ? area2 : 0;
  if (!keep) return r;
  uint mp_id = mp_micropolygon_id(mp_grid_id(&sp), m);
  MpCover cover = {mp_quad_opacity(vc[0].w, vc[1].w, vc[2].w, vc[3].w),
                   mp_quad_opacity(vn[0].w, vn[1].w, vn[2].w, vn[3].w), mp_opacity_surface(mp_placed_patch_id(sp.patch, sp.instance)),
                   mp_material_cut(materials, patch_info, sp.patch) || mp_quad_cut(vc[0].w, vc[1].w, vc[2].w, vc[3].w)};
  /* Before shading, the grid's colours are not yet its own: opaque. */
  if (kind >= MP_SAMPLE_OPAQUE_DEPTH) cover.opacity = 1.0f, cover.holdout = 0.0f, cover.cut = 0;
  if (finds_depth && occlusion_dirty) mp_mark_occlusion_cells(occlusion_dirty, occ, f, v[0].p, v[1].p, v[2].p, v[3].p);
  uint tests = 0u;
  if (blur) {
    ulong idx[4];
    for (int k = 0; k < 4; ++k) idx[k] = grid_base + q[k];
    mp_raster_quad_blur(vp, grid_pm, idx, motion_stride, vc, vn, keep, mp_id, cover, f, sample_offsets, sample_table,
                        kind, keys, colors, normals, visible + slot, &tests);
  } else {
    mp_raster_quad(v, keep, mp_id, cover, f, sample_offsets, kind, keys, colors, normals, visible + slot, &tests);
  }
  r.tests = finds_depth ? tests : 0u;
  return r;
}

#endif
