// Renderer: validates the scene, uploads it, renders the lights' views and
// then the camera's through the one micropolygon pass (micropolygon_pass.h),
// resolves the pixels and reads them back.
#include "micropoly/renderer.h"

#include <algorithm>
#include <chrono>
#include <functional>
#include <optional>
#include <utility>

#include "cl/device_session.h"
#include "micropoly/error.h"
#include "pipeline/pass/bound_split.h"
#include "pipeline/frame/buckets.h"
#include "pipeline/frame/camera_view.h"
#include "pipeline/frame/frame_params.h"
#include "pipeline/frame/image_read_back.h"
#include "pipeline/materials/material_programs.h"
#include "pipeline/pass/micropolygon_pass.h"
#include "pipeline/pass/micropolygon_stages.h"
#include "pipeline/pass/occlusion_culling.h"
#include "pipeline/device_scene/scene_buffers.h"
#include "pipeline/device_scene/scene_fingerprint.h"
#include "pipeline/shadows/shadow_maps.h"
#include "pipeline/world/world_lighting.h"
#include "stages/mp_blur.h"
#include "stages/mp_raster.h"

namespace mp {
namespace {

// Sub-patches per dice batch: grid buffers hold this many (max_grid+1)^2 grids.
constexpr cl_uint kDiceBatch = 8192;

// What would help a frame whose phase (DeviceSession::failed_activity) ran
// out of host memory.
std::string host_memory_advice(const std::string& phase) {
  const std::string first = phase.substr(0, phase.find('/'));
  if (first == "upload")
    return "the scene's surfaces did not fit as their patches were built (each patch of every placed copy takes "
           "about 700 bytes here and again on the device): render fewer copies of heavy objects, or lower their "
           "subdivision levels or their image textures' sizes";
  if (first == "shadows")
    return "the lights' views did not fit: lower the shadow memory budget, or shadow fewer lights";
  if (first == "readback")
    return "the image did not come back: lower the resolution, or leave out the Depth and Normal passes";
  return "the frame's work did not fit: close other programs, or lower the resolution, the samples or the "
         "sample and bound & split memory budgets";
}

// The frame's statistics of every pass' bound & split.
class FrameStatsObserver : public PassObserver {
 public:
  explicit FrameStatsObserver(RenderStats& st) : st_(st) {}
  void bound_split_done(const BoundSplitResult& r) override {
    st_.bound_split_peak_bytes = std::max(st_.bound_split_peak_bytes, r.peak_bytes);
    st_.bound_split_launches += r.launches;
  }

