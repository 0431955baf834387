// The binned sampler (kernels/stages/sample_bins.cl; made for GPUs, taken
// only where RenderSettings::sampler asks for it): a batch's
// runs of micropolygons are bounded in bins, counted, offset and scattered
// into per-bin lists by three small launches, then a work-group per bin
// samples them with the bin's keys in local memory. Nothing comes back to
// the host: the lists' room is fixed by the batch's runs (each reaches at
// most MP_BIN_RUN_TILES bins; the runs reaching more are sampled by the
// per-micropolygon sampler beside the bins).
#include <algorithm>

#include "core/mp_compat.h"
#include "core/mp_types.h"
#include "geometry/mp_grid.h"
#include "stages/mp_raster.h"
#include "pipeline/pass/micropolygon_stages.h"
#include "cl/kernel_args.h"

namespace mp {

int SampleStage::bin_side(int spp, size_t local_bytes) {
  // 8 KiB of the device's local memory are left to the kernel's own arrays
  // and the driver.
  const size_t room = std::min(kBinKeyBytes, local_bytes > 8192 ? local_bytes - 8192 : 0);
  for (size_t side : {32, 16, 8})
    if (side * side * size_t(spp) * sizeof(cl_ulong) <= room) return int(side);
  return 0;
}

void SampleStage::bin_on_device(const cl::Buffer& diceable, cl_uint first, cl_uint count, const FrameParams& f,
                                GridBuffers& grids, StageTimer& timer) {
  DeviceQueue& q = session_.queue();
  bin_first_ = first;
  bin_count_ = count;
  bin_runs_per_grid_ = (mp_grid_max_micropolygons(cl_uint(f.max_grid)) + MP_TILE_RUN - 1) / MP_TILE_RUN;
  // Room for the largest batch, so the lists are sized once.
  const size_t most_runs = size_t(grids.capacity) * bin_runs_per_grid_;
  const cl_uint runs = count * bin_runs_per_grid_;
  session_.reserve(bin_rects_, bin_rect_bytes_, most_runs * sizeof(cl_int4), "bin bounds");
  session_.reserve(bin_entries_, bin_entry_bytes_, most_runs * MP_BIN_RUN_TILES * sizeof(cl_uint), "bin lists");
  const cl_uint bins = bins_x_ * bins_y_;
  bind_args(bin_runs_, diceable, first, count, f, grids.p, bin_runs_per_grid_, cl_int(bin_side_), bins_x_,
            bin_rects_, bin_counts_);
  cl::Event bounded, offset, scattered;
  q.enqueueNDRangeKernel(bin_runs_, cl::NullRange, round_up_range(runs), cl::NDRange(64), nullptr, &bounded);
  timer.add(Stage::Sample, bounded);
  bind_args(bin_offsets_, bin_counts_, bins, bin_starts_, bin_cursors_);
  q.enqueueNDRangeKernel(bin_offsets_, cl::NullRange, cl::NDRange(MP_BIN_GROUP), cl::NDRange(MP_BIN_GROUP), nullptr,
                         &offset);
  timer.add(Stage::Sample, offset);
  bind_args(bin_scatter_, runs, bins_x_, bin_rects_, bin_cursors_, bin_entries_);
  q.enqueueNDRangeKernel(bin_scatter_, cl::NullRange, round_up_range(runs), cl::NDRange(64), nullptr, &scattered);
  timer.add(Stage::Sample, scattered);
}

void SampleStage::sample_bins(const cl::Buffer& diceable, const SceneBuffers& scene, const FrameParams& f,
                              GridBuffers& grids, StageTimer& timer, cl_uint pass) {
  const cl_uint kind = pass & MP_SAMPLE_KIND, after = pass & MP_SAMPLE_AFTER_MARK;
  // The wide runs first, by sample.cl's passes; the bins' own depth phase
  // then starts from their keys, and whichever is nearest writes last.
  if (kind == MP_SAMPLE_ATTRIBUTES) {
    sample_micropolygons(diceable, bin_first_, bin_count_, scene, f, grids, timer, MP_SAMPLE_DEPTH | after, true);
    sample_micropolygons(diceable, bin_first_, bin_count_, scene, f, grids, timer, pass, true);
  } else {
    sample_micropolygons(diceable, bin_first_, bin_count_, scene, f, grids, timer, pass, true);
  }
  const int spp = f.spp_x * f.spp_y;
  const size_t key_bytes = size_t(bin_side_) * size_t(bin_side_) * size_t(spp) * sizeof(cl_ulong);
  cl::Kernel& k = bins_kernel_.bind(scene, diceable, bin_first_, f, grids.p, grids.c, grids.n, offsets_, bin_starts_,
                                    bin_entries_, bin_runs_per_grid_, cl_int(bin_side_), bins_x_, pass, keys_,
                                    colors_, normals_, totals_, occlusion_dirty_, occlusion_, grids.visible,
                                    cl::Local(key_bytes));
  cl::Event e;
  const size_t bins = size_t(bins_x_) * bins_y_;
  session_.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(bins * MP_BIN_GROUP), cl::NDRange(MP_BIN_GROUP),
                                        nullptr, &e);
  timer.add(Stage::Sample, e);
}

}  // namespace mp
