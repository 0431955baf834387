// Bound & split strategies. Both hand batches of diceable sub-patches
// (SubPatch records, kernels/core/mp_types.h) to a sink, which dices, shades and
// samples them before bound & split continues.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <functional>
#include <utility>

#include "cl/device_session.h"
#include "micropoly/error.h"
#include "micropoly/renderer.h"
#include "pipeline/device_scene/scene_buffers.h"
#include "pipeline/device_scene/scene_kernel.h"
#include "pipeline/pass/stage_timer.h"

namespace mp {

// Receives `count` diceable sub-patches at the start of `buffer`; the buffer
// may be reused as soon as the call returns (commands are in order).
using DiceSink = std::function<void(const cl::Buffer& buffer, cl_uint count)>;

struct BoundSplitResult {
  size_t peak_bytes = 0;  // device memory the strategy held at its peak
  size_t launches = 0;    // bound & split kernel launches
  size_t occluded = 0;    // sub-patches culled by occlusion
  size_t waves = 0;       // waves the roots were taken in (bounded method)
  bool cancelled = false;
};

// Tallies the device memory a strategy holds, to report its peak.
class MemoryTally {
 public:
  void add(size_t bytes) {
    current_ += bytes;
    if (current_ > peak_) peak_ = current_;
  }
  void remove(size_t bytes) { current_ -= bytes; }
  size_t peak() const { return peak_; }

 private:
  size_t current_ = 0, peak_ = 0;
};

// A device buffer whose size is counted in a MemoryTally while it lives.
class TalliedBuffer {
 public:
  TalliedBuffer(MemoryTally& tally) : tally_(&tally) {}
  ~TalliedBuffer() { tally_->remove(bytes_); }
  TalliedBuffer(const TalliedBuffer&) = delete;
  TalliedBuffer& operator=(const TalliedBuffer&) = delete;
  // Makes the buffer hold at least `bytes` (contents are not kept).
  void reserve(DeviceSession& session, size_t bytes) {
    if (bytes <= bytes_ && bytes_ > 0) return;
    tally_->remove(bytes_);
    buffer_ = cl::Buffer();
    bytes_ = 0;  // until the new buffer exists
    buffer_ = session.allocate(bytes, "bound & split queue");
    bytes_ = std::max<size_t>(bytes, 16);
    tally_->add(bytes_);
  }
  void swap_with(TalliedBuffer& other) {
    std::swap(buffer_, other.buffer_);
    std::swap(bytes_, other.bytes_);
  }
  const cl::Buffer& get() const { return buffer_; }
  size_t bytes() const { return bytes_; }

 private:
  MemoryTally* tally_;
  cl::Buffer buffer_;
  size_t bytes_ = 0;
};

// The views a pass renders: none (the frame's own view, `frame`), or up to
// MP_MAX_PASS_VIEWS FrameParams in a device buffer (shadow maps), each patch
// once per view; shadow views also come with their page masks.
struct PassViews {
  cl::Buffer views;       // FrameParams per view (empty: the frame's view)
  cl_uint count = 0;
  cl::Buffer page_masks;  // shadow views' page mask pyramids (mp_bound.h)
};

// Occlusion culling of a pass over the camera's view (occlusion_culling.h):
// the roots are taken near to far, in waves while the pyramid is young (CPU
// devices; GPUs where the roots overlap deeply, OcclusionWaves), and
// after a batch that more work follows, `refresh` (dice, shade and sample
// have run) rebuilds the pyramid the later sub-patches are tested against.
struct PassOcclusion {
  cl::Buffer pyramid;
  OcclusionParams params{};  // levels 0: off
  cl::Buffer root_order;     // patch indices near to far
  std::function<void()> refresh;
  bool waves = true;  // take the roots in waves (bound_split_bounded.cpp)
  // Roots at the start of root_order that an earlier look found may be
  // seen (MarkingDepth::seen_first): the bounded method takes them as a wave
  // of their own, sampled before any later root is taken (0: no such wave).
  cl_uint first_wave = 0;
  bool on() const { return params.levels > 0; }
};

struct BoundSplitContext {
  DeviceSession& session;
  const SceneBuffers& scene;
  const FrameParams& frame;
  StageTimer& timer;
  const DiceSink& sink;
  const ProgressCallback& progress;
  const PassViews& views;
  const PassOcclusion& occlusion;
  // Every view's roots (mp_instance.h); a pass whose count exceeds 2^32 is refused.
  cl_uint root_count() const {
    const uint64_t n = uint64_t(scene.root_count) * std::max<cl_uint>(views.count, 1);
    if (n > UINT32_MAX)
      throw Error(std::to_string(scene.root_count) + " patches and instances in " + std::to_string(views.count) +
                  " views exceed the 2^32 roots of one pass: use fewer instances or fewer lights");
    return cl_uint(n);
  }
};

// Device buffers of the bounded method, kept between frames so a renderer
// that draws many frames with one budget allocates them once. Each buffer is
// reallocated whenever its size changes, so what is held is exactly what the
// current budget asks for.
struct BoundedWorkspace {
  SceneKernel step;  // bs_bounded_step, made on first use and kept with its scene data bound
  cl::Kernel control;  // bs_bounded_control (chained launches), made on first use
  cl::Buffer stacks, sizes, ring, diceable, counters;
  size_t stacks_bytes = 0, sizes_bytes = 0, ring_bytes = 0, diceable_bytes = 0, counters_bytes = 0;
};

// Weber, Wimmer & Owens 2015: fixed worker pool, depth-first per worker,
// memory fixed by `budget_bytes` (never exceeded; throws if too small).
// Up to `max_chain` launches are chained on the device between two reads
// of the counters (1: a read after every launch); each worker handles up to
// `steps` sub-patches per launch (RenderSettings::bound_split_steps).
BoundSplitResult bound_split_bounded(BoundSplitContext& ctx, size_t budget_bytes, cl_uint dice_capacity,
                                     BoundedWorkspace& workspace, cl_uint max_chain, cl_uint steps);
// Patney & Owens 2008: whole queue per iteration, compacted by prefix sums.
BoundSplitResult bound_split_breadth(BoundSplitContext& ctx, cl_uint dice_capacity);

}  // namespace mp
