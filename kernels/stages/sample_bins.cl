/* Sample by bins (RenderSettings::sampler "bins"): a sort-middle
 * rasteriser (Laine & Karras 2011, "High-performance software rasterization
 * on GPUs") whose bins are small enough that their samples' keys fit a
 * work-group's local memory. Per
 * batch, with no host round trip:
 *  - bin_runs bounds each run of MP_TILE_RUN micropolygons of a grid in
 *    bins and counts the runs per bin;
 *  - bin_offsets turns the counts into each bin's first entry;
 *  - bin_scatter writes each run into the lists of the bins it reaches;
 *  - sample_bins: a work-group per bin loads the bin's keys into local
 *    memory, finds every sample's nearest key among its runs' micropolygons
 *    with local atomics, lets each sample's owner write its colour and
 *    normal, and stores the keys back once.
 * The micropolygons are rasterised by the same code as the
 * per-micropolygon sampler (mp_quad_sampler.h) and the nearest key wins
 * whatever the order, so the image is that sampler's bit for bit. Runs that
 * reach more than MP_BIN_RUN_TILES bins are marked (x < 0 in their rect)
 * and sampled by sample.cl beside these. Made for GPUs, it loses to
 * sample.cl on them: a batch's grids cover a few of the frame's bins, so
 * few work-groups run (docs/performance.md, "Sample by bins"). */
#include "stages/mp_quad_sampler.h"

/* The bins that run r of grid k (of diceable sub-patches [first, first +
 * count); runs_per_grid per grid) reaches, as (bx0, by0, bx1, by1): none
 * (bx0 > bx1) where no micropolygon of it can be rasterised inside the
 * frame, x < 0 where they are more than MP_BIN_RUN_TILES; counted in
 * `counts` (one per bin, bins_x per row) where they are not. */
__kernel void bin_runs(__global const SubPatch* diceable, uint first, uint count, FrameParams f,
                       __global const float4* grid_p, uint runs_per_grid, int side, uint bins_x,
                       __global int4* rects, volatile __global uint* counts) {
  uint gid = get_global_id(0), m0, m1;
  MpGridShape g;
  ulong base;
  if (!mp_grid_run(diceable, first, count, gid, runs_per_grid, f, &g, &base, &m0, &m1)) return;
  long x0 = LONG_MAX, y0 = LONG_MAX, x1 = LONG_MIN, y1 = LONG_MIN;
  for (uint m = m0; m < m1; ++m) {
    uint q[4];
    if (!mp_grid_micropolygon(&g, m, q)) continue;
    MpFixed2 p[4];
    int ok = 1;
    for (int i = 0; i < 4; ++i) {
      float inv_d;
      p[i] = mp_raster_position(grid_p[base + q[i]], f, &inv_d, &ok);
    }
    if (!ok) continue;
    for (int i = 0; i < 4; ++i) x0 = min(x0, p[i].x), x1 = max(x1, p[i].x), y0 = min(y0, p[i].y), y1 = max(y1, p[i].y);
  }
  int4 r = (int4)(1, 1, 0, 0);
  if (x0 <= x1 && x1 >= 0 && y1 >= 0 && (x0 >> MP_SUBPIXEL_BITS) < f.width && (y0 >> MP_SUBPIXEL_BITS) < f.height) {
    int px0 = (int)max(x0 >> MP_SUBPIXEL_BITS, (long)0), px1 = (int)min(x1 >> MP_SUBPIXEL_BITS, (long)f.width - 1);
    int py0 = (int)max(y0 >> MP_SUBPIXEL_BITS, (long)0), py1 = (int)min(y1 >> MP_SUBPIXEL_BITS, (long)f.height - 1);
    r = (int4)(px0 / side, py0 / side, px1 / side, py1 / side);
    if ((r.z - r.x + 1) * (r.w - r.y + 1) > MP_BIN_RUN_TILES) {
      r = (int4)(-1, -1, -1, -1);
    } else {
      for (int by = r.y; by <= r.w; ++by)
        for (int bx = r.x; bx <= r.z; ++bx) atomic_inc(&counts[(uint)by * bins_x + (uint)bx]);
    }
  }
  rects[gid] = r;
}

