// The stages after bound & split, run once per batch of diceable
// sub-patches: dice -> shade -> sample, then resolve once per bucket
// (buckets.h). Grids live in fixed slots of (max_grid+1)^2 vertices.
#pragma once

#include <functional>
#include <vector>

#include "cl/device_session.h"
#include "cl/kernel_args.h"
#include "micropoly/renderer.h"
#include "pipeline/frame/buckets.h"
#include "pipeline/frame/frame_params.h"
#include "pipeline/device_scene/scene_buffers.h"
#include "pipeline/device_scene/scene_kernel.h"
#include "pipeline/pass/stage_timer.h"

namespace mp {

// What the per-tile sample tables (positions, lens positions) and the
// resolve's filter weights depend on.
struct SamplePattern {
  int spp_x = 0, spp_y = 0;
  cl_uint seed = 0;
  int lens = 0, motion = 0, blades = 0;
  float radius = 0, x_scale = 0, rotation = 0;
  std::vector<float> shutter_curve;  // with motion (Scene::shutter_curve)
  bool operator==(const SamplePattern& o) const {
    return spp_x == o.spp_x && spp_y == o.spp_y && seed == o.seed && lens == o.lens && motion == o.motion &&
           blades == o.blades && radius == o.radius && x_scale == o.x_scale && rotation == o.rotation &&
           shutter_curve == o.shutter_curve;
  }
};
SamplePattern sample_pattern(const FrameParams& f, const std::vector<float>& shutter_curve = {});


// A time in the shutter as a shutter curve opens it: uniform times [0, 1]
// through the inverse of the curve's cumulative openness (piecewise linear
// curve, so a piecewise quadratic CDF; solved per segment). Monotonic, so
// strata of times stay strata.
float warp_shutter_time(float u, const std::vector<float>& curve);

struct GridBuffers {
  GridBuffers(DeviceSession& session, cl_uint capacity, int max_grid);
  cl::Buffer p, n, c;  // float4 per grid vertex
  cl_uint capacity;    // sub-patches per batch
  size_t vertices_per_slot;
  // Motion blur: positions at each motion step (step k from k * slot_space()),
  // and the centre's positions before displacement; made on first use.
  cl::Buffer motion_p, rest_p;
  int motion_steps = 0;
  size_t slot_space() const { return size_t(capacity) * vertices_per_slot; }
  void ensure_motion(DeviceSession& session, int steps);
  // The batch's layout (GridLayoutStage): each grid's first vertex and first
  // micropolygon, then the batch's totals (count + 1 uints each). The
  // micropolygon offsets are kept on the host too, to size sample launches.
  cl::Buffer vertex_offsets, micropolygon_offsets;
  cl_uint vertex_total = 0;
  // Visibility first (SampleStage::visibility): a byte per slot, set where
  // the grid is opaque and owns a sample before shading.
  cl::Buffer visible;
  std::vector<cl_uint> micropolygon_offsets_host;
};

// Counts each grid's vertices and micropolygons and sums them into offsets,
// so that dice, shade and sample launch one work-item per vertex or
// micropolygon rather than per fixed slot.
class GridLayoutStage {
 public:
  GridLayoutStage(DeviceSession& session, cl_uint capacity);
  ~GridLayoutStage();
  GridLayoutStage(const GridLayoutStage&) = delete;
  GridLayoutStage& operator=(const GridLayoutStage&) = delete;
  void run(const cl::Buffer& diceable, cl_uint count, const FrameParams& f, GridBuffers& grids, StageTimer& timer);
  void begin_frame() { micropolygons_ = 0; }
  size_t micropolygons() const { return micropolygons_; }  // diced this frame