 private:
  RenderStats& st_;
};

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
        read_back(session),
        programs(session),
        shadow_maps(session),
        occlusion(session) {}
  GridLayoutStage layout;
  DiceStage dice;
  ShadeStage shade;
  SampleStage sample;
  ResolveStage resolve;
  ImageReadBack read_back;
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
  // The frame: upload, the lights' views, the camera's view bucket by
  // bucket, read back (left in flight when `overlapped`); the steps below.
  void render_frame(const Scene& scene, RenderResult& out, const ProgressCallback& progress, bool overlapped);
  // A frame checked and rendered within guarded(); Renderer::render and
  // render_overlapped.
  void render(const Scene& scene, RenderResult& out, const ProgressCallback& progress, bool overlapped);
  // Runs `frame` (a render, or the wait for an overlapped one's pixels),
  // turning a device error into an mp::Error and readying the session for
  // the next frame after any failure.
  void guarded(const std::function<void()>& frame);
  RenderStats& begin_stats(RenderResult& out);
  static FrameSetup setup_frame(const Scene& scene, const DeviceInfo& device, bool tile_sampler, RenderStats& st);
  // The scene, its lights and its world on the device (kept while the scene
  // stays the same); returns every light, the world's included.
  std::vector<Light> upload(const Scene& scene, RenderStats& st);
  GridBuffers& frame_grids(const FrameParams& f);
  static std::vector<Bucket> frame_buckets(const Scene& scene, const FrameParams& f, DeviceSession& s);
  void stop(RenderResult& out, std::chrono::steady_clock::time_point started);
  // Starts the image's read-back; ends it too unless `overlapped`.
  void read_back(const Scene& scene, const FrameSetup& frame, RenderResult& out, bool overlapped);
  // The frame's host waits and launches (queue_counts.h) into its stats.
  void collect_queue_counts(RenderStats& st);
  void collect_stage_times(StageTimer& timer, RenderStats& st);
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
  // moving camera keeps them), kept while the world stays the same; world_key
  // is set once both are complete. Its glossy maps are device memory, made
  // again when absent (a new world, or the device's memory dropped).
  WorldMap world_map;
  std::vector<Light> world_lights;
  cl::Buffer world_glossy;
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
    world_glossy = cl::Buffer();
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
  if (session) session->queue().drain(), session->transfer_queue().drain();
  stages.reset();  // waits for a read-back's worker
  world_glossy = cl::Buffer();
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
  impl_->render(scene, out, progress, false);
}

void Renderer::render_overlapped(const Scene& scene, RenderResult& out, const ProgressCallback& progress) {
  impl_->render(scene, out, progress, true);
}

void Renderer::Impl::render(const Scene& scene, RenderResult& out, const ProgressCallback& progress,
                            bool overlapped) {
  validate_scene(scene);
  guarded([&] {
    ready_session();
    render_frame(scene, out, progress, overlapped);
  });
}

void Renderer::finish_frame() {
  Impl& impl = *impl_;
  if (!impl.stages) return;  // a failed frame took its read-back with it
  impl.guarded([&] {
    DeviceSession::Activity activity(*impl.session, "readback");
    impl.stages->read_back.finish();
  });
}

void Renderer::Impl::guarded(const std::function<void()>& frame) {
  try {
    frame();
  } catch (const cl::Error& e) {
    // A device error mid-frame: the frame's device state goes, and the
    // session is reopened (device lost) or tested (an out-of-resources
    // error, which some drivers also return for a faulted kernel) before the
    // next frame. The message names the phase of the frame that failed.
    const bool lost = cl_error_means_device_lost(e.err());
    recover(lost ? SessionHealth::Lost : SessionHealth::Suspect);
    const std::string phase = session ? session->failed_activity() : std::string();
    const std::string where = phase.empty() ? "" : " (" + phase + ")";
    throw Error("rendering on '" + info.name + "' failed" + where + ": " + describe_cl_error(e) +
                (lost ? "; the next render reopens the device" : "; the frame's device memory was freed"));
  } catch (const std::bad_alloc&) {
    // Host memory: the frame's stages go as for any other failure below,
    // and the message says which phase did not fit and what would help.
    recover(SessionHealth::Good);
    const std::string phase = session ? session->failed_activity() : std::string();
    throw Error("rendering on '" + info.name + "' failed" + (phase.empty() ? "" : " (" + phase + ")") +
                ": the computer ran out of host memory; " + host_memory_advice(phase));
  } catch (...) {
    // Any other failure (a buffer larger than the device allows, a
    // progress callback that raised) may also leave stages half set up:
    // the next frame builds them anew on the same session.
    recover(SessionHealth::Good);
    throw;
  }
}

void Renderer::Impl::render_frame(const Scene& scene, RenderResult& out, const ProgressCallback& progress,
                                  bool overlapped) {
  const auto started = std::chrono::steady_clock::now();
  DeviceSession& s = *session;
  DeviceStages& d = *stages;
  if (d.read_back.lands_in(out)) {  // the last overlapped frame's, into the same result
    DeviceSession::Activity activity(s, "readback");
    d.read_back.finish();
  }
  RenderStats& st = begin_stats(out);
  const FrameSetup frame = setup_frame(scene, s.info(), s.tile_sampler(), st);
  StageTimer timer;
  const std::vector<Light> lights = upload(scene, st);
  const SceneBuffers& buffers = *d.scene_buffers;
  GridBuffers& grids = frame_grids(frame.params);
  FrameProgress asks(progress);
  if (!asks(0.0f)) return stop(out, started);  // cancelled before the frame's buffers are set up
  FrameStatsObserver observer(st);
  MicropolygonPass pass(s, buffers, scene.settings, {d.layout, d.dice, d.programs, grids, d.bounded}, timer, asks,
                        observer);
  // The lights' views first: shading the camera's view reads their maps.
  auto shadows_started = std::chrono::steady_clock::now();
  std::optional<DeviceSession::Activity> activity(std::in_place, s, "shadows");
  // The marking culls the camera's view as the camera does: near to far,
  // not under motion blur or depth of field (camera_view.cpp).
  cl::Buffer camera_order;
  if (scene.settings.shadows && scene.settings.occlusion_culling && !mp_blur_on(frame.params))
    camera_order = d.occlusion.root_order(buffers.host_patch_bounds, buffers.host_instance_bounds, d.scene_key, frame.params);
  bool going = d.shadow_maps.render(scene, lights, frame, pass, camera_order, st.shadows);
  activity.reset();
  st.timings_ms.shadows_wall = ms_since(shadows_started);
  // Then the camera's view, bucket by bucket within the sample budget.
  const std::vector<Bucket> buckets = frame_buckets(scene, frame.params, s);
  st.buckets = buckets.size();
  d.layout.begin_frame();
  d.read_back.before_resolve();  // the last frame's transfers read the image buffers
  const CameraStages camera{d.shade, d.programs, d.sample, d.resolve, d.occlusion};
  for (size_t b = 0; b < buckets.size() && going; ++b) {
    asks.set_share(float(b) / float(buckets.size()), 1.0f / float(buckets.size()));
    going = render_camera_bucket(pass, camera, scene, frame, buckets[b], d.shadow_maps.inputs(),
                                 d.shadow_maps.camera_roots(), d.scene_key, st);
  }
  if (!going) {
    s.queue().finish();
    return stop(out, started);
  }
  read_back(scene, frame, out, overlapped);
  // The kernels' times are read once they are done (a finished read-back
  // waited for them); an overlapped one may go on.
  if (overlapped || scene.settings.read_back == ReadBack::None) s.queue().finish();
  collect_stage_times(timer, st);
  collect_queue_counts(st);
  st.timings_ms.total = ms_since(started);
  if (progress) progress(1.0f);
}

RenderStats& Renderer::Impl::begin_stats(RenderResult& out) {
  out.stats = RenderStats{};
  RenderStats& st = out.stats;
  st.device = session->info().name;
  session->queue_counts().reset();
  if (first_render) {
    st.program_build_ms = session->program_build_ms();
    st.program_cache_hit = session->program_cache_hit();
    first_render = false;
  }
  return st;
}

FrameSetup Renderer::Impl::setup_frame(const Scene& scene, const DeviceInfo& device, bool tile_sampler,
                                       RenderStats& st) {
  FrameSetup frame = make_frame_setup(scene);
  // The sampler (RenderSettings::sampler): the tile sampler, which keeps
  // its sample colors planar, or (always for blurred frames) the
  // per-micropolygon one, and always where the device cannot build the
  // tile sampler (DeviceSession::tile_sampler).
  frame.params.planar_colors = (scene.settings.sampler == Sampler::Tiles ||
                                (scene.settings.sampler == Sampler::Auto && device.type == "cpu")) &&
                               !mp_blur_on(frame.params) && tile_sampler;
  // The binned sampler: pinhole frames, where the setting asks for it (on
  // the H200 it lost to the per-micropolygon sampler: docs/performance.md).
  frame.bin_sampler = !frame.params.planar_colors && !mp_blur_on(frame.params) &&
                      scene.settings.sampler == Sampler::Bins;
  frame.params.holdout_covers = scene.settings.holdout_covers ? 1 : 0;
  // Whether any material can hold out (mp_closures.h's mp_add_holdout in its
  // program): only then does the resolve read samples' held-out shares.
  frame.params.holdouts = std::any_of(scene.material_programs.begin(), scene.material_programs.end(),
                                      [](const MaterialProgram& p) {
                                        return p.source.find("mp_add_holdout") != std::string::npos;
                                      })
                              ? 1
                              : 0;
  st.width = frame.params.width;
  st.height = frame.params.height;
  st.spp = frame.params.spp_x * frame.params.spp_y;
  return frame;
}

std::vector<Light> Renderer::Impl::upload(const Scene& scene, RenderStats& st) {
  DeviceSession& s = *session;
  DeviceStages& d = *stages;
  const auto started = std::chrono::steady_clock::now();
  DeviceSession::Activity activity(s, "upload");
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
        world_glossy = cl::Buffer();
        world_key = wkey;
      }
      if (!world_glossy()) world_glossy = prefilter_world_glossy(s, world_map);
    }
    lights.insert(lights.end(), world_lights.begin(), world_lights.end());
    if (fresh) {
      upload_lights(s, lights, scene.camera.world_to_camera, *d.scene_buffers);
      set_world_glossy(s, world_glossy, *d.scene_buffers);
    }
  }
  if (fresh) d.scene_key = key;
  st.timings_ms.upload = ms_since(started);
  st.patches = d.scene_buffers->placed_patches;
  st.instances = d.scene_buffers->instance_count;
  st.scene_bytes = d.scene_buffers->bytes;
  return lights;
}

