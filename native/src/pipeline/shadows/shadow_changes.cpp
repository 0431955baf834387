#include "pipeline/shadows/shadow_changes.h"

#include <algorithm>

namespace mp {

ShadowCasters shadow_casters(const Scene& scene, const ShadowGeometryKeys& keys) {
  ShadowCasters out;
  out.global = keys.global;
  out.all = geometry_fingerprint(keys);
  for (size_t i = 0; i < scene.meshes.size(); ++i) {
    const Mesh& m = scene.meshes[i];
    if (m.cast_shadows)
      out.surfaces.push_back({keys.meshes[i], surface_bounds(scene, m), !m.motion_object_to_world.empty()});
  }
  for (size_t i = 0; i < scene.bezier_patches.size(); ++i) {
    const BezierPatches& b = scene.bezier_patches[i];
    if (b.cast_shadows) out.surfaces.push_back({keys.patch_sets[i], surface_bounds(scene, b), false});
  }
  const std::vector<WorldBounds> boxes = instance_bounds(scene);
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    if (inst.cast_shadows)
      out.surfaces.push_back({keys.instances[i], boxes[i], !inst.motion_object_to_world.empty()});
  }
  std::sort(out.surfaces.begin(), out.surfaces.end(),
            [](const ShadowCaster& a, const ShadowCaster& b) { return a.key < b.key; });
  return out;
}

std::optional<std::vector<WorldBounds>> shadow_changes(const ShadowCasters& before, const ShadowCasters& after) {
  if (before.global != after.global) return std::nullopt;
  // Both lists are sorted by key: walk them together; equal keys (the same
  // surface, or equal duplicates) pair off, the rest changed.
  std::vector<WorldBounds> boxes;
  auto changed = [&](const ShadowCaster& c) {
    if (c.transform_motion || boxes.size() == kMaxShadowChanges) return false;
    boxes.push_back(c.bounds);
    return true;
  };
  size_t i = 0, j = 0;
  while (i < before.surfaces.size() || j < after.surfaces.size()) {
    if (j == after.surfaces.size() || (i < before.surfaces.size() && before.surfaces[i].key < after.surfaces[j].key)) {
      if (!changed(before.surfaces[i++])) return std::nullopt;
    } else if (i == before.surfaces.size() || after.surfaces[j].key < before.surfaces[i].key) {
      if (!changed(after.surfaces[j++])) return std::nullopt;
    } else {
      ++i, ++j;
    }
  }
  return boxes;
}

}  // namespace mp
