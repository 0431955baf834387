// Exclusive prefix sum of a device uint array (kernels/stages/scan.cl).
#pragma once

#include <memory>
#include <vector>

#include "cl/device_session.h"
#include "pipeline/pass/bound_split.h"

namespace mp {

class PrefixSum {
 public:
  PrefixSum(DeviceSession& session, MemoryTally& tally);
  // Scans data[0, n) in place; returns the total of the n inputs.
  cl_uint exclusive_scan(const cl::Buffer& data, cl_uint n, StageTimer& timer);
  // The same without reading the total back: it stays in data[n].
  void exclusive_scan_on_device(const cl::Buffer& data, cl_uint n, StageTimer& timer);

 private:
  void scan_level(const cl::Buffer& data, cl_uint n, size_t level, StageTimer& timer);
  DeviceSession& session_;
  MemoryTally& tally_;
  cl::Kernel blocks_, add_;
  std::vector<std::unique_ptr<TalliedBuffer>> sums_;  // block sums per recursion level
};

}  // namespace mp
