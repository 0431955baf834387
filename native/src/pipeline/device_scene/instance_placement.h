// Instances on the device (kernels/geometry/mp_instance.h): each prototype
// surface an instance places is built and uploaded once, in its own space,
// in the variant its instances ask for (RIB's material, sidedness and
// orientation at ObjectInstance; most scenes have one per surface); each
// instance then costs one DeviceInstance and one DeviceObject per surface
// of its prototype, never a copy of its patches.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

#include "micropoly/scene.h"
#include "pipeline/device_scene/patch_cache.h"

namespace mp {

struct HostSceneData;

struct PrototypeVariants {
  std::deque<Mesh> meshes;  // the variants' surfaces (stable addresses for PatchCache::Surface)
  std::deque<BezierPatches> sets;
  std::vector<PatchCache::Surface> surfaces;          // one per variant, to build
  std::vector<std::vector<uint32_t>> of_instance;     // per instance: its surfaces' variants (meshes, then sets)
};
PrototypeVariants prototype_variants(const Scene& scene);

// Appends the variants' patches (shapes: PatchCache's, one per variant) after
// the patches placed on their own, with each variant's tree of patches, and
// the instances' records, objects and motion rows. Throws mp::Error where
// the roots exceed 2^32.
void place_instances(const Scene& scene, const PrototypeVariants& variants,
                     const std::vector<std::shared_ptr<const PatchBuffer>>& shapes, HostSceneData& out);

}  // namespace mp
