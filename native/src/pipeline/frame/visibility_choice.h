// Whether a camera batch takes visibility first (SampleStage::visibility):
// always or never when the setting says so; under Auto, chosen batch by
// batch from what the last batch measured. Visibility first saves the
// shading of the grids it finds hidden and costs its own depth and marking
// passes, so it pays where much is hidden and shading costs more than
// rasterising depth (hidden layers under lamps with soft shadows), and
// loses where little is hidden or shading is cheap. The next batch takes
// it when the hidden micropolygons' shading would cost more than the
// passes:
//  - after a batch that took it: the micropolygons of the grids it left
//    unshaded, against its passes' device time;
//  - after one that did not: the micropolygons the tile sampler found hidden
//    when it sampled them (by what came before them, as near to far order
//    makes most hidden ones), against the passes' cost per micropolygon on
//    the last batch that took it, or at first kFirstPassesShare of the
//    batch's sample time (0.5 to 0.9 of the sample stage on PoCL).
// What a hidden micropolygon costs to shade is not the average: behind
// other surfaces it is often in their shadow too, where soft shadows filter
// most (nested shells with the lamp inside), or lit as cheaply as the rest
// (the lamp outside). So it is solved from the two kinds of batch: a batch
// that took it shades the seen ones only (c_seen per micropolygon), one
// that did not shades all at the average c = h c_hidden + (1 - h) c_seen
// for its hidden share h; until both are measured, c_hidden = c. A batch
// that did not take it must find it paying by a margin (kStartMargin) for
// the next to take it.
// The first batch of a view (a CPU's first wave, one root) takes it not.
#pragma once

#include <algorithm>
#include <cstddef>
#include <utility>

#include "micropoly/scene.h"
#include "pipeline/pass/micropolygon_stages.h"

namespace mp {

class VisibilityChoice {
 public:
  // `automatic`: chosen by measurement (then `on` is only the first choice).
  VisibilityChoice(bool automatic, bool on) : automatic_(automatic), on_(on) {}
  bool automatic() const { return automatic_; }
  // For the next batch.
  bool take() const { return on_; }

  struct Batch {
    bool took = false;
    double passes_ms = 0, shade_ms = 0, sample_ms = 0;  // device time
    size_t grids = 0, micropolygons = 0;
    size_t unshaded = 0;  // grids it left unshaded (took)
    size_t lost = 0;      // micropolygons hidden when sampled (did not take)
  };
  void measured(const Batch& b) {
    if (!automatic_ || b.micropolygons == 0) return;
    const double n = double(b.micropolygons);
    double hidden = 0, cost = 0;
    if (b.took) {
      hidden = std::min(n, double(b.unshaded) * n / double(b.grids ? b.grids : 1));
      if (n > hidden) seen_ = b.shade_ms / (n - hidden);
      cost = b.passes_ms;
      passes_per_micropolygon_ = b.passes_ms / n;
    } else {
      hidden = double(b.lost);
      average_ = b.shade_ms / n;
      share_ = hidden / n;
      cost = passes_per_micropolygon_ > 0 ? passes_per_micropolygon_ * n : kFirstPassesShare * b.sample_ms;
    }
    // A margin to start (device times on a busy CPU vary by a tenth or more
    // from batch to batch), none to go on.
    on_ = hidden_cost() * hidden > (on_ ? 1.0 : kStartMargin) * cost;
  }

 private:
  // Shading per hidden micropolygon (ms), from the last batch of each kind.
  double hidden_cost() const {
    if (seen_ < 0 || share_ <= 0) return average_;
    return std::max(0.0, (average_ - (1.0 - share_) * seen_) / share_);
  }
  static constexpr double kFirstPassesShare = 0.9;
  static constexpr double kStartMargin = 1.25;
  bool automatic_, on_;
  double passes_per_micropolygon_ = 0;  // the last batch that took it: its passes
  double seen_ = -1;                    // and its shading, per micropolygon shaded
  double average_ = 0, share_ = 0;      // the last that did not: its shading per micropolygon, hidden share
};

// The camera view's use of it, batch by batch: chooses (the setting, or
// Auto's VisibilityChoice on CPU devices whose view culls and whose roots'
// boxes overlap deeply), runs the visibility passes, and has the batch's
// counts read while the queue goes on, to weigh them when the next batch
// comes.
class CameraVisibility {
 public:
  CameraVisibility(const RenderSettings& settings, const DeviceInfo& device, bool culling, double root_overlap,
                   SampleStage& sample, StageTimer& timer);
  ~CameraVisibility();
  CameraVisibility(const CameraVisibility&) = delete;
  CameraVisibility& operator=(const CameraVisibility&) = delete;
  // Before a batch is shaded: whether it takes visibility first, and if so
  // its passes run; the marks shading reads (none: shade every grid).
  const cl::Buffer& before_shading(const cl::Buffer& diceable, cl_uint count, const SceneBuffers& scene,
                                   const FrameParams& f, GridBuffers& grids);
  bool took() const { return took_; }
  void before_sampling() { sample_from_ = timer_.cursor(); }
  void after_sampling(const GridBuffers& grids, cl_uint count);

 private:
  void weigh_last();
  VisibilityChoice choice_;
  SampleStage& sample_;
  StageTimer& timer_;
  const cl::Buffer none_;
  bool took_ = false, pending_ = false;
  size_t passes_from_ = 0, shade_from_ = 0, sample_from_ = 0;  // the batch's timer cursors
  VisibilityChoice::Batch last_;  // the batch whose counts are being read
  std::pair<size_t, size_t> last_passes_, last_shade_, last_sample_;
  SampleStage::HiddenCounts counted_;  // the counts at the last batch weighed
};

}  // namespace mp
