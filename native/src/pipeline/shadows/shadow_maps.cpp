#include "pipeline/shadows/shadow_maps.h"

#include <algorithm>
#include <numeric>
#include <string>
#include <unordered_set>

#include "cl/kernel_args.h"
#include "micropoly/error.h"
#include "shadow/mp_shadow.h"
#include "pipeline/pass/occlusion_culling.h"
#include "pipeline/device_scene/scene_fingerprint.h"

namespace mp {
// Host vectors written to the device here live only for the call, so every
// write blocks until the device has the data.
namespace {

constexpr size_t kPageBytes = size_t(MP_PAGE_TEXELS) * sizeof(cl_uint);
// What a page costs in all: its texels, its cells' and its own farthest
// depths and its dirty byte (occlusion culling), its slot in the list of
// pages to clear and its page-table write.
constexpr size_t kPageCost = kPageBytes + (64 + 1) * sizeof(cl_uint) + sizeof(cl_uint) + 1 + sizeof(cl_uint2);
// A kept marking vertex: its position and (soft shadows) its normal.
constexpr size_t kKeptVectorBytes = 3 * sizeof(cl_float);  // packed (vstore3), position and normal alike
// The marking pass dices the camera's view this many times coarser (in
// micropolygon edge) than the frame: its vertices mark the pages around
// them, and need to be close only next to a page.
constexpr float kMarkCoarsening = 8.0f;

// Each marking vertex's box reaches its neighbours: one coarse micropolygon edge.
cl_float mark_reach(const FrameParams& coarse) { return coarse.micropoly_edge; }

// Requested pages the device lists for the host (collect_requests); more
// are read as whole tables. A page-table entry's share is half a byte.
cl_uint list_capacity(cl_uint table_entries) { return std::max<cl_uint>(4096, table_entries / 16); }

// The markings' coarse view of the camera's.
FrameParams marking_view(const FrameSetup& frame) {
  FrameParams coarse = frame.params;
  coarse.micropoly_edge *= kMarkCoarsening;
  // Its grids' vertices mark pages wherever they lie, sample or not.
  coarse.samples = MP_SAMPLES_UNKNOWN;
  return coarse;
}

// What every marking step shares: its launches count as the marking, its
// wall time joins the marking's, and it works in the coarse view.
struct MarkingStep {
  MarkingStep(MicropolygonPass& pass, const FrameSetup& frame, const ShadowLayout& layout, ShadowStats& stats)
      : timer(pass.timer()), to(timer, Stage::ShadowMark), coarse(marking_view(frame)),
        shadow_count(cl_uint(layout.shadows.size())), stats_(stats) {}
  ~MarkingStep() { stats_.mark_wall_ms += ms_since(started_); }
  StageTimer& timer;
  StageTimer::Redirect to;
  const FrameParams coarse;
  const cl_uint shadow_count;  // shadow records, one per light