GridBuffers& Renderer::Impl::frame_grids(const FrameParams& f) {
  DeviceStages& d = *stages;
  if (!d.grids || d.grids->vertices_per_slot != static_cast<size_t>(f.max_grid + 1) * (f.max_grid + 1)) {
    d.grids.reset();
    d.grids = std::make_unique<GridBuffers>(*session, kDiceBatch, f.max_grid);
  }
  return *d.grids;
}

std::vector<Bucket> Renderer::Impl::frame_buckets(const Scene& scene, const FrameParams& f, DeviceSession& s) {
  // Buckets within the sample memory budget (buckets.h); a key, a color
  // and a normal per sample, and no buffer larger than the device allows.
  const size_t sample_bytes = sizeof(cl_ulong) + 3 * sizeof(cl_float) + sizeof(cl_uint);
  const size_t budget = static_cast<size_t>(double(scene.settings.sample_memory_mib) * 1048576.0);
  const size_t max_samples = std::min(budget / sample_bytes, s.max_alloc_bytes() / (3 * sizeof(cl_float)));
  const int reach = mp_filter_reach(std::max(scene.settings.filter_width, 1e-3f));
  return plan_buckets(f.width, f.height, f.spp_x * f.spp_y, reach, max_samples);
}

void Renderer::Impl::collect_queue_counts(RenderStats& st) {
  const QueueCounts& counts = session->queue_counts();
  st.host_waits = counts.waits.total();
  st.host_waits_by_phase = counts.waits.by_phase();
  st.kernel_launches = counts.launches.total();
  st.kernel_launches_by_phase = counts.launches.by_phase();
}

