// Renderer: validates the scene, uploads it, runs bound & split with batches
// of dice -> shade -> sample, then resolves the pixels.
#include "micropoly/renderer.h"

#include <algorithm>
#include <chrono>
#include <optional>
#include <utility>

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

// Everything built on one device session that outlives a frame: the stages'
// kernels, the buffers whose size does not depend on the scene, and the last
// scene uploaded. A frame that fails drops all of it (Renderer::Impl::recover),
// so nothing a failed frame left half-built is seen again.
struct DeviceStages {
  explicit DeviceStages(DeviceSession& session)
      : layout(session, kDiceBatch),
        dice(session),
        shade(session),
        sample(session),
        resolve(session),
        programs(session),
        shadow_maps(session),
        occlusion(session) {}
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
  // The last scene uploaded, kept for the next render of the same content
  // (scene_fingerprint.h): progressive passes and repeated frames skip
  // building and uploading patches. scene_key is set only once the scene,
  // its lights and its world are all on the device.
  std::unique_ptr<SceneBuffers> scene_buffers;
  uint64_t scene_key = 0;
};

// What a failed frame says about its device session.
enum class SessionHealth {
  Good,     // the last frame succeeded (or none failed)
  Suspect,  // an error that can also mean a faulted device: ask it before use
  Lost,     // a device-lost error: open the device anew
};

struct Renderer::Impl {
  explicit Impl(const std::string& device_selector)
      : selector(device_selector), session(std::make_unique<DeviceSession>(selector)), info(session->info()) {}
  // The session and stages ready for a frame: after a failed frame, the
  // session is asked whether it still works (or, lost, reopened) and the
  // stages are built anew.
  DeviceSession& ready_session();
  void render_frame(const Scene& scene, RenderResult& out, const ProgressCallback& progress);
  // After a frame failed: waits for what the queue still holds (it may point
  // into host memory that is about to go), then frees the frame's device
  // state. `health` decides what the next render does with the session.
  void recover(SessionHealth health);

  std::string selector;
  std::unique_ptr<DeviceSession> session;
  std::unique_ptr<DeviceStages> stages;
  DeviceInfo info;  // the session's, kept while it is being reopened
  SessionHealth health = SessionHealth::Good;
  bool first_render = true;
  // The world's map and the lights derived from it (world-space, so a
  // moving camera keeps them), kept while the world stays the same. Host
  // memory only, and world_key is set once all three are complete.
  WorldMap world_map;
  std::vector<Light> world_lights;
  std::vector<glm::vec4> world_glossy;
  uint64_t world_key = 0;
  // Object-space patches of the last scenes' shapes: a moved camera or
  // object re-places them instead of rebuilding (patch_cache.h). Host
  // memory, filled before anything is uploaded.
  PatchCache patch_cache;
};

DeviceSession& Renderer::Impl::ready_session() {
  if (session && health == SessionHealth::Suspect && !session->responds()) health = SessionHealth::Lost;
  if (!session || health == SessionHealth::Lost) {
    // The old context goes first: a driver may hold the lost device's
    // memory until it is released. The fault plan carries over so a test's
    // one fault is not planted again by the new session.
    const FaultInjector faults = session ? session->faults().reopened() : FaultInjector();
    stages.reset();
    session.reset();
    try {
      session = std::make_unique<DeviceSession>(selector, faults);
    } catch (const Error& e) {
      throw Error("the OpenCL device '" + info.name + "' stopped responding and could not be opened again (" +
                  e.what() + "): check the driver (dmesg lists GPU faults), or choose another device");
    }
    info = session->info();
    first_render = true;
  }
  health = SessionHealth::Good;
  session->clear_failed_activity();
  if (!stages) {
    DeviceSession::Activity activity(*session, "setup");
    stages = std::make_unique<DeviceStages>(*session);
  }
  return *session;
}

void Renderer::Impl::recover(SessionHealth failed) {
  if (session) session->queue().drain();
  stages.reset();
  health = failed;
}

Renderer::Renderer(const std::string& selector) : impl_(std::make_unique<Impl>(selector)) {}
Renderer::~Renderer() = default;