 private:
  ShadowStats& stats_;
  const std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();
};

}  // namespace

ShadowMaps::ShadowMaps(DeviceSession& session)
    : session_(session),
      mark_(session.program(), "mark_shadow_pages"),
      mark_kept_(session.program(), "mark_kept_shadow_pages"),
      mark_soft_(session.program(), "mark_soft_shadow_pages"),
      mark_soft_grid_(session.program(), "mark_soft_shadow_pages_grid"),
      clear_(session.program(), "clear_shadow_pages"),
      set_entries_(session.program(), "set_page_entries"),
      list_requests_(session.program(), "list_requests"),
      farthest_(session.program(), "shadow_page_farthest"),
      occlusion_build_(session.program(), "shadow_occlusion_build"),
      sample_(session.program(), "shadow_sample"),
      list_count_(session.allocate(sizeof(cl_uint), "shadow request count")),
      depth_(session) {}

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

void ShadowMaps::clear_requests(const ShadowLayout& layout) {
  const size_t n = layout.table_entries;
  session_.reserve(requests_, requests_capacity_, n, "shadow page requests");
  session_.queue().enqueueFillBuffer(requests_, cl_uchar(0), 0, n);
  session_.reserve(caps_, caps_held_, n * sizeof(cl_uint), "shadow page caps");
  session_.queue().enqueueFillBuffer(caps_, cl_uint(0), 0, n * sizeof(cl_uint));
}

CameraRoots ShadowMaps::camera_roots() {
  // A wave of its own costs a partly filled batch (about a millisecond on a
  // GPU): worth it only where an eighth of the roots or more lie hidden.
  const cl_uint roots = depth_.roots(), seen = depth_.seen_count();
  if (roots == 0 || size_t(roots - seen) * 8 < roots) return CameraRoots{};
  return CameraRoots{depth_.seen_order(), seen};
}

bool ShadowMaps::camera_view(const ShadowLayout& layout, const FrameSetup& frame, MicropolygonPass& pass, bool soft,
                             const cl::Buffer& camera_order, ShadowStats& stats) {
  MarkingStep step(pass, frame, layout, stats);
  StageTimer& timer = step.timer;
  const FrameParams& coarse = step.coarse;
  const cl_uint shadow_count = step.shadow_count;
  GridBuffers& grids = pass.grids();
  const SceneBuffers& buffers = pass.scene();
  camera_order_ = camera_order;
  depth_.begin(frame.params, camera_order(), timer);
  kept_vertices_ = 0;
  kept_overflow_ = false;
  bool keep = true;
  ViewTarget target;
  // The soft marking's search compares with the displaced surface's tangent plane.
  target.normals = soft;
  target.take = [&](const cl::Buffer& diceable, cl_uint count) {
    const cl_uint vertices = grids.vertex_total;
    ++stats.batches;
    depth_.rasterise(diceable, count, buffers, coarse, grids, timer);
    // The kept vertices stay within their share of the budget: past it the
    // batch marks its pages now, before the depth is complete (all its
    // vertices, seen or not), and the soft marking dices the view again.
    if (keep && size_t(kept_vertices_) + vertices > kept_limit_) keep = false, kept_overflow_ = true;
    if (keep) keep_room(size_t(kept_vertices_) + vertices);
    bind_args(mark_, diceable, count, grids.vertex_offsets, vertices, coarse, grids.p, grids.n, inputs_.shadows,
              inputs_.levels, shadow_count, request_args(), mark_reach(coarse), cl_uint(soft), cl_uint(!keep),
              cl_uint(keep),
              cl_uint(soft), kept_vertices_, keep ? kept_p_ : grids.p, keep && soft ? kept_n_ : grids.n,
              depth_.image(), OcclusionParams{});  // unwritten when not kept; no depth test yet
    launch(mark_, vertices, timer);
    if (keep) kept_vertices_ += vertices;
  };
  const BoundSplitResult r = pass.run(
      PassView{coarse, PassViews{}, depth_.occlusion(camera_order, session_.info().type == "cpu", timer)}, target);
  stats.marking_occluded += r.occluded;
  if (r.cancelled) return false;
  // Complete: the markings and any pass over the view again test against
  // all of it, and the camera's view takes first the roots it may see.
  depth_.refresh(timer);
  depth_.seen_first(camera_order, buffers.patch_count, buffers, frame.params, timer);
  return true;
}

bool ShadowMaps::mark(const ShadowLayout& layout, const FrameSetup& frame, MicropolygonPass& pass, bool first,
                      std::vector<ShadowPageKey>& keys, std::vector<uint32_t>& entries, ShadowStats& stats) {
  MarkingStep step(pass, frame, layout, stats);
  StageTimer& timer = step.timer;
  const FrameParams& coarse = step.coarse;
  const cl_uint shadow_count = step.shadow_count;
  if (kept_vertices_ > 0) {
    bind_args(mark_kept_, kept_p_, kept_vertices_, coarse, inputs_.shadows, inputs_.levels, shadow_count,
              request_args(), mark_reach(coarse), cl_uint(kept_normals_), depth_.image(), depth_.params());
    launch(mark_kept_, kept_vertices_, timer);
  }
  // The batches past the kept share marked their pages in the camera's
  // view; at a coarser level bias they do so again, diced anew.
  GridBuffers& grids = pass.grids();
  if (kept_overflow_ && !first &&
      !mark_again(pass, coarse, false, mark_, stats, [&](const cl::Buffer& diceable, cl_uint count) {
        bind_args(mark_, diceable, count, grids.vertex_offsets, grids.vertex_total, coarse, grids.p, grids.n,
                  inputs_.shadows, inputs_.levels, shadow_count, request_args(), mark_reach(coarse),
                  cl_uint(kept_normals_), cl_uint(1), cl_uint(0), cl_uint(0), cl_uint(0), grids.p, grids.n,
                  depth_.image(), depth_.params());
      }))
    return false;
  collect_requests(layout, keys, entries);
  return true;
}

bool ShadowMaps::mark_soft(const ShadowLayout& layout, const FrameSetup& frame, MicropolygonPass& pass,
                           std::vector<ShadowPageKey>& keys, std::vector<uint32_t>& entries, ShadowStats& stats) {
  // The soft marking adds to the first's requests.
  MarkingStep step(pass, frame, layout, stats);
  StageTimer& timer = step.timer;
  const FrameParams& coarse = step.coarse;
  const cl_uint shadow_count = step.shadow_count;
  GridBuffers& grids = pass.grids();
  if (kept_overflow_) {
    // More vertices than the budget keeps: the view is diced again, as the
    // camera's view diced it (culled by its complete depth), and marked
    // batch by batch.
    if (!mark_again(pass, coarse, true, mark_soft_grid_, stats, [&](const cl::Buffer& diceable, cl_uint count) {
          bind_args(mark_soft_grid_, diceable, count, grids.vertex_offsets, coarse, grids.p, grids.n,
                    inputs_.shadows, inputs_.levels, shadow_count, inputs_.pages, inputs_.pool, request_args(),
                    mark_reach(coarse), depth_.image(), depth_.params());
        }))
      return false;
  } else if (kept_vertices_ > 0) {
    bind_args(mark_soft_, kept_p_, kept_n_, kept_vertices_, coarse, inputs_.shadows, inputs_.levels, shadow_count,
              inputs_.pages, inputs_.pool, request_args(), mark_reach(coarse), depth_.image(), depth_.params());
    launch(mark_soft_, kept_vertices_, timer);
  }
  collect_requests(layout, keys, entries);
  return true;
}

void ShadowMaps::launch(cl::Kernel& kernel, cl_uint items, StageTimer& timer) {
  cl::Event e;
  session_.queue().enqueueNDRangeKernel(kernel, cl::NullRange, round_up_range(items), cl::NDRange(64), nullptr, &e);
  timer.add(Stage::ShadowMark, e);
}

bool ShadowMaps::mark_again(MicropolygonPass& pass, const FrameParams& coarse, bool normals, cl::Kernel& kernel,
                            ShadowStats& stats, const std::function<void(const cl::Buffer&, cl_uint)>& bind) {
  ++stats.marking_passes;
  GridBuffers& grids = pass.grids();
  ViewTarget target;
  target.normals = normals;
  target.take = [&](const cl::Buffer& diceable, cl_uint count) {
    ++stats.batches;
    if (grids.vertex_total == 0) return;
    bind(diceable, count);
    launch(kernel, grids.vertex_total, pass.timer());
  };
  const BoundSplitResult r = pass.run(PassView{coarse, PassViews{}, depth_.complete(camera_order_)}, target);
  stats.marking_occluded += r.occluded;
  return !r.cancelled;
}

void ShadowMaps::keep_room(size_t vertices) {
  const bool normals = kept_normals_;
  if (vertices <= kept_capacity_) return;
  const size_t grown = std::max(vertices, std::min(kept_capacity_ + kept_capacity_ / 2, kept_limit_));
  cl::Buffer p = session_.allocate(grown * kKeptVectorBytes, "shadow marking vertices");
  cl::Buffer nrm = normals ? session_.allocate(grown * kKeptVectorBytes, "shadow marking normals") : cl::Buffer();
  if (kept_vertices_ > 0) {
    session_.queue().enqueueCopyBuffer(kept_p_, p, 0, 0, size_t(kept_vertices_) * kKeptVectorBytes);
    if (normals)
      session_.queue().enqueueCopyBuffer(kept_n_, nrm, 0, 0, size_t(kept_vertices_) * kKeptVectorBytes);
  }
  kept_p_ = p;
  kept_n_ = nrm;
  kept_capacity_ = grown;
}

void ShadowMaps::collect_requests(const ShadowLayout& layout, std::vector<ShadowPageKey>& keys,
                                  std::vector<uint32_t>& entries) {
  const cl_uint n = cl_uint(layout.table_entries);
  DeviceQueue& q = session_.queue();
  // The requested entries and their caps, listed on the device: a few
  // hundred pairs to read rather than every table (a sun's 393,216 entries).
  const cl_uint capacity = list_capacity(n);
  session_.reserve(list_, list_held_, size_t(capacity) * sizeof(cl_uint2), "shadow request list");
  cl_uint count = 0;
  q.enqueueFillBuffer(list_count_, cl_uint(0), 0, sizeof count);
  bind_args(list_requests_, requests_, caps_, n, list_count_, list_, capacity);
  q.enqueueNDRangeKernel(list_requests_, cl::NullRange, round_up_range(n, 256), cl::NDRange(256));
  q.enqueueReadBuffer(list_count_, CL_TRUE, 0, sizeof count, &count);
  std::vector<cl_uint2> listed(count);
  if (count <= capacity) {
    if (count) q.enqueueReadBuffer(list_, CL_TRUE, 0, size_t(count) * sizeof(cl_uint2), listed.data());
  } else {
    // More than the list holds: the whole tables.
    std::vector<uint8_t> requested(n);
    std::vector<uint32_t> caps(n);
    q.enqueueReadBuffer(requests_, CL_TRUE, 0, n, requested.data());
    q.enqueueReadBuffer(caps_, CL_TRUE, 0, size_t(n) * sizeof(cl_uint), caps.data());
    listed.clear();
    for (cl_uint e = 0; e < n; ++e)
      if (requested[e]) listed.push_back({{e, caps[e]}});
  }
  // Coarser maps first (a budget too short for everything keeps them), in
  // the layout's order among equals, each map's pages in raster order.
  std::vector<size_t> order(layout.maps.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return layout.maps[a].coarseness > layout.maps[b].coarseness; });
  std::vector<size_t> rank(layout.maps.size());
  for (size_t r = 0; r < order.size(); ++r) rank[order[r]] = r;
  // Maps by their first table entry, to find each entry's.
  std::vector<std::pair<uint32_t, size_t>> starts(layout.maps.size());
  for (size_t i = 0; i < layout.maps.size(); ++i) starts[i] = {layout.maps[i].table, i};
  std::sort(starts.begin(), starts.end());
  struct Listed {
    size_t rank, map;
    cl_uint2 entry;
  };
  std::vector<Listed> sorted;
  sorted.reserve(listed.size());
  for (const cl_uint2& l : listed) {
    auto it = std::upper_bound(starts.begin(), starts.end(), std::make_pair(l.s[0], ~size_t(0)));
    const size_t map = std::prev(it)->second;
    sorted.push_back({rank[map], map, l});
  }
  std::sort(sorted.begin(), sorted.end(), [](const Listed& a, const Listed& b) {
    return a.rank != b.rank ? a.rank < b.rank : a.entry.s[0] < b.entry.s[0];
  });
  keys.clear();
  entries.clear();
  request_caps_.clear();
  for (const Listed& l : sorted) {
    const ShadowMapInfo& m = layout.maps[l.map];
    const uint32_t e = l.entry.s[0], at = e - m.table;
    ShadowPageKey k;
    k.light = layout.light_keys[size_t(m.light)];
    k.map = m.map_id;
    layout.page_position(m, int(at % uint32_t(m.side)), int(at / uint32_t(m.side)), &k.x, &k.y);
    keys.push_back(k);
    entries.push_back(e);
    request_caps_.push_back(l.entry.s[1]);
  }
}

