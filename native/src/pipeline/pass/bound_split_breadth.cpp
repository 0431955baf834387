// Breadth-first bound & split (Patney & Owens 2008): every iteration
// classifies the whole queue in parallel; exclusive prefix sums give each
// diceable sub-patch its slot in the diceable list and each split sub-patch the
// slots of its two children in the next queue. Memory follows the widest
// level of the split tree, which is what the bounded method avoids.
#include <algorithm>

#include "pipeline/pass/bound_split.h"
#include "cl/kernel_args.h"
#include "pipeline/pass/prefix_sum.h"

namespace mp {

BoundSplitResult bound_split_breadth(BoundSplitContext& ctx, cl_uint dice_capacity) {
  DeviceSession& s = ctx.session;
  DeviceQueue& queue = s.queue();
  MemoryTally tally;
  BoundSplitResult result;
  {
    TalliedBuffer queue_in(tally), queue_out(tally), decision(tally), dice_flag(tally), split_flag(tally);
    TalliedBuffer diceable(tally), batch(tally);
    PrefixSum scan(s, tally);
    // Made per pass: the breadth-first method is the reference, not the
    // renderer's default, so it keeps no kernels between passes.
    cl::Kernel scatter(s.program(), "bs_breadth_scatter");
    SceneKernel init(s.program(), "bs_init_queue"), classify(s.program(), "bs_breadth_classify");

    // Occlusion culling tests each level's sub-patches against what the
    // levels before it sampled (the roots, all taken at once, against none).
    const PassOcclusion& occ = ctx.occlusion;
    TalliedBuffer occluded(tally);
    occluded.reserve(s, sizeof(cl_uint));
    queue.enqueueFillBuffer(occluded.get(), cl_uint(0), 0, sizeof(cl_uint));
    cl_uint n = ctx.root_count();
    const size_t rec = sizeof(SubPatch);
    queue_in.reserve(s, n * rec);
    cl::Kernel& k0 = init.bind(ctx.scene, queue_in.get(), n, ctx.views.count, occ.on() ? occ.root_order : cl::Buffer());
    cl::Event e0;
    queue.enqueueNDRangeKernel(k0, cl::NullRange, round_up_range(n), cl::NDRange(64), nullptr, &e0);
    ctx.timer.add(Stage::BoundSplit, e0);

    for (int depth = 0; n > 0; ++depth) {
      decision.reserve(s, n * sizeof(cl_uint));
      dice_flag.reserve(s, (n + 1) * sizeof(cl_uint));
      split_flag.reserve(s, (n + 1) * sizeof(cl_uint));
      cl::Kernel& k = classify.bind(ctx.scene, queue_in.get(), n, ctx.frame, ctx.views.views, ctx.views.count,
                                    ctx.views.page_masks, occ.on() ? occ.pyramid : cl::Buffer(), occ.params,
                                    occluded.get(), decision.get(), dice_flag.get(), split_flag.get());
      cl::Event e1;
      queue.enqueueNDRangeKernel(k, cl::NullRange, round_up_range(n + 1), cl::NDRange(64), nullptr, &e1);
      ctx.timer.add(Stage::BoundSplit, e1);
      ++result.launches;

      cl_uint dice_total = scan.exclusive_scan(dice_flag.get(), n, ctx.timer);
      cl_uint split_total = scan.exclusive_scan(split_flag.get(), n, ctx.timer);
      queue_out.reserve(s, static_cast<size_t>(split_total) * 2 * rec);
      diceable.reserve(s, static_cast<size_t>(dice_total) * rec);

      bind_args(scatter, queue_in.get(), n, decision.get(), dice_flag.get(), split_flag.get(), queue_out.get(),
                diceable.get());
      cl::Event e2;
      queue.enqueueNDRangeKernel(scatter, cl::NullRange, round_up_range(n), cl::NDRange(64), nullptr, &e2);
      ctx.timer.add(Stage::BoundSplit, e2);

      // Hand the diceable list on in batches the grid buffers can hold.
      for (cl_uint first = 0; first < dice_total; first += dice_capacity) {
        cl_uint count = std::min(dice_capacity, dice_total - first);
        if (first == 0 && count == dice_total) {
          ctx.sink(diceable.get(), count);
        } else {
          batch.reserve(s, static_cast<size_t>(dice_capacity) * rec);
          queue.enqueueCopyBuffer(diceable.get(), batch.get(), first * rec, 0, count * rec);
          ctx.sink(batch.get(), count);
        }
      }
      queue_in.swap_with(queue_out);
      n = split_total * 2;
      if (n > 0 && dice_total > 0 && occ.on()) occ.refresh();
      if (ctx.progress && !ctx.progress(std::min(0.95f, 0.1f * static_cast<float>(depth + 1)))) {
        result.cancelled = true;
        break;
      }
    }
    cl_uint culled = 0;
    queue.enqueueReadBuffer(occluded.get(), CL_TRUE, 0, sizeof culled, &culled);
    result.occluded = culled;
  }
  result.peak_bytes = tally.peak();
  return result;
}

}  // namespace mp
