// Occlusion culling of the camera's view (kernels/stages/mp_occlusion.h): a
// max-depth pyramid rebuilt from the sample buffer between dice batches, and
// the patches' order near to far, so the first batches fill the pyramid with
// what hides the rest. Bound & split tests every sub-patch against it.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "cl/device_session.h"
#include "core/mp_types.h"
#include "pipeline/frame/buckets.h"
#include "pipeline/pass/stage_timer.h"

namespace mp {

class OcclusionCulling {
 public:
  explicit OcclusionCulling(DeviceSession& session);
  // Sizes the pyramid to the frame and marks every cell infinitely far
  // (nothing is culled until the first refresh).
  void begin_frame(const FrameParams& f, StageTimer& timer);
  // Rebuilds the pyramid from the samples written so far.
  void refresh(const cl::Buffer& keys, const FrameParams& f, StageTimer& timer);
  // Pixels of bucket b (whose samples `keys` holds, of frame f) with a
  // surface in any of their samples (a pass over the samples).
  size_t covered_pixels(const cl::Buffer& keys, const FrameParams& f, StageTimer& timer, const Bucket& b);
  const cl::Buffer& pyramid() const { return pyramid_; }
  // A byte per level-0 cell the sample stage sets where it writes samples;
  // a refresh reads only those cells.
  const cl::Buffer& dirty() const { return dirty_; }
  const OcclusionParams& params() const { return params_; }
  // The patches near to far for this scene and view (near_to_far_order),
  // kept while neither changes.
  // `instances`: the instances' boxes (2 per instance), which count in the
  // overlap but are not ordered (their roots follow the patches').
  const cl::Buffer& root_order(const std::vector<glm::vec4>& boxes, const std::vector<glm::vec4>& instances,
                               uint64_t scene_key, const FrameParams& f);
  // The overlap of the roots' boxes that root_order found.
  double root_overlap() const { return overlap_; }

 private:
  void size_for(const FrameParams& f);
  void build_base(const cl::Buffer& keys, const FrameParams& f, bool all, StageTimer& timer,
                  const cl_int4& count_region);
  DeviceSession& session_;
  cl::Kernel base_, reduce_;
  cl::Buffer pyramid_, dirty_, covered_;
  size_t cells_held_ = 0, cells_ = 0;
  cl::Buffer order_;
  uint64_t order_key_ = 0;
  double overlap_ = 0;
  OcclusionParams params_{};
};

// The layout of a max-depth pyramid over frame f whose level-0 cells are
// 2^cell_shift pixels wide, halving up to one cell.
OcclusionParams occlusion_layout(const FrameParams& f, int cell_shift);

// Patch indices ordered by the distance from the eye to their camera-space
// boxes (lo and hi per patch), those whose box lies outside the view last:
// the order bound & split takes its roots in when culling.
// `overlap` receives how many boxes cover a point of the frame that any
// covers, on average over a coarse grid (boxes reaching behind the eye
// count as covering all): an estimate, from above, of the depth complexity
// bound & split will meet. Each of `instances`' boxes counts twice there
// (a closed prototype covers what it covers with a front and a back) but
// takes no place in the order.
std::vector<cl_uint> near_to_far_order(const std::vector<glm::vec4>& boxes, const FrameParams& f,
                                       double* overlap = nullptr, const std::vector<glm::vec4>& instances = {});

// Patch indices ordered by their camera-space boxes' nearness to view v's
// eye: the distance from it (perspective views: a point light's cube faces
// all share the eye) or the nearest depth along the view (orthographic: a
// sun's levels all share the direction). The order a light's views take
// their roots in when culling (shadow_maps.h).
std::vector<cl_uint> view_near_to_far_order(const std::vector<glm::vec4>& boxes, const FrameParams& v);

}  // namespace mp