void ShadowMaps::write_table(size_t entries, const std::vector<cl_uint2>& writes) {
  DeviceQueue& q = session_.queue();
  session_.reserve(inputs_.pages, pages_capacity_, entries * sizeof(cl_uint), "shadow page tables");
  q.enqueueFillBuffer(inputs_.pages, cl_uint(0), 0, entries * sizeof(cl_uint));
  if (writes.empty()) return;
  session_.reserve(writes_, writes_capacity_, writes.size() * sizeof(cl_uint2), "shadow page-table writes");
  q.enqueueWriteBuffer(writes_, CL_TRUE, 0, writes.size() * sizeof(cl_uint2), writes.data());
  bind_args(set_entries_, writes_, cl_uint(writes.size()), inputs_.pages);
  q.enqueueNDRangeKernel(set_entries_, cl::NullRange, round_up_range(cl_uint(writes.size())), cl::NDRange(64));
}

void ShadowMaps::ensure_pool(uint32_t pages) {
  if (pages <= pool_pages_) return;
  const uint32_t grown = std::max(pages, std::min<uint32_t>(pool_pages_ + pool_pages_ / 2, uint32_t(pool_.capacity())));
  cl::Buffer bigger = session_.allocate(size_t(grown) * kPageBytes, "shadow map page pool");
  cl::Buffer dirty = session_.allocate(size_t(grown), "shadow page marks");
  // Pages kept from earlier frames move along.
  if (pool_pages_ > 0)
    session_.queue().enqueueCopyBuffer(inputs_.pool, bigger, 0, 0, size_t(pool_pages_) * kPageBytes);
  inputs_.pool = bigger;
  dirty_ = dirty;
  pool_pages_ = grown;
}