const DeviceInfo& Renderer::device() const { return impl_->info; }

void Renderer::inject_device_fault(const std::string& plan) {
  const FaultPlan parsed = parse_fault_plan(plan);
  // Armed on the session the next frame uses; stages a failed frame dropped
  // are not built here, so a plan can target their setup.
  if (!impl_->session || impl_->health == SessionHealth::Lost) impl_->ready_session();
  impl_->session->faults().arm(parsed);
}

RenderResult Renderer::render(const Scene& scene, const ProgressCallback& progress) {
  RenderResult out;
  render(scene, out, progress);
  return out;
}

void Renderer::render(const Scene& scene, RenderResult& out, const ProgressCallback& progress) {
  validate_scene(scene);
  Impl& impl = *impl_;
  try {
    impl.ready_session();
    impl.render_frame(scene, out, progress);
  } catch (const cl::Error& e) {
    // A device error mid-frame: the frame's device state goes, and the
    // session is reopened (device lost) or tested (an out-of-resources
    // error, which some drivers also return for a faulted kernel) before the
    // next frame. The message names the phase of the frame that failed.
    const bool lost = cl_error_means_device_lost(e.err());
    impl.recover(lost ? SessionHealth::Lost : SessionHealth::Suspect);
    const std::string phase = impl.session ? impl.session->failed_activity() : std::string();
    const std::string where = phase.empty() ? "" : " (" + phase + ")";
    throw Error("rendering on '" + impl.info.name + "' failed" + where + ": " + describe_cl_error(e) +
                (lost ? "; the next render reopens the device" : "; the frame's device memory was freed"));
  } catch (...) {
    // Any other failure (a buffer larger than the device allows, host
    // memory, a progress callback that raised) may also leave stages half
    // set up: the next frame builds them anew on the same session.
    impl.recover(SessionHealth::Good);
    throw;
  }
}

