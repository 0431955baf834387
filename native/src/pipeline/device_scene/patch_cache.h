// Object-space device patches per surface shape, kept between renders.
//
// Building patches (OpenSubdiv refinement, Bezier conversion, welding shared
// edges) is the costly part of preparing a scene; placing them (transforming
// points and edge curves into camera space, tagging materials) is cheap. The
// cache builds each distinct shape once, in its own object space, and
// prepare_scene_data places it for every object that has that shape. So:
//   - a moved camera or object (viewport orbit, animation) re-places only;
//   - an edit rebuilds only the edited shape;
//   - duplicates and instances of one mesh are built once per scene;
//   - distinct shapes missing from the cache are built in parallel.
// Entries that the last scene did not use are dropped when the next scene
// is prepared, so the cache holds at most two scenes' worth of shapes.
#pragma once

#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "micropoly/scene.h"
#include "subdiv/patch_buffer.h"

namespace mp {

class PatchCache {
 public:
  // One surface of a scene: a Mesh or a BezierPatches set (the other null).
  struct Surface {
    const Mesh* mesh = nullptr;
    const BezierPatches* set = nullptr;
  };
  // Object-space patches (shared edges welded, UVs for `uv_layers` layers,
  // material and flag fields of PatchInfo left 0) of every surface, in order;
  // surfaces of one shape get the same buffer. Throws mp::Error like the
  // builders do (a mesh OpenSubdiv rejects).
  std::vector<std::shared_ptr<const PatchBuffer>> shapes(const std::vector<Surface>& surfaces, int uv_layers);

  size_t hits() const { return hits_; }      // over the cache's life
  size_t builds() const { return builds_; }

 private:
  struct Entry {
    std::shared_ptr<const PatchBuffer> patches;
    size_t points = 0, faces = 0;  // checked on a hit, against key collisions
    uint64_t last_use = 0;
  };
  std::unordered_map<uint64_t, Entry> entries_;
  uint64_t scene_ = 0;
  size_t hits_ = 0, builds_ = 0;
};

}  // namespace mp