const cl::Buffer& ShadowMaps::light_order(int light, const FrameParams& v, const SceneBuffers& buffers,
                                          uint64_t scene_key) {
  static const cl::Buffer none;
  if (orders_.size() <= size_t(light)) orders_.resize(size_t(light) + 1);
  LightOrder& o = orders_[size_t(light)];
  // Any permutation of the patches renders the same pages (the order only
  // decides what culling sees first), so an order stays while the geometry
  // and the number of patches do, even where the patches were uploaded in
  // another order (the geometry's key leaves out what only the camera sees).
  const size_t patches = buffers.host_patch_bounds.size() / 2;
  uint64_t key = (scene_key ^ 0x9e3779b97f4a7c15ull ^ uint64_t(patches)) * 0x100000001b3ull;
  for (float x : v.view) key = (key ^ uint64_t(as_uint(x))) * 0x100000001b3ull;
  key = (key ^ uint64_t(v.ortho)) * 0x100000001b3ull;
  if (o.order() && o.key == key) return o.order;
  o = LightOrder{};
  const size_t bytes = std::max<size_t>(patches, 1) * sizeof(cl_uint);
  size_t held = 0;
  for (const LightOrder& other : orders_) held += other.bytes;
  if (held + bytes > orders_limit_) return none;
  const std::vector<cl_uint> order = view_near_to_far_order(buffers.host_patch_bounds, v);
  o.order = session_.allocate(bytes, "shadow patch order", CL_MEM_READ_ONLY);
  if (!order.empty())
    session_.queue().enqueueWriteBuffer(o.order, CL_TRUE, 0, order.size() * sizeof(cl_uint), order.data());
  o.bytes = bytes;
  o.key = key;
  return o.order;
}