void Renderer::Impl::render_frame(const Scene& scene, RenderResult& out, const ProgressCallback& progress) {
  auto t_start = std::chrono::steady_clock::now();
  DeviceSession& s = *session;
  DeviceStages& d = *stages;
  out.stats = RenderStats{};
  RenderStats& st = out.stats;
  st.device = s.info().name;
  if (first_render) {
    st.program_build_ms = s.program_build_ms();
    st.program_cache_hit = s.program_cache_hit();
    first_render = false;
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
  {
    StageTimer timer;
    auto t_upload = std::chrono::steady_clock::now();
    std::optional<DeviceSession::Activity> upload_activity(std::in_place, s, "upload");
    d.programs.prepare(scene, st);
    const uint64_t key = scene_fingerprint(scene);
    const bool fresh = !d.scene_buffers || d.scene_key != key;
    if (fresh) {
      d.scene_buffers.reset();  // free the old scene's device memory first
      d.scene_key = 0;          // and forget it until the new one is complete
      HostSceneData host = prepare_scene_data(scene, &patch_cache);
      d.scene_buffers = std::make_unique<SceneBuffers>(upload_scene_data(s, host));
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
        if (wkey != world_key) {
          world_map = scene.world.program >= 0 ? d.programs.bake_world(scene, *d.scene_buffers)
                                               : given_world_map(scene.world);
          world_lights = mp::world_lights(world_map, scene.world, scene.settings.world_probes);
          world_glossy = world_glossy_maps(world_map);
          world_key = wkey;
        }
      }
      lights.insert(lights.end(), world_lights.begin(), world_lights.end());
      if (fresh) {
        upload_lights(s, lights, scene.camera.world_to_camera, *d.scene_buffers);
        upload_world_glossy(s, world_glossy, *d.scene_buffers);
      }
    }
    if (fresh) d.scene_key = key;
    upload_activity.reset();
    const SceneBuffers& buffers = *d.scene_buffers;
    st.timings_ms.upload = ms_since(t_upload);
    st.patches = buffers.patch_count;

    if (!d.grids || d.grids->vertices_per_slot != static_cast<size_t>(f.max_grid + 1) * (f.max_grid + 1)) {
      d.grids.reset();
      d.grids = std::make_unique<GridBuffers>(s, kDiceBatch, f.max_grid);
    }
    GridBuffers& grids = *d.grids;
    const cl_uint capacity = grids.capacity;
    DiceStage& dice = d.dice;
    ShadeStage& shade = d.shade;
    SampleStage& sample = d.sample;
    ResolveStage& resolve = d.resolve;
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
      DeviceSession::Activity activity(s, "bound_split");
      if (scene.settings.bound_split == BoundSplitMethod::Bounded) {
        size_t budget = static_cast<size_t>(std::max(0.0f, scene.settings.bound_split_memory_mib) * 1048576.0);
        r = bound_split_bounded(ctx, budget, capacity, d.bounded);
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
    std::optional<DeviceSession::Activity> shadows_activity(std::in_place, s, "shadows");
    const bool shadows_done = d.shadow_maps.render(scene, lights, frame, buffers, {d.layout, dice, d.programs, grids},
                                                        run_pass, timer, st.shadows);
    shadows_activity.reset();
    st.timings_ms.shadows_wall = ms_since(t_shadows);
    const ShadowInputs& shadows = d.shadow_maps.inputs();
    d.layout.begin_frame();
    FrameParams fb = f;  // the bucket being rendered
    DiceSink sink = [&](const cl::Buffer& diceable, cl_uint count) {
      if (cancelled) return;
      std::optional<DeviceSession::Activity> activity(std::in_place, s, "dice");
      d.layout.run(diceable, count, fb, grids, timer);
      dice.run(diceable, count, buffers, fb, grids, timer);
      if (mp_motion_on(fb)) dice.run_motion(diceable, count, buffers, fb, grids, timer);
      d.programs.displace(diceable, count, buffers, fb, grids, timer);
      if (mp_motion_on(fb)) dice.displaced(diceable, count, fb, grids, timer);
      activity.emplace(s, "shade");
      shade.run(diceable, count, buffers, fb, grids, shadows, timer);
      d.programs.shade(diceable, count, buffers, fb, grids, shadows, timer);
      // The tile sampler takes a batch at once (its lists cover the batch)
      // and asks between parts of its tiles.
      activity.emplace(s, "sample");
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
      std::optional<DeviceSession::Activity> activity(std::in_place, s, "sample");
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
        activity.emplace(s, "occlusion");
        OcclusionCulling& occ = d.occlusion;
        occ.begin_frame(fb, timer);
        camera_occlusion.pyramid = occ.pyramid();
        camera_occlusion.params = occ.params();
        camera_occlusion.root_order = occ.root_order(buffers.host_patch_bounds, d.scene_key, fb);
        camera_occlusion.waves = s.info().type == "cpu";
        sample.mark_occlusion_cells(occ.dirty(), occ.params());
        camera_occlusion.refresh = [&] {
          if (!cancelled) occ.refresh(sample.keys(), fb, timer);
        };
        pass_occlusion = &camera_occlusion;
      }
      activity.reset();
      const BoundSplitResult bs = run_pass(fb, PassViews{}, sink);
      pass_occlusion = &no_occlusion;
      if (cancelled || bs.cancelled) {
        stopped = true;
        break;
      }
      activity.emplace(s, "occlusion");
      covered += d.occlusion.covered_pixels(sample.keys(), fb, timer, bucket);
      activity.emplace(s, "resolve");
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
    DeviceSession::Activity readback_activity(s, "readback");
    resolve.read_back(frame, scene.settings.depth_and_normal_passes, out);
    // The world behind the frame: its program, evaluated per pixel on the
    // device (finer than the baked map), or the map a scene gave.
    if (scene.world.present() && scene.world.camera)
      out.background = scene.world.program >= 0 ? d.programs.world_background(scene, buffers, f)
                                                : world_background(world_map, frame, scene.camera);
    else
      out.background.clear();
    st.timings_ms.readback += ms_since(t_resolve);
    timer.collect();
    st.micropolygons = d.layout.micropolygons();
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
  }
  st.timings_ms.total = ms_since(t_start);
  if (progress) progress(1.0f);
}

}  // namespace mp