/* One work-group: each bin's first entry (an exclusive prefix sum of
 * `counts` into `starts`, its total in starts[n]), the same into `cursors`
 * for bin_scatter, and the counts cleared for the next batch. */
__kernel __attribute__((reqd_work_group_size(MP_BIN_GROUP, 1, 1))) void bin_offsets(__global uint* counts, uint n,
                                                                                     __global uint* starts,
                                                                                     __global uint* cursors) {
  __local uint sums[MP_BIN_GROUP];
  uint l = get_local_id(0), carry = 0u;
  for (uint base = 0u; base < n; base += MP_BIN_GROUP) {
    uint i = base + l, v = i < n ? counts[i] : 0u;
    sums[l] = v;
    barrier(CLK_LOCAL_MEM_FENCE);
    /* Inclusive scan of the chunk (Hillis & Steele 1986). */
    for (uint d = 1u; d < MP_BIN_GROUP; d <<= 1) {
      uint add = l >= d ? sums[l - d] : 0u;
      barrier(CLK_LOCAL_MEM_FENCE);
      sums[l] += add;
      barrier(CLK_LOCAL_MEM_FENCE);
    }
    if (i < n) {
      starts[i] = cursors[i] = carry + sums[l] - v;
      counts[i] = 0u;
    }
    carry += sums[MP_BIN_GROUP - 1];
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (l == 0u) starts[n] = carry;
}

/* Each binned run (rects from bin_runs; `runs` of them) into the list of
 * every bin it reaches: entry k * runs_per_grid + r. The order within a
 * list follows the atomics, which the nearest key makes harmless. */
__kernel void bin_scatter(uint runs, uint bins_x, __global const int4* rects, volatile __global uint* cursors,
                          __global uint* entries) {
  uint gid = get_global_id(0);
  if (gid >= runs) return;
  int4 r = rects[gid];
  if (r.x < 0) return;
  for (int by = r.y; by <= r.w; ++by)
    for (int bx = r.x; bx <= r.z; ++bx) entries[atomic_inc(&cursors[(uint)by * bins_x + (uint)bx])] = gid;
}

/* What a work-item of sample_bins counted (as sample.cl's mp_count_sampled). */
typedef struct {
  ulong area2;
  uint micropolygons, tests;
} MpBinCounts;

/* One phase of sample_bins: every micropolygon of the bin's runs through
 * pass `pass`, the work-group's items taking them in turn. */
inline MpBinCounts mp_bin_phase(__global const uint* patch_info, __global const DeviceInstance* instances,
                                __global const DeviceMaterial* materials,
                                __global const SubPatch* diceable, uint first, FrameParams f,
                                __global const float4* grid_p, __global const float4* grid_c,
                                __global const float4* grid_n, __global const ushort* sample_offsets,
                                __global const uint* entries, uint start, uint n, uint runs_per_grid, uint pass,
                                MpKeys keys, __global float* colors, __global uint* normals,
                                __global uchar* occlusion_dirty, OcclusionParams occ, __global uchar* visible) {
  MpBinCounts c = {0ul, 0u, 0u};
  for (uint i = get_local_id(0); i < n * MP_TILE_RUN; i += MP_BIN_GROUP) {
    uint e = entries[start + i / MP_TILE_RUN];
    uint slot = first + e / runs_per_grid, m = (e % runs_per_grid) * MP_TILE_RUN + i % MP_TILE_RUN;
    /* Pinhole frames only: no motion steps, no lens table. */
    MpSampled r = mp_sample_micropolygon(patch_info, instances, materials, diceable, slot, m, f, grid_p, grid_c, grid_n,
                                         sample_offsets, grid_p, grid_p, 0ul, pass, keys, colors, normals,
                                         occlusion_dirty, occ, visible, 0);
    c.area2 += (ulong)r.area2;
    c.micropolygons += r.area2 > 0 ? 1u : 0u;
    c.tests += r.tests;
  }
  return c;
}

/* A work-group per bin of `side` pixels (bins_x per row): its lists
 * (entries[starts[b], starts[b + 1])) through pass `pass`:
 * MP_SAMPLE_ATTRIBUTES (a depth phase, then the attributes' phase),
 * MP_SAMPLE_OPAQUE_DEPTH or MP_SAMPLE_MARK, each with MP_SAMPLE_AFTER_MARK
 * where visibility first took the batch. tile_keys: side * side * spp
 * keys. totals: as sample.cl's. */
__kernel __attribute__((reqd_work_group_size(MP_BIN_GROUP, 1, 1))) void sample_bins(
    MP_SCENE_PARAMS __global const SubPatch* diceable, uint first, FrameParams f, __global const float4* grid_p,
    __global const float4* grid_c, __global const float4* grid_n, __global const ushort* sample_offsets,
    __global const uint* starts, __global const uint* entries, uint runs_per_grid, int side, uint bins_x, uint pass,
    volatile __global ulong* keys, __global float* colors, __global uint* normals, volatile __global ulong* totals,
    __global uchar* occlusion_dirty, OcclusionParams occ, __global uchar* visible, __local ulong* tile_keys) {
  __local ulong sums[3];
  uint b = get_group_id(0), l = get_local_id(0);
  uint start = starts[b], n = starts[b + 1u] - start;
  if (n == 0u) return; /* the whole work-group */
  MpKeys k;
  k.frame = keys;
  k.tile = tile_keys;
  k.x0 = (int)(b % bins_x) * side, k.y0 = (int)(b / bins_x) * side;
  k.x1 = min(k.x0 + side, f.width) - 1, k.y1 = min(k.y0 + side, f.height) - 1;
  k.stride = side;
  int spp = f.spp_x * f.spp_y;
  /* The bin's keys: each of its rows is a contiguous run of the frame's. */
  uint row = (uint)((k.x1 - k.x0 + 1) * spp), rows = (uint)(k.y1 - k.y0 + 1);
  for (uint i = l; i < row * rows; i += MP_BIN_GROUP) {
    uint y = i / row, x = i % row;
    tile_keys[y * (uint)(side * spp) + x] = keys[((ulong)(k.y0 + (int)y) * (ulong)f.width + (ulong)k.x0) * (ulong)spp + x];
  }
  if (l < 3u) sums[l] = 0ul;
  barrier(CLK_LOCAL_MEM_FENCE);
  uint kind = pass & MP_SAMPLE_KIND, after = pass & MP_SAMPLE_AFTER_MARK;
  MpBinCounts c = {0ul, 0u, 0u};
  /* Phase 0 finds the depths (all but the mark pass), phase 1 writes the
   * attributes or marks. One call site, so the rasteriser is inlined once
   * (called twice, NVIDIA's compiler made it a call, several times slower). */
  uint phase0 = kind == MP_SAMPLE_MARK ? 1u : 0u, phase1 = kind == MP_SAMPLE_OPAQUE_DEPTH ? 0u : 1u;
  for (uint phase = phase0; phase <= phase1; ++phase) {
    uint p = phase == 1u ? pass : (kind == MP_SAMPLE_ATTRIBUTES ? MP_SAMPLE_DEPTH : kind) | after;
    MpBinCounts pc = mp_bin_phase(patch_info, instances, materials, diceable, first, f, grid_p, grid_c, grid_n, sample_offsets,
                                  entries, start, n, runs_per_grid, p, k, colors, normals, occlusion_dirty, occ, visible);
    if (phase == 0u) c = pc;
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (kind != MP_SAMPLE_MARK)
    for (uint i = l; i < row * rows; i += MP_BIN_GROUP) {
      uint y = i / row, x = i % row;
      keys[((ulong)(k.y0 + (int)y) * (ulong)f.width + (ulong)k.x0) * (ulong)spp + x] = tile_keys[y * (uint)(side * spp) + x];
    }
  /* The work-group's counts by local atomics, then one global atomic each. */
  if (kind != MP_SAMPLE_MARK) {
    if (c.micropolygons) {
      atom_add(&sums[0], (ulong)c.micropolygons);
      atom_add(&sums[1], c.area2);
      atom_add(&sums[2], (ulong)c.tests);
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    if (l == 0u && sums[0] > 0u)
      for (int i = 0; i < 3; ++i) atom_add(&totals[i], sums[i]);
  }
}
