#include "pipeline/shadow_maps.h"

#include <algorithm>
#include <numeric>
#include <string>
#include <unordered_set>

#include "micropoly/error.h"
#include "mp_shadow.h"
#include "pipeline/scene_fingerprint.h"

namespace mp {
// Host vectors written to the device here live only for the call, so every
// write blocks until the device has the data.
namespace {

constexpr size_t kPageBytes = size_t(MP_PAGE_TEXELS) * sizeof(cl_uint);
// The marking pass dices the camera's view this many times coarser (in
// micropolygon edge) than the frame: its vertices mark the pages around
// them, and need to be close only next to a page.
constexpr float kMarkCoarsening = 8.0f;

// Each marking vertex's box reaches its neighbours: one coarse micropolygon edge.
cl_float mark_reach(const FrameParams& coarse) { return coarse.micropoly_edge; }

}  // namespace

ShadowMaps::ShadowMaps(DeviceSession& session)
    : session_(session),
      mark_(session.program(), "mark_shadow_pages"),
      mark_soft_(session.program(), "mark_soft_shadow_pages"),
      clear_(session.program(), "clear_shadow_pages"),
      set_entries_(session.program(), "set_page_entries"),
      sample_(session.program(), "shadow_sample") {}

void ShadowMaps::upload_records(const ShadowLayout& layout) {
  DeviceQueue& q = session_.queue();
  session_.reserve(inputs_.shadows, records_capacity_, layout.shadows.size() * sizeof(DeviceShadow), "shadow records");
  session_.reserve(inputs_.levels, levels_capacity_, layout.levels.size() * sizeof(DeviceShadowLevel),
       "shadow level records");
  q.enqueueWriteBuffer(inputs_.shadows, CL_TRUE, 0, layout.shadows.size() * sizeof(DeviceShadow),
                       layout.shadows.data());
  if (!layout.levels.empty())
    q.enqueueWriteBuffer(inputs_.levels, CL_TRUE, 0, layout.levels.size() * sizeof(DeviceShadowLevel),
                         layout.levels.data());
}

bool ShadowMaps::mark(const ShadowLayout& layout, const FrameSetup& frame, const SceneBuffers& buffers,
                      const ShadowPassStages& stages, const BoundSplitRunner& run, StageTimer& timer, bool keep,
                      std::vector<ShadowPageKey>& keys, std::vector<uint32_t>& entries, ShadowStats& stats) {
  StageTimer::Redirect to(timer, Stage::ShadowMark);
  const auto started = std::chrono::steady_clock::now();
  DeviceQueue& q = session_.queue();
  const size_t n = layout.table_entries;
  session_.reserve(requests_, requests_capacity_, n, "shadow page requests");
  q.enqueueFillBuffer(requests_, cl_uchar(0), 0, n);
  FrameParams coarse = frame.params;
  coarse.micropoly_edge *= kMarkCoarsening;
  const cl_uint light_count = cl_uint(layout.shadows.size());
  GridBuffers& grids = stages.grids;
  kept_vertices_ = 0;
  DiceSink sink = [&](const cl::Buffer& diceable, cl_uint count) {
    stages.layout.run(diceable, count, coarse, grids, timer);
    stages.dice.run(diceable, count, buffers, coarse, grids, timer);
    // The soft marking's search compares with the displaced surface's tangent plane.
    stages.programs.displace(diceable, count, buffers, coarse, grids, timer, keep);
    const cl_uint vertices = grids.vertex_total;
    ++stats.batches;
    if (keep) keep_room(size_t(kept_vertices_) + vertices);
    cl_uint arg = 0;
    mark_.setArg(arg++, diceable);
    mark_.setArg(arg++, count);
    mark_.setArg(arg++, grids.vertex_offsets);
    mark_.setArg(arg++, vertices);
    mark_.setArg(arg++, coarse);
    mark_.setArg(arg++, grids.p);
    mark_.setArg(arg++, grids.n);
    mark_.setArg(arg++, inputs_.shadows);
    mark_.setArg(arg++, inputs_.levels);
    mark_.setArg(arg++, light_count);
    mark_.setArg(arg++, requests_);
    mark_.setArg(arg++, mark_reach(coarse));
    mark_.setArg(arg++, cl_uint(keep));
    mark_.setArg(arg++, kept_vertices_);
    mark_.setArg(arg++, keep ? kept_p_ : grids.p);  // unwritten when not kept
    mark_.setArg(arg++, keep ? kept_n_ : grids.n);
    cl::Event e;
    q.enqueueNDRangeKernel(mark_, cl::NullRange, round_up_range(vertices), cl::NDRange(64), nullptr, &e);
    timer.add(Stage::ShadowMark, e);
    if (keep) kept_vertices_ += vertices;
  };
  if (run(coarse, PassViews{}, sink).cancelled) return false;
  collect_requests(layout, keys, entries);
  stats.mark_wall_ms += ms_since(started);
  return true;
}

void ShadowMaps::mark_soft(const ShadowLayout& layout, const FrameSetup& frame, StageTimer& timer,
                           std::vector<ShadowPageKey>& keys, std::vector<uint32_t>& entries, ShadowStats& stats) {
  StageTimer::Redirect to(timer, Stage::ShadowMark);
  const auto started = std::chrono::steady_clock::now();
  DeviceQueue& q = session_.queue();
  // The soft marking adds to the first's requests.
  if (kept_vertices_ > 0) {
    FrameParams coarse = frame.params;
    coarse.micropoly_edge *= kMarkCoarsening;
    cl_uint arg = 0;
    mark_soft_.setArg(arg++, kept_p_);
    mark_soft_.setArg(arg++, kept_n_);
    mark_soft_.setArg(arg++, kept_vertices_);
    mark_soft_.setArg(arg++, coarse);
    mark_soft_.setArg(arg++, inputs_.shadows);
    mark_soft_.setArg(arg++, inputs_.levels);
    mark_soft_.setArg(arg++, cl_uint(layout.shadows.size()));
    mark_soft_.setArg(arg++, inputs_.pages);
    mark_soft_.setArg(arg++, inputs_.pool);
    mark_soft_.setArg(arg++, requests_);
    mark_soft_.setArg(arg++, mark_reach(coarse));
    cl::Event e;
    q.enqueueNDRangeKernel(mark_soft_, cl::NullRange, round_up_range(kept_vertices_), cl::NDRange(64), nullptr, &e);
    timer.add(Stage::ShadowMark, e);
  }
  collect_requests(layout, keys, entries);
  stats.mark_wall_ms += ms_since(started);
}

void ShadowMaps::keep_room(size_t vertices) {
  if (vertices <= kept_capacity_) return;
  const size_t grown = std::max(vertices, kept_capacity_ + kept_capacity_ / 2);
  cl::Buffer p = session_.allocate(grown * sizeof(cl_float4), "shadow marking vertices");
  cl::Buffer nrm = session_.allocate(grown * sizeof(cl_float4), "shadow marking normals");
  if (kept_vertices_ > 0) {
    session_.queue().enqueueCopyBuffer(kept_p_, p, 0, 0, size_t(kept_vertices_) * sizeof(cl_float4));
    session_.queue().enqueueCopyBuffer(kept_n_, nrm, 0, 0, size_t(kept_vertices_) * sizeof(cl_float4));
  }
  kept_p_ = p;
  kept_n_ = nrm;
  kept_capacity_ = grown;
}

void ShadowMaps::collect_requests(const ShadowLayout& layout, std::vector<ShadowPageKey>& keys,
                                  std::vector<uint32_t>& entries) {
  const size_t n = layout.table_entries;
  std::vector<uint8_t> requested(n);
  session_.queue().enqueueReadBuffer(requests_, CL_TRUE, 0, n, requested.data());
  // Coarser maps first: a budget too short for everything keeps them.
  std::vector<size_t> order(layout.maps.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return layout.maps[a].coarseness > layout.maps[b].coarseness; });
  keys.clear();
  entries.clear();
  for (size_t i : order) {
    const ShadowMapInfo& m = layout.maps[i];
    for (int sy = 0; sy < m.side; ++sy)
      for (int sx = 0; sx < m.side; ++sx) {
        const uint32_t e = m.table + uint32_t(sy * m.side + sx);
        if (!requested[e]) continue;
        ShadowPageKey k;
        k.light = layout.light_keys[size_t(m.light)];
        k.map = m.map_id;
        layout.page_position(m, sx, sy, &k.x, &k.y);
        keys.push_back(k);
        entries.push_back(e);
      }
  }
}