 private:
  DeviceSession& session_;
  cl::Kernel kernel_;
  cl::Buffer counts_;                 // vertices and micropolygons per grid, interleaved
  std::vector<cl_uint> counts_host_, vertex_offsets_host_;
  cl::Event written_;  // the last batch's offsets written (from vertex_offsets_host_ and the grids')
  size_t micropolygons_ = 0;
};

// The shadow maps that shading reads (kernels/shadow/mp_shadow.h; built by
// ShadowMaps): none unless `enabled`.
struct ShadowInputs {
  bool enabled = false;
  cl::Buffer shadows, levels, pages, pool;
  // As the kernels take them (MP_SHADOW_INPUT_PARAMS, mp_shadow.h): whether
  // enabled, then the four buffers.
  auto args() const { return arg_pack(cl_uint(enabled ? 1 : 0), shadows, levels, pages, pool); }
};

class DiceStage {
 public:
  explicit DiceStage(DeviceSession& session);
  // `views`: the pass' views (count of them; none for the frame's own),
  // which ribbons turn to face (kernels/geometry/mp_ribbon.h).
  void run(const cl::Buffer& diceable, cl_uint count, const SceneBuffers& scene, const FrameParams& f,
           const cl::Buffer& views, cl_uint view_count, GridBuffers& grids, StageTimer& timer);
  // Motion blur: the same grids' positions at every motion step
  // (grids.motion_p). Run before displacement: `displaced` then moves them
  // by what displacement added at the shutter centre.
  void run_motion(const cl::Buffer& diceable, cl_uint count, const SceneBuffers& scene, const FrameParams& f,
                  GridBuffers& grids, StageTimer& timer);
  void displaced(const cl::Buffer& diceable, cl_uint count, const FrameParams& f, GridBuffers& grids,
                 StageTimer& timer);

 private:
  DeviceSession& session_;
  SceneKernel kernel_, motion_kernel_;
  cl::Kernel displaced_kernel_;
};

class ShadeStage {
 public:
  explicit ShadeStage(DeviceSession& session);
  // Shades the batch's grid vertices; with `visible` (visibility first's
  // marks, grids.visible), not those of opaque grids left unmarked.
  void run(const cl::Buffer& diceable, cl_uint count, const SceneBuffers& scene, const FrameParams& f,
           GridBuffers& grids, const ShadowInputs& shadows, const cl::Buffer& visible, StageTimer& timer);

 private:
  DeviceSession& session_;
  SceneKernel kernel_;
};

class SampleStage {
 public:
  explicit SampleStage(DeviceSession& session);
  // Makes the sample buffers (key, color, normal per sample) fit the frame,
  // reusing them when the size is unchanged, and clears them. A frame with
  // planar sample colors (FrameParams.planar_colors, set by the renderer) is
  // sampled by screen tiles (sample_tiles.cl); else, where `bins` asks and
  // a bin's keys fit local memory (bin_side), by bins (sample_bins.cl);
  // else one work-item per micropolygon (sample.cl).
  void begin_frame(const FrameParams& f, StageTimer& timer, const std::vector<float>& shutter_curve = {},
                   bool bins = false);
  bool tiles() const { return tiles_; }
  bool bins() const { return bin_side_ > 0; }
  // The sampler begin_frame chose: "tiles", "bins" or "micropolygons".
  const char* sampler_name() const { return tiles_ ? "tiles" : bin_side_ > 0 ? "bins" : "micropolygons"; }
  // Pixels per side of the binned sampler's bins at `spp` samples per
  // pixel on a device with `local_bytes` of local memory per work-group:
  // the largest of 32, 16 and 8 whose keys (8 bytes a sample) fit
  // kBinKeyBytes and the device; 0 where none does.
  static int bin_side(int spp, size_t local_bytes);
  static constexpr size_t kBinKeyBytes = 32 * 1024;
  // Visibility first, before a batch's grids are shaded: the nearest keys
  // of its grids whose material is opaque whatever its shading, then a mark
  // (grids.visible) on each of those that owns a sample; the others cannot
  // show in the image, and shading skips them. run() then samples the batch
  // with `after_visibility`: those grids' keys stay, the unmarked are
  // skipped. The image is the same either way, bit for bit. Returns the
  // timer's cursor where its own passes start (the tile sampler's binning
  // before it serves the batch's sampling too).
  size_t visibility(const cl::Buffer& diceable, cl_uint count, const SceneBuffers& scene, const FrameParams& f,
                  GridBuffers& grids, StageTimer& timer);
  // Samples the grids of diceable sub-patches [first, first + count).
  // `keep_going` (optional): asked between parts of the work (the tile
  // sampler's launches of kTileChunk tiles); false stops sampling the batch.
  void run(const cl::Buffer& diceable, cl_uint first, cl_uint count, const SceneBuffers& scene, const FrameParams& f,
           GridBuffers& grids, StageTimer& timer, bool after_visibility = false,
           const std::function<bool()>& keep_going = {});
  // From now until the next begin_frame, the depth pass marks the level-0
  // cells of the occlusion pyramid (mp_occlusion.h) it writes in `dirty`.
  void mark_occlusion_cells(const cl::Buffer& dirty, const OcclusionParams& params);
  const cl::Buffer& keys() const { return keys_; }
  const cl::Buffer& colors() const { return colors_; }
  const cl::Buffer& normals() const { return normals_; }
  const cl::Buffer& offsets() const { return offsets_; }
  // Micropolygons rasterised this frame and their total screen area in
  // pixels (front faces only when back faces are culled), the samples
  // tested against their edges in the depth pass, and the sub-patches
  // visibility first left unshaded (blocking read).
  void sampled_totals(size_t& micropolygons, double& area_px, size_t& tests, size_t& unshaded);
  // So far this frame: the sub-patches visibility first left unshaded, and
  // the micropolygons the tile sampler's plain passes found hidden when it
  // sampled them (per tile of their first pixel: a lower bound of what
  // visibility first would have left unshaded). read_hidden_counts()
  // enqueues their read; hidden_counts() waits for it, so the queue keeps
  // working in between.
  struct HiddenCounts {
    size_t unshaded = 0, lost = 0;
  };
  void read_hidden_counts();
  HiddenCounts hidden_counts();

