// What changed in the shadow-casting surfaces from one frame to the next, so
// that the shadow maps render again only the pages a change reaches (an
// object moved in the viewport, an animated one in the next frame) and keep
// the rest. Surfaces are matched by their keys (scene_fingerprint.h), not by
// their place in the Scene, so objects added, removed or reordered are told
// apart from those that stay. Pure host work.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "micropoly/scene.h"
#include "pipeline/device_scene/scene_fingerprint.h"
#include "pipeline/shadows/shadow_layout.h"

namespace mp {

struct ShadowCaster {
  uint64_t key = 0;
  WorldBounds bounds;
  // Moved by a transform over the shutter: where its shadow-view geometry
  // lies is not bounded by the box (rotations interpolate along arcs).
  bool transform_motion = false;
};

struct ShadowCasters {
  uint64_t global = 0;                 // ShadowGeometryKeys::global
  uint64_t all = 0;                    // geometry_fingerprint
  std::vector<ShadowCaster> surfaces;  // those that cast shadows, by key
};

// The scene's shadow-casting surfaces, from its keys (shadow_geometry_keys).
ShadowCasters shadow_casters(const Scene& scene, const ShadowGeometryKeys& keys);

// At most this many changed surfaces are told apart; more change everything.
constexpr size_t kMaxShadowChanges = 64;

// The boxes of the surfaces in one frame and not the other (where they were
// and where they are), or nothing where every page may have changed: the
// global key differs, a changed surface moves over the shutter, or more than
// kMaxShadowChanges changed.
std::optional<std::vector<WorldBounds>> shadow_changes(const ShadowCasters& before, const ShadowCasters& after);

}  // namespace mp
