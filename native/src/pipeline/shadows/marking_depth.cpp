#include "pipeline/shadows/marking_depth.h"

#include <algorithm>

#include "cl/kernel_args.h"
#include "pipeline/pass/occlusion_culling.h"
#include "stages/mp_occlusion.h"

namespace mp {
namespace {

// One sample per 2 x 2 pixels: the coarse micropolygons are about eight
// pixels wide, so each covers a dozen samples or more.
constexpr int kCellShift = 1;

OcclusionParams layout_for(const FrameParams& f) { return occlusion_layout(f, kCellShift); }

}  // namespace

MarkingDepth::MarkingDepth(DeviceSession& session)
    : session_(session),
      raster_(session.program(), "marking_depth"),
      seen_(session.program(), "marking_roots_seen"),
      reduce_(session.program(), "occlusion_reduce"),
      partition_(session.program(), "marking_roots_partition"),
      scan_(session, scan_tally_) {}

size_t MarkingDepth::bytes_for(const FrameParams& f) {
  return size_t(mp_occlusion_cells(layout_for(f))) * sizeof(cl_uint);
}

void MarkingDepth::begin(const FrameParams& f, bool on, StageTimer& timer) {
  params_ = on ? layout_for(f) : OcclusionParams{};
  const size_t cells = on ? size_t(mp_occlusion_cells(params_)) : 1;
  if (cells > held_ || (!on && held_ > 1)) {
    pyramid_ = cl::Buffer();
    held_ = 0;
    pyramid_ = session_.allocate(cells * sizeof(cl_uint), "shadow marking depth");
    held_ = cells;
  }
  cl::Event e;
  session_.queue().enqueueFillBuffer(pyramid_, ~cl_uint(0), 0, cells * sizeof(cl_uint), nullptr, &e);
  timer.add(Stage::ShadowMark, e);
}

void MarkingDepth::rasterise(const cl::Buffer& diceable, cl_uint count, const SceneBuffers& scene,
                             const FrameParams& f, const GridBuffers& grids, StageTimer& timer) {
  if (!on() || count == 0) return;
  const cl_uint total = grids.micropolygon_offsets_host[count] - grids.micropolygon_offsets_host[0];
  if (total == 0) return;
  cl::Kernel& k =
      raster_.bind(scene, diceable, count, grids.micropolygon_offsets, total, f, grids.p, params_, pyramid_);
  cl::Event e;
  session_.queue().enqueueNDRangeKernel(k, cl::NullRange, round_up_range(total), cl::NDRange(64), nullptr, &e);
  timer.add(Stage::ShadowMark, e);
}

void MarkingDepth::refresh(StageTimer& timer) {
  for (int k = 1; k < params_.levels; ++k) {
    bind_args(reduce_, pyramid_, params_, k);
    cl::Event e;
    session_.queue().enqueueNDRangeKernel(
        reduce_, cl::NullRange, range_2d(mp_occlusion_side(params_.base_w, k), mp_occlusion_side(params_.base_h, k)),
        cl::NDRange(8, 8), nullptr, &e);
    timer.add(Stage::ShadowMark, e);
  }
}

PassOcclusion MarkingDepth::occlusion(const cl::Buffer& order, bool waves, StageTimer& timer) {
  PassOcclusion o = complete(order);
  if (!on()) return o;
  o.waves = waves;
  o.refresh = [this, &timer] { refresh(timer); };
  return o;
}

void MarkingDepth::seen_first(const cl::Buffer& order, cl_uint count, const SceneBuffers& scene, const FrameParams& f,
                              StageTimer& timer) {
  roots_ = 0, seen_total_ = kUnread;
  if (!on() || count == 0) return;
  roots_ = count;
  DeviceQueue& q = session_.queue();
  const size_t bytes = size_t(count) * sizeof(cl_uint);
  session_.reserve(flags_, flags_held_, bytes + sizeof(cl_uint), "camera roots seen");  // and the scan's total
  session_.reserve(seen_order_, seen_held_, bytes, "camera roots, seen first");
  cl::Kernel& seen = seen_.bind(scene, order, count, f, pyramid_, params_, flags_);
  cl::Event e;
  q.enqueueNDRangeKernel(seen, cl::NullRange, round_up_range(size_t(count) + 1), cl::NDRange(64), nullptr, &e);
  timer.add(Stage::ShadowMark, e);
  scan_.exclusive_scan_on_device(flags_, count, timer);
  bind_args(partition_, order, count, flags_, seen_order_);
  cl::Event e2;
  q.enqueueNDRangeKernel(partition_, cl::NullRange, round_up_range(count), cl::NDRange(64), nullptr, &e2);
  timer.add(Stage::ShadowMark, e2);
}

cl_uint MarkingDepth::seen_count() {
  if (roots_ == 0) return 0;
  if (seen_total_ == kUnread)
    session_.queue().enqueueReadBuffer(flags_, CL_TRUE, size_t(roots_) * sizeof(cl_uint), sizeof(cl_uint),
                                       &seen_total_);
  return seen_total_;
}

PassOcclusion MarkingDepth::complete(const cl::Buffer& order) const {
  PassOcclusion o;
  if (!on()) return o;
  o.pyramid = pyramid_;
  o.params = params_;
  o.root_order = order;
  o.waves = false;  // nothing the pass dices changes the image
  o.refresh = [] {};
  return o;
}

}  // namespace mp
