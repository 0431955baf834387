// The one micropolygon pass every view runs: bound & split of the scene in
// the view (either method, within its budget) in bounded batches, each
// diced (motion, displacement, and alpha where the view needs opacity) and
// handed to the view's target, which shades and samples it (the camera),
// rasterises its depth into pages (a light's shadow maps) or marks the
// pages its vertices need (the shadow marking). A view supplies its
// projection, its target and its occlusion pyramid; nothing else differs.
#pragma once

#include <functional>

#include "cl/device_session.h"
#include "micropoly/renderer.h"
#include "pipeline/device_scene/scene_buffers.h"
#include "pipeline/frame/frame_params.h"
#include "pipeline/materials/material_programs.h"
#include "pipeline/pass/bound_split.h"
#include "pipeline/pass/frame_progress.h"
#include "pipeline/pass/micropolygon_stages.h"
#include "pipeline/pass/stage_timer.h"

namespace mp {

// What a view does with its batches once they are diced.
struct ViewTarget {
  bool motion = false;   // positions at every motion step (the camera's blurred view)
  bool normals = true;   // displacement keeps the displaced normals
  bool opacity = false;  // materials' alpha programs run (a light's views)
  // The phase a device error while dicing is reported in (DeviceSession's
  // activities), or none: the lights' views report their bound & split.
  const char* dice_activity = nullptr;
  // Called per batch: `count` diced sub-patches at the start of `diceable`,
  // their grids in the pass' GridBuffers.
  std::function<void(const cl::Buffer& diceable, cl_uint count)> take;
};

// A view of the pass: its projection and dicing rate (`frame`), the several
// views it renders at once (a light's shadow maps; none for the frame's
// own) and what culls hidden sub-patches.
struct PassView {
  const FrameParams& frame;
  PassViews views;
  PassOcclusion occlusion;
};

// Told what each pass' bound & split held and launched; the frame's
// statistics are kept by one.
struct PassObserver {
  virtual ~PassObserver() = default;
  virtual void bound_split_done(const BoundSplitResult& result) = 0;
};

// The stages and buffers the pass shares across views and frames.
struct PassStages {
  GridLayoutStage& layout;
  DiceStage& dice;
  MaterialPrograms& programs;
  GridBuffers& grids;
  BoundedWorkspace& bounded;
};

class MicropolygonPass {
 public:
  MicropolygonPass(DeviceSession& session, const SceneBuffers& scene, const RenderSettings& settings,
                   const PassStages& stages, StageTimer& timer, FrameProgress& progress, PassObserver& observer)
      : session_(session), scene_(scene), settings_(settings), stages_(stages), timer_(timer), progress_(progress),
        observer_(observer) {}
  // Renders the scene in `view` into `target`; the result says whether the
  // caller cancelled (progress), before or during the pass, and what bound
  // & split held and culled.
  BoundSplitResult run(const PassView& view, const ViewTarget& target);
  GridBuffers& grids() { return stages_.grids; }
  GridLayoutStage& layout() { return stages_.layout; }
  const SceneBuffers& scene() const { return scene_; }
  StageTimer& timer() { return timer_; }
  DeviceSession& session() { return session_; }
  FrameProgress& progress() { return progress_; }

 private:
  DeviceSession& session_;
  const SceneBuffers& scene_;
  const RenderSettings& settings_;
  PassStages stages_;
  StageTimer& timer_;
  FrameProgress& progress_;
  PassObserver& observer_;
};

}  // namespace mp