 private:
  DeviceSession& session_;
  // The tile sampler (sample_tiles.cpp): projects the grids, sorts them
  // into per-tile lists on the host, then samples each tile.
  // Projects a batch's grids and sorts their runs into per-tile lists; false
  // where no tile is touched.
  bool bin_tiles(const cl::Buffer& diceable, cl_uint first, cl_uint count, const FrameParams& f, GridBuffers& grids,
                 StageTimer& timer);
  // Samples the binned tiles in one pass (pass: MP_SAMPLE_* of mp_raster.h).
  void sample_binned(const cl::Buffer& diceable, const SceneBuffers& scene, const FrameParams& f, GridBuffers& grids,
                     StageTimer& timer, cl_uint pass, const std::function<bool()>& keep_going);
  // One pass of the per-micropolygon sampler over [first, first + count);
  // with `wide_runs`, only the runs that bin_on_device left out.
  void sample_micropolygons(const cl::Buffer& diceable, cl_uint first, cl_uint count, const SceneBuffers& scene,
                            const FrameParams& f, GridBuffers& grids, StageTimer& timer, cl_uint pass,
                            bool wide_runs = false);
  // The binned sampler (sample_bins.cpp): bounds the runs of grids [first,
  // first + count) in bins and writes the bins' lists, all on the device.
  void bin_on_device(const cl::Buffer& diceable, cl_uint first, cl_uint count, const FrameParams& f,
                     GridBuffers& grids, StageTimer& timer);
  // Samples the binned batch through `pass` (MP_SAMPLE_ATTRIBUTES,
  // _OPAQUE_DEPTH or _MARK, with MP_SAMPLE_AFTER_MARK): the runs left out
  // by the per-micropolygon sampler, then every bin.
  void sample_bins(const cl::Buffer& diceable, const SceneBuffers& scene, const FrameParams& f, GridBuffers& grids,
                   StageTimer& timer, cl_uint pass);
  SceneKernel kernel_, blur_kernel_;  // pinhole samples; samples with times and lens positions
  SceneKernel count_unshaded_;
  cl::Kernel clear_;
  cl::Kernel project_, bound_runs_;
  SceneKernel tile_kernel_;
  bool tiles_ = false;
  cl::Buffer projected_, rects_, tile_ids_, tile_starts_, tile_entries_;
  // The lists bin_tiles made: their tiles, runs per grid, tiles per row;
  // binned_ while they hold the batch that visibility() sampled.
  cl_uint active_tiles_ = 0, runs_per_grid_ = 0, tiles_x_ = 0;
  bool binned_ = false;
  size_t projected_bytes_ = 0, rect_bytes_ = 0, tile_bytes_ = 0, start_bytes_ = 0, entry_bytes_ = 0;
  std::vector<cl_int> rects_host_;
  std::vector<cl_uint> tile_counts_, tile_ids_host_, tile_starts_host_, tile_entries_host_;
  // The binned sampler's kernels, lists and the batch they hold
  // (bin_first_, bin_count_; bins_ready_ while visibility() binned it).
  cl::Kernel bin_runs_, bin_offsets_, bin_scatter_;
  SceneKernel bins_kernel_;
  size_t local_bytes_ = 0;
  int bin_side_ = 0;
  cl_uint bins_x_ = 0, bins_y_ = 0, bin_runs_per_grid_ = 0, bin_first_ = 0, bin_count_ = 0;
  bool bins_ready_ = false;
  cl::Buffer bin_rects_, bin_counts_, bin_starts_, bin_cursors_, bin_entries_;
  size_t bin_rect_bytes_ = 0, bin_count_bytes_ = 0, bin_start_bytes_ = 0, bin_cursor_bytes_ = 0,
         bin_entry_bytes_ = 0;
  cl::Buffer occlusion_dirty_;
  OcclusionParams occlusion_{};
  cl::Buffer keys_, colors_, normals_, offsets_, blur_, totals_;
  cl_ulong hidden_host_[2] = {0, 0};
  cl::Event hidden_read_;
  // The sample offsets of `offsets_` for the tile sampler's 16-lane tests:
  // per tile pixel, chunks of 16 x offsets then 16 y offsets.
  cl::Buffer offsets_soa_;
  size_t sample_capacity_ = 0;  // samples the buffers hold (they only grow)
  SamplePattern pattern_;
};

class ResolveStage {
 public:
  explicit ResolveStage(DeviceSession& session);
  ResolveStage(const ResolveStage&) = delete;
  ResolveStage& operator=(const ResolveStage&) = delete;
  // Resolves bucket b's pixels (its samples in `samples`, of frame fb) into
  // the image of `frame`; Depth and Normal only if `passes`. `resolver`
  // picks the kernel (RenderSettings::resolver); Tiles falls back to the
  // pixels' kernel where its tile of samples does not fit the device's
  // local memory or the filter's weight table is not kept.
  void run(const SampleStage& samples, const FrameSetup& frame, const FrameParams& fb, const Bucket& b,
           PixelFilter filter, float filter_width, bool passes, Resolver resolver, StageTimer& timer);
  // The resolved image (float4 per pixel of the frame, rows top first),
  // its Depth (a float per pixel) and Normal (3 floats) where resolved;
  // image_read_back.h brings them to the host.
  const cl::Buffer& image() const { return rgba_; }
  const cl::Buffer& depth() const { return depth_; }
  const cl::Buffer& normal() const { return normal_; }
  // Whether the last run took the tiled kernel (tests).
  bool ran_tiled() const { return ran_tiled_; }

 private:
  DeviceSession& session_;
  cl::Kernel scalar_kernel_, planar_kernel_;  // sample colors sample by sample, or planar (mp_sample.h)
  cl::Kernel tiled_kernel_;                   // resolve_pixels_tiled
  bool gpu_ = false;                          // Resolver::Auto takes tiles
  size_t local_bytes_ = 0;                    // the device's local memory a work-group may take
  bool ran_tiled_ = false;
  cl::Buffer rgba_, depth_, normal_;
  size_t pixels_ = 0;
  // Filter weights per tile position, neighbour and sample (see resolve.cl),
  // rebuilt when the filter or the sampling pattern changes.
  cl::Buffer weights_;
  bool use_weights_ = false;
  int weights_type_ = -1;
  SamplePattern weights_pattern_;
  float weights_width_ = 0;
};

}  // namespace mp
