// Host waits on the device: every call that holds the host until the device
// has done the work queued before it (clFinish, a blocking read, write or
// map, a wait on an event). On a GPU each one is a round trip in which the
// device runs dry while the host reads the answer and decides what to
// launch next; a frame the device drives itself has none (docs/performance.md,
// "Host waits"). Counted per frame by the phase (DeviceSession::Activity)
// they happen in.
#pragma once

#include <algorithm>
#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace mp {

class HostWaits {
 public:
  // One wait, inside the phases `activities` (outermost first).
  void note(const std::vector<const char*>& activities) {
    std::string path;
    for (const char* name : activities) {
      if (!path.empty()) path += '/';
      path += name;
    }
    ++counts_[path.empty() ? "(no phase)" : path];
    ++total_;
  }
  void reset() {
    counts_.clear();
    total_ = 0;
  }
  size_t total() const { return total_; }
  // (phase path, waits), most waits first.
  std::vector<std::pair<std::string, size_t>> by_phase() const {
    std::vector<std::pair<std::string, size_t>> out(counts_.begin(), counts_.end());
    std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
    return out;
  }

 private:
  std::map<std::string, size_t> counts_;
  size_t total_ = 0;
};

}  // namespace mp