bool ShadowMaps::render_views(const std::vector<FrameParams>& views, const std::vector<int>& lights,
                              const std::vector<int>& groups,
                              const std::vector<uint8_t>& masks, const FrameSetup& frame, MicropolygonPass& pass,
                              ShadowStats& stats, bool culling, cl_uint fresh_pages) {
  StageTimer& timer = pass.timer();
  const SceneBuffers& buffers = pass.scene();
  DeviceQueue& q = session_.queue();
  session_.reserve(masks_, masks_capacity_, masks.size(), "shadow page masks");
  if (!masks.empty()) q.enqueueWriteBuffer(masks_, CL_TRUE, 0, masks.size(), masks.data());
  // The pyramids (laid out as the masks), then every pool page's cells and
  // farthest depth (mp_page_occluded).
  const cl_uint page_cells = cl_uint(masks.size()), page_farthest = page_cells + pool_pages_ * 64u;
  if (culling)
    session_.reserve(pyramid_, pyramid_capacity_, (size_t(page_farthest) + pool_pages_) * sizeof(cl_uint),
                     "shadow occlusion pyramids");
  const FrameParams& f = frame.params;
  GridBuffers& grids = pass.grids();
  // Depth only, into the pages: opacity decides which texels a surface
  // covers; normals are not needed.
  ViewTarget target;
  target.normals = false;
  target.opacity = true;
  size_t written = 0;  // micropolygons rasterised in the current pass
  target.take = [&](const cl::Buffer& diceable, cl_uint count) {
    ++stats.batches;
    const cl_uint base = grids.micropolygon_offsets_host[0];
    const cl_uint total = grids.micropolygon_offsets_host[count] - base;
    written += total;
    if (total == 0) return;
    cl::Kernel& k = sample_.bind(buffers, diceable, cl_uint(0), count, grids.micropolygon_offsets, base, total, f,
                                 views_, grids.p, grids.c, inputs_.pages, inputs_.pool, dirty_);
    cl::Event e;
    q.enqueueNDRangeKernel(k, cl::NullRange, round_up_range(total), cl::NDRange(64), nullptr, &e);
    timer.add(Stage::Sample, e);
  };
  for (size_t first = 0; first < views.size();) {
    // A pass takes up to MP_MAX_PASS_VIEWS views; with culling, one culling
    // group's only (ShadowLayout::cull_group: one light's, or the world's
    // probe suns'), whose patches it takes near to far from its first
    // light. Any order culls correctly (each view tests against its own
    // pages); a near-to-far one culls most.
    size_t count = 1;
    while (first + count < views.size() && count < MP_MAX_PASS_VIEWS &&
           (!culling || groups[first + count] == groups[first]))
      ++count;
    session_.reserve(views_, views_capacity_, MP_MAX_PASS_VIEWS * sizeof(FrameParams), "shadow views");
    q.enqueueWriteBuffer(views_, CL_TRUE, 0, count * sizeof(FrameParams), views.data() + first);
    PassViews views_of_pass;
    views_of_pass.views = views_;
    views_of_pass.count = cl_uint(count);
    views_of_pass.page_masks = masks_;
    PassOcclusion occlusion;
    // Culling pays where a light's views take their patches near to far:
    // without an order (the orders passed their share of the budget) the
    // pass renders as without culling.
    const cl::Buffer& order = culling ? light_order(lights[first], views[first], buffers, scene_key_) : cl::Buffer();
    if (order()) {
      // The pyramids start from the cleared pages (all empty) and follow
      // what the pass writes: after each dice batch, the farthest depth of
      // the pages it wrote to, then every view's pyramid.
      occlusion.pyramid = pyramid_;
      occlusion.params.levels = 1;
      occlusion.params.page_cells = page_cells;
      occlusion.params.page_farthest = page_farthest;
      occlusion.root_order = order;
      occlusion.waves = session_.info().type == "cpu";
      // A look at the pages costs a pass over those written since the last
      // and over every view's pyramid: it is taken when the micropolygons
      // written since make an eighth of the pass' so far, so a pass of
      // thousands of small batches (a sun's coarse levels over a large
      // scene) looks a few dozen times, and the first batches, which hide
      // the most, at once.
      written = 0;
      size_t looked_at = 0;
      occlusion.refresh = [&, count, looked_at]() mutable {
        if (looked_at > 0 && (written - looked_at) * 8 < written) return;
        looked_at = std::max<size_t>(written, 1);
        cl::Event e1, e2;
        bind_args(farthest_, clear_list_, caps_list_, fresh_pages, inputs_.pool, dirty_, pyramid_, page_cells,
                  page_farthest);
        q.enqueueNDRangeKernel(farthest_, cl::NullRange, cl::NDRange(size_t(fresh_pages) * 64), cl::NDRange(64),
                               nullptr, &e1);
        bind_args(occlusion_build_, views_, inputs_.pages, pyramid_, page_farthest);
        q.enqueueNDRangeKernel(occlusion_build_, cl::NullRange, cl::NDRange(count * 64), cl::NDRange(64), nullptr, &e2);
        timer.add(Stage::Occlusion, e1);
        timer.add(Stage::Occlusion, e2);
      };
      occlusion.refresh();
    }
    const BoundSplitResult r = pass.run(PassView{f, views_of_pass, occlusion}, target);
    stats.subpatches_occluded += r.occluded;
    if (r.cancelled) return false;
    first += count;
  }
  return true;
}

