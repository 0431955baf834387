#include "pipeline/device_scene/patch_cache.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>

#include "geometry/mp_patch.h"
#include "pipeline/device_scene/scene_fingerprint.h"

namespace mp {
namespace {

std::shared_ptr<const PatchBuffer> build_shape(const PatchCache::Surface& s, int uv_layers) {
  auto buffer = std::make_shared<PatchBuffer>();
  buffer->uv_layers = uv_layers;
  const glm::mat4 identity(1.0f);
  if (s.mesh) {
    const Mesh& m = *s.mesh;
    if (m.scheme == SubdivScheme::CatmullClark)
      append_subdiv_patches(m, identity, *buffer);
    else
      append_polygon_patches(m, identity, *buffer);
  } else {
    append_bezier_patches(*s.set, identity, *buffer);
  }
  share_patch_edges(*buffer, 0);
  // Materials and flags belong to the object, not the shape: placed later
  // (all but MP_PATCH_SHAPE_FLAGS, which are the shape's).
  for (glm::uvec4& info : buffer->info) info.y = 0, info.z &= MP_PATCH_SHAPE_FLAGS;
  return buffer;
}

// Runs build(i) for i in [0, n) over up to hardware_concurrency threads; the
// first exception is rethrown once all threads have stopped.
template <typename F>
void parallel_for(size_t n, F build) {
  const size_t threads = std::min<size_t>(n, std::max(1u, std::thread::hardware_concurrency()));
  if (threads <= 1) {
    for (size_t i = 0; i < n; ++i) build(i);
    return;
  }
  std::atomic<size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&] {
    for (size_t i; (i = next++) < n;) {
      try {
        build(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        next = n;
      }
    }
  };
  std::vector<std::thread> pool;
  for (size_t t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace

std::vector<std::shared_ptr<const PatchBuffer>> PatchCache::shapes(const std::vector<Surface>& surfaces,
                                                                    int uv_layers) {
  ++scene_;
  std::vector<uint64_t> keys(surfaces.size());
  std::vector<size_t> missing;  // first surface of each shape to build
  std::unordered_map<uint64_t, size_t> building;
  for (size_t i = 0; i < surfaces.size(); ++i) {
    const Surface& s = surfaces[i];
    keys[i] = s.mesh ? mesh_shape_key(*s.mesh, uv_layers) : patch_set_shape_key(*s.set, uv_layers);
    const size_t points = s.mesh ? s.mesh->points.size() : s.set->control_points.size();
    const size_t faces = s.mesh ? s.mesh->face_vertex_counts.size() : 0;
    auto it = entries_.find(keys[i]);
    if (it != entries_.end() && (it->second.points != points || it->second.faces != faces)) {
      entries_.erase(it);  // a key collision: rebuild rather than trust it
      it = entries_.end();
    }
    if (it != entries_.end()) {
      it->second.last_use = scene_;
      ++hits_;
    } else if (building.emplace(keys[i], i).second) {
      missing.push_back(i);
    } else {
      ++hits_;  // a second surface of a shape built for this scene
    }
  }
  std::vector<std::shared_ptr<const PatchBuffer>> built(missing.size());
  parallel_for(missing.size(), [&](size_t k) { built[k] = build_shape(surfaces[missing[k]], uv_layers); });
  builds_ += missing.size();
  for (size_t k = 0; k < missing.size(); ++k) {
    const Surface& s = surfaces[missing[k]];
    Entry& e = entries_[keys[missing[k]]];
    e.patches = built[k];
    e.points = s.mesh ? s.mesh->points.size() : s.set->control_points.size();
    e.faces = s.mesh ? s.mesh->face_vertex_counts.size() : 0;
    e.last_use = scene_;
  }
  std::vector<std::shared_ptr<const PatchBuffer>> out(surfaces.size());
  for (size_t i = 0; i < surfaces.size(); ++i) out[i] = entries_.at(keys[i]).patches;
  // Keep this scene's and the previous scene's shapes (an undo or a toggled
  // object brings them back); drop older ones.
  for (auto it = entries_.begin(); it != entries_.end();)
    it = it->second.last_use + 1 < scene_ ? entries_.erase(it) : std::next(it);
  return out;
}

}  // namespace mp