void Renderer::Impl::stop(RenderResult& out, std::chrono::steady_clock::time_point started) {
  out.stats.cancelled = true;
  collect_queue_counts(out.stats);
  out.stats.timings_ms.total = ms_since(started);
  out.width = out.height = 0;
  out.rgba.clear(), out.depth.clear(), out.normal.clear();
}

void Renderer::Impl::read_back(const Scene& scene, const FrameSetup& frame, RenderResult& out, bool overlapped) {
  DeviceStages& d = *stages;
  DeviceSession::Activity activity(*session, "readback");
  // The world behind the frame where the camera sees it (an opaque film):
  // its program, evaluated per pixel on the device (finer than the baked
  // map) and laid under the image before it is read, or the map a scene
  // gave, laid under it on the host once the image is in.
  const bool world_seen = scene.world.present() && scene.world.camera;
  const ReadBack format = scene.settings.read_back;
  if (world_seen && scene.world.program >= 0 && format != ReadBack::None)
    d.programs.composite_world(scene, *d.scene_buffers, frame.params, d.resolve.image());
  out.stats.surface_record_bytes = d.programs.record_pool_bytes();
  if (format == ReadBack::None) {
    d.read_back.finish();  // an earlier frame's, if any
    out.width = out.height = 0;  // no pixels (the stats keep the frame's size)
    out.rgba.clear(), out.depth.clear(), out.normal.clear();
    return;
  }
  d.read_back.start(d.resolve, frame, scene.settings.depth_and_normal_passes, format, out);
  const bool map_behind = world_seen && scene.world.program < 0;
  if (overlapped && !map_behind) return;
  d.read_back.finish();
  if (map_behind) composite_world_map(world_map, frame, scene.camera, out.rgba);
}

void Renderer::Impl::collect_stage_times(StageTimer& timer, RenderStats& st) {
  DeviceStages& d = *stages;
  timer.collect();
  st.micropolygons = d.layout.micropolygons();
  d.sample.sampled_totals(st.micropolygons_sampled, st.sampled_area_px, st.sample_tests, st.subpatches_unshaded);
  StageTimings& t = st.timings_ms;
  t.bound_split = timer.ms(Stage::BoundSplit);
  t.dice = timer.ms(Stage::Dice);
  t.shade = timer.ms(Stage::Shade);
  t.sample = timer.ms(Stage::Sample);
  t.resolve = timer.ms(Stage::Resolve);
  t.shadow_mark = timer.ms(Stage::ShadowMark);
  t.shadow_bound_split = timer.ms(Stage::ShadowBoundSplit);
  t.shadow_dice = timer.ms(Stage::ShadowDice);
  t.shadow_sample = timer.ms(Stage::ShadowSample);
  t.occlusion = timer.ms(Stage::Occlusion);
  t.shadow = t.shadow_bound_split + t.shadow_dice + t.shadow_sample;
}

}  // namespace mp
