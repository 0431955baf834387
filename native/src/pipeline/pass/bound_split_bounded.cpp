// Bounded-memory bound & split (Weber, Wimmer & Owens 2015). A fixed pool of
// workers each processes sub-patches depth-first from its own stack, so a
// worker never holds more than (split depth limit + 1) sub-patches. Workers
// that run dry take whole patches from the input, or split children that busy
// workers handed out through a ring buffer. Diceable sub-patches go to a fixed
// buffer; when it is full, that batch is diced, shaded and sampled, and bound
// & split resumes where it stopped. All memory is allocated up front from the
// budget, so the peak is the budget's allocation, whatever the scene.
//
// Each worker handles up to `steps` sub-patches per launch
// (RenderSettings::bound_split_steps): on a GPU one, so that children handed
// out reach idle workers at every step of the tree rather than every 16th
// (a launch lasts as long as its busiest worker; docs/performance.md).
//
// Each launch runs only as many workers as can have work: those still holding
// sub-patches, plus room to double, so the active pool ramps up as the split
// tree widens (a few big patches at first) and a large budget costs no time on
// scenes that cannot use all its workers.
//
// Chained launches (RenderSettings::bound_split_chain; off by default): the host
// enqueues several launches at once, each followed by bs_bounded_control,
// which sets the next launch's counters on the device by the host's rules
// and stops the chain where the host must decide (a full dice batch, the
// roots taken so far done). The host reads the counters once per chain
// instead of once per launch (on the H100 a read-back costs 17-28 us and
// a launch of this kernel 19 us of host time). Measured there, chains of
// up to 16 halve the bound & split reads but add as much launch time as
// they save (0.87-1.03 of unchained frames), so they are off by default.
// Chained launches cover a fixed range of workers, of which those beyond
// BS_ACTIVE return at once. A chain is as long as
// the launches between the last two stops (the first is one launch, and
// one that runs through doubles the next): where every launch ends in a
// stop (a full batch each, as in many lights' views) the launches are read
// one by one as without chains, with no control launches or launches past
// a stop; the images are the same for any length.
#include <algorithm>
#include <string>

#include "micropoly/error.h"
#include "pipeline/pass/bound_split.h"
#include "cl/kernel_args.h"

