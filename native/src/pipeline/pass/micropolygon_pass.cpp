#include "pipeline/pass/micropolygon_pass.h"

#include <algorithm>
#include <optional>

namespace mp {

BoundSplitResult MicropolygonPass::run(const PassView& view, const ViewTarget& target) {
  BoundSplitResult result;
  result.cancelled = progress_.cancelled();
  if (scene_.root_count == 0 || result.cancelled) return result;
  const FrameParams& f = view.frame;
  GridBuffers& grids = stages_.grids;
  // Dicing is the same for every view; the target makes the difference.
  DiceSink sink = [&](const cl::Buffer& diceable, cl_uint count) {
    if (progress_.cancelled()) return;
    std::optional<DeviceSession::Activity> activity;
    if (target.dice_activity) activity.emplace(session_, target.dice_activity);
    stages_.layout.run(diceable, count, f, grids, timer_);
    stages_.dice.run(diceable, count, scene_, f, view.views.views, view.views.count, grids, timer_);
    if (target.motion) stages_.dice.run_motion(diceable, count, scene_, f, grids, timer_);
    stages_.programs.displace(diceable, count, scene_, f, grids, timer_, target.normals);
    if (target.motion) stages_.dice.displaced(diceable, count, f, grids, timer_);
    if (target.opacity) stages_.programs.alpha(diceable, count, scene_, f, grids, timer_);
    activity.reset();
    target.take(diceable, count);
  };
  BoundSplitContext ctx{session_, scene_, f, timer_, sink, progress_.callback(), view.views, view.occlusion};
  DeviceSession::Activity activity(session_, "bound_split");
  if (settings_.bound_split == BoundSplitMethod::Bounded) {
    const size_t budget = static_cast<size_t>(std::max(0.0f, settings_.bound_split_memory_mib) * 1048576.0);
    // Steps per launch (RenderSettings::bound_split_steps): 1 on GPUs, 16 on
    // CPUs unless the settings say.
    const bool gpu = session_.info().type == "gpu";
    const int steps = settings_.bound_split_steps > 0 ? settings_.bound_split_steps : gpu ? 1 : 16;
    result = bound_split_bounded(ctx, budget, grids.capacity, stages_.bounded,
                                 static_cast<cl_uint>(std::max(settings_.bound_split_chain, 1)),
                                 static_cast<cl_uint>(steps));
  } else {
    result = bound_split_breadth(ctx, grids.capacity);
  }
  observer_.bound_split_done(result);
  result.cancelled = result.cancelled || progress_.cancelled();
  return result;
}

}  // namespace mp
