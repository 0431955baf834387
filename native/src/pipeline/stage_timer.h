// Device time per pipeline stage, from OpenCL profiling events.
#pragma once

#include <array>
#include <vector>

#include "cl/cl.h"

namespace mp {

enum class Stage { Upload, BoundSplit, Dice, Shade, Sample, Resolve, Count };

class StageTimer {
 public:
  void add(Stage stage, const cl::Event& event) { pending_.push_back({stage, event}); }
  // Sums the events recorded so far; call after they have completed.
  void collect() {
    for (auto& [stage, event] : pending_) {
      cl_ulong start = event.getProfilingInfo<CL_PROFILING_COMMAND_START>();
      cl_ulong end = event.getProfilingInfo<CL_PROFILING_COMMAND_END>();
      ms_[static_cast<size_t>(stage)] += static_cast<double>(end - start) * 1e-6;
    }
    pending_.clear();
  }
  double ms(Stage stage) const { return ms_[static_cast<size_t>(stage)]; }

 private:
  std::vector<std::pair<Stage, cl::Event>> pending_;
  std::array<double, static_cast<size_t>(Stage::Count)> ms_{};
};

// Rounds a 1D launch up to a multiple of the work-group size used for it.
inline cl::NDRange round_up_range(size_t n, size_t group = 64) { return cl::NDRange(((n + group - 1) / group) * group); }

}  // namespace mp