void ShadowMaps::write_table(size_t entries, const std::vector<cl_uint2>& writes) {
  DeviceQueue& q = session_.queue();
  session_.reserve(inputs_.pages, pages_capacity_, entries * sizeof(cl_uint), "shadow page tables");
  q.enqueueFillBuffer(inputs_.pages, cl_uint(0), 0, entries * sizeof(cl_uint));
  if (writes.empty()) return;
  session_.reserve(writes_, writes_capacity_, writes.size() * sizeof(cl_uint2), "shadow page-table writes");
  q.enqueueWriteBuffer(writes_, CL_TRUE, 0, writes.size() * sizeof(cl_uint2), writes.data());
  set_entries_.setArg(0, writes_);
  set_entries_.setArg(1, cl_uint(writes.size()));
  set_entries_.setArg(2, inputs_.pages);
  q.enqueueNDRangeKernel(set_entries_, cl::NullRange, round_up_range(cl_uint(writes.size())), cl::NDRange(64));
}

void ShadowMaps::ensure_pool(uint32_t pages) {
  if (pages <= pool_pages_) return;
  const uint32_t grown = std::max(pages, std::min<uint32_t>(pool_pages_ + pool_pages_ / 2, uint32_t(pool_.capacity())));
  cl::Buffer bigger = session_.allocate(size_t(grown) * kPageBytes, "shadow map page pool");
  // Pages kept from earlier frames move along.
  if (pool_pages_ > 0)
    session_.queue().enqueueCopyBuffer(inputs_.pool, bigger, 0, 0, size_t(pool_pages_) * kPageBytes);
  inputs_.pool = bigger;
  pool_pages_ = grown;
}

