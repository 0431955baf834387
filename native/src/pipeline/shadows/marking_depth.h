// The camera's coarse depth for the shadow marking (kernels/stages/shadow.cl,
// marking_depth and mp_marking_seen). The marking dices the camera's view
// coarsely; its micropolygons of opaque materials write a depth image of one
// sample per 2 x 2 pixels, which is also the level 0 of an occlusion pyramid
// (mp_occlusion.h) that culls the sub-patches it hides, near to far in waves
// as the camera's own view does. Once the view is done, a marking vertex
// marks pages only if the image says the camera may see it: hidden layers
// and shells request no pages, so the lights' views render none for them.
#pragma once

#include <cstddef>

#include "cl/device_session.h"
#include "pipeline/frame/frame_params.h"
#include "pipeline/pass/bound_split.h"
#include "pipeline/pass/micropolygon_stages.h"
#include "pipeline/pass/prefix_sum.h"
#include "pipeline/pass/stage_timer.h"

namespace mp {

class MarkingDepth {
 public:
  explicit MarkingDepth(DeviceSession& session);
  // Device memory the image and its pyramid take for frame f.
  static size_t bytes_for(const FrameParams& f);
  // Sizes the image and pyramid for frame f and clears them (nothing hidden
  // yet), or turns them off (`on` false: every vertex counts as seen).
  void begin(const FrameParams& f, bool on, StageTimer& timer);
  bool on() const { return params_.levels > 0; }
  // Writes a diced batch's micropolygons (its grids in `grids`).
  void rasterise(const cl::Buffer& diceable, cl_uint count, const SceneBuffers& scene, const FrameParams& f,
                 const GridBuffers& grids, StageTimer& timer);
  // Rebuilds the pyramid's upper levels from the image.
  void refresh(StageTimer& timer);
  // Culling against the image as the view writes it, the roots taken in
  // `order` (waves: CPUs).
  PassOcclusion occlusion(const cl::Buffer& order, bool waves, StageTimer& timer);
  // Culling against the complete image (another pass over the same view).
  PassOcclusion complete(const cl::Buffer& order) const;
  // The camera's roots, `order` (near to far, `count` of them) with those
  // the complete image may show first, each part in its order, into
  // seen_order(); seen_count() says how many may be seen (read when first
  // asked, so the queue runs on meanwhile). The camera takes those as a
  // wave of their own (PassOcclusion::first_wave) and culls the rest against
  // its own samples: the image only orders, it never culls the camera's view.
  void seen_first(const cl::Buffer& order, cl_uint count, const SceneBuffers& scene, const FrameParams& f,
                  StageTimer& timer);
  const cl::Buffer& seen_order() const { return seen_order_; }
  cl_uint seen_count();
  cl_uint roots() const { return roots_; }  // roots seen_first ordered (0: none this frame)
  // The image (level 0 first) and its layout, as the marking kernels take
  // them; a one-cell buffer and zero levels while off.
  const cl::Buffer& image() const { return pyramid_; }
  const OcclusionParams& params() const { return params_; }
  size_t held_bytes() const { return held_ * sizeof(cl_uint); }

 private:
  DeviceSession& session_;
  SceneKernel raster_, seen_;
  cl::Kernel reduce_, partition_;
  MemoryTally scan_tally_;
  PrefixSum scan_;
  cl::Buffer flags_, seen_order_;
  size_t flags_held_ = 0, seen_held_ = 0;
  static constexpr cl_uint kUnread = 0xffffffffu;
  cl_uint roots_ = 0, seen_total_ = kUnread;
  cl::Buffer pyramid_;
  size_t held_ = 0;  // cells the buffer holds
  OcclusionParams params_{};
};

}  // namespace mp
