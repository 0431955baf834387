#include "pipeline/pass/micropolygon_stages.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "cl/kernel_args.h"
#include "micropoly/error.h"
#include "stages/mp_raster.h"

namespace mp {
namespace {

cl::Buffer device_buffer(DeviceSession& s, size_t bytes, const char* what) { return s.allocate(bytes, what); }

}  // namespace

GridBuffers::GridBuffers(DeviceSession& session, cl_uint cap, int max_grid)
    : capacity(cap),
      vertices_per_slot(static_cast<size_t>(max_grid + 1) * static_cast<size_t>(max_grid + 1)) {
  size_t bytes = capacity * vertices_per_slot * sizeof(cl_float4);
  p = device_buffer(session, bytes, "grid position buffer");
  n = device_buffer(session, bytes, "grid normal buffer");
  c = device_buffer(session, bytes, "grid color buffer");
  vertex_offsets = device_buffer(session, (capacity + 1) * sizeof(cl_uint), "grid vertex offsets");
  micropolygon_offsets = device_buffer(session, (capacity + 1) * sizeof(cl_uint), "grid micropolygon offsets");
  visible = device_buffer(session, capacity, "grid visibility marks");
}

GridLayoutStage::GridLayoutStage(DeviceSession& session, cl_uint capacity)
    : session_(session), kernel_(session.program(), "grid_counts") {
  counts_ = device_buffer(session, 2 * size_t(capacity) * sizeof(cl_uint), "grid counts");
}

GridLayoutStage::~GridLayoutStage() {
  try {
    if (written_()) written_.wait();  // the host arrays outlive the writes from them
  } catch (const cl::Error&) {
    // A lost device: nothing is written any more.
  }
}

void GridLayoutStage::run(const cl::Buffer& diceable, cl_uint count, const FrameParams& f, GridBuffers& grids,
                          StageTimer& timer) {
  // The last batch's offsets go to the device without blocking; the host
  // arrays they are written from are reused only once the writes are done.
  if (written_()) {
    if (written_.getInfo<CL_EVENT_COMMAND_EXECUTION_STATUS>() != CL_COMPLETE) session_.queue().wait(written_);
    written_ = cl::Event();
  }
  grids.vertex_total = 0;
  grids.micropolygon_offsets_host.assign(count + 1, 0);
  if (count == 0) return;
  bind_args(kernel_, diceable, count, f, counts_);
  cl::Event e;
  session_.queue().enqueueNDRangeKernel(kernel_, cl::NullRange, round_up_range(count), cl::NDRange(64), nullptr, &e);
  timer.add(Stage::Dice, e);
  // A few thousand numbers: summed on the host, one round trip per batch.
  counts_host_.resize(2 * size_t(count));
  session_.queue().enqueueReadBuffer(counts_, CL_TRUE, 0, counts_host_.size() * sizeof(cl_uint), counts_host_.data());
  vertex_offsets_host_.resize(count + 1);
  cl_uint vertices = 0, micropolygons = 0;
  for (cl_uint k = 0; k < count; ++k) {
    vertex_offsets_host_[k] = vertices;
    grids.micropolygon_offsets_host[k] = micropolygons;
    vertices += counts_host_[2 * k];
    micropolygons += counts_host_[2 * k + 1];
  }
  vertex_offsets_host_[count] = vertices;
  grids.micropolygon_offsets_host[count] = micropolygons;
  grids.vertex_total = vertices;
  micropolygons_ += micropolygons;
  // Without blocking: a GPU's round trip costs more than the batch's
  // layout (the read above is the batch's one wait).
  session_.queue().enqueueWriteBuffer(grids.vertex_offsets, CL_FALSE, 0, (count + 1) * sizeof(cl_uint),
                                      vertex_offsets_host_.data());
  session_.queue().enqueueWriteBuffer(grids.micropolygon_offsets, CL_FALSE, 0, (count + 1) * sizeof(cl_uint),
                                      grids.micropolygon_offsets_host.data(), nullptr, &written_);
}

DiceStage::DiceStage(DeviceSession& session)
    : session_(session),
      kernel_(session.program(), "dice_grids"),
      motion_kernel_(session.program(), "dice_motion_positions"),
      displaced_kernel_(session.program(), "motion_displacement") {}

void GridBuffers::ensure_motion(DeviceSession& session, int steps) {
  if (steps <= motion_steps) return;
  motion_p = cl::Buffer();
  motion_p = device_buffer(session, size_t(steps) * slot_space() * sizeof(cl_float4), "grid motion positions");
  if (!rest_p()) rest_p = device_buffer(session, slot_space() * sizeof(cl_float4), "grid rest positions");
  motion_steps = steps;
}

void DiceStage::run_motion(const cl::Buffer& diceable, cl_uint count, const SceneBuffers& scene, const FrameParams& f,
                           GridBuffers& grids, StageTimer& timer) {
  grids.ensure_motion(session_, int(scene.motion_steps));
  DeviceQueue& q = session_.queue();
  // The centre's positions before displacement (for `displaced`).
  q.enqueueCopyBuffer(grids.p, grids.rest_p, 0, 0, size_t(count) * grids.vertices_per_slot * sizeof(cl_float4));
  for (cl_uint k = 0; k < scene.motion_steps; ++k) {
    // Step k's control points and curves follow the steps before it.
    cl::Kernel& kernel = motion_kernel_.bind(scene, diceable, count, k, f, grids.motion_p,
                                             cl_ulong(size_t(k) * grids.slot_space()), grids.vertex_offsets);
    cl::Event e;
    q.enqueueNDRangeKernel(kernel, cl::NullRange, round_up_range(grids.vertex_total), cl::NDRange(64), nullptr, &e);
    timer.add(Stage::Dice, e);
  }
}

void DiceStage::displaced(const cl::Buffer& diceable, cl_uint count, const FrameParams& f, GridBuffers& grids,
                          StageTimer& timer) {
  bind_args(displaced_kernel_, diceable, count, f, grids.p, grids.rest_p, grids.motion_p, cl_ulong(grids.slot_space()),
            cl_int(f.motion_steps), grids.vertex_offsets);
  cl::Event e;
  session_.queue().enqueueNDRangeKernel(displaced_kernel_, cl::NullRange, round_up_range(grids.vertex_total),
                                        cl::NDRange(64), nullptr, &e);
  timer.add(Stage::Dice, e);
}

void DiceStage::run(const cl::Buffer& diceable, cl_uint count, const SceneBuffers& scene, const FrameParams& f,
                    const cl::Buffer& views, cl_uint view_count, GridBuffers& grids, StageTimer& timer) {
  cl::Kernel& kernel = kernel_.bind(scene, diceable, count, f, views, view_count, grids.p, grids.n,
                                    grids.vertex_offsets);
  cl::Event e;
  session_.queue().enqueueNDRangeKernel(kernel, cl::NullRange, round_up_range(grids.vertex_total), cl::NDRange(64),
                                        nullptr, &e);
  timer.add(Stage::Dice, e);
}

ShadeStage::ShadeStage(DeviceSession& session) : session_(session), kernel_(session.program(), "shade_grids") {}

void ShadeStage::run(const cl::Buffer& diceable, cl_uint count, const SceneBuffers& scene, const FrameParams& f,
                     GridBuffers& grids, const ShadowInputs& shadows, const cl::Buffer& visible, StageTimer& timer) {
  cl::Kernel& kernel = kernel_.bind(scene, diceable, count, f, grids.p, grids.n, grids.c, grids.vertex_offsets,
                                    shadows.args(), visible);
  cl::Event e;
  session_.queue().enqueueNDRangeKernel(kernel, cl::NullRange, round_up_range(grids.vertex_total), cl::NDRange(64),
                                        nullptr, &e);
  timer.add(Stage::Shade, e);
}

SampleStage::SampleStage(DeviceSession& session)
    : session_(session),
      kernel_(session.program(), "sample_micropolygons"),
      blur_kernel_(session.program(), "sample_micropolygons_blur"),
      count_unshaded_(session.program(), "count_unshaded"),
      clear_(session.program(), "clear_samples"),
      project_(session.tile_sampler() ? cl::Kernel(session.program(), "project_grids") : cl::Kernel()),
      bound_runs_(session.tile_sampler() ? cl::Kernel(session.program(), "bound_runs") : cl::Kernel()),
      tile_kernel_(session.tile_sampler() ? SceneKernel(session.program(), "sample_tiles") : SceneKernel()),
      bin_runs_(session.program(), "bin_runs"),
      bin_offsets_(session.program(), "bin_offsets"),
      bin_scatter_(session.program(), "bin_scatter"),
      bins_kernel_(session.program(), "sample_bins"),
      local_bytes_(session.device().getInfo<CL_DEVICE_LOCAL_MEM_SIZE>()) {
  totals_ = session.allocate(5 * sizeof(cl_ulong), "sample totals");
}

void SampleStage::sampled_totals(size_t& micropolygons, double& area_px, size_t& tests, size_t& unshaded) {
  cl_ulong t[5] = {0, 0, 0, 0, 0};
  session_.queue().enqueueReadBuffer(totals_, CL_TRUE, 0, sizeof t, t);
  micropolygons = static_cast<size_t>(t[0]);
  tests = static_cast<size_t>(t[2]);
  unshaded = static_cast<size_t>(t[3]);
  // The sampler sums twice the area in fixed-point units (mp_raster.h).
  area_px = static_cast<double>(t[1]) / (2.0 * MP_SUBPIXEL_ONE * MP_SUBPIXEL_ONE);
}

void SampleStage::read_hidden_counts() {
  session_.queue().enqueueReadBuffer(totals_, CL_FALSE, 3 * sizeof(cl_ulong), sizeof hidden_host_, hidden_host_,
                                     nullptr, &hidden_read_);
}

SampleStage::HiddenCounts SampleStage::hidden_counts() {
  if (hidden_read_()) session_.queue().wait(hidden_read_);
  hidden_read_ = cl::Event();
  return {static_cast<size_t>(hidden_host_[0]), static_cast<size_t>(hidden_host_[1])};
}

float warp_shutter_time(float u, const std::vector<float>& curve) {
  const size_t n = curve.size();
  if (n < 2) return u;
  // Segment k spans [k, k + 1] / (n - 1) with openness from curve[k] to curve[k + 1].
  std::vector<double> area(n, 0.0);
  for (size_t k = 0; k + 1 < n; ++k) area[k + 1] = area[k] + 0.5 * (double(curve[k]) + double(curve[k + 1]));
  const double target = std::clamp(double(u), 0.0, 1.0) * area[n - 1];
  size_t k = size_t(std::upper_bound(area.begin(), area.end(), target) - area.begin());
  k = std::clamp<size_t>(k, 1, n - 1) - 1;
  const double a = curve[k], b = curve[k + 1], r = target - area[k];
  // Area over x in [0, 1] of the segment: a x + (b - a) x^2 / 2 = r.
  double x;
  if (std::fabs(b - a) < 1e-12) {
    x = a > 0.0 ? r / a : 0.0;
  } else {
    const double disc = a * a + 2.0 * (b - a) * r;
    x = (-a + std::sqrt(std::max(disc, 0.0))) / (b - a);
  }
  return float((double(k) + std::clamp(x, 0.0, 1.0)) / double(n - 1));
}

SamplePattern sample_pattern(const FrameParams& f, const std::vector<float>& shutter_curve) {
  SamplePattern p;
  p.spp_x = f.spp_x, p.spp_y = f.spp_y, p.seed = f.seed;
  p.lens = mp_lens_on(f);
  p.motion = mp_motion_on(f);
  if (p.motion) p.shutter_curve = shutter_curve;
  if (p.lens)
    p.blades = f.aperture_blades, p.radius = f.lens_radius, p.x_scale = f.lens_x_scale,
    p.rotation = f.aperture_rotation;
  return p;
}

void SampleStage::mark_occlusion_cells(const cl::Buffer& dirty, const OcclusionParams& params) {
  occlusion_dirty_ = dirty;
  occlusion_ = params;
}

void SampleStage::begin_frame(const FrameParams& f, StageTimer& timer, const std::vector<float>& shutter_curve,
                              bool bins) {
  mark_occlusion_cells(cl::Buffer(), OcclusionParams{});
  tiles_ = f.planar_colors != 0;
  const int spp = f.spp_x * f.spp_y;
  bins_ready_ = false;
  bin_side_ = bins && !tiles_ && !mp_blur_on(f) ? bin_side(spp, local_bytes_) : 0;
  if (bin_side_ > 0) {
    bins_x_ = cl_uint((f.width + bin_side_ - 1) / bin_side_);
    bins_y_ = cl_uint((f.height + bin_side_ - 1) / bin_side_);
    const size_t bins = size_t(bins_x_) * bins_y_;
    session_.reserve(bin_counts_, bin_count_bytes_, bins * sizeof(cl_uint), "bin counts");
    session_.reserve(bin_starts_, bin_start_bytes_, (bins + 1) * sizeof(cl_uint), "bin list starts");
    session_.reserve(bin_cursors_, bin_cursor_bytes_, bins * sizeof(cl_uint), "bin list cursors");
    // bin_offsets clears the counts it reads; cleared here too, so that a
    // batch stopped between the two leaves no count behind.
    session_.queue().enqueueFillBuffer(bin_counts_, cl_uint(0), 0, bins * sizeof(cl_uint));
  }
  size_t samples = static_cast<size_t>(f.width) * static_cast<size_t>(f.height) * static_cast<size_t>(spp);
  // The buffers only grow: the viewport alternates a small preview with the
  // full view, and reallocating (and first touching) the full view's buffers
  // for every refinement cost it about a tenth of a second on the CPU.
  if (samples > sample_capacity_) {
    keys_ = colors_ = normals_ = cl::Buffer();  // release before allocating anew
    keys_ = device_buffer(session_, samples * sizeof(cl_ulong), "sample depth buffer");
    colors_ = device_buffer(session_, samples * 3 * sizeof(cl_float), "sample color buffer");
    normals_ = device_buffer(session_, samples * sizeof(cl_uint), "sample normal buffer");
    sample_capacity_ = samples;
  }
  const SamplePattern pattern = sample_pattern(f, shutter_curve);
  if (!(pattern == pattern_) || !offsets_()) {
    // Sample positions, and times and lens positions, of one tile
    // (kernels/stages/mp_raster.h, mp_blur.h), computed here once.
    const size_t tile = static_cast<size_t>(MP_SAMPLE_TILE) * MP_SAMPLE_TILE * spp;
    std::vector<cl_ushort> offsets(tile);
    // (lx, ly, t, 0) per tile pixel and slot, then each slot's box over the
    // tile, (lx0, lx1, ly0, ly1) and (t0, t1, 0, 0): the bound the
    // rasteriser uses per slot. Without lens or motion their values are 0.
    const bool blur = mp_blur_on(f);
    std::vector<cl_float4> table(blur ? tile + 2 * size_t(spp) : 1, cl_float4{{0.0f, 0.0f, 0.0f, 0.0f}});
    for (int s = 0; s < spp && blur; ++s) {
      table[tile + 2 * s] = cl_float4{{3e38f, -3e38f, 3e38f, -3e38f}};
      table[tile + 2 * s + 1] = cl_float4{{3e38f, -3e38f, 0.0f, 0.0f}};
    }
    for (int ty = 0; ty < MP_SAMPLE_TILE; ++ty)
      for (int tx = 0; tx < MP_SAMPLE_TILE; ++tx)
        for (int s = 0; s < spp; ++s) {
          const size_t i = (static_cast<size_t>(ty) * MP_SAMPLE_TILE + tx) * spp + s;
          offsets[i] = static_cast<cl_ushort>(mp_sample_offset_packed(tx, ty, s, f));
          if (!blur) continue;
          const float2 l = mp_lens_on(f) ? mp_sample_lens(tx, ty, s, f) : float2{0.0f, 0.0f};
          const float t = mp_motion_on(f) ? warp_shutter_time(mp_sample_time(tx, ty, s, f), shutter_curve) : 0.5f;
          table[i] = cl_float4{{l.x, l.y, t, 0.0f}};
          cl_float4& lb = table[tile + 2 * s];
          cl_float4& tb = table[tile + 2 * s + 1];
          lb.s[0] = std::min(lb.s[0], l.x), lb.s[1] = std::max(lb.s[1], l.x);
          lb.s[2] = std::min(lb.s[2], l.y), lb.s[3] = std::max(lb.s[3], l.y);
          tb.s[0] = std::min(tb.s[0], t), tb.s[1] = std::max(tb.s[1], t);
        }
    const int chunks = (spp + 15) / 16;
    std::vector<cl_ushort> soa(size_t(MP_SAMPLE_TILE) * MP_SAMPLE_TILE * chunks * 32, 0);
    for (size_t p = 0; p < size_t(MP_SAMPLE_TILE) * MP_SAMPLE_TILE; ++p)
      for (int s = 0; s < spp; ++s) {
        const cl_ushort o = offsets[p * spp + s];
        cl_ushort* chunk = &soa[(p * chunks + s / 16) * 32];
        chunk[s % 16] = o & 0xffu;
        chunk[16 + s % 16] = o >> 8;
      }
    offsets_soa_ = session_.allocate(soa.size() * sizeof(cl_ushort), "sample pattern", CL_MEM_READ_ONLY);
    session_.queue().enqueueWriteBuffer(offsets_soa_, CL_TRUE, 0, soa.size() * sizeof(cl_ushort), soa.data());
    offsets_ = session_.allocate(offsets.size() * sizeof(cl_ushort), "sample pattern", CL_MEM_READ_ONLY);
    session_.queue().enqueueWriteBuffer(offsets_, CL_TRUE, 0, offsets.size() * sizeof(cl_ushort), offsets.data());
    blur_ = session_.allocate(table.size() * sizeof(cl_float4), "sample times and lens positions", CL_MEM_READ_ONLY);
    session_.queue().enqueueWriteBuffer(blur_, CL_TRUE, 0, table.size() * sizeof(cl_float4), table.data());
    pattern_ = pattern;
  }
  cl_ulong zero = 0;
  session_.queue().enqueueFillBuffer(totals_, zero, 0, 5 * sizeof zero);
  bind_args(clear_, keys_, static_cast<cl_ulong>(samples));
  cl::Event e;
  session_.queue().enqueueNDRangeKernel(clear_, cl::NullRange, round_up_range(samples, 256), cl::NDRange(256), nullptr,
                                        &e);
  timer.add(Stage::Sample, e);
}

void SampleStage::sample_micropolygons(const cl::Buffer& diceable, cl_uint first, cl_uint count,
                                       const SceneBuffers& scene, const FrameParams& f, GridBuffers& grids,
                                       StageTimer& timer, cl_uint pass, bool wide_runs) {
  // The run's micropolygons, numbered within the batch by its layout.
  const cl_uint base = grids.micropolygon_offsets_host[first];
  const cl_uint total = grids.micropolygon_offsets_host[first + count] - base;
  if (total == 0) return;
  SceneKernel& sampler = mp_blur_on(f) ? blur_kernel_ : kernel_;
  // Motion positions: any valid buffer when there are none.
  cl::Kernel& k = sampler.bind(scene, diceable, first, count, grids.micropolygon_offsets, base, total, f, grids.p,
                               grids.c, grids.n, offsets_, pass, keys_, colors_, normals_, totals_, occlusion_dirty_,
                               occlusion_, blur_, grids.motion_p() ? grids.motion_p : grids.p,
                               cl_ulong(grids.slot_space()), grids.visible, wide_runs ? bin_rects_ : cl::Buffer(),
                               wide_runs ? bin_runs_per_grid_ : cl_uint(0));
  cl::Event e;
  session_.queue().enqueueNDRangeKernel(k, cl::NullRange, round_up_range(total), cl::NDRange(64), nullptr, &e);
  timer.add(Stage::Sample, e);
}

size_t SampleStage::visibility(const cl::Buffer& diceable, cl_uint count, const SceneBuffers& scene,
                               const FrameParams& f, GridBuffers& grids, StageTimer& timer) {
  binned_ = bins_ready_ = false;
  if (count == 0) return timer.cursor();
  const cl_uchar unmarked = 0;
  session_.queue().enqueueFillBuffer(grids.visible, unmarked, 0, count);
  size_t passes = timer.cursor();
  if (tiles_) {
    binned_ = bin_tiles(diceable, 0, count, f, grids, timer);
    passes = timer.cursor();
    if (binned_) {
      sample_binned(diceable, scene, f, grids, timer, MP_SAMPLE_OPAQUE_DEPTH, {});
      sample_binned(diceable, scene, f, grids, timer, MP_SAMPLE_MARK, {});
    }
  } else if (bins()) {
    bin_on_device(diceable, 0, count, f, grids, timer);
    bins_ready_ = true;
    passes = timer.cursor();
    sample_bins(diceable, scene, f, grids, timer, MP_SAMPLE_OPAQUE_DEPTH);
    sample_bins(diceable, scene, f, grids, timer, MP_SAMPLE_MARK);
  } else {
    sample_micropolygons(diceable, 0, count, scene, f, grids, timer, MP_SAMPLE_OPAQUE_DEPTH);
    sample_micropolygons(diceable, 0, count, scene, f, grids, timer, MP_SAMPLE_MARK);
  }
  cl::Kernel& k = count_unshaded_.bind(scene, diceable, count, grids.visible, totals_);
  cl::Event e;
  session_.queue().enqueueNDRangeKernel(k, cl::NullRange, round_up_range(count), cl::NDRange(64), nullptr, &e);
  timer.add(Stage::Sample, e);
  return passes;
}

void SampleStage::run(const cl::Buffer& diceable, cl_uint first, cl_uint count, const SceneBuffers& scene,
                      const FrameParams& f, GridBuffers& grids, StageTimer& timer, bool after_visibility,
                      const std::function<bool()>& keep_going) {
  if (count == 0) return;
  const cl_uint after = after_visibility ? MP_SAMPLE_AFTER_MARK : 0u;
  if (tiles_) {
    // The lists visibility() made for this batch serve again.
    const bool binned = after_visibility && binned_;
    binned_ = false;
    if (binned || (!after_visibility && bin_tiles(diceable, first, count, f, grids, timer)))
      sample_binned(diceable, scene, f, grids, timer, MP_SAMPLE_ATTRIBUTES | after, keep_going);
    return;
  }
  if (bins()) {
    // The lists visibility() made for this batch serve again.
    if (!(after_visibility && bins_ready_)) bin_on_device(diceable, first, count, f, grids, timer);
    bins_ready_ = false;
    sample_bins(diceable, scene, f, grids, timer, MP_SAMPLE_ATTRIBUTES | after);
    return;
  }
  // The first pass finds each sample's nearest key; the second lets its owner write.
  sample_micropolygons(diceable, first, count, scene, f, grids, timer, MP_SAMPLE_DEPTH | after);
  sample_micropolygons(diceable, first, count, scene, f, grids, timer, MP_SAMPLE_ATTRIBUTES | after);
}

ResolveStage::ResolveStage(DeviceSession& session)
    : session_(session),
      scalar_kernel_(session.program(), "resolve_pixels"),
      planar_kernel_(session.program(), "resolve_pixels_planar"),
      tiled_kernel_(session.program(), "resolve_pixels_tiled") {
  gpu_ = (session.device().getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_GPU) != 0;
  local_bytes_ = session.device().getInfo<CL_DEVICE_LOCAL_MEM_SIZE>();
}

void ResolveStage::run(const SampleStage& samples, const FrameSetup& frame, const FrameParams& fb, const Bucket& b,
                       PixelFilter filter, float filter_width, bool passes, Resolver resolver, StageTimer& timer) {
  const FrameParams& f = frame.params;
  size_t pixels = static_cast<size_t>(f.width) * static_cast<size_t>(f.height);
  if (pixels != pixels_) {
    rgba_ = cl::Buffer(), depth_ = cl::Buffer(), normal_ = cl::Buffer();
    rgba_ = session_.allocate(pixels * sizeof(cl_float4), "image buffer");
    depth_ = session_.allocate(pixels * sizeof(cl_float), "depth pass buffer");
    normal_ = session_.allocate(pixels * 3 * sizeof(cl_float), "normal pass buffer");
    pixels_ = pixels;
  }
  int type = filter == PixelFilter::Box        ? MP_FILTER_BOX
             : filter == PixelFilter::Gaussian ? MP_FILTER_GAUSSIAN
             : filter == PixelFilter::Triangle ? MP_FILTER_TRIANGLE
                                               : MP_FILTER_BLACKMAN_HARRIS;
  auto row = [&](int i) {
    glm::vec3 r = glm::vec3(frame.camera_to_world[0][i], frame.camera_to_world[1][i], frame.camera_to_world[2][i]);
    return cl_float4{{r.x, r.y, r.z, 0.0f}};
  };
  filter_width = std::max(filter_width, 1e-3f);
  const SamplePattern pattern = sample_pattern(f);
  if (type != weights_type_ || filter_width != weights_width_ || !(pattern == weights_pattern_)) {
    const int reach = mp_filter_reach(filter_width), side = 2 * reach + 1;
    const int spp = f.spp_x * f.spp_y;
    const size_t count = size_t(MP_SAMPLE_TILE) * MP_SAMPLE_TILE * side * side * spp;
    use_weights_ = count * sizeof(float) <= (size_t(64) << 20);
    std::vector<float> w(use_weights_ ? count : 1, 0.0f);
    if (use_weights_) {
      size_t i = 0;
      for (int ty = 0; ty < MP_SAMPLE_TILE; ++ty)
        for (int tx = 0; tx < MP_SAMPLE_TILE; ++tx)
          for (int dy = -reach; dy <= reach; ++dy)
            for (int dx = -reach; dx <= reach; ++dx) {
              int nx = (tx + dx) & (MP_SAMPLE_TILE - 1), ny = (ty + dy) & (MP_SAMPLE_TILE - 1);
              for (int s = 0; s < spp; ++s) {
                uint o = mp_sample_offset_packed(nx, ny, s, f);
                float sx = float(dx) + float(o & 0xffu) / MP_SUBPIXEL_ONE - 0.5f;
                float sy = float(dy) + float(o >> 8) / MP_SUBPIXEL_ONE - 0.5f;
                w[i++] = mp_filter_weight(type, sx, sy, filter_width);
              }
            }
    }
    weights_ = session_.allocate(w.size() * sizeof(float), "pixel filter weights", CL_MEM_READ_ONLY);
    session_.queue().enqueueWriteBuffer(weights_, CL_TRUE, 0, w.size() * sizeof(float), w.data());
    weights_type_ = type, weights_width_ = filter_width, weights_pattern_ = pattern;
  }
  // Tiles: a tile of MP_RESOLVE_TILE pixels a side and the filter's reach
  // around it, one float4 a sample, in local memory (a quarter of it left to
  // the compiler). Otherwise the 16-lane kernel for planar colors of 16
  // samples or more; below that the scalar one, which PoCL vectorises across
  // pixels instead.
  const size_t tile_side = MP_RESOLVE_TILE + 2 * static_cast<size_t>(mp_filter_reach(filter_width));
  const size_t tile_bytes = tile_side * tile_side * static_cast<size_t>(fb.spp_x * fb.spp_y) * sizeof(cl_float4);
  const bool tiles = (resolver == Resolver::Tiles || (resolver == Resolver::Auto && gpu_)) && use_weights_ &&
                     tile_bytes <= local_bytes_ / 4 * 3;
  ran_tiled_ = tiles;
  cl::Kernel& k = tiles                                          ? tiled_kernel_
                  : fb.planar_colors && fb.spp_x * fb.spp_y >= 16 ? planar_kernel_
                                                                  : scalar_kernel_;
  const cl_int4 region{{b.x0 - b.sx0, b.y0 - b.sy0, b.x1 - b.sx0, b.y1 - b.sy0}};
  const auto args = arg_pack(fb, type, filter_width, samples.offsets(), weights_, use_weights_ ? 1 : 0,
                             samples.keys(), samples.colors(), samples.normals(), row(0), row(1), row(2), rgba_,
                             depth_, normal_, passes ? 1 : 0, region, cl_int2{{b.sx0, b.sy0}}, cl_int(f.width));
  if (tiles)
    bind_args(k, args, cl::Local(tile_bytes));
  else
    bind_args(k, args);
  static_assert(MP_RESOLVE_TILE == 8, "both kernels run in work-groups of 8 x 8 pixels");
  size_t gx = ((static_cast<size_t>(b.x1 - b.x0) + 7) / 8) * 8, gy = ((static_cast<size_t>(b.y1 - b.y0) + 7) / 8) * 8;
  cl::Event e;
  session_.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(gx, gy), cl::NDRange(8, 8), nullptr, &e);
  timer.add(Stage::Resolve, e);
}

}  // namespace mp