namespace mp {
namespace {

// Counter slots, as BS_* in kernels/stages/bound_split.cl.
enum Counter {
  kPoolHead = 0, kPoolTail = 1, kNextRoot = 2, kDiceCount = 3, kBusy = 4, kIdle = 5, kMaxBusy = 6, kOccluded = 7,
  kRingHead0 = 8, kRingTail0 = 9, kDonate = 10, kRootLimit = 11, kActive = 12, kOccludedSum = 13, kStop = 14,
  kSteps = 15, kCounters = 16
};
constexpr size_t kMaxWorkers = size_t(1) << 20;
// With occlusion culling, the roots (near to far) are taken in waves: a
// wave's sub-patches are diced, shaded and sampled and the pyramid rebuilt
// before the next wave is taken, so the nearest surfaces hide the rest early
// (taken all at once, a launch's thousands of workers would split roots from
// every depth before anything is sampled). The first wave is one root, each
// next a quarter larger than the last (with steps of one half, more of each
// shell of bench/occlusion_bench.py's nested shells was diced beside the
// part of the one in front that hides it, before that was sampled), and at
// least kMinWave sub-patches' worth. Each wave costs a partly filled dice
// batch, so once the pyramid holds a quarter of the scene's sub-patches (as
// far as the waves so far tell; at most half a batch), a wave that finds
// less than 1/kWorthwhile of its sub-patches hidden ends the waves and the
// rest are taken at once. A partly filled batch costs about a millisecond
// of launches and host round trips on a GPU, more than rasterising a few
// hidden layers there, so waves are for CPU devices (PassOcclusion::waves),
// and for GPUs only where the camera's roots overlap deeply enough to hide
// much (OcclusionWaves, camera_view.cpp); otherwise a GPU rebuilds the
// pyramid at the batches' natural ends only. Where
// an earlier look (the shadow marking's coarse depth) put the roots it may
// see first (PassOcclusion::first_wave), those are one wave on any device,
// sampled before the rest are taken: the rest are then tested against what
// hides them, at the cost of one partly filled batch.
constexpr size_t kWorthwhile = 64;
constexpr cl_uint kMinWave = 64;

void ensure(DeviceSession& s, cl::Buffer& buffer, size_t& held, size_t bytes) {
  if (held == bytes) return;
  buffer = cl::Buffer();
  held = 0;  // until the new buffer exists
  buffer = s.allocate(bytes, "bound & split workspace");
  held = bytes;
}

}  // namespace

BoundSplitResult bound_split_bounded(BoundSplitContext& ctx, size_t budget_bytes, cl_uint dice_capacity,
                                     BoundedWorkspace& ws, cl_uint max_chain, cl_uint steps) {
  DeviceSession& s = ctx.session;
  DeviceQueue& queue = s.queue();
  const size_t rec = sizeof(SubPatch);
  // A path down the deepest instance's tree of patches (mp_instance.h),
  // then the splits of one patch.
  const cl_uint stack_depth = static_cast<cl_uint>(ctx.frame.max_depth + ctx.scene.tree_depth) + 2;
  const size_t fixed = static_cast<size_t>(dice_capacity) * rec + kCounters * sizeof(cl_uint);
  // Per worker: its stack, its stack size and one ring slot.
  const size_t per_worker = stack_depth * rec + sizeof(cl_uint) + rec;
  const size_t min_workers = 64;
  if (budget_bytes < fixed + min_workers * per_worker)
    throw Error("bound & split memory budget of " + std::to_string(budget_bytes >> 10) + " KiB is too small; it needs at least " +
                std::to_string((fixed + min_workers * per_worker + 1023) >> 10) + " KiB");
  size_t workers = std::min(kMaxWorkers, (budget_bytes - fixed) / per_worker);
  workers = std::max(min_workers, workers / 64 * 64);  // whole work-groups
  const cl_uint ring_capacity = static_cast<cl_uint>(workers);

  BoundSplitResult result;
  {
    ensure(s, ws.stacks, ws.stacks_bytes, workers * stack_depth * rec);
    ensure(s, ws.sizes, ws.sizes_bytes, workers * sizeof(cl_uint));
    ensure(s, ws.ring, ws.ring_bytes, static_cast<size_t>(ring_capacity) * rec);
    ensure(s, ws.diceable, ws.diceable_bytes, static_cast<size_t>(dice_capacity) * rec);
    ensure(s, ws.counters, ws.counters_bytes, kCounters * sizeof(cl_uint));
    result.peak_bytes = ws.stacks_bytes + ws.sizes_bytes + ws.ring_bytes + ws.diceable_bytes + ws.counters_bytes;
    cl_uint zero = 0;
    queue.enqueueFillBuffer(ws.sizes, zero, 0, workers * sizeof(cl_uint));

    const PassOcclusion& occ = ctx.occlusion;
    if (!ws.step.kernel()()) ws.step = SceneKernel(s.program(), "bs_bounded_step");
    if (max_chain > 1 && !ws.control()) ws.control = cl::Kernel(s.program(), "bs_bounded_control");
    cl::Kernel& step =
        ws.step.bind(ctx.scene, occ.on() ? occ.root_order : cl::Buffer(), ctx.frame, ctx.views.views, ctx.views.count,
                     ctx.views.page_masks, occ.on() ? occ.pyramid : cl::Buffer(), occ.params, ws.stacks, ws.sizes,
                     stack_depth, ws.ring, ring_capacity, ws.diceable, dice_capacity, ws.counters, std::max(steps, 1u));
    const cl_uint root_count = ctx.root_count();
    const cl_uint first_wave = occ.on() && occ.first_wave < root_count ? occ.first_wave : 0;
    cl_uint root_limit = occ.on() && occ.waves ? std::min<cl_uint>(root_count, 1) : root_count;
    if (first_wave > 0) root_limit = std::min(root_limit, first_wave);
    result.waves = 1;
    size_t diced = 0, wave_roots = root_limit, diced_before_wave = 0, occluded_before_wave = 0;
    auto whole_groups = [&](size_t n) { return std::min(workers, std::max<size_t>(64, (n + 63) / 64 * 64)); };
    // More workers than a few dice batches' worth would mostly hold work they
    // cannot hand on until the next flush, so growth stops there.
    const size_t useful = 4 * static_cast<size_t>(dice_capacity);
    size_t launch = whole_groups(std::min<size_t>(root_limit, useful));
    cl_uint head = 0, tail = 0, next_root = 0, dice_count = 0, hungry = static_cast<cl_uint>(launch);
    // Chained launches cover every worker a launch can take (a launch is at
    // most the larger of the last one and `useful`, in whole groups).
    const size_t chain_range = whole_groups(std::max(launch, useful));
    if (max_chain > 1)
      bind_args(ws.control, ws.counters, ring_capacity, dice_capacity, static_cast<cl_uint>(workers),
                static_cast<cl_uint>(useful));
    cl_uint chain = 1, since_stop = 0;
    // The roots taken so far as the pass's progress; false once cancelled.
    auto keep_going = [&] {
      return !ctx.progress ||
             ctx.progress(0.95f * static_cast<float>(next_root) / static_cast<float>(std::max(root_count, 1u)));
    };
    for (;;) {
      // The counters, and what changes per launch: the ring's head and tail,
      // the donation limit (at most as many children as there will be idle
      // workers), the roots taken so far and the workers that run.
      cl_uint c[kCounters] = {head, tail, next_root, dice_count, 0, 0, 0, 0, head, tail, hungry, root_limit,
                              static_cast<cl_uint>(launch), 0, 0, 0};
      queue.enqueueWriteBuffer(ws.counters, CL_FALSE, 0, sizeof c, c);
      for (cl_uint k = 0; k < chain; ++k) {
        cl::Event e;
        queue.enqueueNDRangeKernel(step, cl::NullRange, cl::NDRange(chain > 1 ? chain_range : launch), cl::NDRange(64),
                                   nullptr, &e);
        ctx.timer.add(Stage::BoundSplit, e);
        if (chain > 1) {
          queue.enqueueNDRangeKernel(ws.control, cl::NullRange, cl::NDRange(1), cl::NullRange, nullptr, &e);
          ctx.timer.add(Stage::BoundSplit, e);
        }
      }
      queue.enqueueReadBuffer(ws.counters, CL_TRUE, 0, sizeof c, c);
      ctx.timer.collect();
      const cl_uint ran = chain > 1 ? c[kSteps] : 1;
      result.launches += ran;
      since_stop += ran;
      if (chain > 1 && !c[kStop]) {
        // Every launch of the chain ran and the device set the next one's
        // counters: go on from there, with a longer chain.
        head = c[kRingHead0], tail = c[kRingTail0], next_root = c[kNextRoot], dice_count = c[kDiceCount];
        hungry = c[kDonate], launch = c[kActive];
        result.occluded += c[kOccludedSum];
        chain = std::min(max_chain, 2 * chain);
        if (!keep_going()) {
          result.cancelled = true;
          break;
        }
        continue;
      }
      // A stop (or a single launch): the counters are as the last launch
      // left them, and the host decides as below.
      if (chain > 1) {
        head = c[kRingHead0], tail = c[kRingTail0], hungry = c[kDonate];  // as the last launch started
        c[kOccluded] = c[kOccludedSum];
      }

      const cl_uint head0 = head;
      head = std::min(c[kPoolHead], tail);
      tail = std::min({c[kPoolTail], tail + hungry, head0 + ring_capacity});
      next_root = std::min(c[kNextRoot], root_limit);
      dice_count = std::min(c[kDiceCount], dice_capacity);
      result.occluded += c[kOccluded];
      const size_t busy = c[kBusy];
      if (head == tail) head = tail = 0;  // keep ring indices small (bs_bounded_control alike)
      const bool wave_done = busy == 0 && head == tail && next_root >= root_limit;
      const bool done = wave_done && root_limit >= root_count;
      // A wave ends in a flush once it has kMinWave sub-patches to dice (or
      // it is the last); smaller ones are carried into the next wave.
      // The seen roots' wave (first_wave) is sampled whole before any other.
      const bool seen_done = wave_done && root_limit == first_wave;
      // The next chain: as long as the launches since the last stop, or twice
      // as long as this one where it ran through (bs_bounded_control's rule).
      if (dice_count == dice_capacity || wave_done) {
        chain = std::clamp<cl_uint>(since_stop, 1, max_chain);
        since_stop = 0;
      } else {
        chain = std::min(max_chain, 2 * chain);
      }
      if (dice_count == dice_capacity ||
          (wave_done && dice_count > 0 && (done || seen_done || dice_count >= kMinWave))) {
        ctx.sink(ws.diceable, dice_count);
        diced += dice_count;
        dice_count = 0;
        if (!done && occ.on()) occ.refresh();
      }
      if (done) break;
      if (wave_done) {
        // A quarter more roots than the last wave, and (up to four times the
        // last) enough for kMinWave sub-patches at the rate per root so far;
        // or all that are left once a wave tested against a pyramid of a
        // quarter of the scene's sub-patches (as far as the rate tells; at
        // most half a batch) found less than 1/kWorthwhile of them hidden.
        const double per_root = static_cast<double>(diced + result.occluded) / root_limit;
        const double expected = per_root * root_count;
        const bool judged = diced_before_wave > 0 &&
                            static_cast<double>(diced_before_wave) >= std::min(0.5 * dice_capacity, 0.25 * expected);
        const size_t wave_subpatches = (diced - diced_before_wave) + (result.occluded - occluded_before_wave);
        const bool worthwhile = !judged || (result.occluded - occluded_before_wave) * kWorthwhile >= wave_subpatches;
        size_t roots = wave_roots + (wave_roots + 3) / 4;
        if (diced + result.occluded >= kMinWave)  // a rate measured on enough sub-patches; at most 4x the last
          roots = std::max(roots, std::min(4 * wave_roots, static_cast<size_t>(double(kMinWave) / per_root)));
        if (!worthwhile || !occ.waves) roots = root_count;
        if (root_limit < first_wave) roots = std::min<size_t>(roots, first_wave - root_limit);
        wave_roots = std::min<size_t>(roots, root_count - root_limit);
        root_limit += static_cast<cl_uint>(wave_roots);
        ++result.waves;
        diced_before_wave = diced;
        occluded_before_wave = result.occluded;
      }
      const size_t pending = (tail - head) + (root_limit - next_root);
      launch = whole_groups(std::max<size_t>(c[kMaxBusy], std::min(2 * busy + pending, useful)));
      hungry = static_cast<cl_uint>(launch > busy ? launch - busy : 0);
      if (!keep_going()) {
        result.cancelled = true;
        break;
      }
    }
    queue.finish();
  }
  return result;
}

}  // namespace mp
