#include "pipeline/frame/camera_view.h"

#include <algorithm>
#include <optional>

#include "stages/mp_blur.h"

namespace mp {
namespace {

// Sub-patches sampled per launch when the caller can cancel.
constexpr cl_uint kSampleChunk = 256;

}  // namespace

// The threshold (kGpuWavesFromOverlap) from the H200: waves cost 1.35x at an
// overlap of 13 (16 stacked sheets), 1.4x at 6.7 (one shell around the
// camera) and 2.4-4.4x on the standard scenes (1-8), and gave 0.58x at 104
// (16 nested shells), 0.94x at 469 (64 shells) and 0.68x at 1,332 (1,000
// stacked layers): each wave's partly filled batch costs a GPU launches and
// host waits, which only much hidden work repays (docs/performance.md).
bool camera_takes_waves(const RenderSettings& settings, const DeviceInfo& device, double root_overlap) {
  if (settings.occlusion_waves != OcclusionWaves::Auto) return settings.occlusion_waves == OcclusionWaves::On;
  return device.type == "cpu" || root_overlap >= kGpuWavesFromOverlap;
}

bool render_camera_bucket(MicropolygonPass& pass, const CameraStages& stages, const Scene& scene,
                          const FrameSetup& frame, const Bucket& bucket, const ShadowInputs& shadows,
                          const CameraRoots& roots, uint64_t scene_key, RenderStats& st) {
  DeviceSession& s = pass.session();
  FrameProgress& progress = pass.progress();
  StageTimer& timer = pass.timer();
  const SceneBuffers& buffers = pass.scene();
  SampleStage& sample = stages.sample;
  const FrameParams fb = bucket_frame(frame.params, bucket);
  std::optional<DeviceSession::Activity> activity(std::in_place, s, "sample");
  sample.begin_frame(fb, timer, scene.shutter_curve, frame.bin_sampler);
  st.sampler = sample.sampler_name();
  if (progress.asked()) {
    s.queue().finish();  // clearing a large sample buffer takes a while: look again
    progress(0.0f);
  }
  PassView view{fb, PassViews{}, PassOcclusion{}};
  bool culling = false;
  // A blurred occluder hides only part of what lies behind it: culling
  // against the shutter centre's pinhole depths would lose what the lens
  // and the other times see past it.
  if (scene.settings.occlusion_culling && !mp_blur_on(fb)) {
    activity.emplace(s, "occlusion");
    OcclusionCulling& occ = stages.occlusion;
    occ.begin_frame(fb, timer);
    view.occlusion.pyramid = occ.pyramid();
    view.occlusion.params = occ.params();
    view.occlusion.root_order = occ.root_order(buffers.host_patch_bounds, buffers.host_instance_bounds, scene_key, fb);
    if (roots.seen > 0) view.occlusion.root_order = roots.order, view.occlusion.first_wave = roots.seen;
    st.root_overlap = occ.root_overlap();
    view.occlusion.waves = camera_takes_waves(scene.settings, s.info(), st.root_overlap);
    st.occlusion_waves = view.occlusion.waves;
    sample.mark_occlusion_cells(occ.dirty(), occ.params());
    view.occlusion.refresh = [&] {
      if (!progress.cancelled()) occ.refresh(sample.keys(), fb, timer);
    };
    culling = true;
  }
  activity.reset();
  CameraVisibility visibility(scene.settings, s.info(), culling, stages.occlusion.root_overlap(), sample, timer);

  ViewTarget target;
  target.motion = mp_motion_on(fb);
  target.dice_activity = "dice";
  target.take = [&](const cl::Buffer& diceable, cl_uint count) {
    GridBuffers& grids = pass.grids();
    std::optional<DeviceSession::Activity> step(std::in_place, s, "sample");
    const cl::Buffer& visible = visibility.before_shading(diceable, count, buffers, fb, grids);
    step.emplace(s, "shade");
    stages.shade.run(diceable, count, buffers, fb, grids, shadows, visible, timer);
    stages.programs.shade(diceable, count, buffers, fb, grids, shadows, visible, timer);
    visibility.before_sampling();
    // The tile sampler takes a batch at once (its lists cover the batch)
    // and asks between parts of its tiles.
    step.emplace(s, "sample");
    const cl_uint chunk = progress.asked() && !sample.tiles() ? kSampleChunk : count;
    std::function<bool()> ask;
    if (progress.asked())
      ask = [&] {
        s.queue().finish();
        return progress.again();
      };
    for (cl_uint first = 0; first < count && !progress.cancelled(); first += chunk) {
      sample.run(diceable, first, std::min(chunk, count - first), buffers, fb, grids, timer, visibility.took(), ask);
      if (progress.asked()) {
        s.queue().finish();
        progress.again();
      }
    }
    st.subpatches_diced += count;
    ++st.batches;
    visibility.after_sampling(grids, count);
  };
  const BoundSplitResult bs = pass.run(view, target);
  st.subpatches_occluded += bs.occluded;
  st.waves += bs.waves;
  if (bs.cancelled) return false;

  activity.emplace(s, "occlusion");
  st.covered_pixels += stages.occlusion.covered_pixels(sample.keys(), fb, timer, bucket);
  activity.emplace(s, "resolve");
  stages.resolve.run(sample, frame, fb, bucket, scene.settings.filter, scene.settings.filter_width,
                     scene.settings.depth_and_normal_passes, scene.settings.resolver, timer);
  st.resolver = stages.resolve.ran_tiled() ? "tiles" : "pixels";
  return true;
}

}  // namespace mp
