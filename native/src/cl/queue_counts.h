// What a frame asks of the device queue, counted by the phase
// (DeviceSession::Activity) it happens in:
// - host waits: every call that holds the host until the device has done
//   the work queued before it (clFinish, a blocking read, write or map, a
//   wait on an event). On a GPU each is a round trip in which the device
//   runs dry while the host reads the answer and decides what to launch
//   next; a frame the device drives itself has none.
// - kernel launches: each costs the driver's enqueue, and on a GPU a
//   launch's fixed cost, however little it does.
// A frame counts from its start (the renderer resets the counts there):
// setting up a device's stages before the first frame is not in them.
// bench/device_limits measures both costs on a device (docs/performance.md,
// "Host waits and kernel launches").
#pragma once

#include <algorithm>
#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace mp {

class PhaseCounts {
 public:
  // One event inside the phases `activities` (outermost first).
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
  // (phase path, count), most first.
  std::vector<std::pair<std::string, size_t>> by_phase() const {
    std::vector<std::pair<std::string, size_t>> out(counts_.begin(), counts_.end());
    std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
    return out;
  }

 private:
  std::map<std::string, size_t> counts_;
  size_t total_ = 0;
};

struct QueueCounts {
  PhaseCounts waits, launches;
  void reset() {
    waits.reset();
    launches.reset();
  }
};

}  // namespace mp
