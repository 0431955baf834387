#include "pipeline/pass/prefix_sum.h"

#include "cl/kernel_args.h"

namespace mp {
namespace {
constexpr cl_uint kGroup = 256, kBlock = 2 * kGroup;  // as MP_SCAN_GROUP / MP_SCAN_BLOCK in scan.cl
}

PrefixSum::PrefixSum(DeviceSession& session, MemoryTally& tally)
    : session_(session),
      tally_(tally),
      blocks_(session.program(), "scan_blocks"),
      add_(session.program(), "scan_add_block_offsets") {}

void PrefixSum::scan_level(const cl::Buffer& data, cl_uint n, size_t level, StageTimer& timer) {
  cl_uint groups = (n + kBlock - 1) / kBlock;
  while (sums_.size() <= level) sums_.push_back(std::make_unique<TalliedBuffer>(tally_));
  // One extra slot past the block sums holds the level's grand total.
  sums_[level]->reserve(session_, (groups + 1) * sizeof(cl_uint));
  const cl::Buffer& sums = sums_[level]->get();
  bind_args(blocks_, data, n, sums);
  cl::Event e;
  session_.queue().enqueueNDRangeKernel(blocks_, cl::NullRange, cl::NDRange(groups * kGroup), cl::NDRange(kGroup),
                                        nullptr, &e);
  timer.add(Stage::BoundSplit, e);
  if (groups > 1) {
    scan_level(sums, groups, level + 1, timer);
    bind_args(add_, data, n, sums);
    cl::Event e2;
    session_.queue().enqueueNDRangeKernel(add_, cl::NullRange, round_up_range(n, kGroup), cl::NDRange(kGroup), nullptr,
                                          &e2);
    timer.add(Stage::BoundSplit, e2);
  }
}

void PrefixSum::exclusive_scan_on_device(const cl::Buffer& data, cl_uint n, StageTimer& timer) {
  // The caller's array holds n + 1 entries with data[n] == 0, so after the
  // exclusive scan data[n] is the total.
  scan_level(data, n + 1, 0, timer);
}

cl_uint PrefixSum::exclusive_scan(const cl::Buffer& data, cl_uint n, StageTimer& timer) {
  if (n == 0) return 0;
  exclusive_scan_on_device(data, n, timer);
  cl_uint total = 0;
  session_.queue().enqueueReadBuffer(data, CL_TRUE, n * sizeof(cl_uint), sizeof total, &total);
  return total;
}

}  // namespace mp
