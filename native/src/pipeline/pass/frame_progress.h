// The caller's progress callback as a frame asks it: between bound & split
// launches and between sample chunks, each bucket reporting its share of
// the frame; once the caller says stop, every later ask says stop too.
#pragma once

#include "micropoly/renderer.h"

namespace mp {

class FrameProgress {
 public:
  explicit FrameProgress(const ProgressCallback& caller)
      : caller_(caller), ask_([this](float p) { return (*this)(p); }) {}
  FrameProgress(const FrameProgress&) = delete;
  FrameProgress& operator=(const FrameProgress&) = delete;

  // Reports p of the current share; false once cancelled.
  bool operator()(float p) {
    last_ = p;
    if (!cancelled_ && caller_ && !caller_(base_ + scale_ * p)) cancelled_ = true;
    return !cancelled_;
  }
  // Asks again at the last progress reported.
  bool again() { return (*this)(last_); }
  // The share of the frame that progress 0..1 now stands for.
  void set_share(float base, float scale) { base_ = base, scale_ = scale; }
  bool cancelled() const { return cancelled_; }
  // Whether the caller asks at all (then the frame waits for the device
  // between chunks, so that it can answer).
  bool asked() const { return bool(caller_); }
  // This object as a ProgressCallback, for code that takes one.
  const ProgressCallback& callback() const { return ask_; }

 private:
  const ProgressCallback& caller_;
  ProgressCallback ask_;
  bool cancelled_ = false;
  float last_ = 0.0f, base_ = 0.0f, scale_ = 1.0f;
};

}  // namespace mp
