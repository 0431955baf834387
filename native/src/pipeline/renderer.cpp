// Renderer: validates the scene, uploads it, runs bound & split with batches
// of dice -> shade -> sample, then resolves the pixels.
#include "micropoly/renderer.h"

#include <algorithm>
#include <chrono>

#include "cl/device_session.h"
#include "micropoly/error.h"
#include "pipeline/bound_split.h"
#include "pipeline/buckets.h"
#include "pipeline/frame_params.h"
#include "pipeline/material_programs.h"
#include "pipeline/micropolygon_stages.h"
#include "pipeline/occlusion_culling.h"
#include "pipeline/scene_buffers.h"
#include "pipeline/scene_fingerprint.h"
#include "pipeline/shadow_maps.h"
#include "pipeline/world_lighting.h"
#include "mp_blur.h"
#include "mp_raster.h"

namespace mp {
namespace {

// Sub-patches per dice batch: grid buffers hold this many (max_grid+1)^2 grids.
constexpr cl_uint kDiceBatch = 8192;
// Sub-patches sampled per launch when the caller can cancel.
constexpr cl_uint kSampleChunk = 256;

}  // namespace

// Everything that outlives one frame: the device session, the stages' kernels
// and the buffers whose size does not depend on the scene.
struct Renderer::Impl {
  explicit Impl(const std::string& selector)
      : session(selector),
        layout(session, kDiceBatch),
        dice(session),
        shade(session),
        sample(session),
        resolve(session),
        programs(session),
        shadow_maps(session),
        occlusion(session) {}
  DeviceSession session;
  GridLayoutStage layout;
  DiceStage dice;
  ShadeStage shade;
  SampleStage sample;
  ResolveStage resolve;
  MaterialPrograms programs;
  ShadowMaps shadow_maps;
  OcclusionCulling occlusion;
  std::unique_ptr<GridBuffers> grids;
  BoundedWorkspace bounded;
  bool first_render = true;
  // The last scene uploaded, kept for the next render of the same content
  // (scene_fingerprint.h): progressive passes and repeated frames skip
  // building and uploading patches.
  std::unique_ptr<SceneBuffers> scene_buffers;
  uint64_t scene_key = 0;
  // The world's map and the lights derived from it (world-space, so a
  // moving camera keeps them), kept while the world stays the same.
  WorldMap world_map;
  std::vector<Light> world_lights;
  std::vector<glm::vec4> world_glossy;
  uint64_t world_key = 0;
  // Object-space patches of the last scenes' shapes: a moved camera or
  // object re-places them instead of rebuilding (patch_cache.h).
  PatchCache patch_cache;
};

Renderer::Renderer(const std::string& selector) : impl_(std::make_unique<Impl>(selector)) {}
Renderer::~Renderer() = default;

const DeviceInfo& Renderer::device() const { return impl_->session.info(); }

RenderResult Renderer::render(const Scene& scene, const ProgressCallback& progress) {
  RenderResult out;
  render(scene, out, progress);
  return out;
}

void Renderer::render(const Scene& scene, RenderResult& out, const ProgressCallback& progress) {
  validate_scene(scene);
  auto t_start = std::chrono::steady_clock::now();
  DeviceSession& s = impl_->session;
  out.stats = RenderStats{};
  RenderStats& st = out.stats;
  st.device = s.info().name;
  if (impl_->first_render) {
    st.program_build_ms = s.program_build_ms();
    st.program_cache_hit = s.program_cache_hit();
    impl_->first_render = false;
  }
  FrameSetup frame = make_frame_setup(scene);
  // The sampler (RenderSettings::sampler): the tile sampler, which keeps
  // its sample colors planar, or (always for blurred frames) the
  // per-micropolygon one, and always where the device cannot build the
  // tile sampler (DeviceSession::tile_sampler).
  frame.params.planar_colors = (scene.settings.sampler == Sampler::Tiles ||
                                (scene.settings.sampler == Sampler::Auto && s.info().type == "cpu")) &&
                               !mp_blur_on(frame.params) && s.tile_sampler();
  frame.params.holdout_covers = scene.settings.holdout_covers ? 1 : 0;
  // Whether any material can hold out (mp_closures.h's mp_add_holdout in its
  // program): only then does the resolve read samples' held-out shares.
  frame.params.holdouts = std::any_of(scene.material_programs.begin(), scene.material_programs.end(),
                                      [](const MaterialProgram& p) {
                                        return p.source.find("mp_add_holdout") != std::string::npos;
                                      })
                              ? 1
                              : 0;
  const FrameParams& f = frame.params;
  st.width = f.width;
  st.height = f.height;
  st.spp = f.spp_x * f.spp_y;
  try {
    StageTimer timer;
    auto t_upload = std::chrono::steady_clock::now();
    impl_->programs.prepare(scene, st);
    const uint64_t key = scene_fingerprint(scene);
    const bool fresh = !impl_->scene_buffers || impl_->scene_key != key;
    if (fresh) {
      impl_->scene_buffers.reset();  // free the old scene's device memory first
      HostSceneData host = prepare_scene_data(scene, &impl_->patch_cache);
      impl_->scene_buffers = std::make_unique<SceneBuffers>(upload_scene_data(s.context(), s.queue(), host));
      impl_->scene_key = key;
    } else {
      st.scene_reused = true;
    }
    // The scene's lights, then its world's (world_lighting.h). The world's
    // map is baked (with the uploaded images) only when the world changed,
    // and its lights join the device's after the scene's upload: the scene
    // key covers camera, lights and world, so reused buffers hold them.
    std::vector<Light> lights = scene.lights;
    if (scene.world.present()) {
      if (fresh) {
        const uint64_t wkey = world_fingerprint(scene);
        if (wkey != impl_->world_key) {
          impl_->world_map = scene.world.program >= 0 ? impl_->programs.bake_world(scene, *impl_->scene_buffers)
                                                      : given_world_map(scene.world);
          impl_->world_lights = world_lights(impl_->world_map, scene.world, scene.settings.world_probes);
          impl_->world_glossy = world_glossy_maps(impl_->world_map);
          impl_->world_key = wkey;
        }
      }
      lights.insert(lights.end(), impl_->world_lights.begin(), impl_->world_lights.end());
      if (fresh) {
        upload_lights(s.context(), s.queue(), lights, scene.camera.world_to_camera, *impl_->scene_buffers);
        upload_world_glossy(s.context(), s.queue(), impl_->world_glossy, *impl_->scene_buffers);
      }
    }
    const SceneBuffers& buffers = *impl_->scene_buffers;
    st.timings_ms.upload = ms_since(t_upload);
    st.patches = buffers.patch_count;

    if (!impl_->grids || impl_->grids->vertices_per_slot != static_cast<size_t>(f.max_grid + 1) * (f.max_grid + 1)) {
      impl_->grids.reset();
      impl_->grids = std::make_unique<GridBuffers>(s, kDiceBatch, f.max_grid);
    }
    GridBuffers& grids = *impl_->grids;
    const cl_uint capacity = grids.capacity;
    DiceStage& dice = impl_->dice;
    ShadeStage& shade = impl_->shade;
    SampleStage& sample = impl_->sample;
    ResolveStage& resolve = impl_->resolve;
    if (progress && !progress(0.0f)) {  // cancelled before the frame's buffers are set up
      st.cancelled = true;
      out.width = out.height = 0;
      out.rgba.clear(), out.depth.clear(), out.normal.clear();
      return;
    }
    // Buckets within the sample memory budget (buckets.h); a key, a color
    // and a normal per sample, and no buffer larger than the device allows.
    const size_t sample_bytes = sizeof(cl_ulong) + 3 * sizeof(cl_float) + sizeof(cl_uint);
    const size_t budget = static_cast<size_t>(double(scene.settings.sample_memory_mib) * 1048576.0);
    const size_t max_samples = std::min(budget / sample_bytes, s.max_alloc_bytes() / (3 * sizeof(cl_float)));
    const int reach = mp_filter_reach(std::max(scene.settings.filter_width, 1e-3f));
    const std::vector<Bucket> buckets = plan_buckets(f.width, f.height, f.spp_x * f.spp_y, reach, max_samples);
    st.buckets = buckets.size();

    // Cancellation: the caller's progress callback is asked between bound &
    // split launches and between sample chunks, so a cancel takes effect within
    // one chunk's worth of device work.
    bool cancelled = false;
    float last_progress = 0.0f;
    float progress_base = 0.0f, progress_scale = 1.0f;  // the bucket's share of the frame
    ProgressCallback keep_going = [&](float p) {
      last_progress = p;
      p = progress_base + progress_scale * p;
      if (!cancelled && progress && !progress(p)) cancelled = true;
      return !cancelled;
    };
    // Bound & split of the scene in one pass: the camera's view, or the
    // lights' views of the shadow maps.
    // Occlusion culling applies to the camera's own pass only.
    const PassOcclusion no_occlusion;
    const PassOcclusion* pass_occlusion = &no_occlusion;
    BoundSplitRunner run_pass = [&](const FrameParams& pass_frame, const PassViews& views, const DiceSink& pass_sink) {
      BoundSplitContext ctx{s, buffers, pass_frame, timer, pass_sink, keep_going, views, *pass_occlusion};
      BoundSplitResult r;
      if (buffers.patch_count == 0 || cancelled) return r;
      if (scene.settings.bound_split == BoundSplitMethod::Bounded) {
        size_t budget = static_cast<size_t>(std::max(0.0f, scene.settings.bound_split_memory_mib) * 1048576.0);
        r = bound_split_bounded(ctx, budget, capacity, impl_->bounded);
      } else {
        r = bound_split_breadth(ctx, capacity);
      }
      st.bound_split_peak_bytes = std::max(st.bound_split_peak_bytes, r.peak_bytes);
      st.bound_split_launches += r.launches;
      st.subpatches_occluded += r.occluded;
      r.cancelled = r.cancelled || cancelled;
      return r;
    };
    // The shadow maps first: shading the camera's view reads them.
    auto t_shadows = std::chrono::steady_clock::now();
    const bool shadows_done = impl_->shadow_maps.render(scene, lights, frame, buffers, {impl_->layout, dice, impl_->programs, grids},
                                                        run_pass, timer, st.shadows);
    st.timings_ms.shadows_wall = ms_since(t_shadows);
    const ShadowInputs& shadows = impl_->shadow_maps.inputs();
    impl_->layout.begin_frame();
    FrameParams fb = f;  // the bucket being rendered
    DiceSink sink = [&](const cl::Buffer& diceable, cl_uint count) {
      if (cancelled) return;
      impl_->layout.run(diceable, count, fb, grids, timer);
      dice.run(diceable, count, buffers, fb, grids, timer);
      if (mp_motion_on(fb)) dice.run_motion(diceable, count, buffers, fb, grids, timer);
      impl_->programs.displace(diceable, count, buffers, fb, grids, timer);
      if (mp_motion_on(fb)) dice.displaced(diceable, count, fb, grids, timer);
      shade.run(diceable, count, buffers, fb, grids, shadows, timer);
      impl_->programs.shade(diceable, count, buffers, fb, grids, shadows, timer);
      // The tile sampler takes a batch at once (its lists cover the batch)
      // and asks between parts of its tiles.
      const cl_uint chunk = progress && !sample.tiles() ? kSampleChunk : count;
      std::function<bool()> ask;
      if (progress)
        ask = [&] {
          s.queue().finish();
          return keep_going(last_progress);
        };
      for (cl_uint first = 0; first < count && !cancelled; first += chunk) {
        sample.run(diceable, first, std::min(chunk, count - first), buffers, fb, grids, timer, ask);
        if (progress) {
          s.queue().finish();
          keep_going(last_progress);
        }
      }
      st.subpatches_diced += count;
      ++st.batches;
    };
    bool stopped = !shadows_done;
    size_t covered = 0;
    for (size_t bi = 0; bi < buckets.size() && !stopped; ++bi) {
      const Bucket& bucket = buckets[bi];
      fb = bucket_frame(f, bucket);
      progress_base = float(bi) / float(buckets.size()), progress_scale = 1.0f / float(buckets.size());
      sample.begin_frame(fb, timer, scene.shutter_curve);
      if (progress) {
        s.queue().finish();  // clearing a large sample buffer takes a while: look again
        keep_going(0.0f);
      }
      PassOcclusion camera_occlusion;
      pass_occlusion = &no_occlusion;
      // A blurred occluder hides only part of what lies behind it: culling
      // against the shutter centre's pinhole depths would lose what the lens
      // and the other times see past it.
      if (scene.settings.occlusion_culling && !mp_blur_on(fb)) {
        OcclusionCulling& occ = impl_->occlusion;
        occ.begin_frame(fb, timer);
        camera_occlusion.pyramid = occ.pyramid();
        camera_occlusion.params = occ.params();
        camera_occlusion.root_order = occ.root_order(buffers.host_patch_bounds, impl_->scene_key, fb);
        camera_occlusion.waves = s.info().type == "cpu";
        sample.mark_occlusion_cells(occ.dirty(), occ.params());
        camera_occlusion.refresh = [&] {
          if (!cancelled) occ.refresh(sample.keys(), fb, timer);
        };
        pass_occlusion = &camera_occlusion;
      }
      const BoundSplitResult bs = run_pass(fb, PassViews{}, sink);
      pass_occlusion = &no_occlusion;
      if (cancelled || bs.cancelled) {
        stopped = true;
        break;
      }
      covered += impl_->occlusion.covered_pixels(sample.keys(), fb, timer, bucket);
      auto t_resolve = std::chrono::steady_clock::now();
      resolve.run(sample, frame, fb, bucket, scene.settings.filter, scene.settings.filter_width,
                  scene.settings.depth_and_normal_passes, timer);
      st.timings_ms.readback += ms_since(t_resolve);
    }
    if (stopped) {
      s.queue().finish();
      st.cancelled = true;
      st.timings_ms.total = ms_since(t_start);
      out.width = out.height = 0;
      out.rgba.clear(), out.depth.clear(), out.normal.clear();
      return;
    }
    st.covered_pixels = covered;
    auto t_resolve = std::chrono::steady_clock::now();
    resolve.read_back(frame, scene.settings.depth_and_normal_passes, out);
    // The world behind the frame: its program, evaluated per pixel on the
    // device (finer than the baked map), or the map a scene gave.
    if (scene.world.present() && scene.world.camera)
      out.background = scene.world.program >= 0 ? impl_->programs.world_background(scene, buffers, f)
                                                : world_background(impl_->world_map, frame, scene.camera);
    else
      out.background.clear();
    st.timings_ms.readback += ms_since(t_resolve);
    timer.collect();
    st.micropolygons = impl_->layout.micropolygons();
    sample.sampled_totals(st.micropolygons_sampled, st.sampled_area_px, st.sample_tests);
    st.timings_ms.bound_split = timer.ms(Stage::BoundSplit);
    st.timings_ms.dice = timer.ms(Stage::Dice);
    st.timings_ms.shade = timer.ms(Stage::Shade);
    st.timings_ms.sample = timer.ms(Stage::Sample);
    st.timings_ms.resolve = timer.ms(Stage::Resolve);
    st.timings_ms.shadow_mark = timer.ms(Stage::ShadowMark);
    st.timings_ms.shadow_bound_split = timer.ms(Stage::ShadowBoundSplit);
    st.timings_ms.shadow_dice = timer.ms(Stage::ShadowDice);
    st.timings_ms.shadow_sample = timer.ms(Stage::ShadowSample);
    st.timings_ms.occlusion = timer.ms(Stage::Occlusion);
    st.timings_ms.shadow = st.timings_ms.shadow_bound_split + st.timings_ms.shadow_dice + st.timings_ms.shadow_sample;
  } catch (const cl::Error& e) {
    throw Error("rendering on '" + s.info().name + "': " + describe_cl_error(e));
  }
  st.timings_ms.total = ms_since(t_start);
  if (progress) progress(1.0f);
}

}  // namespace mp