bool ShadowMaps::render_views(const std::vector<FrameParams>& views, const std::vector<uint8_t>& masks,
                              const FrameSetup& frame, const SceneBuffers& buffers, const ShadowPassStages& stages,
                              const BoundSplitRunner& run, StageTimer& timer, ShadowStats& stats) {
  DeviceQueue& q = session_.queue();
  session_.reserve(masks_, masks_capacity_, masks.size(), "shadow page masks");
  if (!masks.empty()) q.enqueueWriteBuffer(masks_, CL_TRUE, 0, masks.size(), masks.data());
  const FrameParams& f = frame.params;
  GridBuffers& grids = stages.grids;
  DiceSink sink = [&](const cl::Buffer& diceable, cl_uint count) {
    ++stats.batches;
    stages.layout.run(diceable, count, f, grids, timer);
    stages.dice.run(diceable, count, buffers, f, grids, timer);
    stages.programs.displace(diceable, count, buffers, f, grids, timer, false);
    stages.programs.alpha(diceable, count, buffers, f, grids, timer);
    const cl_uint base = grids.micropolygon_offsets_host[0];
    const cl_uint total = grids.micropolygon_offsets_host[count] - base;
    if (total == 0) return;
    sample_.setArg(0, diceable);
    sample_.setArg(1, cl_uint(0));
    sample_.setArg(2, count);
    sample_.setArg(3, grids.micropolygon_offsets);
    sample_.setArg(4, base);
    sample_.setArg(5, total);
    sample_.setArg(6, buffers.patch_info);
    sample_.setArg(7, buffers.materials);
    sample_.setArg(8, f);
    sample_.setArg(9, views_);
    sample_.setArg(10, grids.p);
    sample_.setArg(11, grids.c);
    sample_.setArg(12, inputs_.pages);
    sample_.setArg(13, inputs_.pool);
    cl::Event e;
    q.enqueueNDRangeKernel(sample_, cl::NullRange, round_up_range(total), cl::NDRange(64), nullptr, &e);
    timer.add(Stage::Sample, e);
  };
  for (size_t first = 0; first < views.size(); first += MP_MAX_PASS_VIEWS) {
    const size_t count = std::min<size_t>(MP_MAX_PASS_VIEWS, views.size() - first);
    session_.reserve(views_, views_capacity_, MP_MAX_PASS_VIEWS * sizeof(FrameParams), "shadow views");
    q.enqueueWriteBuffer(views_, CL_TRUE, 0, count * sizeof(FrameParams), views.data() + first);
    PassViews pass;
    pass.views = views_;
    pass.count = cl_uint(count);
    pass.page_masks = masks_;
    if (run(f, pass, sink).cancelled) return false;
  }
  return true;
}

