/* Sample: a software rasteriser for micropolygons. Each work-item takes one
 * micropolygon (two triangles of a quad of a stitched grid, mp_grid.h; one of
 * them empty where the quad has collapsed into a triangle), finds the
 * jittered samples it covers with fixed-point edge functions, and resolves visibility per sample
 * with a 64-bit atomic minimum of (depth, micropolygon id) (the visibility
 * buffer trick of Karis et al. 2021, Nanite). A second pass, run after the
 * first has finished, lets the one micropolygon whose key won each sample write
 * its color and normal, so the result never depends on execution order. */
#pragma OPENCL EXTENSION cl_khr_int64_base_atomics : enable
#pragma OPENCL EXTENSION cl_khr_int64_extended_atomics : enable
#include "mp_compat.h"
#include "mp_patch.h"
#include "mp_types.h"
#include "mp_hash.h"
#include "mp_raster.h"
#include "mp_grid.h"
#include "mp_occlusion.h"

#define MP_PASS_DEPTH 0u
#define MP_PASS_ATTRIBUTES 1u

typedef struct {
  MpFixed2 p;
  float inv_d;    /* 1/depth (perspective) or depth (orthographic) */
  float3 c_over_d;
  float3 n_over_d;
} MpRasterVertex;

inline MpRasterVertex mp_raster_vertex(float4 p, float4 c, float4 n, FrameParams f, int* ok) {
  MpRasterVertex v;
  float d = -p.z;
  float inv = f.ortho ? 1.0f : 1.0f / d;
  float rx = f.ax * p.x * inv + f.bx, ry = f.ay * p.y * inv + f.by;
  if (!(fabs(rx) < MP_RASTER_GUARD && fabs(ry) < MP_RASTER_GUARD) || (!f.ortho && !(d > 0.0f))) *ok = 0;
  v.p.x = mp_to_fixed(rx);
  v.p.y = mp_to_fixed(ry);
  /* Perspective-correct interpolation: attributes / d and 1/d are affine in screen space. */
  float w = f.ortho ? 1.0f : inv;
  v.inv_d = f.ortho ? d : inv;
  v.c_over_d = c.xyz * w;
  v.n_over_d = n.xyz * w;
  return v;
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

/* Sample s of pixel (px, py), covered by triangle t at barycentrics (la,
 * lb, lc): within the clip range and the stochastic opacity, the depth pass
 * keeps the nearest key and the attribute pass lets its owner write. */
inline void mp_sample_write(const MpTriangle* t, float la, float lb, float lc, int px, int py, int s, int spp,
                            uint mp_id, float opacity, FrameParams f, uint pass, volatile __global ulong* keys,
                            __global float* colors, __global uint* normals) {
  float inv_d = la * t->a.inv_d + lb * t->b.inv_d + lc * t->c.inv_d;
  float d = f.ortho ? inv_d : 1.0f / inv_d;
  if (!(d >= f.clip_near && d <= f.clip_far)) return;
  ulong index = ((ulong)py * (ulong)f.width + (ulong)px) * (ulong)spp + (ulong)s;
  if (opacity < 1.0f && mp_hash_unit(mp_hash_combine(mp_id, (uint)index)) >= opacity) return;
  ulong key = ((ulong)as_uint(d) << 32) | (ulong)mp_id;
  if (pass == MP_PASS_DEPTH) {
    if (key < keys[index]) atom_min(&keys[index], key);
  } else if (keys[index] == key) {
    float w = f.ortho ? 1.0f : d;
    float3 col = (la * t->a.c_over_d + lb * t->b.c_over_d + lc * t->c.c_over_d) * w;
    float3 nrm = (la * t->a.n_over_d + lb * t->b.n_over_d + lc * t->c.n_over_d) * w;
    vstore3(col, index, colors);
    if (f.normal_pass) normals[index] = mp_encode_normal(normalize(nrm));
  }
}

/* Rasterises the quad's triangles (v00, v10, v11) and (v00, v11, v01) that
 * `keep` selects (bit 0 and bit 1). */
inline void mp_raster_quad(MpRasterVertex v00, MpRasterVertex v10, MpRasterVertex v11, MpRasterVertex v01, uint keep,
                           uint mp_id, float opacity, FrameParams f, __global const ushort* offsets, uint pass,
                           volatile __global ulong* keys, __global float* colors, __global uint* normals) {
  MpTriangle tris[2];
  tris[0] = mp_setup_triangle(v00, v10, v11);
  tris[1] = mp_setup_triangle(v00, v11, v01);
  tris[0].e.valid &= (int)(keep & 1u);
  tris[1].e.valid &= (int)(keep >> 1);
  long xmin = min(min(v00.p.x, v10.p.x), min(v11.p.x, v01.p.x)), xmax = max(max(v00.p.x, v10.p.x), max(v11.p.x, v01.p.x));
  long ymin = min(min(v00.p.y, v10.p.y), min(v11.p.y, v01.p.y)), ymax = max(max(v00.p.y, v10.p.y), max(v11.p.y, v01.p.y));
  int px0 = (int)max(xmin >> MP_SUBPIXEL_BITS, (long)0), px1 = (int)min(xmax >> MP_SUBPIXEL_BITS, (long)f.width - 1);
  int py0 = (int)max(ymin >> MP_SUBPIXEL_BITS, (long)0), py1 = (int)min(ymax >> MP_SUBPIXEL_BITS, (long)f.height - 1);
  int spp = f.spp_x * f.spp_y;
  for (int py = py0; py <= py1; ++py)
    for (int px = px0; px <= px1; ++px)
      for (int s = 0; s < spp; ++s) {
        MpFixed2 q = mp_sample_position(px, py, s, spp, f, offsets);
        if (q.x < xmin || q.x > xmax || q.y < ymin || q.y > ymax) continue;
        float la, lb, lc;
        int k = 0;
        if (!mp_edge_triangle_covers(&tris[0].e, q, &la, &lb, &lc)) {
          k = 1;
          if (!mp_edge_triangle_covers(&tris[1].e, q, &la, &lb, &lc)) continue;
        }
        mp_sample_write(&tris[k], la, lb, lc, px, py, s, spp, mp_id, opacity, f, pass, keys, colors, normals);
      }
}

/* Raster vertex of view-space point p seen from lens position L (zero
 * without a lens), with its attributes; 0 where it cannot be rasterised. */
inline int mp_blur_vertex(float3 p, float2 L, float4 c, float4 n, FrameParams f, MpRasterVertex* v) {
  float rx, ry, inv_d;
  if (f.ortho) {
    rx = f.ax * p.x + f.bx, ry = f.ay * p.y + f.by, inv_d = -p.z;
  } else if (!mp_project_lens(p, L, f, &rx, &ry, &inv_d)) {
    return 0;
  }
  if (!(fabs(rx) < MP_RASTER_GUARD && fabs(ry) < MP_RASTER_GUARD)) return 0;
  float w = f.ortho ? 1.0f : inv_d;
  v->p.x = mp_to_fixed(rx);
  v->p.y = mp_to_fixed(ry);
  v->inv_d = inv_d;
  v->c_over_d = c.xyz * w;
  v->n_over_d = n.xyz * w;
  return 1;
}

/* Grows the raster box by view-space point p seen from every lens position
 * of the box bx (x range) by (y range); 0 where p is behind the lens. */
inline int mp_blur_box(float3 p, float2 bx, float2 by, FrameParams f, float* box) {
  float x0, x1, y0, y1;
  if (f.ortho) {
    x0 = x1 = f.ax * p.x + f.bx, y0 = y1 = f.ay * p.y + f.by;
  } else {
    float d = -p.z;
    if (!(d > 0.0f)) return 0;
    float inv = 1.0f / d, k = 1.0f / f.focus_distance - inv;
    x0 = f.ax * (p.x * inv + bx.x * k) + f.bx, x1 = f.ax * (p.x * inv + bx.y * k) + f.bx;
    y0 = f.ay * (p.y * inv + by.x * k) + f.by, y1 = f.ay * (p.y * inv + by.y * k) + f.by;
  }
  box[0] = fmin(box[0], fmin(x0, x1)), box[1] = fmax(box[1], fmax(x0, x1));
  box[2] = fmin(box[2], fmin(y0, y1)), box[3] = fmax(box[3], fmax(y0, y1));
  return 1;
}

/* The quad as samples that carry times and lens positions see it
 * (mp_blur.h): each sample slot s has its own bound, the quad's raster box
 * over the times and lens positions its slot takes (the table's box of slot
 * s after the tile's entries: (lx0, lx1, ly0, ly1), (t0, t1)), and each
 * sample in it moves the four vertices to its own time and lens position
 * before the same fixed-point edge tests. Shared vertices move alike in
 * every sample, so the grid stays watertight in each. Triangles keep the
 * shutter centre's culling (`keep`); attributes are the centre's (shading
 * once per grid vertex). Motion positions: pm[idx[i] + k * stride] for step k. */
inline void mp_raster_quad_blur(const float4* p, __global const float4* pm, const ulong* idx, ulong stride,
                                const float4* c, const float4* n, uint keep, uint mp_id, float opacity, FrameParams f,
                                __global const ushort* offsets, __global const float4* table, uint pass,
                                volatile __global ulong* keys, __global float* colors, __global uint* normals) {
  int spp = f.spp_x * f.spp_y;
  int steps = mp_motion_on(f) ? f.motion_steps : 0;
  __global const float4* slot_boxes = table + MP_SAMPLE_TILE * MP_SAMPLE_TILE * spp;
  for (int s = 0; s < spp; ++s) {
    float4 lb = slot_boxes[2 * s], tb = slot_boxes[2 * s + 1];
    float2 bx = (float2)(lb.x, lb.y), by = (float2)(lb.z, lb.w);
    float box[4] = {3.0e38f, -3.0e38f, 3.0e38f, -3.0e38f};
    int ok = 1;
    for (int i = 0; i < 4 && ok; ++i) {
      if (!steps) {
        ok = mp_blur_box(p[i].xyz, bx, by, f, box);
        continue;
      }
      /* Linear between steps: the ends of the slot's time range and the
       * steps inside it bound the path (perspective keeps lines straight). */
      ok = mp_blur_box(mp_motion_position(pm + idx[i], stride, steps, tb.x).xyz, bx, by, f, box) &&
           mp_blur_box(mp_motion_position(pm + idx[i], stride, steps, tb.y).xyz, bx, by, f, box);
      for (int k = 1; k + 1 < steps && ok; ++k) {
        float tk = (float)k / (float)(steps - 1);
        if (tk > tb.x && tk < tb.y) ok = mp_blur_box(pm[idx[i] + (ulong)k * stride].xyz, bx, by, f, box);
      }
    }
    if (!ok) continue;
    /* One fixed-point unit of slack for the rounding of positions. */
    long fx0 = mp_to_fixed(box[0]) - 1, fx1 = mp_to_fixed(box[1]) + 1;
    long fy0 = mp_to_fixed(box[2]) - 1, fy1 = mp_to_fixed(box[3]) + 1;
    int px0 = (int)max(fx0 >> MP_SUBPIXEL_BITS, (long)0), px1 = (int)min(fx1 >> MP_SUBPIXEL_BITS, (long)f.width - 1);
    int py0 = (int)max(fy0 >> MP_SUBPIXEL_BITS, (long)0), py1 = (int)min(fy1 >> MP_SUBPIXEL_BITS, (long)f.height - 1);
    for (int py = py0; py <= py1; ++py)
      for (int px = px0; px <= px1; ++px) {
        MpFixed2 sq = mp_sample_position(px, py, s, spp, f, offsets);
        if (sq.x < fx0 || sq.x > fx1 || sq.y < fy0 || sq.y > fy1) continue;
        int tx = (px + f.crop_x0) & (MP_SAMPLE_TILE - 1), ty = (py + f.crop_y0) & (MP_SAMPLE_TILE - 1);
        float4 e = table[(ty * MP_SAMPLE_TILE + tx) * spp + s];
        MpRasterVertex v[4];
        int live = 1;
        for (int i = 0; i < 4; ++i) {
          float3 q = steps ? mp_motion_position(pm + idx[i], stride, steps, e.z).xyz : p[i].xyz;
          live &= mp_blur_vertex(q, (float2)(e.x, e.y), c[i], n[i], f, &v[i]);
        }
        if (!live) continue;
        MpTriangle tris[2];
        tris[0] = mp_setup_triangle(v[0], v[1], v[2]);
        tris[1] = mp_setup_triangle(v[0], v[2], v[3]);
        tris[0].e.valid &= (int)(keep & 1u);
        tris[1].e.valid &= (int)(keep >> 1);
        float la, lb, lc;
        int t = 0;
        if (!mp_edge_triangle_covers(&tris[0].e, sq, &la, &lb, &lc)) {
          t = 1;
          if (!mp_edge_triangle_covers(&tris[1].e, sq, &la, &lb, &lc)) continue;
        }
        mp_sample_write(&tris[t], la, lb, lc, px, py, s, spp, mp_id, opacity, f, pass, keys, colors, normals);
      }
  }
}

/* Micropolygons that reach the rasteriser and their total screen area, summed
 * per work-group in local memory (one atomic per group): the dicing density
 * the benchmarks report as micropolygons per pixel of surface. */
inline void mp_count_sampled(uint l, long area2, uint pass, volatile __global ulong* totals, __local ulong* area_sum,
                             __local uint* count_sum) {
  area_sum[l] = (ulong)area2;
  count_sum[l] = area2 > 0 ? 1u : 0u;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint s = 32u; s > 0u; s >>= 1) {
    if (l < s) {
      area_sum[l] += area_sum[l + s];
      count_sum[l] += count_sum[l + s];
    }
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (pass == MP_PASS_DEPTH && l == 0u && count_sum[0] > 0u) {
    atom_add(&totals[0], (ulong)count_sum[0]);
    atom_add(&totals[1], area_sum[0]);
  }
}

/* Marks the occlusion pyramid's level-0 cells under the micropolygon's
 * raster bound as changed (occlusion.cl rebuilds only those). */
inline void mp_mark_occlusion_cells(__global uchar* dirty, OcclusionParams o, FrameParams f, MpFixed2 a, MpFixed2 b,
                                    MpFixed2 c, MpFixed2 d) {
  long xmin = min(min(a.x, b.x), min(c.x, d.x)), xmax = max(max(a.x, b.x), max(c.x, d.x));
  long ymin = min(min(a.y, b.y), min(c.y, d.y)), ymax = max(max(a.y, b.y), max(c.y, d.y));
  int x0 = (int)clamp(xmin >> MP_SUBPIXEL_BITS, (long)0, (long)f.width - 1) >> o.cell_shift;
  int x1 = (int)clamp(xmax >> MP_SUBPIXEL_BITS, (long)0, (long)f.width - 1) >> o.cell_shift;
  int y0 = (int)clamp(ymin >> MP_SUBPIXEL_BITS, (long)0, (long)f.height - 1) >> o.cell_shift;
  int y1 = (int)clamp(ymax >> MP_SUBPIXEL_BITS, (long)0, (long)f.height - 1) >> o.cell_shift;
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) dirty[y * o.base_w + x] = (uchar)1;
}

