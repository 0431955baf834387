// Device time per pipeline stage, from OpenCL profiling events.
#pragma once

#include <array>
#include <chrono>
#include <optional>
#include <vector>

#include "cl/cl.h"

namespace mp {

// ShadowMark: the shadow maps' page marking; Shadow*: their rendering (the
// bound & split, dicing and sampling of the lights' views).
enum class Stage {
  Upload,
  BoundSplit,
  Dice,
  Shade,
  Sample,
  Resolve,
  ShadowMark,
  ShadowBoundSplit,
  ShadowDice,
  ShadowSample,
  Occlusion,
  Count
};

class StageTimer {
 public:
  void add(Stage stage, const cl::Event& event) { pending_.push_back({redirected(stage), event}); }
  // While a Redirect lives, events count for its stage; one to
  // ShadowBoundSplit sends the camera stages to their shadow twins (the
  // lights' views run the same stages as the camera's).
  class Redirect {
   public:
    Redirect(StageTimer& timer, Stage stage) : timer_(timer), previous_(timer.redirect_) { timer.redirect_ = stage; }
    ~Redirect() { timer_.redirect_ = previous_; }
    Redirect(const Redirect&) = delete;
    Redirect& operator=(const Redirect&) = delete;

   private:
    StageTimer& timer_;
    std::optional<Stage> previous_;
  };
  // Sums the events recorded so far; call after they have completed.
  void collect() {
    for (auto& [stage, event] : pending_) {
      const double ms = event_ms(event);
      ms_[static_cast<size_t>(stage)] += ms;
      collected_.push_back(ms);
    }
    pending_.clear();
  }
  double ms(Stage stage) const { return ms_[static_cast<size_t>(stage)]; }
  // A point in the events recorded so far, and the device time of those
  // recorded between two such points (they must have completed).
  size_t cursor() const { return collected_.size() + pending_.size(); }
  double ms_between(size_t from, size_t to) const {
    double ms = 0;
    for (size_t i = from; i < to && i < cursor(); ++i)
      ms += i < collected_.size() ? collected_[i] : event_ms(pending_[i - collected_.size()].second);
    return ms;
  }

 private:
  static double event_ms(const cl::Event& e) {
    return static_cast<double>(e.getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                               e.getProfilingInfo<CL_PROFILING_COMMAND_START>()) * 1e-6;
  }
  Stage redirected(Stage s) const {
    if (!redirect_) return s;
    if (*redirect_ != Stage::ShadowBoundSplit) return *redirect_;
    return s == Stage::BoundSplit ? Stage::ShadowBoundSplit
           : s == Stage::Dice || s == Stage::Shade ? Stage::ShadowDice
                                                  : Stage::ShadowSample;
  }
  std::vector<std::pair<Stage, cl::Event>> pending_;
  std::vector<double> collected_;  // each collected event's time, in order
  std::optional<Stage> redirect_;
  std::array<double, static_cast<size_t>(Stage::Count)> ms_{};
};

// Milliseconds of wall time since t0.
inline double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Rounds a 1D launch up to a multiple of the work-group size used for it.
inline cl::NDRange round_up_range(size_t n, size_t group = 64) {
  return cl::NDRange(((n + group - 1) / group) * group);
}

// A 2-D range of 8 x 8 work-groups covering w x h.
inline cl::NDRange range_2d(int w, int h) {
  return cl::NDRange(static_cast<size_t>((w + 7) / 8 * 8), static_cast<size_t>((h + 7) / 8 * 8));
}

}  // namespace mp
