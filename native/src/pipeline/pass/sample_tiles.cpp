// The sample stage by screen tiles (kernels/stages/sample_tiles.cl), for CPUs: the
// grids of a dice batch are projected and their runs of micropolygons
// bounded on the device, sorted into per-tile lists here (a counting sort
// over some ten thousand runs: cheaper than a device sort's launches, and it
// keeps each list in batch order, so the output never depends on timing),
// then each non-empty tile is sampled by one work-item.
#include <algorithm>

#include "core/mp_compat.h"
#include "core/mp_types.h"
#include "geometry/mp_grid.h"
#include "stages/mp_raster.h"
#include "pipeline/pass/micropolygon_stages.h"
#include "cl/kernel_args.h"

namespace mp {
namespace {

// Room for `count` elements of `size` bytes, and half as many again when it
// grows (the lists' lengths vary from batch to batch).
void ensure(DeviceSession& s, cl::Buffer& buffer, size_t& capacity, size_t count, size_t size, const char* what) {
  if (count * size <= capacity && capacity > 0) return;
  s.reserve(buffer, capacity, std::max(count * size, capacity + capacity / 2), what);
}

// Work-items (tiles) per work-group of the tile sampler.
constexpr size_t kTileGroup = 1;
// Tiles per launch when the caller may cancel: a few tens of milliseconds
// of a 2-core CPU's work.
constexpr cl_uint kTileChunk = 128;

}  // namespace

bool SampleStage::bin_tiles(const cl::Buffer& diceable, cl_uint first, cl_uint count, const FrameParams& f,
                            GridBuffers& grids, StageTimer& timer) {
  DeviceQueue& q = session_.queue();
  ensure(session_, projected_, projected_bytes_, grids.slot_space(), sizeof(cl_int4), "projected grid vertices");
  // Runs of micropolygons per grid (MP_TILE_RUN): enough for the largest grid.
  const cl_uint runs_per_grid = (mp_grid_max_micropolygons(cl_uint(f.max_grid)) + MP_TILE_RUN - 1) / MP_TILE_RUN;
  const size_t runs = size_t(count) * runs_per_grid;
  ensure(session_, rects_, rect_bytes_, size_t(grids.capacity) * runs_per_grid, sizeof(cl_int4), "run tile bounds");
  bind_args(project_, diceable, first, count, f, grids.p, projected_);
  cl::Event e;
  q.enqueueNDRangeKernel(project_, cl::NullRange, round_up_range(count), cl::NDRange(64), nullptr, &e);
  timer.add(Stage::Sample, e);
  bind_args(bound_runs_, diceable, first, count, f, projected_, runs_per_grid, rects_);
  cl::Event b;
  q.enqueueNDRangeKernel(bound_runs_, cl::NullRange, round_up_range(runs), cl::NDRange(64), nullptr, &b);
  timer.add(Stage::Sample, b);
  rects_host_.resize(4 * runs);
  q.enqueueReadBuffer(rects_, CL_TRUE, 0, rects_host_.size() * sizeof(cl_int), rects_host_.data());

  // Counting sort of (tile, run) pairs by tile, runs in batch order in each.
  const cl_uint tiles_x = (cl_uint(f.width) + MP_RASTER_TILE - 1) / MP_RASTER_TILE;
  const cl_uint tiles_y = (cl_uint(f.height) + MP_RASTER_TILE - 1) / MP_RASTER_TILE;
  tile_counts_.assign(size_t(tiles_x) * tiles_y, 0);
  auto for_each_tile = [&](size_t k, auto&& fn) {
    const cl_int* r = &rects_host_[4 * size_t(k)];
    for (cl_int ty = r[1]; ty <= r[3]; ++ty)
      for (cl_int tx = r[0]; tx <= r[2]; ++tx) fn(cl_uint(ty) * tiles_x + cl_uint(tx));
  };
  for (size_t k = 0; k < runs; ++k) for_each_tile(k, [&](cl_uint t) { ++tile_counts_[t]; });
  tile_ids_host_.clear();
  tile_starts_host_.clear();
  cl_uint entries = 0;
  for (size_t t = 0; t < tile_counts_.size(); ++t) {
    if (!tile_counts_[t]) continue;
    tile_ids_host_.push_back(cl_uint(t));
    tile_starts_host_.push_back(entries);
    const cl_uint n = tile_counts_[t];
    tile_counts_[t] = entries;  // now the tile's next free entry
    entries += n;
  }
  tile_starts_host_.push_back(entries);
  active_tiles_ = cl_uint(tile_ids_host_.size());
  runs_per_grid_ = runs_per_grid;
  tiles_x_ = tiles_x;
  if (active_tiles_ == 0) return false;
  tile_entries_host_.resize(entries);
  // Entry: the run's grid slot * runs_per_grid + its run.
  const cl_uint base = first * runs_per_grid;
  for (size_t k = 0; k < runs; ++k)
    for_each_tile(k, [&](cl_uint t) { tile_entries_host_[tile_counts_[t]++] = base + cl_uint(k); });

  ensure(session_, tile_ids_, tile_bytes_, active_tiles_, sizeof(cl_uint), "tile list");
  ensure(session_, tile_starts_, start_bytes_, active_tiles_ + 1, sizeof(cl_uint), "tile list starts");
  ensure(session_, tile_entries_, entry_bytes_, entries, sizeof(cl_uint), "tile grid lists");
  q.enqueueWriteBuffer(tile_ids_, CL_FALSE, 0, active_tiles_ * sizeof(cl_uint), tile_ids_host_.data());
  q.enqueueWriteBuffer(tile_starts_, CL_FALSE, 0, (active_tiles_ + 1) * sizeof(cl_uint), tile_starts_host_.data());
  q.enqueueWriteBuffer(tile_entries_, CL_FALSE, 0, entries * sizeof(cl_uint), tile_entries_host_.data());
  // The host lists must outlive their (asynchronous) uploads.
  q.finish();
  return true;
}

void SampleStage::sample_binned(const cl::Buffer& diceable, const SceneBuffers& scene, const FrameParams& f,
                                GridBuffers& grids, StageTimer& timer, cl_uint pass,
                                const std::function<bool()>& keep_going) {
  // All tiles in one launch, or (when the caller may cancel) in parts, with
  // a question between them. A fixed work-group size: PoCL compiles a
  // kernel once per size it meets.
  const cl_uint active = active_tiles_;
  const cl_uint part = keep_going ? kTileChunk : active;
  for (cl_uint first_tile = 0; first_tile < active; first_tile += part) {
    if (first_tile > 0 && !keep_going()) break;
    cl::Kernel& k = tile_kernel_.bind(scene, diceable, f, projected_, grids.c, grids.n, offsets_, offsets_soa_,
                                      tile_ids_, tile_starts_, tile_entries_, runs_per_grid_, first_tile, active,
                                      tiles_x_, keys_, colors_, normals_, totals_, occlusion_dirty_, occlusion_, pass,
                                      grids.visible);
    cl::Event t;
    const cl::NDRange range = round_up_range(std::min(part, active - first_tile), kTileGroup);
    session_.queue().enqueueNDRangeKernel(k, cl::NullRange, range, cl::NDRange(kTileGroup), nullptr, &t);
    timer.add(Stage::Sample, t);
  }
}

}  // namespace mp