bool ShadowMaps::render(const Scene& scene, const std::vector<Light>& lights, const FrameSetup& frame,
                        MicropolygonPass& pass, const cl::Buffer& camera_order, ShadowStats& stats) {
  pending_.clear();
  if (render_maps(scene, lights, frame, pass, camera_order, stats)) return true;
  // Cancelled: the pages granted for rendering this frame may hold nothing
  // their keys name; the others stay.
  std::unordered_set<ShadowPageKey, ShadowPageKeyHash> pending(pending_.begin(), pending_.end());
  pool_.forget_if([&](const ShadowPageKey& k) { return pending.count(k) > 0; });
  return false;
}

void ShadowMaps::forget_changed_pages(const ShadowLayout& layout, const std::vector<Light>& lights,
                                      ShadowCasters casters) {
  const std::optional<std::vector<WorldBounds>> boxes = shadow_changes(casters_, casters);
  casters_ = std::move(casters);
  if (!boxes) {
    pool_.clear();
    return;
  }
  if (boxes->empty() || pool_.resident() == 0) return;
  std::unordered_map<uint64_t, size_t> light_of;
  for (size_t i = 0; i < layout.light_keys.size(); ++i)
    if (layout.light_keys[i]) light_of[layout.light_keys[i]] = i;
  pool_.forget_if([&](const ShadowPageKey& k) {
    const auto it = light_of.find(k.light);
    if (it == light_of.end()) return true;
    for (const WorldBounds& box : *boxes)
      if (shadow_page_touches(lights[it->second], k.map, k.x, k.y, box)) return true;
    return false;
  });
}

