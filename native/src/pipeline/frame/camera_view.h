// The camera's view of one bucket (buckets.h): the micropolygon pass
// shades and samples each batch into the bucket's sample buffer, culling
// against the occlusion pyramid those samples build (waves near to far on
// CPU devices, and on GPUs where the roots overlap deeply), then the
// bucket is resolved into the image.
#pragma once

#include <cstdint>
#include <vector>

#include "micropoly/renderer.h"
#include "pipeline/frame/buckets.h"
#include "pipeline/frame/frame_params.h"
#include "pipeline/frame/visibility_choice.h"
#include "pipeline/materials/material_programs.h"
#include "pipeline/pass/micropolygon_pass.h"
#include "pipeline/pass/micropolygon_stages.h"
#include "pipeline/pass/occlusion_culling.h"

namespace mp {

// The stages only the camera's view runs.
struct CameraStages {
  ShadeStage& shade;
  MaterialPrograms& programs;
  SampleStage& sample;
  ResolveStage& resolve;
  OcclusionCulling& occlusion;
};

// The camera's roots with those an earlier look may see first (the shadow
// marking's coarse depth, MarkingDepth::seen_first): taken as a wave of
// their own when culling. None (seen 0): near to far only.
struct CameraRoots {
  cl::Buffer order;
  cl_uint seen = 0;
};

// Whether the camera's view takes its roots in waves (RenderSettings::
// occlusion_waves): Auto on CPU devices, and on others where the roots'
// boxes overlap at least kGpuWavesFromOverlap deep on average
// (OcclusionCulling::root_overlap).
constexpr double kGpuWavesFromOverlap = 64.0;
bool camera_takes_waves(const RenderSettings& settings, const DeviceInfo& device, double root_overlap);

// Renders bucket `bucket` of `frame` (shading reads `shadows`) and resolves
// it; false when the caller cancelled. `scene_key` keys the patches' order.
bool render_camera_bucket(MicropolygonPass& pass, const CameraStages& stages, const Scene& scene,
                          const FrameSetup& frame, const Bucket& bucket, const ShadowInputs& shadows,
                          const CameraRoots& roots, uint64_t scene_key, RenderStats& stats);

}  // namespace mp
