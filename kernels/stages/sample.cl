/* Sample, one work-item per micropolygon (mp_quad_sampler.h): each resolves
 * visibility per sample with a 64-bit atomic minimum of (depth, micropolygon
 * id) on the frame's keys (the visibility buffer trick of Karis et al. 2021,
 * Nanite). A second pass, run after the first has finished, lets the one
 * micropolygon whose key won each sample write its color and normal, so the
 * result never depends on execution order. */
#include "stages/mp_quad_sampler.h"

/* The sampler's body for one work-item; `blur` (a constant in each kernel
 * below) picks the stochastic path, so the pinhole kernel carries none of
 * its code. */
#define MP_SAMPLE_ARGS                                                                                                 \
  __global const SubPatch *diceable, uint first, uint count, __global const uint *offsets, uint base, uint total,    \
      FrameParams f, __global const float4 *grid_p, __global const float4 *grid_c,                                   \
      __global const float4 *grid_n, __global const ushort *sample_offsets, uint pass, volatile __global ulong *keys, \
      __global float *colors, __global uint *normals, volatile __global ulong *totals,                               \
      __global uchar *occlusion_dirty, OcclusionParams occ, __global const float4 *sample_table,                      \
      __global const float4 *grid_pm, ulong motion_stride, __global uchar *visible, __global const int4 *bin_rects, \
      uint bin_runs
#define MP_SAMPLE_PASS                                                                                                 \
  diceable, first, count, offsets, base, total, f, grid_p, grid_c, grid_n, sample_offsets, pass, keys,                \
      colors, normals, totals, occlusion_dirty, occ, sample_table, grid_pm, motion_stride, visible, bin_rects, bin_runs

/* One work-item per micropolygon of grids [first, first + count): `offsets`
 * holds each grid of the batch's first micropolygon (from the batch's
 * layout, GridLayoutStage), `base` is the first of these grids' and `total`
 * their number. A work-item finds its grid by binary search, so no
 * work-item idles on an unused grid slot. */
inline void mp_sample(__global const uint* patch_info, __global const DeviceInstance* instances,
                      __global const DeviceMaterial* materials, MP_SAMPLE_ARGS,
                      __local ulong* area_sum, __local uint* count_sum, __local uint* test_sum, const int blur) {
  uint gid = get_global_id(0);
  MpSampled r = {0, 0u};
  if (gid < total && count > 0u) {
    uint slot = first + mp_find_grid(offsets + first, count, base + gid);
    uint m = base + gid - offsets[slot];
    /* Beside the binned sampler (sample_bins.cl): only the runs it left out. */
    if (!bin_runs || bin_rects[(ulong)(slot - first) * bin_runs + m / MP_TILE_RUN].x < 0)
      r = mp_sample_micropolygon(patch_info, instances, materials, diceable, slot, m, f, grid_p, grid_c, grid_n, sample_offsets,
                                 sample_table, grid_pm, motion_stride, pass, mp_frame_keys(keys, f), colors, normals,
                                 occlusion_dirty, occ, visible, blur);
  }
  /* Uniform over the work-group: whether this pass counts at all. */
  uint kind = pass & MP_SAMPLE_KIND;
  int counting = kind == MP_SAMPLE_DEPTH || kind == MP_SAMPLE_OPAQUE_DEPTH;
  mp_count_sampled(get_local_id(0), (ulong)r.area2, r.area2 > 0 ? 1u : 0u, r.tests, counting, totals, area_sum,
                   count_sum, test_sum);
}

__kernel __attribute__((reqd_work_group_size(64, 1, 1))) void sample_micropolygons(MP_SCENE_PARAMS MP_SAMPLE_ARGS) {
  __local ulong area_sum[64];
  __local uint count_sum[64], test_sum[64];
  mp_sample(patch_info, instances, materials, MP_SAMPLE_PASS, area_sum, count_sum, test_sum, 0);
}

/* Samples with times and lens positions (mp_blur.h). */
__kernel __attribute__((reqd_work_group_size(64, 1, 1)))
void sample_micropolygons_blur(MP_SCENE_PARAMS MP_SAMPLE_ARGS) {
  __local ulong area_sum[64];
  __local uint count_sum[64], test_sum[64];
  mp_sample(patch_info, instances, materials, MP_SAMPLE_PASS, area_sum, count_sum, test_sum, 1);
}

/* Visibility first's count, after its mark pass: one work-item per grid of
 * the batch, adding to totals[3] the opaque grids that own no sample, which
 * shading skips. */
__kernel void count_unshaded(MP_SCENE_PARAMS __global const SubPatch* diceable, uint count,
                             __global const uchar* visible, volatile __global ulong* totals) {
  uint k = get_global_id(0);
  if (k >= count || visible[k] || !mp_material_opaque(materials, patch_info, diceable[k].patch)) return;
  atom_add(&totals[3], 1ul);
}
