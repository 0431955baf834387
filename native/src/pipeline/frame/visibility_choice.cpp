#include "pipeline/frame/visibility_choice.h"

namespace mp {
namespace {

// Auto tries it on CPU devices, where shading a vertex can cost many times
// rasterising its depth, when the view culls and its roots' boxes overlap
// at least this deep on average (OcclusionCulling::root_overlap, an
// estimate from above of the depth complexity bound & split meets). GPUs
// shade fast and rasterise with atomics: Auto leaves it off there.
constexpr double kTriedFromOverlap = 2.0;

VisibilityChoice choose(const RenderSettings& s, const DeviceInfo& device, bool culling, double overlap) {
  if (s.visibility_first != VisibilityFirst::Auto) return {false, s.visibility_first == VisibilityFirst::On};
  // Automatic, the first batch (a CPU's first wave, one root) not taking it.
  if (device.type == "cpu" && culling && overlap >= kTriedFromOverlap) return {true, false};
  return {false, false};
}

}  // namespace

CameraVisibility::CameraVisibility(const RenderSettings& settings, const DeviceInfo& device, bool culling,
                                   double root_overlap, SampleStage& sample, StageTimer& timer)
    : choice_(choose(settings, device, culling, root_overlap)), sample_(sample), timer_(timer) {}

CameraVisibility::~CameraVisibility() {
  // The counts' read must not outlive the frame.
  if (!pending_) return;
  try {
    sample_.hidden_counts();
  } catch (const cl::Error&) {
    // The device failed; the frame reports it elsewhere.
  }
}

const cl::Buffer& CameraVisibility::before_shading(const cl::Buffer& diceable, cl_uint count,
                                                   const SceneBuffers& scene, const FrameParams& f,
                                                   GridBuffers& grids) {
  weigh_last();
  took_ = choice_.take();
  passes_from_ = timer_.cursor();
  if (took_) passes_from_ = sample_.visibility(diceable, count, scene, f, grids, timer_);
  shade_from_ = timer_.cursor();
  return took_ ? grids.visible : none_;
}

void CameraVisibility::after_sampling(const GridBuffers& grids, cl_uint count) {
  if (!choice_.automatic()) return;
  // Weighed when the next batch comes: the queue has finished this one by
  // then, and kept working meanwhile.
  sample_.read_hidden_counts();
  last_ = VisibilityChoice::Batch{};
  last_.took = took_;
  last_.grids = count;
  last_.micropolygons = grids.micropolygon_offsets_host[count] - grids.micropolygon_offsets_host[0];
  last_passes_ = {passes_from_, shade_from_};
  last_shade_ = {shade_from_, sample_from_};
  last_sample_ = {sample_from_, timer_.cursor()};
  pending_ = true;
}

void CameraVisibility::weigh_last() {
  if (!pending_) return;
  pending_ = false;
  const SampleStage::HiddenCounts now = sample_.hidden_counts();
  last_.passes_ms = timer_.ms_between(last_passes_.first, last_passes_.second);
  last_.shade_ms = timer_.ms_between(last_shade_.first, last_shade_.second);
  last_.sample_ms = timer_.ms_between(last_sample_.first, last_sample_.second);
  last_.unshaded = now.unshaded - counted_.unshaded;
  last_.lost = now.lost - counted_.lost;
  counted_ = now;
  choice_.measured(last_);
}

}  // namespace mp