/* One work-item per micropolygon of grids [first, first + count): `offsets`
 * holds each grid of the batch's first micropolygon (from the batch's
 * layout, GridLayoutStage), `base` is the first of these grids' and `total`
 * their number. A work-item finds its grid by binary search, so no
 * work-item idles on an unused grid slot. */
__kernel __attribute__((reqd_work_group_size(64, 1, 1)))
void sample_micropolygons(__global const SubPatch* diceable, uint first, uint count, __global const uint* offsets,
                                   uint base, uint total, __global const uint* patch_info,
                                   FrameParams f, __global const float4* grid_p, __global const float4* grid_c,
                                   __global const float4* grid_n, __global const ushort* sample_offsets, uint pass,
                                   volatile __global ulong* keys,
                                   __global float* colors, __global uint* normals, volatile __global ulong* totals,
                                   __global uchar* occlusion_dirty, OcclusionParams occ,
                                   __global const float4* sample_table, __global const float4* grid_pm,
                                   ulong motion_stride) {
  __local ulong area_sum[64];
  __local uint count_sum[64];
  uint stride = (uint)f.max_grid + 1u;
  uint gid = get_global_id(0);
  int live = gid < total && count > 0u;
  uint slot = first, m = 0u;
  SubPatch sp;
  MpGridShape g;
  uint q[4];
  if (live) {
    slot = first + mp_find_grid(offsets + first, count, base + gid);
    m = base + gid - offsets[slot];
    sp = diceable[slot];
    g = mp_grid_shape(&sp, (uint)f.max_grid);
    live = mp_grid_micropolygon(&g, m, q);
  }
  MpRasterVertex v[4]; /* counter-clockwise in (u, v) */
  float4 vp[4], vc[4], vn[4];
  ulong grid_base = (ulong)slot * stride * stride;
  if (live) {
    int ok = 1;
    for (int k = 0; k < 4; ++k) {
      ulong idx = grid_base + q[k];
      vp[k] = grid_p[idx], vc[k] = grid_c[idx], vn[k] = grid_n[idx];
      v[k] = mp_raster_vertex(vp[k], vc[k], vn[k], f, &ok);
    }
    live = ok;
  }
  uint keep = 0u;
  long area2 = 0;
  if (live) {
    /* Front faces run counter-clockwise on screen, i.e. negative raster
     * area. Each triangle is culled on its own: a quad of a stitching strip
     * can turn one triangle away near a silhouette while the other still
     * faces the camera. */
    uint flags = patch_info[4 * (ulong)sp.patch + 2];
    long a0 = mp_edge(v[0].p, v[1].p, v[2].p), a1 = mp_edge(v[0].p, v[2].p, v[3].p);
    keep = 3u;
    if (f.backface_culling && !(flags & MP_PATCH_DOUBLE_SIDED)) {
      int flip = (flags & MP_PATCH_FLIP_ORIENTATION) != 0u;
      keep = ((flip ? a0 > 0 : a0 < 0) ? 1u : 0u) | ((flip ? a1 > 0 : a1 < 0) ? 2u : 0u);
    }
    area2 = ((keep & 1u) ? (a0 < 0 ? -a0 : a0) : 0) + ((keep & 2u) ? (a1 < 0 ? -a1 : a1) : 0);
  }
  mp_count_sampled(get_local_id(0), area2, pass, totals, area_sum, count_sum);
  if (!keep) return;
  uint grid_id = mp_hash32(sp.patch);
  for (int k = 0; k < 8; ++k) grid_id = mp_hash_combine(grid_id, as_uint(sp.corner[k]));
  uint mp_id = mp_hash_combine(grid_id, m);
  float opacity = grid_c[grid_base + q[0]].w;
  if (pass == MP_PASS_DEPTH && occlusion_dirty) mp_mark_occlusion_cells(occlusion_dirty, occ, f, v[0].p, v[1].p, v[2].p, v[3].p);
  if (mp_blur_on(f)) {
    ulong idx[4];
    for (int k = 0; k < 4; ++k) idx[k] = grid_base + q[k];
    mp_raster_quad_blur(vp, grid_pm, idx, motion_stride, vc, vn, keep, mp_id, opacity, f, sample_offsets, sample_table, pass,
                        keys, colors, normals);
  } else
    mp_raster_quad(v[0], v[1], v[2], v[3], keep, mp_id, opacity, f, sample_offsets, pass, keys, colors, normals);
}