bool ShadowMaps::render(const Scene& scene, const std::vector<Light>& lights, const FrameSetup& frame, const SceneBuffers& buffers,
                        const ShadowPassStages& stages, const BoundSplitRunner& run, StageTimer& timer,
                        ShadowStats& stats) {
  stats = ShadowStats{};
  const RenderSettings& settings = scene.settings;
  stats.budget_bytes = size_t(double(settings.shadow_memory_mib) * 1048576.0);
  inputs_.enabled = false;
  if (!settings.shadows || buffers.patch_count == 0) return true;
  ShadowLayout layout = make_shadow_layout(scene, lights, frame, world_bounds(scene), geometry_fingerprint(scene));
  if (layout.shadowed_lights == 0) {
    pool_.clear();
    return true;
  }
  stats.lights = layout.shadowed_lights;

  // The budget holds the page tables, the requests, the page masks (at most
  // a third of the tables) and the views first; pages take the rest.
  const size_t fixed = size_t(layout.table_entries) * (sizeof(cl_uint) + 1) + size_t(layout.table_entries) * 4 / 3 +
                       MP_MAX_PASS_VIEWS * sizeof(FrameParams) + layout.shadows.size() * sizeof(DeviceShadow) +
                       layout.levels.size() * sizeof(DeviceShadowLevel);
  if (stats.budget_bytes < fixed + 16 * kPageBytes)
    throw Error("the shadow map memory budget of " + std::to_string(settings.shadow_memory_mib) + " MiB is too small for " +
                std::to_string(layout.shadowed_lights) + " shadowed lights: it needs at least " +
                std::to_string((fixed + 16 * kPageBytes + 1048575) >> 20) + " MiB");
  const size_t capacity = (stats.budget_bytes - fixed) / kPageBytes;
  if (pool_.capacity() != capacity) {
    pool_.set_capacity(capacity);
    if (pool_.resident() == 0) pool_pages_ = std::min<uint32_t>(pool_pages_, uint32_t(capacity));
  }
  std::unordered_set<uint64_t> present;
  if (settings.keep_shadow_pages)
    for (uint64_t k : layout.light_keys)
      if (k) present.insert(k);
  pool_.keep_only(present);

  // First: hard shadows' pages and soft shadows' first search round's; a
  // budget too short for them coarsens every light.
  std::vector<ShadowPageKey> keys;
  std::vector<uint32_t> entries;
  bool soft = false;
  if (settings.soft_shadow_pages)
    for (const DeviceShadow& d : layout.shadows) soft = soft || (d.kind != MP_SHADOW_NONE && d.shape != MP_SHADOW_SHAPE_POINT);
  for (int bias = 0;; ++bias) {
    set_shadow_level_bias(layout, bias);
    upload_records(layout);
    if (!mark(layout, frame, buffers, stages, run, timer, soft, keys, entries, stats)) return false;
    stats.level_bias = bias;
    if (keys.size() <= capacity || bias >= kMaxShadowLevelBias) break;
  }
  if (!allocate_and_render(layout, keys, entries, frame, buffers, stages, run, timer, stats)) return false;
  // Then, where those maps show occluders near a receiver, the pages soft
  // shadows' second round and filters read there.
  if (soft) {
    mark_soft(layout, frame, timer, keys, entries, stats);
    if (!allocate_and_render(layout, keys, entries, frame, buffers, stages, run, timer, stats)) return false;
  }
  inputs_.enabled = true;
  stats.pages_requested = keys.size();
  stats.per_light.clear();
  for (size_t l = 0; l < lights.size(); ++l) {
    if (layout.shadows[l].kind == MP_SHADOW_NONE) continue;
    const uint32_t entries_of_light = layout.shadows[l].kind == MP_SHADOW_SUN
                                          ? layout.shadows[l].levels * uint32_t(MP_MAP_PAGES * MP_MAP_PAGES)
                                          : 6u * MP_CUBE_FACE_ENTRIES;
    stats.per_light.push_back({int(l), light_pages_[l], light_pages_[l] * kPageBytes + entries_of_light * sizeof(cl_uint)});
  }
  stats.peak_bytes = size_t(pool_pages_) * kPageBytes + pages_capacity_ + requests_capacity_ + masks_capacity_ +
                     views_capacity_ + records_capacity_ + levels_capacity_ + clear_capacity_ + writes_capacity_ +
                     2 * kept_capacity_ * sizeof(cl_float4);
  return true;
}