bool ShadowMaps::render_maps(const Scene& scene, const std::vector<Light>& lights, const FrameSetup& frame,
                             MicropolygonPass& pass, const cl::Buffer& camera_order, ShadowStats& stats) {
  const SceneBuffers& buffers = pass.scene();
  stats = ShadowStats{};
  depth_.seen_first(cl::Buffer(), 0, buffers, frame.params, pass.timer());  // none until the marking orders them
  const RenderSettings& settings = scene.settings;
  stats.budget_bytes = size_t(double(settings.shadow_memory_mib) * 1048576.0);
  inputs_.enabled = false;
  if (!settings.shadows || buffers.root_count == 0) return true;
  const ShadowGeometryKeys geometry = shadow_geometry_keys(scene);
  scene_key_ = geometry_fingerprint(geometry);
  ShadowLayout layout = make_shadow_layout(scene, lights, frame, world_bounds(scene), geometry.global);
  if (layout.shadowed_lights == 0) {
    pool_.clear();
    return true;
  }
  stats.lights = layout.shadowed_lights;

  bool soft_lights = false;
  for (const DeviceShadow& d : layout.shadows)
    soft_lights = soft_lights || (d.kind != MP_SHADOW_NONE && d.shape != MP_SHADOW_SHAPE_POINT);
  const bool soft = soft_lights && settings.soft_shadow_pages;
  capped_ = settings.soft_shadow_pages || !soft_lights;

  // The budget holds the page tables, the requests, their caps and list, the page masks (at most
  // a third of the tables) and, with culling, their pyramids, the camera's
  // coarse depth, the views and the lights' records first; then the
  // marking's kept vertices take up to an eighth (where there is a depth to
  // test them against, or soft shadows to mark from them) and the lights'
  // patch orders (culling) up to a sixteenth; pages take the rest. Every
  // part stays within its share, so the whole never exceeds the budget. A
  // budget too short for the depth, or for culling's parts, and sixteen
  // pages does without them.
  const size_t masks = size_t(layout.table_entries) * 4 / 3;
  size_t fixed = size_t(layout.table_entries) * (2 * sizeof(cl_uint) + 1) +
                 size_t(list_capacity(cl_uint(layout.table_entries))) * sizeof(cl_uint2) + masks +
                 MP_MAX_PASS_VIEWS * sizeof(FrameParams) + layout.shadows.size() * sizeof(DeviceShadow) +
                 layout.levels.size() * sizeof(DeviceShadowLevel);
  const size_t depth_bytes = MarkingDepth::bytes_for(frame.params);
  const bool depth_on =
      camera_order() && fixed + depth_bytes + stats.budget_bytes / 8 + 16 * kPageCost <= stats.budget_bytes;
  if (depth_on) fixed += depth_bytes;
  const size_t kept_share = soft || depth_on ? stats.budget_bytes / 8 : 0;
  const bool culling = settings.occlusion_culling && fixed + kept_share + masks * sizeof(cl_uint) +
                                                            stats.budget_bytes / 16 + 16 * kPageCost <=
                                                        stats.budget_bytes;
  const size_t orders_share = culling ? stats.budget_bytes / 16 : 0;
  if (culling) fixed += masks * sizeof(cl_uint);
  if (stats.budget_bytes < fixed + kept_share + orders_share + 16 * kPageCost)
    throw Error("the shadow map memory budget of " + std::to_string(settings.shadow_memory_mib) + " MiB is too small for " +
                std::to_string(layout.shadowed_lights) + " shadowed lights: it needs at least " +
                std::to_string((fixed + kept_share + orders_share + 16 * kPageCost + 1048575) >> 20) + " MiB");
  const size_t kept_vertex_bytes = soft ? 2 * kKeptVectorBytes : kKeptVectorBytes;
  kept_limit_ = kept_share / kept_vertex_bytes;
  orders_limit_ = orders_share;
  // Kept buffers of another size or kind (frames before had or lacked soft shadows) go.
  if (kept_capacity_ > kept_limit_ || kept_normals_ != soft) kept_p_ = kept_n_ = cl::Buffer(), kept_capacity_ = 0;
  kept_normals_ = soft;
  for (LightOrder& o : orders_)
    if (o.bytes > orders_limit_) o = LightOrder{};
  const size_t capacity = (stats.budget_bytes - fixed - kept_share - orders_share) / kPageCost;
  if (pool_.capacity() != capacity) {
    pool_.set_capacity(capacity);
    if (pool_pages_ > capacity) {
      // A smaller budget: the pool buffer goes, and its pages with it.
      pool_.clear();
      inputs_.pool = dirty_ = cl::Buffer();
      pool_pages_ = 0;
    }
  }
  std::unordered_set<uint64_t> present;
  if (settings.keep_shadow_pages)
    for (uint64_t k : layout.light_keys)
      if (k) present.insert(k);
  pool_.keep_only(present);
  // A light's pages outlive changes to surfaces they do not reach (the
  // surfaces' boxes are found only when some surface changed).
  if (scene_key_ != casters_.all) forget_changed_pages(layout, lights, shadow_casters(scene, geometry));

  // First: hard shadows' pages and soft shadows' first search round's; a
  // budget too short for them coarsens every light.
  std::vector<ShadowPageKey> keys;
  std::vector<uint32_t> entries;
  set_shadow_level_bias(layout, 0);
  upload_records(layout);
  clear_requests(layout);
  if (!camera_view(layout, frame, pass, soft, depth_on ? camera_order : cl::Buffer(), stats)) return false;
  for (int bias = 0;; ++bias) {
    if (bias > 0) {
      set_shadow_level_bias(layout, bias);
      upload_records(layout);
      clear_requests(layout);
    }
    if (!mark(layout, frame, pass, bias == 0, keys, entries, stats)) return false;
    stats.level_bias = bias;
    if (keys.size() <= capacity || bias >= kMaxShadowLevelBias) break;
  }
  if (!allocate_and_render(layout, keys, entries, frame, pass, stats, culling)) return false;
  // Then, where those maps show occluders near a receiver, the pages soft
  // shadows' second round and filters read there.
  if (soft) {
    if (!mark_soft(layout, frame, pass, keys, entries, stats)) return false;
    if (!allocate_and_render(layout, keys, entries, frame, pass, stats, culling)) return false;
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
  size_t orders = 0;
  for (const LightOrder& o : orders_) orders += o.bytes;
  stats.peak_bytes = size_t(pool_pages_) * (kPageBytes + 1) + pages_capacity_ + requests_capacity_ + caps_held_ +
                     list_held_ +
                     masks_capacity_ + pyramid_capacity_ + views_capacity_ + records_capacity_ + levels_capacity_ +
                     clear_capacity_ + caps_capacity_ + writes_capacity_ + kept_capacity_ * (kept_normals_ ? 2 : 1) * kKeptVectorBytes +
                     depth_.held_bytes() + orders;
  return true;
}

bool ShadowMaps::allocate_and_render(const ShadowLayout& layout, const std::vector<ShadowPageKey>& keys,
                                     const std::vector<uint32_t>& entries, const FrameSetup& frame,
                                     MicropolygonPass& pass, ShadowStats& stats, bool culling) {
  StageTimer& timer = pass.timer();
  const auto started = std::chrono::steady_clock::now();
  struct AddWall {
    double& to;
    std::chrono::steady_clock::time_point from;
    ~AddWall() { to += ms_since(from); }
  } add_wall{stats.render_wall_ms, started};
  // Pages render only what lies in front of the farthest receiver that
  // asked for them (requests), where every reader of a page asked for it:
  // not where pages are missing (readers fall back to coarser levels that
  // others asked for) nor where soft shadows read levels that no marking
  // asked for (RenderSettings::soft_shadow_pages off).
  std::vector<ShadowPagePool::Grant> grants;
  pool_.grant(keys, capped_ ? request_caps_ : std::vector<uint32_t>{}, grants);

  // Page tables: the granted pages, marked for rendering where new.
  std::vector<uint32_t> table(layout.table_entries, 0u);
  std::vector<uint32_t> fresh, fresh_caps;
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
    if (g.render) {
      fresh.push_back(g.physical), pending_.push_back(keys[i]);
      fresh_caps.push_back(capped_ ? request_caps_[i] : ShadowPagePool::kUncapped);
    }
  }
  if (stats.pages_missing > 0 && capped_) {
    for (size_t i = 0; i < keys.size(); ++i)
      if (grants[i].render) pool_.uncap(keys[i]);
    std::fill(fresh_caps.begin(), fresh_caps.end(), ShadowPagePool::kUncapped);
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
  std::vector<int> view_lights;
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
    view_lights.push_back(m.light);
  }
  stats.views += views.size();
  std::vector<int> view_groups;
  for (int l : view_lights) view_groups.push_back(layout.cull_group[size_t(l)]);
  if (culling) {
    // Each culling group's views together, a light's within it: a culling
    // pass takes one group's.
    std::vector<size_t> by_group(views.size());
    std::iota(by_group.begin(), by_group.end(), size_t(0));
    std::stable_sort(by_group.begin(), by_group.end(), [&](size_t a, size_t b) {
      return view_groups[a] != view_groups[b] ? view_groups[a] < view_groups[b] : view_lights[a] < view_lights[b];
    });
    std::vector<FrameParams> sorted_views;
    std::vector<int> sorted_lights, sorted_groups;
    for (size_t i : by_group)
      sorted_views.push_back(views[i]), sorted_lights.push_back(view_lights[i]), sorted_groups.push_back(view_groups[i]);
    views.swap(sorted_views);
    view_lights.swap(sorted_lights);
    view_groups.swap(sorted_groups);
  }

  StageTimer::Redirect to(timer, Stage::ShadowBoundSplit);
  session_.reserve(clear_list_, clear_capacity_, fresh.size() * sizeof(cl_uint), "shadow page list");
  q.enqueueWriteBuffer(clear_list_, CL_TRUE, 0, fresh.size() * sizeof(cl_uint), fresh.data());
  session_.reserve(caps_list_, caps_capacity_, fresh.size() * sizeof(cl_uint), "shadow page caps");
  q.enqueueWriteBuffer(caps_list_, CL_TRUE, 0, fresh.size() * sizeof(cl_uint), fresh_caps.data());
  const cl_uint texels = cl_uint(fresh.size() * MP_PAGE_TEXELS);
  bind_args(clear_, clear_list_, texels, inputs_.pool, dirty_);
  cl::Event e;
  q.enqueueNDRangeKernel(clear_, cl::NullRange, round_up_range(texels, 256), cl::NDRange(256), nullptr, &e);
  timer.add(Stage::ShadowSample, e);
  pass.layout().begin_frame();
  if (!render_views(views, view_lights, view_groups, masks, frame, pass, stats, culling, cl_uint(fresh.size())))
    return false;
  stats.micropolygons += pass.layout().micropolygons();
  return true;
}

}  // namespace mp