bool ShadowMaps::allocate_and_render(const ShadowLayout& layout, const std::vector<ShadowPageKey>& keys,
                                     const std::vector<uint32_t>& entries, const FrameSetup& frame,
                                     const SceneBuffers& buffers, const ShadowPassStages& stages,
                                     const BoundSplitRunner& run, StageTimer& timer, ShadowStats& stats) {
  const auto started = std::chrono::steady_clock::now();
  struct AddWall {
    double& to;
    std::chrono::steady_clock::time_point from;
    ~AddWall() { to += ms_since(from); }
  } add_wall{stats.render_wall_ms, started};
  std::vector<ShadowPagePool::Grant> grants;
  pool_.grant(keys, grants);

  // Page tables: the granted pages, marked for rendering where new.
  std::vector<uint32_t> table(layout.table_entries, 0u);
  std::vector<uint32_t> fresh;
  std::vector<cl_uint2> writes;
  writes.reserve(keys.size());
  stats.pages_missing = 0;
  for (size_t i = 0; i < keys.size(); ++i) {
    const ShadowPagePool::Grant& g = grants[i];
    if (g.physical == ShadowPagePool::kNone) {
      ++stats.pages_missing;
      continue;
    }
    table[entries[i]] = g.physical | MP_PAGE_RESIDENT | (g.render ? MP_PAGE_RENDER : 0u);
    writes.push_back({{entries[i], table[entries[i]]}});
    if (g.render) fresh.push_back(g.physical);
  }
  stats.pages_rendered += fresh.size();

  // Resident pages per light: a light's page-table entries follow its first.
  light_pages_.assign(layout.shadows.size(), 0);
  for (const cl_uint2& w : writes)
    for (size_t l = layout.shadows.size(); l-- > 0;)
      if (layout.shadows[l].kind != MP_SHADOW_NONE && w.s[0] >= layout.shadows[l].page_table) {
        ++light_pages_[l];
        break;
      }

  DeviceQueue& q = session_.queue();
  ensure_pool(pool_.extent());
  write_table(table.size(), writes);
  if (fresh.empty()) return true;

  // The views of maps with pages to render, and their page masks.
  std::vector<FrameParams> views;
  std::vector<uint8_t> masks;
  for (const ShadowMapInfo& m : layout.maps) {
    const int n = m.side;
    size_t any = 0;
    std::vector<uint8_t> level(size_t(n) * size_t(n), 0);
    for (int ry = 0; ry < n; ++ry)
      for (int rx = 0; rx < n; ++rx) {
        const int sx = (rx + m.origin_x) & (n - 1), sy = (ry + m.origin_y) & (n - 1);
        if (table[m.table + uint32_t(sy * n + sx)] & MP_PAGE_RENDER) level[size_t(ry) * n + rx] = 1, ++any;
      }
    if (!any) continue;
    FrameParams v = m.view;
    v.page_mask = uint32_t(masks.size());
    masks.insert(masks.end(), level.begin(), level.end());
    for (int s = n; s > 1; s >>= 1) {
      const int h = s / 2;
      std::vector<uint8_t> up(size_t(h) * size_t(h), 0);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < h; ++x)
          up[size_t(y) * h + x] = level[size_t(2 * y) * s + 2 * x] | level[size_t(2 * y) * s + 2 * x + 1] |
                                  level[size_t(2 * y + 1) * s + 2 * x] | level[size_t(2 * y + 1) * s + 2 * x + 1];
      masks.insert(masks.end(), up.begin(), up.end());
      level.swap(up);
    }
    views.push_back(v);
  }
  stats.views += views.size();

  StageTimer::Redirect to(timer, Stage::ShadowBoundSplit);
  session_.reserve(clear_list_, clear_capacity_, fresh.size() * sizeof(cl_uint), "shadow page list");
  q.enqueueWriteBuffer(clear_list_, CL_TRUE, 0, fresh.size() * sizeof(cl_uint), fresh.data());
  const cl_uint texels = cl_uint(fresh.size() * MP_PAGE_TEXELS);
  clear_.setArg(0, clear_list_);
  clear_.setArg(1, texels);
  clear_.setArg(2, inputs_.pool);
  cl::Event e;
  q.enqueueNDRangeKernel(clear_, cl::NullRange, round_up_range(texels, 256), cl::NDRange(256), nullptr, &e);
  timer.add(Stage::ShadowSample, e);
  stages.layout.begin_frame();
  if (!render_views(views, masks, frame, buffers, stages, run, timer, stats)) return false;
  stats.micropolygons += stages.layout.micropolygons();
  return true;
}

}  // namespace mp
